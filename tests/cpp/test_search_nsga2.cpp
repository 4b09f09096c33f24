// NSGA-II (search.hpp) and its pieces (dominance, non-dominated sort, crowding distance,
// hypervolume), checked in milliseconds with a cheap deterministic stub fitness: selection by
// fronts, bounded sizes, an atomic tell, thread-count invariance and checked checkpoints.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
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

constexpr double inf = std::numeric_limits<double>::infinity();

Config nsga_config(int threads = 1) {
  Config c;
  c.search.algorithm = "nsga2";
  c.search.objectives = {"distance:max", "actuation_work_positive:min"};
  c.evolution.population = 12;
  c.evolution.seed = 5;
  c.evolution.threads = threads;
  c.evaluation.reference_check = "off";
  return c;
}

Nsga2 make(const Config& c) {
  return Nsga2(c, search_stub, {}, make_local_evaluator(search_stub, c.evolution.threads));
}

}  // namespace

TEST(Pareto, DominanceSortCrowdingAndHypervolume) {
  const std::vector<double> a = {1, 2}, b = {2, 2}, c = {1, 2};
  EXPECT_TRUE(dominates(a, b));
  EXPECT_FALSE(dominates(b, a));
  EXPECT_FALSE(dominates(a, c));  // equal points: neither
  // Minimised: (1,4) (2,2) (4,1) are the first front; (3,3) is dominated by (2,2); (4,4) by all.
  const std::vector<std::vector<double>> points = {{3, 3}, {1, 4}, {4, 4}, {2, 2}, {4, 1}, {2, 2}};
  const auto fronts = non_dominated_sort(points);
  ASSERT_EQ(fronts.size(), 3U);
  EXPECT_EQ(fronts[0], (std::vector<std::size_t>{1, 3, 4, 5}));
  EXPECT_EQ(fronts[1], (std::vector<std::size_t>{0}));
  EXPECT_EQ(fronts[2], (std::vector<std::size_t>{2}));
  const auto d = crowding_distance({{1, 4}, {2, 2}, {4, 1}});
  EXPECT_EQ(d[0], inf);
  EXPECT_EQ(d[2], inf);
  EXPECT_DOUBLE_EQ(d[1], (4.0 - 1.0) / 3.0 + (4.0 - 1.0) / 3.0);
  EXPECT_EQ(crowding_distance({{1, 1}, {2, 2}}), (std::vector<double>{inf, inf}));
  // Staircase against (5, 5): 4*1 + 3*2 + 1*1 = 11.
  const double ref[] = {5, 5};
  EXPECT_EQ(hypervolume({{1, 4}, {2, 2}, {4, 1}, {6, 0}}, ref), 11.0);
  EXPECT_EQ(hypervolume({}, ref), 0.0);
  const double ref3[] = {5, 5, 5};
  EXPECT_THROW((void)hypervolume({{1, 1, 1}}, ref3), Error);
}

TEST(Nsga2, SettingsThatCannotRunAreRefusedNamingTheKey) {
  const auto message = [](const Config& c) -> std::string {
    try {
      (void)make(c);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "no error";
  };
  Config c = nsga_config();
  c.evolution.population = 20000;
  EXPECT_NE(message(c).find("evolution.population = 20000"), std::string::npos) << message(c);
  c = nsga_config();
  c.search.objectives = {"distance:max", "smoothness:min"};
  EXPECT_NE(message(c).find("search.objectives: no measure \"smoothness\""), std::string::npos)
      << message(c);
  c.search.objectives = {"distance:up"};
  EXPECT_NE(message(c).find("\"max\" or \"min\""), std::string::npos) << message(c);
  c.search.objectives = {"distance", "fitness"};  // the same criterion twice
  EXPECT_NE(message(c).find("twice"), std::string::npos) << message(c);
}

TEST(Nsga2, ThePopulationIsTheFirstFrontsOfParentsAndCandidates) {
  Nsga2 nsga = make(nsga_config());
  for (int g = 0; g < 4; ++g) nsga.step();
  EXPECT_EQ(nsga.generation(), 3);
  ASSERT_EQ(nsga.population().size(), 12U);
  const auto front = nsga.front();
  ASSERT_FALSE(front.empty());
  // No member of the population dominates a front member; front members are sorted by distance.
  for (const Solution* s : front) {
    const std::vector<double> mine = {-s->objectives[0], s->objectives[1]};
    for (const Solution& o : nsga.population()) {
      if (!o.feasible) continue;
      const std::vector<double> other = {-o.objectives[0], o.objectives[1]};
      EXPECT_FALSE(dominates(other, mine));
    }
    EXPECT_EQ(s->objectives[0], search_stub(s->genome).fitness);
  }
  for (std::size_t k = 1; k < front.size(); ++k)
    EXPECT_GE(front[k - 1]->objectives[0], front[k]->objectives[0]);
  const auto row = nsga.history().back();
  EXPECT_EQ(row[2], static_cast<double>(front.size()));
  EXPECT_EQ(row[4], front[0]->objectives[0]);  // best_distance
  EXPECT_GE(row[3], 0.0);                      // hypervolume
  EXPECT_EQ(nsga.reference_point().size(), 2U);
  std::vector<std::vector<double>> minimised;
  for (const Solution* s : front) minimised.push_back({-s->objectives[0], s->objectives[1]});
  const double ref[] = {-nsga.reference_point()[0], nsga.reference_point()[1]};
  EXPECT_EQ(row[3], hypervolume(minimised, ref));
}

TEST(Nsga2, ResultsDoNotDependOnTheThreadCount) {
  Nsga2 one = make(nsga_config(1)), two = make(nsga_config(2));
  for (int g = 0; g < 4; ++g) {
    one.step();
    two.step();
  }
  EXPECT_EQ(without_wall(one.history()), without_wall(two.history()));
  EXPECT_EQ(one.ask(), two.ask());
}

TEST(Nsga2, ARefusedTellChangesNothing) {
  Nsga2 nsga = make(nsga_config());
  nsga.step();
  const std::vector<Genome> asked = nsga.ask();
  const std::string before = nsga.checkpoint();
  std::vector<Fitness> told;
  for (const Genome& g : asked) told.push_back(search_stub(g));
  std::size_t k = 0;
  while (!told[k].viable) ++k;
  for (const double bad : {inf, std::nan("")}) {
    for (const bool work : {false, true}) {
      std::vector<Fitness> f = told;
      (work ? f[k].actuation_work_positive : f[k].fitness) = bad;
      try {
        nsga.tell(f);
        ADD_FAILURE() << "accepted " << bad;
      } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(fmt::format("value {}", k)), std::string::npos)
            << e.what();
        EXPECT_NE(std::string(e.what()).find(work ? "actuation_work_positive" : "fitness"),
                  std::string::npos)
            << e.what();
      }
      EXPECT_EQ(nsga.checkpoint(), before);
      EXPECT_EQ(nsga.ask(), asked);
    }
  }
  EXPECT_TRUE(nsga.tell(told));
  EXPECT_EQ(nsga.generation(), 1);
}

TEST(Nsga2, CheckpointRestoreContinuesIdentically) {
  const Config c = nsga_config();
  Nsga2 straight = make(c), first = make(c);
  for (int g = 0; g < 5; ++g) straight.step();
  for (int g = 0; g < 2; ++g) first.step();
  Nsga2 resumed = make(c);
  resumed.restore(first.checkpoint(), "checkpoint.json");
  EXPECT_EQ(resumed.history(), first.history());
  EXPECT_EQ(resumed.checkpoint(), first.checkpoint());
  for (int g = 0; g < 3; ++g) resumed.step();
  EXPECT_EQ(without_wall(resumed.history()), without_wall(straight.history()));
  EXPECT_EQ(resumed.ask(), straight.ask());
}

TEST(Nsga2, CorruptOrHandEditedCheckpointsAreRefused) {
  const Config c = nsga_config();
  Nsga2 nsga = make(c);
  nsga.step();
  nsga.step();
  const std::string text = nsga.checkpoint();
  const auto [refused, changed] = refused_digit_changes(text, 89, [&](const std::string& bad) {
    Nsga2 target = make(c);
    target.restore(bad, "ckpt");
  });
  EXPECT_GT(changed, 5);
  EXPECT_EQ(refused, changed);
  const auto refuses = [&](const std::function<void(nlohmann::json&)>& edit, const char* what) {
    Nsga2 target = make(c);
    try {
      target.restore(reseal(text, edit), "ckpt");
      ADD_FAILURE() << "accepted: " << what;
    } catch (const CheckpointError& e) {
      EXPECT_NE(std::string(e.what()).find("ckpt"), std::string::npos) << e.what();
    }
  };
  refuses([](nlohmann::json& p) { p["population"].erase(0); }, "a member less");
  refuses([](nlohmann::json& p) { p["history"][1]["front_size"] = 99; }, "front_size");
  refuses([](nlohmann::json& p) { p["evaluations"] = 3; }, "evaluations");
  refuses([](nlohmann::json& p) { p["reference_point"] = nullptr; }, "reference point");
  refuses([](nlohmann::json& p) { p["population"][0]["crowding"] = -1.0; }, "crowding");
  refuses([](nlohmann::json& p) { p["population"][0]["result"]["cell_count"] = -1; }, "cells");
  Config other = c;
  other.search.objectives = {"distance:max", "max_speed:max"};
  Nsga2 foreign = make(other);
  EXPECT_THROW(foreign.restore(text, "ckpt"), CheckpointError);
}

TEST(Nsga2, TheSelectGuardComparesTheReferenceCriteria) {
  Config c = nsga_config();
  c.evaluation.reference_check = "select";
  // At the reference step half the genomes swim invalidly: they are never selected as feasible.
  const FitnessFunction reference = [](const Genome& g) {
    Fitness f = search_stub(g);
    f.valid = genome_hash(g) % 2 == 0;
    f.fitness *= 0.5;
    return f;
  };
  Nsga2 nsga(c, search_stub, reference, make_local_evaluator(search_stub, 1));
  for (int g = 0; g < 3; ++g) nsga.step();
  for (const Solution& s : nsga.population()) {
    if (!s.feasible) continue;
    ASSERT_EQ(s.reference.size(), 2U);
    EXPECT_EQ(genome_hash(s.genome) % 2, 0U);
    EXPECT_EQ(s.objectives, s.reference);
    EXPECT_EQ(s.objectives[0], 0.5 * s.result.fitness);
  }
  Nsga2 resumed(c, search_stub, reference, make_local_evaluator(search_stub, 1));
  resumed.restore(nsga.checkpoint(), "checkpoint.json");
  EXPECT_EQ(resumed.history(), nsga.history());
  resumed.step();
  nsga.step();
  EXPECT_EQ(without_wall(resumed.history()), without_wall(nsga.history()));
}

TEST(Nsga2, AReferenceHookGivesTheSuppliedCriteriaAtTheReferenceStep) {
  Config c = nsga_config();
  c.search.objectives = {"distance:max", "reach:min"};
  c.evaluation.reference_check = "select";
  const auto reach = [](const Genome& g) { return static_cast<double>(genome_hash(g) % 1000); };
  Nsga2 nsga(c, search_stub, search_stub, make_local_evaluator(search_stub, 1), {"reach"});
  int calls = 0;
  nsga.set_reference_hook([&](const std::vector<Genome>& genomes) {
    ++calls;
    Search::ReferenceSwims out;
    for (const Genome& g : genomes) {
      Fitness f = search_stub(g);
      f.fitness *= 0.5;
      out.fitness.push_back(f);
      out.supplied.push_back({2.0 * reach(g)});
    }
    return out;
  });
  const auto tell = [&] {
    const std::vector<Genome> asked = nsga.ask();
    std::vector<Fitness> f;
    std::vector<std::vector<double>> rows;
    for (const Genome& g : asked) {
      f.push_back(search_stub(g));
      rows.push_back({reach(g)});
    }
    return nsga.tell(f, rows);
  };
  for (int g = 0; g < 3; ++g) ASSERT_TRUE(tell());
  EXPECT_EQ(calls, 3);
  int feasible = 0;
  for (const Solution& s : nsga.population()) {
    if (!s.feasible) continue;
    ++feasible;
    const double own = reach(s.genome);
    EXPECT_EQ(s.reference, (std::vector<double>{0.5 * s.result.fitness, 2.0 * own}));
    EXPECT_EQ(s.objectives, s.reference);  // "select" compares the hook's values
    EXPECT_EQ(nsga.measured(s), (std::vector<double>{s.result.fitness, own}));
  }
  EXPECT_GT(feasible, 0);
  // A hook that gives rows of the wrong width is refused, and the tell changes nothing.
  const std::string before = nsga.checkpoint();
  nsga.set_reference_hook([](const std::vector<Genome>& genomes) {
    Search::ReferenceSwims out;
    for (const Genome& g : genomes) {
      out.fitness.push_back(search_stub(g));
      out.supplied.push_back({1.0, 2.0});
    }
    return out;
  });
  expect_error<Error>([&] { tell(); }, {"reference hook gave 2 supplied values", "supplies 1"});
  EXPECT_EQ(nsga.checkpoint(), before);
  // The GA has its own guard.
  Config ga = c;
  ga.search.algorithm = "ga";
  auto search = make_search(ga, search_stub);
  expect_error<Error>([&] { search->set_reference_hook({}); }, {"GA's exploit guard"});
}

TEST(Nsga2, AGivenReferencePointIsKeptAndSavedAndFixedBeforeTheFirstGeneration) {
  Nsga2 nsga = make(nsga_config());
  expect_error<Error>([&] { nsga.set_reference_point({1.0}); }, {"1 values for the 2 criteria"});
  expect_error<Error>([&] { nsga.set_reference_point({0.0, inf}); },
                      {"actuation_work_positive = inf"});
  nsga.set_reference_point({0.0, 1000.0});
  for (int g = 0; g < 2; ++g) nsga.step();
  EXPECT_EQ(nsga.reference_point(), (std::vector<double>{0.0, 1000.0}));
  // the hypervolume against it, by hand: the front's staircase up to (0, 1000)
  std::vector<std::vector<double>> front;
  for (const Solution* s : nsga.front()) front.push_back({-s->objectives[0], s->objectives[1]});
  EXPECT_EQ(nsga.history().back()[3], hypervolume(front, std::vector<double>{0.0, 1000.0}));
  Nsga2 resumed = make(nsga_config());
  resumed.restore(nsga.checkpoint(), "checkpoint.json");
  EXPECT_EQ(resumed.reference_point(), nsga.reference_point());
  expect_error<Error>([&] { resumed.set_reference_point({0.0, 1.0}); },
                      {"before the first generation"});
}

TEST(SearchHistoryColumns, OneTableForTheSearchesAndTheirHistories) {
  const auto columns = search_history_columns("nsga2", {"distance", "actuation_work_positive"});
  std::vector<std::string> names;
  for (const auto& c : columns) names.push_back(c.name);
  EXPECT_EQ(names, (std::vector<std::string>{
                       "generation", "evaluations", "front_size", "hypervolume", "best_distance",
                       "best_actuation_work_positive", "feasible", "discarded", "copies",
                       "reference_evaluations", "disagreements", "wall_seconds"}));
  Nsga2 nsga = make(nsga_config());
  nsga.step();
  EXPECT_EQ(nsga.history_columns().size(), columns.size());
  EXPECT_EQ(nsga.history().back().size(), columns.size());
  expect_error<Error>([] { (void)search_history_columns("ga"); }, {"\"ga\"", "the run's"});
}
