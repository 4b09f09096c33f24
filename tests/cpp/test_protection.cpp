// Morphological innovation protection (evolution.protection_generations) and the morphology kind it
// compares, checked with cheap stub fitness functions.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "animat/body.hpp"
#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/evolution.hpp"
#include "animat/run.hpp"
#include "animat/run_identity.hpp"
#include "test_support.hpp"

using namespace animat;

namespace {

using animat::test::expect_same_history;
using animat::test::slurp;
using animat::test::stub_fitness;

// stub_fitness with a morphology kind: the genome's element count, which mutation's duplications
// and deletions change now and then (so offspring of a new kind appear, and many of the same kind).
Fitness kind_fitness(const Genome& g) {
  Fitness f = stub_fitness(g);
  if (f.viable) f.morphology_kind = static_cast<int>(g.size());
  return f;
}

Config small_config(int protection, std::int64_t seed = 7) {
  Config c;
  c.evolution.population = 20;
  c.evolution.elites = 2;
  c.evolution.seed = seed;
  c.evolution.threads = 1;
  c.evolution.protection_generations = protection;
  return c;
}

struct Trajectory {
  std::vector<std::vector<Individual>> populations;  // after generation 0, 1, ...
  std::vector<GenerationStats> history;
};

Trajectory run(const Config& c, int generations, const FitnessFunction& fitness = kind_fitness) {
  Evolution evo(c, fitness);
  evo.initialize();
  Trajectory t;
  t.populations.push_back(evo.population());
  for (int g = 0; g < generations; ++g) {
    evo.step();
    t.populations.push_back(evo.population());
  }
  t.history = evo.history();
  return t;
}

void expect_same_individuals(const std::vector<Individual>& a, const std::vector<Individual>& b,
                             bool with_kinds = true) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_TRUE(a[i].genome == b[i].genome) << "individual " << i;
    EXPECT_EQ(a[i].result.fitness, b[i].result.fitness) << "individual " << i;
    EXPECT_EQ(a[i].result.viable, b[i].result.viable) << "individual " << i;
    EXPECT_EQ(a[i].id, b[i].id) << "individual " << i;
    EXPECT_EQ(a[i].parent_a, b[i].parent_a) << "individual " << i;
    EXPECT_EQ(a[i].parent_b, b[i].parent_b) << "individual " << i;
    if (with_kinds) {
      EXPECT_EQ(a[i].result.morphology_kind, b[i].result.morphology_kind) << "individual " << i;
      EXPECT_EQ(a[i].morphology_age, b[i].morphology_age) << "individual " << i;
    }
  }
}

// A checkpoint's payload with `edit` applied, under a valid checksum (as an older build wrote it).
std::string edited_checkpoint(const std::string& text,
                              const std::function<void(nlohmann::json&)>& edit) {
  const nlohmann::json outer = nlohmann::json::parse(text);
  nlohmann::json payload = nlohmann::json::parse(outer.at("payload").get<std::string>());
  edit(payload);
  const std::string body = payload.dump();
  return nlohmann::json{{"checksum", fmt::format("{:016x}", fnv1a(body))}, {"payload", body}}
      .dump();
}

}  // namespace

// --- the morphology kind -------------------------------------------------------------------------

TEST(MorphologyKind, CellCountTimesSixteenPlusTheElongationBand) {
  EXPECT_EQ(morphology_kind(Points(0, 2)), 0);
  Points one(1, 2);
  one << 3.0, -2.0;
  EXPECT_EQ(elongation(one), 1.0);
  EXPECT_EQ(morphology_kind(one), 16);
  // A straight line of k unit-spaced cells: sqrt(1 + 4 (k^2 - 1) / 3) (animat.shape's docstring);
  // k = 10: 11.53, band 6 (1.5^6 = 11.39 <= 11.53 < 17.09).
  for (int k : {2, 3, 10, 40}) {
    Points line(k, 2);
    for (int i = 0; i < k; ++i) line.row(i) << 2.0 * i + 1.0, 0.5;  // spacing 2: unit-free
    const double expected = std::sqrt(1.0 + 4.0 * (k * k - 1.0) / 3.0);
    EXPECT_NEAR(elongation(line), expected, 1e-12 * expected) << k;
    EXPECT_EQ(cell_spacing(line), 2.0);
    const int band = std::min(15, static_cast<int>(std::floor(std::log(expected) / std::log(1.5))));
    EXPECT_EQ(morphology_kind(line), 16 * k + band) << k;
  }
  // A long line reaches the last band; a square grid is round (band 0).
  Points long_line(400, 2);
  for (int i = 0; i < 400; ++i) long_line.row(i) << i, 0.0;
  EXPECT_EQ(morphology_kind(long_line), 400 * 16 + 15);
  Points grid(25, 2);
  for (int i = 0; i < 25; ++i) grid.row(i) << i % 5, i / 5;
  EXPECT_NEAR(elongation(grid), 1.0, 1e-12);
  EXPECT_EQ(morphology_kind(grid), 25 * 16);
  // Without the cells' own extent a straight line has no width.
  EXPECT_TRUE(std::isinf(elongation(long_line, 0.0)));
}

// --- the tournament ------------------------------------------------------------------------------

TEST(Protection, ANewMorphologyIsNotBeatenByAFitterOlderOneMoreOftenThanHalf) {
  // 0: fitter, an established kind; 1: less fit, a new kind. p = 1: without protection the fitter
  // always wins.
  std::vector<Individual> pop(2);
  pop[0].result = {2.0, true, true, 32};
  pop[0].result.morphology_kind = 512;
  pop[0].morphology_age = 7;
  pop[1].result = {0.5, true, true, 32};
  pop[1].result.morphology_kind = 513;
  pop[1].morphology_age = 0;
  const std::vector<std::size_t> eligible = {0, 1};
  const int seeds = 10000, protection = 3;
  int fitter_wins = 0, coin_heads = 0;
  for (int s = 0; s < seeds; ++s) {
    Rng rng(static_cast<std::uint64_t>(s));
    const std::size_t winner = tournament(pop, eligible, 1.0, rng, protection);
    // Exactly a fair coin from the tournament's own stream: the two draws of the pair, then one
    // Bernoulli(1/2) instead of Bernoulli(p). The same number of draws as without protection.
    Rng replay(static_cast<std::uint64_t>(s));
    (void)replay.below(2);
    (void)replay.below(1);
    const bool heads = replay.bernoulli(0.5);
    ASSERT_EQ(winner, heads ? 0u : 1u) << "seed " << s;
    ASSERT_EQ(rng(), replay()) << "seed " << s;
    fitter_wins += winner == 0;
    coin_heads += heads;
  }
  EXPECT_EQ(fitter_wins, coin_heads);
  EXPECT_LT(fitter_wins, seeds);
  EXPECT_GT(fitter_wins, 0);

  // Every other case is the paper's tournament, draw for draw: the fitter wins (p = 1).
  auto always_fitter = [&](const std::vector<Individual>& p, int prot, std::size_t fitter) {
    for (int s = 0; s < 2000; ++s) {
      Rng rng(static_cast<std::uint64_t>(s)), plain(static_cast<std::uint64_t>(s));
      EXPECT_EQ(tournament(p, eligible, 1.0, rng, prot), fitter) << "seed " << s;
      (void)tournament(p, eligible, 1.0, plain);
      EXPECT_EQ(rng(), plain()) << "seed " << s;
    }
  };
  always_fitter(pop, 0, 0);  // protection off
  auto same_kind = pop;
  same_kind[1].result.morphology_kind = 512;
  always_fitter(same_kind, protection, 0);  // not a new morphology
  auto old_enough = pop;
  old_enough[1].morphology_age = protection;
  always_fitter(old_enough, protection, 0);  // protected for `protection` generations only
  auto not_younger = pop;
  not_younger[0].morphology_age = 0;
  always_fitter(not_younger, protection, 0);  // only the younger kind is protected
  auto newcomer_fitter = pop;
  newcomer_fitter[1].result.fitness = 3.0;
  always_fitter(newcomer_fitter, protection, 1);  // a fitter newcomer wins as usual
}

// --- the GA --------------------------------------------------------------------------------------

TEST(Protection, OffIsThePapersGaBitForBit) {
  // The key at 0 is the run without the key: same identity, same trajectory; and the morphology
  // kinds do not change a thing without protection (kind_fitness and stub_fitness differ only
  // there).
  Config without = small_config(0);
  Config with_key = without;
  set_value(with_key, "evolution.protection_generations", std::int64_t{0});
  EXPECT_EQ(run_identity(without), run_identity(with_key));
  EXPECT_EQ(run_identity_v1(without), run_identity_v1(with_key));
  EXPECT_EQ(to_toml(without), to_toml(with_key));
  const Trajectory plain = run(without, 15, stub_fitness);
  const Trajectory kinds = run(with_key, 15, kind_fitness);
  for (std::size_t g = 0; g < plain.populations.size(); ++g)
    expect_same_individuals(plain.populations[g], kinds.populations[g], false);
  expect_same_history(plain.history, kinds.history);
  for (const auto& s : kinds.history) EXPECT_EQ(s.protected_count, 0);
  // On, it is part of the run's identity (a resume cannot switch it), and it changes the run.
  const Config on = small_config(4);
  EXPECT_NE(run_identity(on), run_identity(without));
  EXPECT_NE(run_identity_v1(on), run_identity_v1(without));
  const Trajectory protected_run = run(on, 15, kind_fitness);
  bool differs = false;
  for (std::size_t i = 0; i < plain.populations.back().size(); ++i)
    differs = differs ||
              !(plain.populations.back()[i].genome == protected_run.populations.back()[i].genome);
  EXPECT_TRUE(differs);
}

TEST(Protection, AgesCountGenerationsSinceTheLineagesKindAppeared) {
  for (int protection : {0, 3}) {
    const Trajectory t = run(small_config(protection), 20);
    const auto n = static_cast<std::int64_t>(t.populations[0].size());
    for (const Individual& ind : t.populations[0]) EXPECT_EQ(ind.morphology_age, 0);
    int same_kind = 0, new_kind = 0, elites = 0, both_parents_match = 0;
    for (std::size_t g = 1; g < t.populations.size(); ++g) {
      std::map<std::int64_t, const Individual*> previous;
      for (const Individual& ind : t.populations[g - 1]) previous[ind.id] = &ind;
      int young = 0;
      for (const Individual& ind : t.populations[g]) {
        if (ind.result.viable && ind.morphology_age < protection) ++young;
        if (ind.id < static_cast<std::int64_t>(g) * n) {  // an elite: a copy of its old self
          ASSERT_TRUE(previous.count(ind.id));
          EXPECT_EQ(ind.morphology_age, previous[ind.id]->morphology_age + 1);
          EXPECT_EQ(ind.result.morphology_kind, previous[ind.id]->result.morphology_kind);
          ++elites;
          continue;
        }
        int expected = 0;
        int matches = 0;
        for (const std::int64_t parent : {ind.parent_a, ind.parent_b}) {
          if (parent == kNoParent) continue;
          ASSERT_TRUE(previous.count(parent));
          const Individual& p = *previous[parent];
          if (p.result.morphology_kind != ind.result.morphology_kind) continue;
          expected =
              matches++ == 0 ? p.morphology_age + 1 : std::min(expected, p.morphology_age + 1);
        }
        EXPECT_EQ(ind.morphology_age, expected) << "generation " << g << ", id " << ind.id;
        EXPECT_LE(ind.morphology_age, static_cast<int>(g));
        (matches > 0 ? same_kind : new_kind) += 1;
        both_parents_match += matches == 2;
      }
      EXPECT_EQ(t.history[g].protected_count, protection > 0 ? young : 0) << "generation " << g;
    }
    // The stub makes every case happen.
    EXPECT_GT(same_kind, 0);
    EXPECT_GT(new_kind, 0);
    EXPECT_GT(elites, 0);
    EXPECT_GT(both_parents_match, 0);
  }
}

TEST(Protection, DeterministicForAnyThreadCountAndAcrossCheckpointResume) {
  Config c = small_config(4, 11);
  const Trajectory straight = run(c, 14);
  EXPECT_GT(straight.history.back().protected_count + straight.history[3].protected_count, 0);

  c.evolution.threads = 2;
  const Trajectory two = run(c, 14);
  for (std::size_t g = 0; g < straight.populations.size(); ++g)
    expect_same_individuals(straight.populations[g], two.populations[g]);
  expect_same_history(straight.history, two.history);

  Evolution first(c, kind_fitness);
  first.initialize();
  for (int g = 0; g < 6; ++g) first.step();
  const std::string text = first.checkpoint();
  EXPECT_NE(text.find("morphology_age"), std::string::npos);
  EXPECT_NE(text.find("morphology_kind"), std::string::npos);
  Evolution resumed(c, kind_fitness);
  resumed.restore(text);
  EXPECT_EQ(resumed.checkpoint(), text);
  for (int g = 0; g < 8; ++g) resumed.step();
  expect_same_individuals(straight.populations.back(), resumed.population());
  expect_same_history(straight.history, resumed.history());
}

TEST(Protection, ACheckpointWithoutKindsAndAgesResumesARunWithoutProtection) {
  // Checkpoints written before kinds and ages existed lack both: they restore as 0, which a run
  // without protection never reads.
  const Config c = small_config(0, 5);
  const Trajectory straight = run(c, 10);
  Evolution first(c, kind_fitness);
  first.initialize();
  for (int g = 0; g < 4; ++g) first.step();
  const std::string old = edited_checkpoint(first.checkpoint(), [](nlohmann::json& p) {
    for (auto& ind : p.at("population")) {
      ind.erase("morphology_kind");
      ind.erase("morphology_age");
    }
  });
  Evolution resumed(c, kind_fitness);
  resumed.restore(old);
  for (const Individual& ind : resumed.population()) EXPECT_EQ(ind.morphology_age, 0);
  for (int g = 0; g < 6; ++g) resumed.step();
  expect_same_individuals(straight.populations.back(), resumed.population(), false);
  expect_same_history(straight.history, resumed.history());
  // A hand-edited age older than the run is refused.
  const std::string bad = edited_checkpoint(
      first.checkpoint(), [](nlohmann::json& p) { p.at("population")[3]["morphology_age"] = 5; });
  try {
    Evolution e(c, kind_fitness);
    e.restore(bad);
    FAIL() << "expected a CheckpointError";
  } catch (const CheckpointError& e) {
    EXPECT_NE(std::string(e.what()).find("individual 3 has morphology_age 5"), std::string::npos)
        << e.what();
  }
}

TEST(Protection, BadValuesAreRefusedNamingTheKeyAndTheValue) {
  Config c;
  const auto refused = [&](const std::function<void()>& f, const std::string& value) {
    try {
      f();
      ADD_FAILURE() << "expected a ConfigError for " << value;
    } catch (const ConfigError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("evolution.protection_generations"), std::string::npos) << m;
      EXPECT_NE(m.find(value), std::string::npos) << m;
    }
  };
  refused([&] { set_value(c, "evolution.protection_generations", std::int64_t{-1}); }, "-1");
  refused([&] { set_value(c, "evolution.protection_generations", 2.5); }, "2.5");
  refused([&] { apply_override(c, "evolution.protection_generations=-3"); }, "-3");
  refused([&] { apply_override(c, "evolution.protection_generations=1.5"); }, "1.5");
  refused([&] { (void)config_from_toml("[evolution]\nprotection_generations = -1\n"); }, "-1");
  refused([&] { (void)config_from_toml("[evolution]\nprotection_generations = 0.5\n"); }, "0.5");
  EXPECT_EQ(c.evolution.protection_generations, 0);
  set_value(c, "evolution.protection_generations", std::int64_t{25});
  EXPECT_EQ(c.evolution.protection_generations, 25);
}

TEST(Protection, RunDirectoryHasTheProtectedColumnsOnlyWithProtection) {
  for (int protection : {0, 2}) {
    const auto dir = animat::test::fresh_dir("animat_protection_", std::to_string(protection));
    Config c = small_config(protection);
    c.evolution.generations = 4;
    RunOptions opt;
    opt.out = dir;
    opt.quiet = true;
    (void)run_evolution(c, opt, kind_fitness);
    const std::string hist = slurp(dir / "history.csv");
    const std::string family = slurp(dir / "genealogy.csv");
    const std::string lineage = slurp(dir / "best" / "gen_000000.json");
    if (protection == 0) {
      // as before the protection existed
      EXPECT_EQ(hist.rfind("generation,best,mean,median,viable_fraction,best_cells,evaluations,"
                           "swims,best_reference,invalid,drag_limited,wall_seconds\n",
                           0),
                0u);
      EXPECT_EQ(family.rfind("generation,id,parent_a,parent_b,fitness,cells\n", 0), 0u);
      EXPECT_EQ(lineage.find("morphology"), std::string::npos);
    } else {
      EXPECT_EQ(hist.rfind("generation,best,mean,median,viable_fraction,best_cells,evaluations,"
                           "swims,best_reference,invalid,drag_limited,protected,wall_seconds\n",
                           0),
                0u);
      // generation 0: all 20 individuals are new (age 0 < 2); the column before the wall time
      const std::string row0 = hist.substr(
          hist.find('\n') + 1, hist.find('\n', hist.find('\n') + 1) - hist.find('\n') - 1);
      const std::string head = row0.substr(0, row0.rfind(','));
      EXPECT_EQ(head.substr(head.rfind(',') + 1), "20") << row0;
      EXPECT_EQ(family.rfind("generation,id,parent_a,parent_b,fitness,cells,morphology_kind,"
                             "morphology_age\n",
                             0),
                0u);
      EXPECT_NE(lineage.find("\"morphology_age\""), std::string::npos);
      // A resume rewrites the same files.
      c.evolution.generations = 6;
      opt.resume = true;
      (void)run_evolution(c, opt, kind_fitness);
      const auto straight_dir = animat::test::fresh_dir("animat_protection_", "straight");
      RunOptions straight = opt;
      straight.out = straight_dir;
      straight.resume = false;
      (void)run_evolution(c, straight, kind_fitness);
      EXPECT_EQ(slurp(dir / "genealogy.csv"), slurp(straight_dir / "genealogy.csv"));
      const auto rows = [](const std::string& text) {  // without the wall time, the last column
        std::string out;
        for (std::size_t at = 0; at < text.size();) {
          const auto end = text.find('\n', at);
          const std::string line = text.substr(at, end - at);
          out += line.substr(0, line.rfind(',')) + "\n";
          at = end + 1;
        }
        return out;
      };
      EXPECT_EQ(rows(slurp(dir / "history.csv")), rows(slurp(straight_dir / "history.csv")));
      std::filesystem::remove_all(straight_dir);
    }
    std::filesystem::remove_all(dir);
  }
}

TEST(Protection, TellRefusesANegativeKindAsTheCheckpointCouldNotHoldIt) {
  Evolution evo(small_config(2));
  const std::vector<Genome> genomes = evo.ask();
  std::vector<Fitness> told(genomes.size(), Fitness{1.0, true, true, 3});
  told[1].morphology_kind = -4;
  try {
    (void)evo.tell(told);
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("value 1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("morphology_kind -4"), std::string::npos) << e.what();
  }
  told[1].morphology_kind = 4;
  EXPECT_TRUE(evo.tell(told));
}
