// Draws random genomes until one develops into a viable embryo whose body has actuated cells,
// builds that body and swims it for 100 control steps at the default parameters; prints the
// distance its centre of mass moved.
#include <cstdint>
#include <cstdio>

#include "animat/body.hpp"
#include "animat/config.hpp"
#include "animat/development.hpp"
#include "animat/evaluate.hpp"
#include "animat/genome.hpp"
#include "animat/random.hpp"

int main() {
  const animat::Config config;  // every section at its defaults (the paper's settings)
  for (std::uint64_t tries = 1; tries <= 100000; ++tries) {
    animat::Rng rng = animat::Rng::derive(1, tries);
    const animat::Genome genome = animat::random_genome(config.genome, rng);
    const animat::Embryo embryo =
        animat::develop(genome, config.genome, config.grn, config.development);
    if (!embryo.viable) continue;
    const animat::Body body = animat::build_body(embryo, config.body);
    // no cell oscillates: it would not move
    if (body.amplitude.cwiseAbs().maxCoeff() == 0.0) continue;
    const animat::SwimResult swim = animat::swim(body, config.scene, config.physics, 100);
    std::printf("viable genome after %llu tries: %d cells; swum 100 steps: distance %.6g (%s)\n",
                static_cast<unsigned long long>(tries), embryo.cell_count(), swim.distance,
                swim.valid ? "valid" : swim.failure.c_str());
    return swim.stable ? 0 : 1;
  }
  std::printf("no viable genome in 100000 tries\n");
  return 1;
}
