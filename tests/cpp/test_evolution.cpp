// The GA engine, checked in milliseconds with a cheap deterministic stub fitness.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <tuple>

#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/evolution.hpp"
#include "animat/run.hpp"
#include "test_support.hpp"

using namespace animat;

namespace {

using animat::test::expect_same_history;
using animat::test::expect_same_population;
using animat::test::expect_same_results;
using animat::test::slurp;
using animat::test::stub_fitness;

Config small_config(int population = 20, std::int64_t seed = 7) {
  Config c;
  c.evolution.population = population;
  c.evolution.elites = 2;
  c.evolution.seed = seed;
  c.evolution.threads = 1;
  return c;
}

std::vector<GenerationStats> run(const Config& c, int generations) {
  Evolution evo(c, stub_fitness);
  evo.initialize();
  for (int g = 0; g < generations; ++g) evo.step();
  return evo.history();
}

std::filesystem::path fresh_dir(const std::string& name) {
  return animat::test::fresh_dir("animat_test_", name);
}

}  // namespace

TEST(Tournament, FitterWinsWithProbabilityP) {
  std::vector<Individual> pop(2);
  pop[0].result = {1.0, true, true, 3};
  pop[1].result = {0.5, true, true, 3};
  const std::vector<std::size_t> eligible = {0, 1};
  for (double p : {0.8, 0.9}) {
    Rng rng(11);
    const int draws = 100000;
    int fitter = 0;
    for (int k = 0; k < draws; ++k) fitter += tournament(pop, eligible, p, rng) == 0;
    const double sigma = std::sqrt(p * (1 - p) / draws);
    EXPECT_NEAR(static_cast<double>(fitter) / draws, p, 5 * sigma) << "p = " << p;
  }
  Rng rng(12);
  for (int k = 0; k < 10000; ++k) ASSERT_EQ(tournament(pop, eligible, 1.0, rng), 0u);
}

TEST(Tournament, DrawsTwoDistinctIndividualsUniformly) {
  std::vector<Individual> pop(5);
  for (int i = 0; i < 5; ++i)
    pop[static_cast<std::size_t>(i)].result = {static_cast<double>(i), true, true, 3};
  const std::vector<std::size_t> eligible = {0, 1, 2, 3, 4};
  // With p = 1 the winner is the fitter of the pair: P(winner = k) = (number of pairs where k is
  // max)/C(5,2) = k/10.
  Rng rng(3);
  std::vector<int> wins(5, 0);
  const int draws = 200000;
  for (int k = 0; k < draws; ++k) ++wins[tournament(pop, eligible, 1.0, rng)];
  for (int k = 0; k < 5; ++k) {
    const double p = k / 10.0, sigma = std::sqrt(p * (1 - p) / draws) + 1e-12;
    EXPECT_NEAR(static_cast<double>(wins[static_cast<std::size_t>(k)]) / draws, p, 5 * sigma)
        << "k = " << k;
  }
}

TEST(Tournament, ProbabilityRampsLinearlyOverTheFirst1000Generations) {
  const EvolutionParams p;
  EXPECT_DOUBLE_EQ(tournament_probability(p, 0), 0.8);
  EXPECT_DOUBLE_EQ(tournament_probability(p, 250), 0.85);
  EXPECT_DOUBLE_EQ(tournament_probability(p, 500), 0.9);
  EXPECT_DOUBLE_EQ(tournament_probability(p, 1000), 1.0);
  EXPECT_DOUBLE_EQ(tournament_probability(p, 5000), 1.0);
  for (int g = 1; g <= 1000; ++g)
    ASSERT_GT(tournament_probability(p, g), tournament_probability(p, g - 1));
}

TEST(Evolution, InitialPopulationIsViableAndCountsTries) {
  Evolution evo(small_config(), stub_fitness);
  evo.initialize();
  ASSERT_EQ(evo.population().size(), 20u);
  int total = 0;
  for (const auto& ind : evo.population()) {
    EXPECT_TRUE(ind.result.viable);
    EXPECT_GE(ind.tries, 1);
    total += ind.tries;
  }
  EXPECT_EQ(evo.evaluations(), total);
  EXPECT_GT(total, 20);  // 1 genome in 4 is non-viable, so some individual needed a second try
}

TEST(Evolution, ElitismNeverLosesTheBest) {
  Evolution evo(small_config(), stub_fitness);
  evo.initialize();
  double previous = evo.history().back().best;
  for (int g = 0; g < 60; ++g) {
    const GenerationStats s = evo.step();
    ASSERT_GE(s.best, previous) << "generation " << s.generation;
    previous = s.best;
  }
  EXPECT_GT(previous, evo.history().front().best);  // selection works on the stub
}

TEST(Evolution, CrossoverFractionIsTwentyPercentWithinBinomialBounds) {
  Config c = small_config(100);
  Evolution evo(c, stub_fitness);
  evo.initialize();
  long long crossovers = 0, offspring = 0;
  for (int g = 0; g < 40; ++g) {
    crossovers += evo.step().crossovers;
    offspring += c.evolution.population - c.evolution.elites;
  }
  const double p = 0.2, sigma = std::sqrt(p * (1 - p) / static_cast<double>(offspring));
  EXPECT_NEAR(static_cast<double>(crossovers) / static_cast<double>(offspring), p, 4 * sigma);
}

TEST(Evolution, StallStopTriggersAfterExactlyNGenerationsWithoutImprovement) {
  Config c = small_config();
  c.evolution.stall_generations = 7;
  const FitnessFunction flat = [](const Genome&) { return Fitness{1.0, true, true, 3}; };
  Evolution evo(c, flat);
  evo.initialize();
  for (int g = 1; g <= 7; ++g) {
    EXPECT_TRUE(evo.stop_reason().empty()) << "generation " << evo.generation();
    evo.step();
    EXPECT_EQ(evo.generations_without_improvement(), g);
  }
  EXPECT_NE(evo.stop_reason().find("no improvement for evolution.stall_generations = 7"),
            std::string::npos)
      << evo.stop_reason();
  EXPECT_EQ(evo.generation(), 7);
}

TEST(Evolution, GenerationCapStops) {
  Config c = small_config();
  c.evolution.generations = 3;
  Evolution evo(c, stub_fitness);
  evo.initialize();
  for (int g = 0; g < 3; ++g) {
    EXPECT_TRUE(evo.stop_reason().empty());
    evo.step();
  }
  EXPECT_NE(evo.stop_reason().find("generation cap"), std::string::npos);
}

TEST(Evolution, UnchangedOffspringAreNeverReEvaluated) {
  Config c = small_config();
  c.mutation = MutationParams{0, 0, 0, 0, 0, 0, 1, 1};  // no mutation at all
  c.evolution.crossover_fraction = 0.0;
  std::atomic<int> calls{0};
  const FitnessFunction counting = [&](const Genome& g) {
    ++calls;
    return stub_fitness(g);
  };
  Evolution evo(c, counting);
  evo.initialize();
  const int after_init = calls.load();
  for (int g = 0; g < 5; ++g) evo.step();
  EXPECT_EQ(calls.load(), after_init);  // every offspring is a copy of a parent: nothing to swim
}

TEST(Evolution, OffspringOfAnEvaluatedNetworkKeepItsFitness) {
  // A fitness that reads only the genome's network, and a reference that reads only it too.
  Config c = small_config(30);
  c.development.jitter_stream = "fixed";
  c.evaluation.reference_check = "select";
  const GenomeKey key = evaluation_key(c);
  ASSERT_TRUE(key);
  std::atomic<int> calls{0};
  const auto of_network = [&, key](double scale) {
    return [&, key, scale](const Genome& g) {
      ++calls;
      Fitness f;
      f.viable = true;
      f.stable = true;
      f.cell_count = 5;
      f.fitness = scale * static_cast<double>(std::hash<std::string>{}(key(g)) % 1000);
      return f;
    };
  };
  auto evolve = [&](bool keyed) {
    calls = 0;
    Evolution evo(c, of_network(1.0), of_network(1.01));
    if (keyed) evo.set_fitness_key(key);
    evo.initialize();
    for (int g = 0; g < 25; ++g) evo.step();
    return std::tuple{evo.history(), evo.population(), calls.load()};
  };
  const auto [h_genome, pop_genome, calls_genome] = evolve(false);
  const auto [h_keyed, pop_keyed, calls_keyed] = evolve(true);
  expect_same_results(h_genome, h_keyed);
  expect_same_population(pop_genome, pop_keyed);
  EXPECT_LT(calls_keyed, calls_genome);
  EXPECT_LT(h_keyed.back().evaluations, h_genome.back().evaluations);
}

TEST(Evolution, TheGenomeIsTheKeyWhenDevelopmentReadsItsHash) {
  Config c = small_config();
  EXPECT_EQ(c.development.jitter_stream, "genome");
  EXPECT_FALSE(evaluation_key(c));  // the placement jitter is seeded by the genome's hash
  c.development.jitter_stream = "fixed";
  EXPECT_TRUE(evaluation_key(c));
}

TEST(Evolution, DeterministicForAnyThreadCountAndSeed) {
  Config one = small_config(30);
  Config two = one;
  two.evolution.threads = 2;
  const auto h1 = run(one, 25), h2 = run(two, 25), h1b = run(one, 25);
  expect_same_history(h1, h2);
  expect_same_history(h1, h1b);
  Config other = one;
  other.evolution.seed = 8;
  const auto h3 = run(other, 25);
  bool differs = false;
  for (std::size_t i = 0; i < h1.size(); ++i) differs |= h1[i].mean != h3[i].mean;
  EXPECT_TRUE(differs);
}

TEST(Evolution, CheckpointResumeReproducesTheUninterruptedRun) {
  const Config c = small_config(24);
  Evolution straight(c, stub_fitness);
  straight.initialize();
  for (int g = 0; g < 20; ++g) straight.step();

  Evolution first(c, stub_fitness);
  first.initialize();
  for (int g = 0; g < 10; ++g) first.step();
  const std::string ckpt = first.checkpoint();
  Evolution resumed(c, stub_fitness);
  resumed.restore(ckpt);
  EXPECT_EQ(resumed.generation(), 10);
  for (int g = 0; g < 10; ++g) resumed.step();

  expect_same_history(straight.history(), resumed.history());
  ASSERT_EQ(straight.population().size(), resumed.population().size());
  for (std::size_t i = 0; i < straight.population().size(); ++i) {
    EXPECT_TRUE(straight.population()[i].genome == resumed.population()[i].genome)
        << "individual " << i;
    EXPECT_EQ(straight.population()[i].result, resumed.population()[i].result);
  }
}

TEST(Evolution, IdsAndParentsTraceEveryIndividualToThePreviousGeneration) {
  Config c = small_config(20);
  c.evolution.crossover_fraction = 0.5;  // many of both kinds
  Evolution evo(c, stub_fitness);
  evo.initialize();
  const auto n = static_cast<std::int64_t>(c.evolution.population);
  for (std::int64_t i = 0; i < n; ++i) {
    EXPECT_EQ(evo.population()[static_cast<std::size_t>(i)].id, i);
    EXPECT_EQ(evo.population()[static_cast<std::size_t>(i)].parent_a, kNoParent);
    EXPECT_EQ(evo.population()[static_cast<std::size_t>(i)].parent_b, kNoParent);
  }
  int crossovers_seen = 0, mutants_seen = 0;
  for (int g = 1; g <= 8; ++g) {
    const std::vector<Individual> before = evo.population();
    std::set<std::int64_t> previous;
    for (const auto& ind : before) previous.insert(ind.id);
    const GenerationStats s = evo.step();
    int crossovers = 0;
    for (std::size_t i = 0; i < evo.population().size(); ++i) {
      const Individual& ind = evo.population()[i];
      if (ind.id < g * n) {  // an elite: the same individual as before, parents and all
        const auto it = std::find_if(before.begin(), before.end(),
                                     [&](const Individual& b) { return b.id == ind.id; });
        ASSERT_NE(it, before.end()) << "generation " << g << " id " << ind.id;
        EXPECT_TRUE(it->genome == ind.genome);
        EXPECT_EQ(it->parent_a, ind.parent_a);
        continue;
      }
      EXPECT_EQ(ind.id, g * n + static_cast<std::int64_t>(i)) << "generation " << g;
      EXPECT_TRUE(previous.count(ind.parent_a)) << "generation " << g << " index " << i;
      if (ind.parent_b != kNoParent) {
        EXPECT_TRUE(previous.count(ind.parent_b)) << "generation " << g << " index " << i;
        ++crossovers;
      } else {
        ++mutants_seen;
      }
    }
    EXPECT_EQ(crossovers, s.crossovers) << "generation " << g;
    crossovers_seen += crossovers;
  }
  EXPECT_GT(crossovers_seen, 0);
  EXPECT_GT(mutants_seen, 0);

  // Ids survive a checkpoint; one written before ids existed restores with each individual born at
  // its generation and parents unknown, and the run goes on identically.
  const std::string ckpt = evo.checkpoint();
  Evolution same(c, stub_fitness);
  same.restore(ckpt);
  for (std::size_t i = 0; i < evo.population().size(); ++i) {
    EXPECT_EQ(same.population()[i].id, evo.population()[i].id);
    EXPECT_EQ(same.population()[i].parent_a, evo.population()[i].parent_a);
    EXPECT_EQ(same.population()[i].parent_b, evo.population()[i].parent_b);
  }
  nlohmann::json payload =
      nlohmann::json::parse(nlohmann::json::parse(ckpt)["payload"].get<std::string>());
  for (auto& ind : payload["population"]) {
    ind.erase("id");
    ind.erase("parent_a");
    ind.erase("parent_b");
  }
  const std::string body = payload.dump();
  Evolution old(c, stub_fitness);
  old.restore(
      nlohmann::json{{"checksum", fmt::format("{:016x}", fnv1a(body))}, {"payload", body}}.dump());
  for (std::size_t i = 0; i < old.population().size(); ++i) {
    EXPECT_EQ(old.population()[i].id, 8 * n + static_cast<std::int64_t>(i));
    EXPECT_EQ(old.population()[i].parent_a, kNoParent);
  }
  old.step();
  same.step();
  expect_same_history(old.history(), same.history());
  for (std::size_t i = 0; i < old.population().size(); ++i)
    EXPECT_TRUE(old.population()[i].genome == same.population()[i].genome);
}

TEST(Evolution, CorruptOrMismatchedCheckpointIsRefused) {
  const Config c = small_config();
  Evolution evo(c, stub_fitness);
  evo.initialize();
  evo.step();
  const std::string good = evo.checkpoint();
  auto message = [&](const std::string& text, const Config& cfg) {
    Evolution other(cfg, stub_fitness);
    try {
      other.restore(text, "run/checkpoint.json");
    } catch (const CheckpointError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(
      message(good.substr(0, good.size() / 2), c).find("run/checkpoint.json: corrupt checkpoint"),
      std::string::npos);
  std::string flipped = good;
  const auto pos = flipped.find("fitness");
  ASSERT_NE(pos, std::string::npos);
  flipped[pos + 12] = flipped[pos + 12] == '1' ? '2' : '1';
  EXPECT_NE(message(flipped, c).find("checksum"), std::string::npos) << message(flipped, c);
  Config changed = c;
  changed.scene.drag_normal = 10.0;
  EXPECT_NE(message(good, changed).find("different run configuration"), std::string::npos);
  Config longer = c;
  longer.evolution.generations = 500;  // stopping knobs may change on resume
  EXPECT_EQ(message(good, longer), "no error");
  EXPECT_NE(message("{\"checksum\": \"0\", \"payload\": 3}", c).find("not an animat checkpoint"),
            std::string::npos);
}

TEST(RunDirectory, WritesConfigHistoryLineageAndCheckpointThenResumes) {
  const auto dir = fresh_dir("rundir");
  Config c = small_config();
  c.evolution.generations = 6;
  RunOptions opt;
  opt.out = dir;
  opt.quiet = true;
  const RunSummary s = run_evolution(c, opt, stub_fitness);
  EXPECT_NE(s.stop_reason.find("generation cap"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(dir / "checkpoint.json"));
  EXPECT_EQ(load_config(dir / "config.toml"), c);
  const std::string hist = slurp(dir / "history.csv");
  EXPECT_EQ(hist.rfind("generation,best,mean,median,viable_fraction,best_cells,evaluations,swims,"
                       "best_reference,invalid,drag_limited,wall_seconds\n",
                       0),
            0u);
  EXPECT_EQ(std::count(hist.begin(), hist.end(), '\n'), 1 + 7);  // header + generations 0..6
  EXPECT_TRUE(std::filesystem::exists(dir / "best" / "gen_000000.json"));
  // genealogy.csv: the initial population, then every generation's offspring (the elites are not
  // born again): 20 + 6 x 18 rows.
  const std::string family = slurp(dir / "genealogy.csv");
  EXPECT_EQ(family.rfind("generation,id,parent_a,parent_b,fitness,cells\n", 0), 0u);
  EXPECT_EQ(std::count(family.begin(), family.end(), '\n'), 1 + 20 + 6 * 18);
  EXPECT_NE(family.find("\n0,0,-1,-1,"), std::string::npos);
  EXPECT_NE(family.find("\n6,139,"), std::string::npos);  // the last offspring: 6 x 20 + 19

  // A second run into the same directory is refused; a resume with a higher cap continues it.
  EXPECT_THROW(run_evolution(c, opt, stub_fitness), IoError);
  c.evolution.generations = 10;
  opt.resume = true;
  const RunSummary r = run_evolution(c, opt, stub_fitness);
  EXPECT_EQ(r.history.back().generation, 10);
  const std::string hist2 = slurp(dir / "history.csv");
  EXPECT_EQ(std::count(hist2.begin(), hist2.end(), '\n'), 1 + 11);

  Config straight_cfg = c;
  RunOptions straight_opt;
  straight_opt.out = fresh_dir("straight");
  straight_opt.quiet = true;
  const RunSummary straight = run_evolution(straight_cfg, straight_opt, stub_fitness);
  expect_same_history(straight.history, r.history);
  EXPECT_EQ(slurp(dir / "genealogy.csv"), slurp(straight_opt.out / "genealogy.csv"));
  std::filesystem::remove_all(dir);
  std::filesystem::remove_all(straight_opt.out);
}

TEST(RunDirectory, MissingResumeDirectoryIsAClearError) {
  RunOptions opt;
  opt.out = fresh_dir("missing");
  opt.resume = true;
  opt.quiet = true;
  try {
    (void)run_evolution(small_config(), opt, stub_fitness);
    FAIL() << "expected an error";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("resume directory does not exist"), std::string::npos)
        << e.what();
  }
}

TEST(EndToEnd, SmallRealRunImprovesTheBestFitness) {
  // Real chain (development, body, swim) at a small scale: 16 individuals, 10 generations, 1000
  // steps.
  Config c;
  c.evolution.population = 16;
  c.evolution.generations = 10;
  c.evolution.seed = 1;
  c.evolution.threads = 2;
  c.evaluation.steps = 1000;
  RunOptions opt;
  opt.quiet = true;
  const RunSummary r = run_evolution(c, opt);
  ASSERT_EQ(r.history.size(), 11u);
  EXPECT_GT(r.history.front().best, 0.0);
  EXPECT_GT(r.history.back().best, 1.5 * r.history.front().best)
      << "initial " << r.history.front().best << ", final " << r.history.back().best;
  EXPECT_TRUE(r.best.result.viable);
  EXPECT_TRUE(r.best.result.stable);
  EXPECT_GE(r.best.result.cell_count, 3);
}

TEST(EndToEnd, RealRunIsIdenticalOnOneAndTwoThreads) {
  Config c;
  c.evolution.population = 12;
  c.evolution.generations = 4;
  c.evolution.seed = 5;
  c.evaluation.steps = 400;
  RunOptions opt;
  opt.quiet = true;
  c.evolution.threads = 1;
  const RunSummary one = run_evolution(c, opt);
  c.evolution.threads = 2;
  const RunSummary two = run_evolution(c, opt);
  expect_same_history(one.history, two.history);
  EXPECT_TRUE(one.best.genome == two.best.genome);
}

TEST(EndToEnd, ARealRunKeyedByTheNetworkHasTheSameResultsWithFewerEvaluations) {
  // The real chain at the fixed jitter stream: run_evolution keys by the network
  // (evaluation_key); the same fitness handed over without a key evaluates every new genome.
  Config c;
  c.development.jitter_stream = "fixed";
  c.evolution.population = 16;
  c.evolution.generations = 6;
  c.evolution.seed = 3;
  c.evolution.threads = 2;
  c.evaluation.steps = 400;
  c.evaluation.reference_check = "select";
  RunOptions opt;
  opt.quiet = true;
  const RunSummary keyed = run_evolution(c, opt);
  const RunSummary whole =
      run_evolution(c, opt, swim_fitness(c), swim_fitness(reference_config(c)));
  expect_same_results(whole.history, keyed.history);
  EXPECT_TRUE(whole.best.genome == keyed.best.genome);
  EXPECT_TRUE(whole.best.result == keyed.best.result);
  expect_same_population(whole.population, keyed.population);
  EXPECT_LT(keyed.history.back().evaluations, whole.history.back().evaluations);
}

// --- The Python paths held to the engine's rules (tell, statistics, the exploit guard)
// ----------------

namespace {

constexpr double kHuge = std::numeric_limits<double>::max();

// Completes generation 0 and `generations` more by ask()/tell(), every viable genome told `value`.
Evolution told_everything(const Config& c, double value, int generations) {
  Evolution evo(c);
  while (evo.generation() < generations) {
    const std::vector<Genome> genomes = evo.ask();
    std::vector<Fitness> f;
    f.assign(genomes.size(), Fitness{value, true, true, 5});
    evo.tell(f);
  }
  return evo;
}

}  // namespace

TEST(Evolution, TellRefusesWhatTheEnginesOwnEvaluationsRefuseNamingTheValue) {
  Config c = small_config(6);  // evaluation.objective = distance: a fitness is >= 0
  Evolution evo(c);
  const std::size_t n = evo.ask().size();
  auto told = [&](std::size_t at, Fitness bad) {
    std::vector<Fitness> f(n, Fitness{1.0, true, true, 3});
    f[at] = bad;
    try {
      evo.tell(f);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string negative = told(2, Fitness{-1.5, true, true, 3});
  EXPECT_NE(negative.find("value 2"), std::string::npos) << negative;
  EXPECT_NE(negative.find("fitness -1.5"), std::string::npos) << negative;
  EXPECT_NE(negative.find(">= 0"), std::string::npos) << negative;
  const std::string cells = told(4, Fitness{1.0, true, true, -7});
  EXPECT_NE(cells.find("value 4"), std::string::npos) << cells;
  EXPECT_NE(cells.find("cell_count -7"), std::string::npos) << cells;
  const std::string infinite =
      told(0, Fitness{std::numeric_limits<double>::infinity(), true, true, 3});
  EXPECT_NE(infinite.find("value 0"), std::string::npos) << infinite;
  EXPECT_NE(infinite.find("fitness inf"), std::string::npos) << infinite;
  // Nothing was taken: the ask is still pending, and a good tell completes generation 0.
  EXPECT_TRUE(evo.asked());
  EXPECT_EQ(evo.generation(), -1);
  EXPECT_TRUE(evo.tell(std::vector<Fitness>(n, Fitness{1.0, true, true, 3})));
  EXPECT_EQ(evo.generation(), 0);

  // A signed objective accepts a negative fitness, and its checkpoint restores.
  c.evaluation.objective = "speed_toward";
  const Evolution signed_run = told_everything(c, -2.0, 1);
  Evolution back(c);
  back.restore(signed_run.checkpoint());
  EXPECT_EQ(back.history().back().mean, -2.0);
}

TEST(Evolution, StatisticsOfHugeFiniteFitnessesStayFiniteAndTheCheckpointRestores) {
  // The plain mean of 6 fitnesses of DBL_MAX was inf: the checkpoint held null and never restored.
  Config c = small_config(6);
  const Evolution top = told_everything(c, kHuge, 2);
  for (const auto& s : top.history()) {
    EXPECT_EQ(s.mean, kHuge) << "generation " << s.generation;
    EXPECT_EQ(s.median, kHuge) << "generation " << s.generation;
  }
  Evolution back(c);
  back.restore(top.checkpoint());
  EXPECT_EQ(back.generation(), 2);
  c.evaluation.objective = "speed_toward";  // signed: the same at the other end
  const Evolution bottom = told_everything(c, -kHuge, 1);
  EXPECT_EQ(bottom.history().back().mean, -kHuge);
  EXPECT_EQ(bottom.history().back().median, -kHuge);
  Evolution back2(c);
  back2.restore(bottom.checkpoint());
  EXPECT_EQ(back2.generation(), 1);
}

TEST(RunDirectory, HugeFiniteFitnessesGiveAFiniteHistoryAndAResumableCheckpoint) {
  // animat_evolve's path (run_evolution): every history row finite, the checkpoint resumes, and the
  // resumed run is the uninterrupted one.
  const FitnessFunction huge = [](const Genome& g) {
    Fitness f = stub_fitness(g);
    // in [DBL_MAX/4, 3 DBL_MAX/4]
    if (f.viable) f.fitness = kHuge * (0.5 + 0.25 * std::clamp(f.fitness, -1.0, 1.0));
    return f;
  };
  const auto dir = fresh_dir("huge");
  Config c = small_config(8);
  c.evolution.generations = 3;
  RunOptions opt;
  opt.out = dir;
  opt.quiet = true;
  const RunSummary first = run_evolution(c, opt, huge);
  for (const auto& s : first.history) {
    EXPECT_TRUE(std::isfinite(s.mean) && std::isfinite(s.median)) << "generation " << s.generation;
    EXPECT_LE(s.mean, s.best);
    EXPECT_GE(s.mean, kHuge / 4);
  }
  const std::string hist = slurp(dir / "history.csv");
  EXPECT_EQ(hist.find("inf"), std::string::npos) << hist;
  EXPECT_EQ(slurp(dir / "checkpoint.json").find("null"), std::string::npos);
  c.evolution.generations = 5;
  opt.resume = true;
  const RunSummary resumed = run_evolution(c, opt, huge);
  EXPECT_EQ(resumed.history.back().generation, 5);
  RunOptions straight;
  straight.out = fresh_dir("huge_straight");
  straight.quiet = true;
  expect_same_history(run_evolution(c, straight, huge).history, resumed.history);
  std::filesystem::remove_all(dir);
  std::filesystem::remove_all(straight.out);
}

TEST(Evolution, ARefusedReferenceLeavesTheEngineAsBeforeTheTell) {
  // The exploit guard's reference evaluation runs inside tell(); a reference that is not finite was
  // stored (the checkpoint then held null). Now it is refused and the tell undone, the ask pending.
  Config c = small_config(6);
  c.evaluation.reference_check = "record";
  int calls = 0;
  const FitnessFunction flaky = [&calls](const Genome& g) {
    Fitness f = stub_fitness(g);
    // first reference: refused
    if (++calls == 1) f.fitness = std::numeric_limits<double>::quiet_NaN();
    return f;
  };
  Evolution evo(c, {}, flaky);
  Evolution twin(c, {}, stub_fitness);
  auto answer = [](const std::vector<Genome>& genomes) {
    std::vector<Fitness> f;
    for (const Genome& g : genomes) f.push_back(stub_fitness(g));
    return f;
  };
  while (evo.generation() < 0) {
    const auto genomes = evo.ask();
    ASSERT_EQ(genomes, twin.ask());
    const auto f = answer(genomes);
    twin.tell(f);
    if (twin.generation() == 0) {  // this tell completes generation 0: its reference is evaluated
      EXPECT_THROW(evo.tell(f), Error);
      EXPECT_EQ(evo.generation(), -1);
      EXPECT_TRUE(evo.asked());
      EXPECT_EQ(evo.ask(), genomes);
    }
    evo.tell(f);
  }
  for (int g = 0; g < 3; ++g) {
    const auto genomes = evo.ask();
    ASSERT_EQ(genomes, twin.ask());
    evo.tell(answer(genomes));
    twin.tell(answer(genomes));
  }
  expect_same_history(evo.history(), twin.history());
  for (std::size_t k = 0; k < evo.history().size(); ++k)
    EXPECT_EQ(evo.history()[k].best_reference, twin.history()[k].best_reference) << k;
  Evolution back(c, {}, stub_fitness);
  back.restore(evo.checkpoint());
  EXPECT_EQ(back.generation(), 3);
}

TEST(Evolution, AFitnessFunctionThatIsInterruptedStopsTheGenerationAtOnce) {
  // A Python objective hit by Ctrl-C throws Interrupted: no evaluation starts after it (they all
  // did, one after the other, before), and the run stops "interrupted" with a resumable checkpoint.
  Config c = small_config(8);
  c.evolution.generations = 4;
  c.evaluation.reference_check = "off";
  int calls = 0, interrupt_at = 0;
  const FitnessFunction counting = [&](const Genome& g) {
    if (++calls == interrupt_at) throw Interrupted("interrupted by the test");
    return stub_fitness(g);
  };
  // Where generation 2 starts, counted in calls.
  RunOptions probe;
  probe.quiet = true;
  int calls_before_gen2 = -1;
  probe.callback = [&](const GenerationStats& s, const Evolution&) {
    if (s.generation == 1) calls_before_gen2 = calls;
    return true;
  };
  (void)run_evolution(c, probe, counting);
  ASSERT_GT(calls_before_gen2, 0);
  const auto dir = fresh_dir("interrupted_fitness");
  RunOptions opt;
  opt.out = dir;
  opt.quiet = true;
  calls = 0;
  interrupt_at = calls_before_gen2 + 1;  // the first evaluation of generation 2
  const RunSummary s = run_evolution(c, opt, counting);
  EXPECT_EQ(s.stop_reason, "interrupted");
  EXPECT_EQ(calls, interrupt_at) << "evaluations started after the interruption";
  EXPECT_EQ(s.history.back().generation, 1);
  opt.resume = true;
  interrupt_at = 0;
  const RunSummary resumed = run_evolution(c, opt, counting);
  EXPECT_EQ(resumed.history.back().generation, 4);
  std::filesystem::remove_all(dir);
}
