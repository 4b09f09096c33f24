// MAP-Elites and its grid archive (search.hpp), checked in milliseconds with a cheap deterministic
// stub fitness: the grid's bins, bounded sizes, an atomic tell, thread-count invariance and
// checkpoints that are checked on load.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>

#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/evaluator.hpp"
#include "animat/search.hpp"
#include "search_support.hpp"
#include "test_support.hpp"

using namespace animat;
using animat::test::expect_error;
using animat::test::refused_digit_changes;
using animat::test::reseal;
using animat::test::search_stub;
using animat::test::without_wall;

namespace {

Config me_config(int threads = 1) {
  Config c;
  c.search.algorithm = "map_elites";
  c.search.descriptors = {"cells", "fitness"};
  c.search.bins = {8.0, 5.0};
  c.search.batch = 12;
  c.evolution.seed = 3;
  c.evolution.threads = threads;
  c.evaluation.reference_check = "off";
  return c;
}

MapElites make(const Config& c) {
  return MapElites(c, search_stub, {}, make_local_evaluator(search_stub, c.evolution.threads));
}

}  // namespace

TEST(Archive, BinsFollowTheEdgesAndClipOutsideTheRange) {
  Config c = me_config();
  const Measure* cells = &find_measure("cells", c, "search.descriptors");
  const Measure* fitness = &find_measure("fitness", c, "search.descriptors");
  Archive a({cells, fitness}, {8, 5});  // cells: edges 1, 9, 17, ..., 65; fitness: 0, 10, ...
  EXPECT_EQ(a.cells(), 40U);
  const auto at = [&](double x, double y) {
    const double v[] = {x, y};
    return a.index_of(v);
  };
  EXPECT_EQ(at(1, 0), 0U);
  EXPECT_EQ(at(8.999, 9.999), 0U);
  EXPECT_EQ(at(9, 10), 1U * 5 + 1);  // a value on an interior edge belongs to the bin above
  EXPECT_EQ(at(64.9, 49.9), 7U * 5 + 4);
  EXPECT_EQ(at(65, 50), 7U * 5 + 4);  // hi itself: the last bin
  EXPECT_EQ(at(-3, -1), 0U);          // below lo: the first bin
  EXPECT_EQ(at(1e9, 1e9), 7U * 5 + 4);
}

TEST(Archive, RangesOtherThanTheTablesPlaceTheEdges) {
  Config c = me_config();
  const Measure* cells = &find_measure("cells", c, "search.descriptors");
  Archive a({cells}, {4}, {{10.0, 30.0}});  // edges 10, 15, 20, 25, 30
  ASSERT_EQ(a.ranges().size(), 1U);
  EXPECT_EQ(a.ranges()[0].lo, 10.0);
  EXPECT_EQ(a.ranges()[0].hi, 30.0);
  const auto at = [&](double x) {
    const double v[] = {x};
    return a.index_of(v);
  };
  EXPECT_EQ(at(1), 0U);  // below lo (the table's lo is 1): the first bin
  EXPECT_EQ(at(14.999), 0U);
  EXPECT_EQ(at(15), 1U);
  EXPECT_EQ(at(29.999), 3U);
  EXPECT_EQ(at(64), 3U);  // at or above hi: the last bin
  Archive table({cells}, {4});
  EXPECT_EQ(table.ranges()[0].lo, cells->lo);
  EXPECT_EQ(table.ranges()[0].hi, cells->hi);
}

TEST(Archive, ARangeThatIsNotFiniteLoBelowHiIsRefusedNamingTheKey) {
  Config c = me_config();
  const Measure* cells = &find_measure("cells", c, "search.descriptors");
  for (const Range r :
       {Range{3.0, 3.0}, Range{5.0, 1.0}, Range{0.0, std::numeric_limits<double>::infinity()},
        Range{std::numeric_limits<double>::quiet_NaN(), 1.0}}) {
    SCOPED_TRACE(fmt::format("[{}, {}]", r.lo, r.hi));
    expect_error([&] { Archive a({cells}, {4}, {r}); }, {"search.ranges: the range of \"cells\""});
  }
  EXPECT_THROW(Archive({cells}, {4}, {{0.0, 1.0}, {0.0, 1.0}}), ConfigError);
}

TEST(Archive, ACvtValueGoesToTheNearestCentroidAfterScalingAndClipping) {
  Config c = me_config();
  const std::vector<const Measure*> d = {&find_measure("cells", c, "k"),
                                         &find_measure("fitness", c, "k")};
  // unit cube corners and its centre; ranges [0, 10) and [0, 100)
  const Archive a = Archive::cvt(d, {{0.0, 10.0}, {0.0, 100.0}},
                                 {{0.0, 0.0}, {1.0, 1.0}, {0.5, 0.5}, {1.0, 0.0}});
  EXPECT_EQ(a.kind(), "cvt");
  EXPECT_EQ(a.cells(), 4U);
  EXPECT_TRUE(a.bins().empty());
  EXPECT_EQ(a.index_of(std::vector<double>{1.0, 5.0}), 0U);
  EXPECT_EQ(a.index_of(std::vector<double>{5.0, 50.0}), 2U);
  EXPECT_EQ(a.index_of(std::vector<double>{9.0, 10.0}), 3U);
  EXPECT_EQ(a.index_of(std::vector<double>{1e9, 1e9}), 1U);    // clipped to (1, 1)
  EXPECT_EQ(a.index_of(std::vector<double>{-5.0, -1.0}), 0U);  // clipped to (0, 0)
  // (0.5, 0) is as near to (0, 0), (0.5, 0.5) and (1, 0): the lowest index
  EXPECT_EQ(a.index_of(std::vector<double>{5.0, 0.0}), 0U);
  EXPECT_EQ(nearest_centroid(std::vector<double>{0.75, 0.25}, a.centroids()), 2U);
}

TEST(Archive, CvtCentroidsOutsideTheUnitCubeOrOfTheWrongShapeAreRefused) {
  Config c = me_config();
  const std::vector<const Measure*> d = {&find_measure("cells", c, "k")};
  const std::vector<Range> r = {{0.0, 10.0}};
  expect_error([&] { (void)Archive::cvt(d, r, {}); }, {"centroids: 0 rows"});
  expect_error([&] { (void)Archive::cvt(d, r, {{0.5}, {1.5}}); }, {"centroids: row 1 holds 1.5"});
  expect_error([&] { (void)Archive::cvt(d, r, {{std::nan("")}}); }, {"centroids: row 0 holds nan"});
  expect_error([&] { (void)Archive::cvt(d, r, {{0.5, 0.5}}); }, {"row 0 has 2 values for the 1"});
}

TEST(MapElites, CvtSizesAreRefusedNamingTheKeyBeforeTheSearchIsMade) {
  Config c = me_config();
  c.search.archive = "cvt";
  c.search.cells = 20;
  c.search.samples = 200;
  const MapElites me = make(c);
  EXPECT_EQ(me.archive().centroids(), cvt_centroids(2, 20, 3, 200));
  c.search.cells = 1000000;
  c.search.samples = 0;
  expect_error([&] { validate(c); }, {"search.cells = 1000000 with search.samples = 20000000"});
  expect_error([&] { (void)make(c); }, {"search.cells = 1000000"});
  c.search.cells = 20;
  c.search.samples = 10;
  expect_error([&] { (void)make(c); }, {"search.samples = 10: fewer samples than the 20 cells"});
}

TEST(MapElites, TheStallRuleStopsAfterGenerationsWithoutANewOrBetterElite) {
  Config c = me_config();
  c.evolution.stall_generations = 2;
  MapElites me = make(c);
  const auto same = [](const std::vector<Genome>& genomes) {
    Fitness f;
    f.viable = f.stable = f.valid = true;
    f.fitness = 5.0;
    f.cell_count = 9;
    return std::vector<Fitness>(genomes.size(), f);
  };
  me.tell(same(me.ask()));  // generation 0 fills one cell
  EXPECT_EQ(me.stop_reason(), "");
  me.tell(same(me.ask()));
  EXPECT_EQ(me.stop_reason(), "");
  me.tell(same(me.ask()));
  EXPECT_EQ(me.stop_reason(),
            "no elite added or improved for evolution.stall_generations = 2 generations");
}

TEST(Archive, AnEliteIsReplacedOnlyByAStrictlyBetterCandidate) {
  Config c = me_config();
  Archive a({&find_measure("cells", c, "k")}, {4});
  Elite e;
  e.descriptors = {5.0};
  e.objective = 2.0;
  EXPECT_TRUE(a.add(e));
  EXPECT_FALSE(a.add(e));  // a tie keeps the elite
  e.objective = 3.0;
  EXPECT_TRUE(a.add(e));
  e.descriptors = {60.0};
  e.objective = 0.5;
  EXPECT_TRUE(a.add(e));
  EXPECT_EQ(a.elites().size(), 2U);
  EXPECT_DOUBLE_EQ(a.qd_score(), 3.5);
  EXPECT_DOUBLE_EQ(a.coverage(), 0.5);
  EXPECT_EQ(a.best()->objective, 3.0);
}

TEST(Archive, ExactSumIsMathFsum) {
  const double terms[] = {1e16, 1.0, -1e16, 1.0};
  EXPECT_EQ(exact_sum(terms), 2.0);  // a plain sum gives 0 or 1
  const double tenths[] = {0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1};
  EXPECT_EQ(exact_sum(tenths), 1.0);
  EXPECT_EQ(exact_sum({}), 0.0);
}

TEST(MapElites, TooManyCellsAreRefusedNamingTheKeyAndValue) {
  Config c = me_config();
  c.search.bins = {100000.0};
  expect_error([&] { (void)make(c); }, {"search.bins = [100000, 100000]", "1e+10 cells"});
  // Four descriptors of 100000 bins: 1e20 cells, past what an int64 holds, refused the same way.
  c.search.descriptors = {"cells", "fitness", "cells", "fitness"};
  EXPECT_THROW((void)make(c), ConfigError);
}

TEST(MapElites, DescriptorsOutsideTheTableOrWithoutARangeAreRefusedByName) {
  Config c = me_config();
  c.search.descriptors = {"shade", "cells"};
  expect_error([&] { (void)make(c); }, {"search.descriptors: no measure \"shade\""});
  c.search.descriptors = {"actuation_work_positive", "cells"};
  expect_error([&] { (void)make(c); }, {"give the descriptors' ranges in search.ranges"});
  // With search.ranges, a measure without a range of its own is a descriptor.
  c.search.ranges = {0.0, 100.0, 1.0, 65.0};
  const MapElites me = make(c);
  EXPECT_EQ(me.archive().ranges()[0].hi, 100.0);
  EXPECT_EQ(me.archive().ranges()[1].lo, 1.0);
  c.search.ranges = {0.0, 100.0, 1.0};
  expect_error([&] { (void)make(c); }, {"search.ranges: 3 numbers"});
}

TEST(MapElites, SearchRangesAreCheckedWithTheConfig) {
  Config c = me_config();
  c.search.ranges = {0.0, 100.0};
  expect_error([&] { validate(c); }, {"search.ranges = [0.0, 100.0]: give lo and hi for each of "
                                      "the 2 of search.descriptors"});
  c.search.ranges = {0.0, 100.0, 7.0, 7.0};
  expect_error([&] { validate(c); },
               {"the range of \"fitness\", [7.0, 7.0], is not finite lo < hi"});
  c.search.ranges = {0.0, 100.0, 0.0, 7.0};
  EXPECT_NO_THROW(validate(c));
}

TEST(MapElites, FirstGenerationIsRandomViableGenomesThenOffspringOfElites) {
  const Config c = me_config();
  MapElites me = make(c);
  const std::vector<Genome> first = me.ask();
  ASSERT_EQ(first.size(), 12U);
  for (std::size_t i = 0; i < first.size(); ++i) {
    Rng rng = Rng::derive(3, 0, i);
    EXPECT_EQ(first[i], random_viable_genome(c, rng)) << i;
  }
  EXPECT_EQ(me.ask(), first);  // asking again: the same genomes
  me.step();
  EXPECT_EQ(me.generation(), 0);
  EXPECT_GT(me.archive().elites().size(), 0U);
  me.step();
  me.step();
  const auto h = me.history();
  ASSERT_EQ(h.size(), 3U);
  for (std::size_t k = 0; k < h.size(); ++k) {
    EXPECT_EQ(h[k][0], static_cast<double>(k));
    EXPECT_EQ(h[k][1], 12.0 * static_cast<double>(k + 1));  // evaluations
  }
  EXPECT_EQ(h.back()[5], static_cast<double>(me.archive().elites().size()));
  EXPECT_EQ(h.back()[2], me.archive().qd_score());
  for (const auto& [cell, e] : me.archive().elites()) {
    EXPECT_EQ(cell, me.archive().index_of(e.descriptors));
    EXPECT_EQ(e.objective, search_stub(e.genome).fitness);
  }
}

TEST(MapElites, ResultsDoNotDependOnTheThreadCount) {
  MapElites one = make(me_config(1)), two = make(me_config(2));
  for (int g = 0; g < 4; ++g) {
    one.step();
    two.step();
  }
  EXPECT_EQ(without_wall(one.history()), without_wall(two.history()));
  EXPECT_EQ(one.ask(), two.ask());
}

TEST(MapElites, ARefusedTellChangesNothing) {
  MapElites me = make(me_config());
  me.step();
  const std::vector<Genome> asked = me.ask();
  const std::string before = me.checkpoint();
  std::vector<Fitness> told;
  for (const Genome& g : asked) told.push_back(search_stub(g));
  for (const double bad : {std::numeric_limits<double>::infinity(), std::nan(""), -2.0, 1e308}) {
    std::vector<Fitness> f = told;
    std::size_t k = 0;
    while (!f[k].viable) ++k;
    f[k].fitness = bad;
    SCOPED_TRACE(fmt::format("fitness {}", bad));
    // 1e308 is finite, but the QD-score of two such elites would overflow
    expect_error<Error>([&] { me.tell(f); }, {fmt::format("value {}", k), "fitness",
                                              bad == 1e308 ? "QD-score" : "fitness"});
    EXPECT_EQ(me.checkpoint(), before);
    EXPECT_EQ(me.ask(), asked);
  }
  EXPECT_THROW(me.tell(std::vector<Fitness>(told.size() - 1)), Error);
  EXPECT_EQ(me.checkpoint(), before);
  EXPECT_TRUE(me.tell(told));
  EXPECT_EQ(me.generation(), 1);
}

TEST(MapElites, CheckpointRestoreContinuesIdentically) {
  const Config c = me_config();
  MapElites straight = make(c), first = make(c);
  for (int g = 0; g < 5; ++g) straight.step();
  for (int g = 0; g < 2; ++g) first.step();
  MapElites resumed = make(c);
  resumed.restore(first.checkpoint(), "checkpoint.json");
  EXPECT_EQ(resumed.history(), first.history());
  for (int g = 0; g < 3; ++g) resumed.step();
  EXPECT_EQ(without_wall(resumed.history()), without_wall(straight.history()));
  EXPECT_EQ(resumed.ask(), straight.ask());
}

TEST(MapElites, CorruptOrHandEditedCheckpointsAreRefused) {
  const Config c = me_config();
  MapElites me = make(c);
  me.step();
  me.step();
  const std::string text = me.checkpoint();
  // Every one-digit change of the text is refused (the checksum, or the JSON, catches it).
  const auto [refused, changed] = refused_digit_changes(text, 97, [&](const std::string& bad) {
    MapElites target = make(c);
    target.restore(bad, "ckpt");
  });
  EXPECT_GT(changed, 5);
  EXPECT_EQ(refused, changed);
  // Hand edits with a valid checksum: what the engine could never have written.
  const auto refuses = [&](const std::function<void(nlohmann::json&)>& edit, const char* what) {
    MapElites target = make(c);
    try {
      target.restore(reseal(text, edit), "ckpt");
      ADD_FAILURE() << "accepted: " << what;
    } catch (const CheckpointError& e) {
      EXPECT_NE(std::string(e.what()).find("ckpt"), std::string::npos) << e.what();
    }
  };
  refuses([](nlohmann::json& p) { p["elites"][0]["result"]["fitness"] = 49.0; }, "fitness");
  refuses([](nlohmann::json& p) { p["elites"][0]["cell"] = 39; }, "cell");
  refuses([](nlohmann::json& p) { p["generation"] = 5; }, "generation");
  refuses([](nlohmann::json& p) { p["evaluations"] = 7; }, "evaluations");
  refuses([](nlohmann::json& p) { p["history"][1]["qd_score"] = 1.0; }, "qd_score");
  refuses([](nlohmann::json& p) { p["elites"][0]["result"]["viable"] = false; }, "viable");
  refuses([](nlohmann::json& p) { p["format"] = "animat.nsga2"; }, "format");
  // Another run's configuration (its identity).
  Config other = c;
  other.search.bins = {4.0};
  MapElites foreign = make(other);
  EXPECT_THROW(foreign.restore(text, "ckpt"), CheckpointError);
}

TEST(MapElites, TheRecordGuardEvaluatesEachNewEliteAtTheReferenceStep) {
  Config c = me_config();
  c.evaluation.reference_check = "record";
  int references = 0;
  std::mutex m;
  const FitnessFunction reference = [&](const Genome& g) {
    std::lock_guard<std::mutex> lock(m);
    ++references;
    Fitness f = search_stub(g);
    f.fitness *= 0.5;  // disagrees with the nominal fitness
    return f;
  };
  MapElites me(c, search_stub, reference, make_local_evaluator(search_stub, 1));
  me.step();
  const auto row = me.history().back();
  EXPECT_EQ(row[8], static_cast<double>(references));  // reference_evaluations
  EXPECT_EQ(row[8], static_cast<double>(me.archive().elites().size()));
  int disagree = 0;
  for (const auto& [cell, e] : me.archive().elites()) {
    EXPECT_EQ(e.reference, 0.5 * e.result.fitness);
    disagree += reference_disagrees(e.result.fitness, e.reference, c.evaluation) ? 1 : 0;
  }
  EXPECT_EQ(row[9], static_cast<double>(disagree));
}

TEST(MapElites, TheSelectGuardComparesTheReferenceFitness) {
  Config c = me_config();
  c.evaluation.reference_check = "select";
  // The reference step reverses the ranking: an elite must be the best by its reference.
  const FitnessFunction reference = [](const Genome& g) {
    Fitness f = search_stub(g);
    f.fitness = 50.0 - f.fitness;
    return f;
  };
  MapElites me(c, search_stub, reference, make_local_evaluator(search_stub, 1));
  me.step();
  me.step();
  int candidates = 0;
  for (const auto& row : me.history()) candidates += 12 - static_cast<int>(row[7]);
  EXPECT_EQ(me.history().back()[8],
            static_cast<double>(candidates));  // every candidate's reference
  for (const auto& [cell, e] : me.archive().elites()) {
    EXPECT_EQ(e.reference, 50.0 - e.result.fitness);
    EXPECT_EQ(e.objective, e.reference);
  }
  EXPECT_EQ(me.history().back()[4], me.archive().best()->reference);
  MapElites resumed(c, search_stub, reference, make_local_evaluator(search_stub, 1));
  resumed.restore(me.checkpoint(), "checkpoint.json");
  EXPECT_EQ(resumed.history(), me.history());
  // The caller's reference swims (a hook) replace the engine's: the same search as above.
  MapElites hooked(c, search_stub, search_stub, make_local_evaluator(search_stub, 1));
  hooked.set_reference_hook([&](const std::vector<Genome>& genomes) {
    Search::ReferenceSwims out;
    for (const Genome& g : genomes) out.fitness.push_back(reference(g));
    return out;
  });
  hooked.step();
  hooked.step();
  EXPECT_EQ(without_wall(hooked.history()), without_wall(me.history()));
}

namespace {

// A descriptor the table lacks, its values the caller's: genome k of a batch gets (k mod 4) / 4.
Config supplied_config() {
  Config c = me_config();
  c.search.descriptors = {"shade", "cells"};
  c.search.bins = {4.0, 8.0};
  c.search.ranges = {0.0, 1.0, 1.0, 65.0};
  return c;
}

MapElites make_supplied(const Config& c) {
  return MapElites(c, search_stub, {}, make_local_evaluator(search_stub, c.evolution.threads),
                   {"shade"});
}

std::vector<std::vector<double>> shades(std::size_t n) {
  std::vector<std::vector<double>> out;
  for (std::size_t k = 0; k < n; ++k) out.push_back({static_cast<double>(k % 4) / 4.0});
  return out;
}

}  // namespace

TEST(MapElites, SuppliedDescriptorsAreTheCallersValues) {
  const Config c = supplied_config();
  MapElites me = make_supplied(c);
  ASSERT_EQ(me.supplied(), std::vector<std::string>{"shade"});
  for (int g = 0; g < 3; ++g) {
    const auto genomes = me.ask();
    std::vector<Fitness> told;
    for (const Genome& genome : genomes) told.push_back(search_stub(genome));
    ASSERT_TRUE(me.tell(told, shades(genomes.size())));
  }
  ASSERT_GE(me.archive().elites().size(), 3U);
  for (const auto& [cell, e] : me.archive().elites()) {
    EXPECT_EQ(cell / 8, static_cast<std::size_t>(e.descriptors[0] * 4.0));  // the shade's bin
    EXPECT_EQ(e.descriptors[1], static_cast<double>(e.result.cell_count));
  }
  // The checkpoint keeps the supplied values: a restore is the same archive.
  MapElites again = make_supplied(c);
  again.restore(me.checkpoint(), "checkpoint");
  ASSERT_EQ(again.archive().elites().size(), me.archive().elites().size());
  for (const auto& [cell, e] : me.archive().elites())
    EXPECT_EQ(again.archive().elites().at(cell).descriptors, e.descriptors);
}

TEST(MapElites, SuppliedValuesAreCheckedBeforeAnythingChanges) {
  const Config c = supplied_config();
  MapElites me = make_supplied(c);
  const auto genomes = me.ask();
  std::vector<Fitness> told;
  for (const Genome& genome : genomes) told.push_back(search_stub(genome));
  std::size_t k = 0;
  while (!(told[k].viable && told[k].stable && told[k].valid)) ++k;
  auto bad = shades(genomes.size());
  bad[k][0] = std::numeric_limits<double>::quiet_NaN();
  expect_error<Error>([&] { (void)me.tell(told, bad); },
                      {fmt::format("value {}", k), "descriptor shade = nan"});
  EXPECT_THROW((void)me.tell(told), Error);  // no rows
  EXPECT_THROW((void)me.tell(told, shades(genomes.size() - 1)), Error);
  EXPECT_EQ(me.generation(), -1);
  EXPECT_TRUE(me.archive().elites().empty());
  EXPECT_TRUE(me.tell(told, shades(genomes.size())));
  // Without search.ranges a supplied descriptor has no range; a table search refuses rows.
  Config no_ranges = c;
  no_ranges.search.ranges = {};
  EXPECT_THROW((void)make_supplied(no_ranges), ConfigError);
  MapElites plain = make(me_config());
  (void)plain.ask();
  EXPECT_THROW((void)plain.tell(told, shades(genomes.size())), Error);
}
