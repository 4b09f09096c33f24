#include <cstdio>
#include <cstdlib>
#include <array>
#include "animat/config.hpp"
#include "animat/evaluate.hpp"
#include "animat/development.hpp"
#include "animat/body.hpp"
#include "animat/embedding.hpp"
#include "animat/physics.hpp"
#include "animat/random.hpp"
using namespace animat;
int main(int argc, char** argv) {
  long seed = std::atol(argv[1]); int k = std::atoi(argv[2]);
  Config config;
  Rng rng = Rng::derive(20120707, static_cast<std::uint64_t>(seed));
  const Genome g = random_genome(config.genome, rng);
  Body b = build_body(develop(g, config.genome, config.grn, config.development));
  b.amplitude.setConstant(0.2); b.frequency.setConstant(config.development.frequency_max);
  SceneParams scene; scene.drag_normal = std::array<double,4>{0.2,0.5,2.0,10.0}[k % 4];
  std::printf("cells %d skin %ld regions %d dn %g\n", b.node_count(), (long)b.skin.rows(), b.region_count(), scene.drag_normal);
  for (auto& loop : b.skin_loops) { std::printf("skin loop:"); for (int v : loop) std::printf(" %d", v); std::printf("\n"); }
  Simulation sim(b, scene);
  sim.monitor_embedding(b);
  Points prev = sim.positions();
  for (int s = 0; s < 4000; ++s) {
    sim.step();
    if (sim.first_broken_step() >= 0) {
      Points x = sim.positions();
      std::printf("broken at step %d, collisions %ld\n", s, sim.counters().collisions);
      for (int e = 0; e < b.skin.rows(); ++e) for (int f = e + 1; f < b.skin.rows(); ++f) {
        int a = b.skin(e,0), bb = b.skin(e,1), c = b.skin(f,0), d = b.skin(f,1);
        if (a==c||a==d||bb==c||bb==d) continue;
        if (segments_intersect(x(a,0),x(a,1),x(bb,0),x(bb,1),x(c,0),x(c,1),x(d,0),x(d,1))) {
          std::printf("cross %d-%d x %d-%d\n", a, bb, c, d);
          for (int v : {a,bb,c,d}) std::printf("  %d: (%.6f,%.6f) -> (%.6f,%.6f)\n", v, prev(v,0), prev(v,1), x(v,0), x(v,1));
        }
      }
      return 0;
    }
    prev = sim.positions();
  }
  std::printf("never broke\n");
}
