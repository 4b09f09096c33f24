// The measures' table (search.hpp): the shape and frequency measures that every evaluation carries
// and the locomotion measure of searches that read it (EvaluationResult -> Fitness), their ranges
// (animat.qd.DESCRIPTORS') and their names.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "animat/body.hpp"
#include "animat/config.hpp"
#include "animat/development.hpp"
#include "animat/errors.hpp"
#include "animat/evaluate.hpp"
#include "animat/evolution.hpp"
#include "animat/genome.hpp"
#include "animat/locomotion.hpp"
#include "animat/random.hpp"
#include "animat/search.hpp"
#include "animat/shape.hpp"
#include "animat/wire.hpp"

using namespace animat;

namespace {

/// numpy's median of the cells' frequencies.
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2.0;
}

}  // namespace

TEST(Measures, ShapeAndFrequencyHaveQdsRangesAndReadTheirFitnessFields) {
  const Config c;
  Fitness f;
  f.elongation = 2.5;
  f.protrusions = 3;
  f.symmetric_pair = 1;
  f.concavity = 0.125;
  f.frequency = 4.25;
  f.locomotion = 3;
  struct Row {
    const char* name;
    double lo, hi, value;
  };
  for (const Row& r : {Row{"elongation", 1.0, 4.0, 2.5}, Row{"protrusions", 0.0, 8.0, 3.0},
                       Row{"symmetric_pair", 0.0, 2.0, 1.0}, Row{"concavity", 0.0, 0.5, 0.125},
                       Row{"frequency", 0.5, 6.0, 4.25}, Row{"locomotion", 0.0, 6.0, 3.0}}) {
    const Measure& m = find_measure(r.name, c, "search.descriptors");
    EXPECT_EQ(std::string(m.name), r.name);
    EXPECT_EQ(m.lo, r.lo) << r.name;
    EXPECT_EQ(m.hi, r.hi) << r.name;
    EXPECT_EQ(m.of(f), r.value) << r.name;
  }
  std::set<std::string> names;
  for (const Measure& m : measures()) EXPECT_TRUE(names.insert(m.name).second) << m.name;
}

TEST(Measures, TheDefaultDescriptorsAreMeasuresOfTheEngine) {
  const Config c;
  ASSERT_EQ(c.search.descriptors, (std::vector<std::string>{"elongation", "protrusions"}));
  for (const std::string& name : c.search.descriptors)
    EXPECT_EQ(std::string(find_measure(name, c, "search.descriptors").name), name);
}

TEST(Measures, AnUnknownNameIsRefusedNamingTheKeyAndListingTheMeasures) {
  const Config c;
  try {
    (void)find_measure("gait", c, "search.descriptors");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("search.descriptors: no measure \"gait\""), std::string::npos) << what;
    EXPECT_NE(
        what.find("elongation, protrusions, symmetric_pair, concavity, frequency, locomotion"),
        std::string::npos)
        << what;
  }
}

TEST(Measures, AnEvaluationCarriesTheShapeAndFrequencyOfItsBody) {
  Config c;
  c.evaluation.steps = 20;
  Rng rng(11);
  for (int k = 0; k < 8; ++k) {
    const Genome g = random_viable_genome(c, rng);
    const Fitness f = fitness_of(evaluate(g, c));
    ASSERT_TRUE(f.viable) << k;
    const Embryo e = develop(g, c.genome, c.grn, c.development);
    const Body body = build_body(e, c.body);
    const Shape sh = body_shape(body);
    EXPECT_EQ(f.elongation, sh.elongation) << k;
    EXPECT_EQ(f.protrusions, static_cast<int>(sh.protrusions.size())) << k;
    EXPECT_EQ(f.symmetric_pair, sh.symmetric_pairs.empty() ? 0 : 1) << k;
    EXPECT_EQ(f.concavity, sh.concavity) << k;
    EXPECT_EQ(f.frequency,
              median(std::vector<double>(body.frequency.data(),
                                         body.frequency.data() + body.frequency.size())))
        << k;
    EXPECT_GE(f.elongation, 1.0) << k;
  }
}

TEST(Measures, ANonViableEvaluationHasZeroMeasures) {
  Config c;
  c.evaluation.steps = 20;
  Rng rng(5);
  Fitness f;
  f.viable = true;
  for (int k = 0; k < 200 && f.viable; ++k)
    f = fitness_of(evaluate(random_genome(c.genome, rng), c));
  ASSERT_FALSE(f.viable) << "no random genome of 200 is non-viable";
  EXPECT_EQ(f.elongation, 0.0);
  EXPECT_EQ(f.protrusions, 0);
  EXPECT_EQ(f.symmetric_pair, 0);
  EXPECT_EQ(f.concavity, 0.0);
  EXPECT_EQ(f.frequency, 0.0);
  EXPECT_EQ(f.locomotion, -1);
}

TEST(Measures, LocomotionIsMeasuredOnlyWhenTheSearchReadsIt) {
  Config c;
  EXPECT_FALSE(needs_locomotion(c));  // the GA
  c.search.algorithm = "map_elites";
  EXPECT_FALSE(needs_locomotion(c));  // elongation, protrusions
  c.search.descriptors = {"cells", "locomotion"};
  EXPECT_TRUE(needs_locomotion(c));
  c.search.algorithm = "nsga2";
  EXPECT_FALSE(needs_locomotion(c));  // its objectives do not name it
  c.search.objectives = {"distance:max", "locomotion:min"};
  EXPECT_TRUE(needs_locomotion(c));
  c.search.objectives = {"locomotion", "distance"};
  EXPECT_TRUE(needs_locomotion(c));
  c.search.objectives = {"locomotion_x:max", "distance"};
  EXPECT_FALSE(needs_locomotion(c));
  c.search.algorithm = "ga";
  EXPECT_FALSE(needs_locomotion(c));
}

TEST(Measures, AnEvaluationClassifiesItsSwimOnlyWhenTheSearchReadsLocomotion) {
  Config ga;
  ga.evaluation.steps = 240;
  Config qd = ga;
  qd.search.algorithm = "map_elites";
  qd.search.descriptors = {"locomotion", "cells"};
  Rng rng(11);
  for (int k = 0; k < 4; ++k) {
    const Genome g = random_viable_genome(ga, rng);
    const Fitness plain = fitness_of(evaluate(g, ga));
    const Fitness measured = fitness_of(evaluate(g, qd));
    EXPECT_EQ(plain.locomotion, -1) << k;
    ASSERT_GE(measured.locomotion, 0) << k;
    EXPECT_LE(measured.locomotion, static_cast<int>(Locomotion::none)) << k;
    Fitness same = measured;
    same.locomotion = -1;
    EXPECT_EQ(same, plain) << k;  // recording the window changes nothing else
  }
}

TEST(Measures, TheLocomotionFieldTravelsOnTheWire) {
  Fitness f{2.5, true, true, 32};
  f.locomotion = static_cast<int>(Locomotion::tail);
  wire::Writer w;
  w.fitness(f);
  wire::Reader r(w.bytes());
  EXPECT_EQ(r.fitness(), f);
  EXPECT_TRUE(r.done());
  EXPECT_EQ(Fitness{}.locomotion, -1);  // not measured
}
