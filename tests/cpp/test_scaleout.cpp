// Scale-out building blocks (docs/cluster.md): the evaluator interface, islands and ring migration,
// and the wire codec of the MPI messages. The MPI runs themselves are checked end to end in
// tests/python/test_mpi.py (mpirun on localhost).
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>

#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/evaluator.hpp"
#include "animat/evolution.hpp"
#include "animat/islands.hpp"
#include "animat/run_identity.hpp"
#include "animat/wire.hpp"
#include "test_support.hpp"

using namespace animat;
using animat::test::expect_same_population;
using animat::test::stub_fitness;

namespace {

#include "../../src/run_identity_v1_comments.inc"

Config island_config(int islands = 3, int population = 12, int interval = 2, int migrants = 1) {
  Config c;
  c.evolution.population = population;
  c.evolution.elites = 1;
  c.evolution.seed = 11;
  c.evolution.threads = 1;
  c.evolution.islands = islands;
  c.evolution.migration_interval = interval;
  c.evolution.migrants = migrants;
  return c;
}

// Counts calls and answers like the stub: an evaluator that is not the OpenMP one.
class CountingEvaluator final : public Evaluator {
 public:
  std::vector<Fitness> evaluate(std::span<const Genome* const> genomes,
                                const StopRequest&) override {
    ++calls;
    evaluated += genomes.size();
    std::vector<Fitness> out;
    for (const Genome* g : genomes) out.push_back(stub_fitness(*g));
    return out;
  }
  std::string describe() const override { return "counting"; }
  int calls = 0;
  std::size_t evaluated = 0;
};

}  // namespace

// ---------------------------------------------------------------------------------------------------
TEST(Evaluator, AnyEvaluatorGivesTheSameRunAsTheOpenMpThreads) {
  Config c = island_config(1, 16);
  Evolution local(c, stub_fitness);
  auto counting = std::make_shared<CountingEvaluator>();
  Evolution other(c, {}, {}, counting);
  local.initialize();
  other.initialize();
  const std::int64_t seeding = other.evaluations();  // the random tries of the initial population
  // The initial population is drawn through the evaluator too (rounds of speculative draws).
  EXPECT_GT(counting->calls, 0);
  const int seeding_calls = counting->calls;
  const std::size_t seeding_evaluated = counting->evaluated;
  for (int g = 0; g < 5; ++g) {
    local.step();
    other.step();
  }
  expect_same_population(local.population(), other.population());
  EXPECT_EQ(local.evaluations(), other.evaluations());
  // one call per generation: the whole generation is handed out at once
  EXPECT_EQ(counting->calls - seeding_calls, 5);
  EXPECT_EQ(seeding + static_cast<std::int64_t>(counting->evaluated - seeding_evaluated),
            other.evaluations());
}

TEST(Evaluator, LocalEvaluatorRethrowsTheFirstErrorByIndex) {
  Config c = island_config(1, 8);
  c.evolution.threads = 2;
  int n = 0;
  std::vector<Genome> genomes(6);
  for (auto& g : genomes) g.dimensions = n++;
  const FitnessFunction failing = [](const Genome& g) -> Fitness {
    if (g.dimensions >= 2) throw Error("genome " + std::to_string(g.dimensions));
    return {};
  };
  try {
    (void)make_local_evaluator(c, failing)->evaluate(genomes);
    FAIL() << "no exception";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "genome 2");
  }
}

// ---------------------------------------------------------------------------------------------------
TEST(Islands, LayoutSplitsThePopulationIntoNearlyEqualContiguousIslands) {
  const IslandLayout l = island_layout(10, 3);
  ASSERT_EQ(l.count(), 3u);
  EXPECT_EQ(l.size(0), 4u);
  EXPECT_EQ(l.size(1), 3u);
  EXPECT_EQ(l.size(2), 3u);
  EXPECT_EQ(l.begin(1), 4u);
  EXPECT_EQ(l.end(2), 10u);
  const std::vector<std::size_t> expected = {0, 0, 0, 0, 1, 1, 1, 2, 2, 2};
  for (std::size_t i = 0; i < 10; ++i) EXPECT_EQ(l.island_of(i), expected[i]) << i;
  EXPECT_EQ(island_layout(7, 1).count(), 1u);
  EXPECT_EQ(island_layout(7, 1).size(0), 7u);
}

TEST(Islands, ConfigErrorsNameTheKeys) {
  Config c = island_config(3, 12, 2, 1);
  EXPECT_NO_THROW(validate(c));
  c.evolution.migrants = 3;  // islands of 4: at most 2 (half), and elites + migrants <= 4
  EXPECT_THROW(validate(c), ConfigError);
  try {
    validate(c);
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("evolution.migrants = 3"), std::string::npos) << e.what();
  }
  c = island_config(7, 12);  // islands of 1
  EXPECT_THROW(validate(c), ConfigError);
  c = island_config(3, 12);
  c.evolution.elites = 4;
  EXPECT_THROW(validate(c), ConfigError);
  // without islands the island keys are not checked against sizes
  c = island_config(1, 12, 1, 100);
  EXPECT_NO_THROW(validate(c));
}

TEST(Islands, RingMigrationCopiesTheBestOverTheWorstOfTheNextIsland) {
  // 3 islands of 4; fitness = 10 * island + position, so the best of island k is its last
  // individual.
  std::vector<Individual> pop(12);
  for (std::size_t i = 0; i < 12; ++i) {
    pop[i].genome.dimensions = static_cast<int>(i);  // a label
    pop[i].result = {static_cast<double>(10 * (i / 4) + i % 4), true, true, 3};
  }
  pop[5].result.viable = false;  // island 1: non-viable is the worst whatever its fitness
  const IslandLayout layout = island_layout(12, 3);
  const auto moves = migrate(pop, layout, 2, 7);
  ASSERT_EQ(moves.size(), 6u);
  // island 0 -> 1: the best two of island 0 (3, 2) replace the worst two of island 1 (5 non-viable,
  // then 4)
  EXPECT_EQ(moves[0], (Migration{7, 0, 1, 3, 5}));
  EXPECT_EQ(moves[1], (Migration{7, 0, 1, 2, 4}));
  EXPECT_EQ(moves[2], (Migration{7, 1, 2, 7, 8}));
  EXPECT_EQ(moves[3], (Migration{7, 1, 2, 6, 9}));
  EXPECT_EQ(moves[4], (Migration{7, 2, 0, 11, 0}));  // the ring closes
  EXPECT_EQ(moves[5], (Migration{7, 2, 0, 10, 1}));
  for (const Migration& m : moves) {
    // a copy, from before any replacement
    EXPECT_EQ(pop[m.to].genome.dimensions, static_cast<int>(m.from));
    EXPECT_EQ(pop[m.to].result, pop[m.from].result);
  }
}

TEST(Islands, MigrantsArriveExactlyAtTheScheduledGenerations) {
  const Config c = island_config(3, 12, 3, 1);
  Evolution evo(c, stub_fitness);
  evo.initialize();
  const IslandLayout layout = island_layout(12, 3);
  for (int g = 1; g <= 10; ++g) {
    evo.step();
    const auto& moves = evo.migrations();
    if (g % 3 != 0) {
      EXPECT_TRUE(moves.empty()) << "generation " << g;
      continue;
    }
    ASSERT_EQ(moves.size(), 3u) << "generation " << g;
    for (std::size_t k = 0; k < 3; ++k) {
      const Migration& m = moves[k];
      EXPECT_EQ(m.generation, g);
      EXPECT_EQ(m.from_island, k);
      EXPECT_EQ(m.to_island, (k + 1) % 3);
      EXPECT_EQ(layout.island_of(m.from), k);
      EXPECT_EQ(layout.island_of(m.to), (k + 1) % 3);
      EXPECT_TRUE(evo.population()[m.to].genome == evo.population()[m.from].genome)
          << "generation " << g;
    }
  }
}

TEST(Islands, SelectionStaysWithinAnIslandBetweenMigrations) {
  // Without migration, no genome material crosses islands: every element of island k is one of
  // island k's initial elements or a new point made by a mutation.
  const Config c = island_config(3, 12, 1000, 1);
  Evolution evo(c, stub_fitness);
  evo.initialize();
  const IslandLayout layout = island_layout(12, 3);
  // coordinates of the initial elements, per island
  std::vector<std::set<std::vector<double>>> initial(3);
  for (std::size_t i = 0; i < 12; ++i)
    for (const auto& e : evo.population()[i].genome.elements)
      initial[layout.island_of(i)].insert(e.coords);
  for (int g = 0; g < 6; ++g) evo.step();
  // Crossover and duplication copy elements; only point moves create new coordinates. An element
  // of island 0 found unchanged in island 1 would mean material crossed.
  for (std::size_t i = 0; i < 12; ++i)
    for (const auto& e : evo.population()[i].genome.elements)
      for (std::size_t other = 0; other < 3; ++other) {
        if (other == layout.island_of(i)) continue;
        EXPECT_EQ(initial[other].count(e.coords), 0u) << "individual " << i;
      }
}

TEST(Islands, DeterministicForAnyThreadCountAndAcrossCheckpointResume) {
  Config c = island_config(3, 12, 2, 1);
  Evolution straight(c, stub_fitness);
  straight.initialize();
  for (int g = 0; g < 7; ++g) straight.step();

  c.evolution.threads = 2;
  Evolution first(c, stub_fitness);
  first.initialize();
  for (int g = 0; g < 3; ++g) first.step();
  Evolution resumed(c, stub_fitness);
  resumed.restore(first.checkpoint());
  for (int g = 0; g < 4; ++g) resumed.step();
  expect_same_population(straight.population(), resumed.population());
  ASSERT_EQ(straight.history().size(), resumed.history().size());
  for (std::size_t i = 0; i < straight.history().size(); ++i)
    EXPECT_EQ(straight.history()[i].best, resumed.history()[i].best);
}

TEST(Islands, OneIslandIsThePapersPopulationAndKeepsTheRunIdentity) {
  // Without islands the island keys neither change the run nor its identity (old checkpoints
  // resume).
  Config a = island_config(1, 12);
  Config b = a;
  b.evolution.migration_interval = 77;
  b.evolution.migrants = 5;
  EXPECT_EQ(run_identity(a), run_identity(b));
  EXPECT_EQ(run_identity_v1(a), run_identity_v1(b));
  Config k = a;
  k.evolution.islands = 2;
  EXPECT_NE(run_identity(a), run_identity(k));
  EXPECT_NE(run_identity_v1(a), run_identity_v1(k));
  // Scheme 1 hashed the TOML without the three island keys and their comments (as before islands
  // existed), with the resource knobs at their defaults; lines after them still count.
  Config plain = a;
  plain.evolution.threads = EvolutionParams{}.threads;
  // with the keys' comments of that time (a key's documentation may change since)
  std::string text = to_toml(plain, kV1Version, [](std::string_view key, std::string_view doc) {
    for (const auto& [k, comment] : kV1Comments)
      if (k == key) return std::string(comment);
    return std::string(doc);
  });
  const auto begin = text.find("# sub-populations evolving apart");
  const auto end = text.find('\n', text.find("\nmigrants = ") + 1) + 1;
  ASSERT_EQ(std::count(text.begin() + static_cast<std::ptrdiff_t>(begin),
                       text.begin() + static_cast<std::ptrdiff_t>(end), '\n'),
            6);
  text.erase(begin, end - begin);
  // So are the late keys at their defaults, each with its comment line.
  for (const char* key : {"\nobjective = ",
                          "\ndirection = ",
                          "\nintegrator = ",
                          "\ngravity = ",
                          "\nground_height = ",
                          "\nground_friction_static = ",
                          "\nground_friction_kinetic = ",
                          "\nground_contact = ",
                          "\nground_stiffness = ",
                          "\nground_damping = ",
                          "\nground_slip_speed = ",
                          "\nsettle_steps = ",
                          "\nenergy_weight = ",
                          "\nenergy_offset = ",
                          "\nextra_inputs = ",
                          "\nextra_outputs = ",
                          "\ngraph = ",
                          "\ndistance_threshold = ",
                          "\nalpha = ",
                          "\nstiffness_min = ",
                          "\nstiffness_max = ",
                          "\nchemical = ",
                          "\nchemical_source = ",
                          "\nchemical_decay_length = ",
                          "\nmode = ",
                          "\nactuation = ",
                          "\nupdate_interval = ",
                          "\ngrn_rate = ",
                          "\nsignal_rate = ",
                          "\nsignal_decay = ",
                          "\nstart_ramp = ",
                          "\nsource_directions = ",
                          "\nsource_seed = ",
                          "\npush_step = ",
                          "\npush_impulse = ",
                          "\npush_cells = ",
                          "\nmorphogen_cutoff = ",
                          "\nenergy_accounting = ",
                          "\nrepeats = ",
                          "\nrepeat_perturbation = ",
                          "\nrepeat_statistic = ",
                          "\ndivision_axis = ",
                          "\njitter_stream = ",
                          "\ndivision_max_contacts = ",
                          "\nupdate_period = ",
                          "\nprotection_generations = ",
                          "\nalgorithm = ",
                          "\ndescriptors = ",
                          "\nbins = ",
                          "\nranges = ",
                          "\nbatch = ",
                          "\narchive = ",
                          "\ncells = ",
                          "\nsamples = ",
                          "\nobjectives = "}) {
    const auto at = text.find(key);
    ASSERT_NE(at, std::string::npos) << key;
    const auto from = text.rfind('\n', at - 1) + 1;
    ASSERT_EQ(text[from], '#') << key;
    text.erase(from, text.find('\n', at + 1) + 1 - from);
  }
  // [control] and [search] are then empty: their headers go too.
  ASSERT_TRUE(text.ends_with("\n[control]\n\n[search]\n"));
  text.erase(text.size() - std::string("\n[control]\n\n[search]\n").size());
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char ch : text) {
    h ^= ch;
    h *= 0x100000001b3ULL;
  }
  EXPECT_EQ(run_identity_v1(a), h);
}

TEST(RunIdentity, RunsCheckpointedBeforeTheLateKeysStillResume) {
  // data/paper_100_generations was checkpointed (scheme 1) before evaluation.objective,
  // evaluation.direction and physics.integrator existed; its checkpoints carry these identities
  // (the checkpoint field "identity"), which the config it was run with must still give.
  const std::filesystem::path run =
      std::filesystem::path(ANIMAT_SOURCE_DIR) / "data" / "paper_100_generations" / "dn2" / "run_1";
  const Config config = load_config(run / "config.toml");
  EXPECT_EQ(run_identity_v1(config), 0xc3f866cda3ad7231ULL);
  // And a late key away from its default is part of the identity.
  Config c = config;
  c.evaluation.objective = "distance_per_size";
  EXPECT_NE(run_identity_v1(c), 0xc3f866cda3ad7231ULL);
  EXPECT_NE(run_identity(c), run_identity(config));
  // (tests/python/test_evolution.py resumes the run's own checkpoint.)
}

constexpr std::uint64_t kPinnedDefaultIdentity = 0x18200722bab35f84ULL;
constexpr std::uint64_t kPinnedStudyIdentity = 0xc1511dfee1a098d1ULL;

TEST(RunIdentity, SchemeTwoIsPinnedAndReadsValuesNotDocumentation) {
  // The identity of the paper's default config and of a study config, pinned: a change of scheme 2
  // would strand every run checkpointed since.
  const std::filesystem::path run =
      std::filesystem::path(ANIMAT_SOURCE_DIR) / "data" / "paper_100_generations" / "dn2" / "run_1";
  EXPECT_EQ(run_identity(Config{}), kPinnedDefaultIdentity);
  EXPECT_EQ(run_identity(load_config(run / "config.toml")), kPinnedStudyIdentity);
  // It is the hash of "section.key = value" lines: the documentation and the version are not in it.
  Config c;
  c.evolution.islands = 3;
  c.evaluation.objective = "distance_x";
  std::string text;
  for (const auto& key : config_keys()) {
    if (config_identity(key) == Identity::resumable) continue;
    if (config_identity(key) == Identity::late && get_value(c, key) == get_value(Config{}, key))
      continue;
    text += key + " = " + format_config_value(get_value(c, key)) + "\n";
  }
  EXPECT_EQ(text.find('#'), std::string::npos);
  EXPECT_NE(text.find("evaluation.objective = \"distance_x\"\n"), std::string::npos) << text;
  EXPECT_NE(text.find("evolution.migrants = 1\n"), std::string::npos);
  EXPECT_EQ(run_identity(c), fnv1a(text));
  // A checkpoint records its scheme; one of an unknown scheme is refused by name.
  c.evolution.population = 12;
  c.evolution.elites = 1;
  Evolution evo(c, stub_fitness);
  evo.initialize();
  const std::string saved = evo.checkpoint();
  EXPECT_NE(saved.find("identity_scheme"), std::string::npos);
  Evolution resumed(c, stub_fitness);
  EXPECT_NO_THROW(resumed.restore(saved, "scheme 2"));
  // One of an unknown scheme (an intact checkpoint: its checksum recomputed) is refused by name.
  nlohmann::json payload =
      nlohmann::json::parse(nlohmann::json::parse(saved).at("payload").get<std::string>());
  EXPECT_EQ(payload.at("identity_scheme"), kRunIdentityScheme);
  payload["identity_scheme"] = 7;
  const std::string body = payload.dump();
  const std::string unknown =
      nlohmann::json{{"checksum", fmt::format("{:016x}", fnv1a(body))}, {"payload", body}}.dump();
  try {
    Evolution(c, stub_fitness).restore(unknown, "unknown.json");
    FAIL();
  } catch (const CheckpointError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown.json: identity scheme 7 is not supported"),
              std::string::npos)
        << e.what();
  }
}

// ---------------------------------------------------------------------------------------------------
TEST(Wire, GenomesAndFitnessTravelBitForBit) {
  Rng rng(5);
  const Genome g = random_genome(GenomeParams{}, rng);
  Fitness f{0.1 + 0.2, true, false, 31};
  wire::Writer w;
  w.genome(g);
  w.fitness(f);
  w.put(std::uint32_t{7});
  w.string("done");
  wire::Reader r(w.bytes());
  const Genome back = r.genome();
  EXPECT_TRUE(back == g);
  for (std::size_t i = 0; i < g.elements.size(); ++i)
    for (std::size_t d = 0; d < g.elements[i].coords.size(); ++d)
      EXPECT_EQ(std::memcmp(&back.elements[i].coords[d], &g.elements[i].coords[d], sizeof(double)),
                0);
  EXPECT_EQ(r.fitness(), f);
  EXPECT_EQ(r.get<std::uint32_t>(), 7u);
  EXPECT_EQ(r.string(), "done");
  EXPECT_TRUE(r.done());
  EXPECT_EQ(wire::genome_bytes(g), 8 + g.elements.size() * (1 + 1 + 4 + 4 + 8 * 2));
}

TEST(Wire, TruncatedOrMalformedMessagesAreErrorsNotReadsPastTheEnd) {
  Rng rng(6);
  wire::Writer w;
  w.genome(random_genome(GenomeParams{}, rng));
  const auto bytes = w.bytes();
  for (std::size_t cut :
       {std::size_t{0}, std::size_t{3}, std::size_t{9}, bytes.size() / 2, bytes.size() - 1}) {
    wire::Reader r(bytes.data(), cut);
    EXPECT_THROW((void)r.genome(), Error) << "cut at " << cut;
  }
  auto bad = bytes;
  bad[8] = 9;  // first element's type
  wire::Reader r(bad);
  EXPECT_THROW((void)r.genome(), Error);
}
