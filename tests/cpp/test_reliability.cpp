// Reliability (docs/reliability.md): bad input never crashes, long runs survive faults, resources
// stay bounded.
//
//   Catalogue.*        every file in tests/bad_inputs/catalogue/ raises the exact animat error its
//                      <case>.expected sidecar names (configs, --set overrides, genomes,
//                      checkpoints)
//   GeneratedInput.*   bad inputs too large or too deep to commit (10^7 elements, 10^5 nesting
//                      levels)
//   CheckpointSanity.* checkpoints with a valid checksum but an inconsistent or out-of-range
//                      content
//   ResourceBounds.*   the documented caps (genome length, cells, steps, population) are enforced
//   Soak.*             20,000 random and mutated genomes through the whole chain (evaluate)
//   ExtremeConfigs.*   valid but extreme configs: never a NaN, never a crash
//   DiskFaults.*       unwritable, full or vanishing output: clear error, previous checkpoint
//                      intact
//   FuzzRegressions.*  every crash the fuzzers found, as a plain test (see fuzz/ and
//                      docs/reliability.md)
//
// docs/reliability.md lists every guarantee with the test that checks it.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/mount.h>
#include <nlohmann/json.hpp>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include "test_support.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <typeinfo>
#include <vector>

#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/evaluate.hpp"
#include "animat/evaluator.hpp"
#include "animat/evolution.hpp"
#include "animat/genome.hpp"
#include "animat/run.hpp"
#include "animat/run_identity.hpp"

namespace fs = std::filesystem;
using namespace animat;
using nlohmann::json;

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define ANIMAT_TEST_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || \
    __has_feature(memory_sanitizer)
#define ANIMAT_TEST_SANITIZED 1
#endif
#endif
#ifndef ANIMAT_TEST_SANITIZED
#define ANIMAT_TEST_SANITIZED 0
#endif

namespace {

const fs::path kCatalogue = fs::path(ANIMAT_SOURCE_DIR) / "tests" / "bad_inputs" / "catalogue";

using animat::test::slurp;
using animat::test::spit;

std::string replace_all(std::string s, std::string_view from, std::string_view to) {
  for (std::size_t pos = 0; (pos = s.find(from, pos)) != std::string::npos; pos += to.size())
    s.replace(pos, from.size(), to);
  return s;
}

fs::path fresh_dir(const std::string& name) { return animat::test::fresh_dir("animat_rel_", name); }

/// The most derived animat error class of `e`, or "foreign <type>" for anything else.
std::string error_class(const std::exception& e) {
  if (dynamic_cast<const IoError*>(&e)) return "IoError";
  if (dynamic_cast<const ConfigError*>(&e)) return "ConfigError";
  if (dynamic_cast<const GenomeError*>(&e)) return "GenomeError";
  if (dynamic_cast<const GeometryError*>(&e)) return "GeometryError";
  if (dynamic_cast<const CheckpointError*>(&e)) return "CheckpointError";
  if (dynamic_cast<const SimulationError*>(&e)) return "SimulationError";
  if (dynamic_cast<const Error*>(&e)) return "Error";
  return std::string("foreign ") + typeid(e).name();
}

using animat::test::stub_fitness;

Config stub_config(int population = 16, std::int64_t seed = 11) {
  Config c;
  c.evolution.population = population;
  c.evolution.elites = 1;
  c.evolution.seed = seed;
  c.evolution.threads = 1;
  return c;
}

/// The config the catalogue's checkpoints are restored against (they hold 2 individuals).
Config catalogue_config() { return stub_config(2); }

std::string fnv_hex(std::string_view s) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : s) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

/// Re-wraps an edited checkpoint payload with a valid checksum (what a careless hand edit does).
std::string rewrap(const json& payload) {
  const std::string body = payload.dump();
  return json{{"checksum", fnv_hex(body)}, {"payload", body}}.dump();
}

// ---------------------------------------------------------------------------------------------------
// The catalogue: tests/bad_inputs/catalogue/<case>.<ext> + <case>.expected
//
//   error: ConfigError            the animat error class the C++ loader throws
//   python: ValueError            the Python exception class (tests/python/test_reliability.py)
//   message: {path}: ...          the exact message ({path} = the path given to the loader), or
//   contains: ...                 substrings the message must contain (one per line)

struct Expected {
  std::string error, python, message;
  std::vector<std::string> contains;
};

Expected read_expected(const fs::path& p) {
  Expected e;
  std::istringstream in(slurp(p));
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    const auto colon = line.find(": ");
    if (colon == std::string::npos) continue;
    const std::string key = line.substr(0, colon), value = line.substr(colon + 2);
    if (key == "error")
      e.error = value;
    else if (key == "python")
      e.python = value;
    else if (key == "message")
      e.message = value;
    else if (key == "contains")
      e.contains.push_back(value);
  }
  return e;
}

std::vector<std::string> catalogue_cases() {
  std::vector<std::string> out;
  if (!fs::is_directory(kCatalogue)) return out;
  for (const auto& entry : fs::directory_iterator(kCatalogue)) {
    const std::string name = entry.path().filename().string();
    const std::string ext = entry.path().extension().string();
    if (ext == ".toml" || ext == ".json" || ext == ".txt") out.push_back(name);
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string case_kind(const std::string& file) { return file.substr(0, file.find('_')); }

/// Feeds one catalogue file to its loader, as a user would.
void load_case(const fs::path& file) {
  const std::string kind = case_kind(file.filename().string());
  if (kind == "config") {
    (void)load_config(file);
  } else if (kind == "override") {
    Config c;
    std::string text = slurp(file);
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
    apply_override(c, text);
  } else if (kind == "genome") {
    (void)load_genome(file);
  } else if (kind == "checkpoint") {
    Evolution evo(catalogue_config(), stub_fitness);
    evo.restore(slurp(file), file.string());
  } else {
    FAIL() << "unknown catalogue kind in " << file;
  }
}

class Catalogue : public ::testing::TestWithParam<std::string> {};

TEST_P(Catalogue, RaisesTheExactExpectedError) {
  const fs::path file = kCatalogue / GetParam();
  const fs::path sidecar = fs::path(file).replace_extension(".expected");
  ASSERT_TRUE(fs::exists(sidecar)) << "no " << sidecar.filename() << " for " << GetParam();
  const Expected want = read_expected(sidecar);
  ASSERT_FALSE(want.error.empty()) << sidecar << " names no error class";
  ASSERT_TRUE(!want.message.empty() || !want.contains.empty()) << sidecar << " names no message";
  std::string cls = "(nothing thrown)", message;
  try {
    load_case(file);
  } catch (const std::exception& e) {
    cls = error_class(e);
    message = e.what();
  } catch (...) {
    cls = "(non-std exception)";
  }
  EXPECT_EQ(cls, want.error) << "message: " << message;
  const std::string path = file.string();
  if (!want.message.empty()) {
    EXPECT_EQ(message, replace_all(want.message, "{path}", path));
  }
  for (const auto& c : want.contains)
    EXPECT_NE(message.find(replace_all(c, "{path}", path)), std::string::npos)
        << "expected to contain: " << c << "\nactual: " << message;
}

INSTANTIATE_TEST_SUITE_P(BadInputs, Catalogue, ::testing::ValuesIn(catalogue_cases()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string n = info.param;
                           for (char& ch : n)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return n;
                         });

TEST(CatalogueIndex, CoversEveryRequiredCaseAndEveryFileHasASidecar) {
  const auto cases = catalogue_cases();
  ASSERT_GE(cases.size(), 60u);
  for (const auto& entry : fs::directory_iterator(kCatalogue)) {
    if (entry.path().extension() != ".expected") continue;
    const std::string stem = entry.path().stem().string();
    const bool has_input = std::any_of(cases.begin(), cases.end(), [&](const std::string& c) {
      return fs::path(c).stem() == stem;
    });
    EXPECT_TRUE(has_input) << entry.path().filename() << " has no input file";
  }
  // The cases the catalogue must hold: configs, genomes and checkpoints.
  for (const char* required :
       {"config_unknown_key.toml", "config_wrong_type_string.toml",
        "config_population_negative.toml", "config_cells_zero.toml", "config_physics_dt_zero.toml",
        "config_physics_dt_negative.toml", "config_drag_nan.toml", "config_population_zero.toml",
        "config_population_1e9.toml", "config_cells_4097.toml", "genome_nan_coordinate.json",
        "genome_inf_coordinate.json", "genome_type_number.json",
        "genome_input_channel_out_of_range.json", "genome_truncated.json", "genome_binary.json",
        "checkpoint_truncated.json", "checkpoint_checksum_mismatch.json",
        "checkpoint_wrong_version.json"})
    EXPECT_NE(std::find(cases.begin(), cases.end(), required), cases.end()) << required;
}

// ---------------------------------------------------------------------------------------------------
// Generated bad inputs

std::string genome_prefix() {
  return R"({"format": "animat.genome", "version": 1, "dimensions": 2, "elements": [)";
}

TEST(GeneratedInput, TenMillionElementGenomeIsRejectedByTheLengthCap) {
  // 10^7 (minimal) elements: rejected by genome.max_elements before any element is read.
  std::string text = genome_prefix();
  text.reserve(text.size() + 20'000'010);
  for (int i = 0; i < 10'000'000; ++i) text += i ? ",0" : "0";
  text += "]}";
  try {
    (void)genome_from_json(text, GenomeParams{}, "big.json");
    FAIL() << "accepted";
  } catch (const GenomeError& e) {
    EXPECT_STREQ(e.what(), "big.json: 10000000 elements exceed genome.max_elements = 10000");
  }
}

TEST(GeneratedInput, TenMillionFullElementGenomeIsRejectedWithinBoundedMemory) {
  // 10^7 complete elements (440 MB of JSON). The loader must reject it without building a DOM of
  // several GB: the child process gets an address-space limit of its current size + 768 MB.
  if (ANIMAT_TEST_SANITIZED)
    GTEST_SKIP() << "address-space limits do not mix with sanitizer shadow memory";
  const std::string element = R"({"type":"promoter","sign":1,"coords":[0.5,0.5]})";
  std::string text = genome_prefix();
  text.reserve(text.size() + 10'000'000 * (element.size() + 1) + 4);
  for (int i = 0; i < 10'000'000; ++i) {
    if (i) text += ',';
    text += element;
  }
  text += "]}";
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    long vm_kb = 0;
    std::ifstream status("/proc/self/status");
    for (std::string line; std::getline(status, line);)
      if (line.rfind("VmSize:", 0) == 0) vm_kb = std::stol(line.substr(7));
    const rlim_t limit = static_cast<rlim_t>(vm_kb) * 1024 + (768ULL << 20);
    const rlimit rl{limit, limit};
    ::setrlimit(RLIMIT_AS, &rl);
    int code = 3;
    try {
      (void)genome_from_json(text, GenomeParams{}, "big.json");
      code = 4;
    } catch (const GenomeError& e) {
      code = std::string(e.what()).find("exceed genome.max_elements = 10000") != std::string::npos
                 ? 0
                 : 1;
    } catch (const std::bad_alloc&) {
      code = 2;
    } catch (...) {
      code = 3;
    }
    ::_exit(code);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status)) << "child died with signal " << WTERMSIG(status);
  const int code = WEXITSTATUS(status);
  EXPECT_EQ(code, 0)
      << (code == 2   ? "the loader ran out of memory (> 768 MB) before rejecting 10^7 elements"
          : code == 1 ? "GenomeError with another message"
          : code == 4 ? "accepted"
                      : "foreign exception");
}

std::string nested(int depth, std::string_view inner = "1") {
  std::string s(static_cast<std::size_t>(depth), '[');
  s += inner;
  s.append(static_cast<std::size_t>(depth), ']');
  return s;
}

TEST(GeneratedInput, DeeplyNestedGenomeJsonIsAnErrorNotAStackOverflow) {
  // 100,000 nested arrays where a value is expected: an error message must not print them
  // recursively.
  const std::string deep = nested(100'000);
  const std::vector<std::string> docs = {
      deep,
      R"({"format": )" + deep + R"(, "version": 1, "dimensions": 2, "elements": []})",
      R"({"format": "animat.genome", "version": )" + deep + R"(, "dimensions": 2, "elements": []})",
      genome_prefix() + R"({"type": )" + deep + R"(, "sign": 1, "coords": [1, 2]}]})",
      genome_prefix() + R"({"type": "promoter", "sign": 1, "coords": )" + deep + "}]}",
      genome_prefix() + R"({"type": "output", "sign": 1, "channel": )" + deep +
          R"(, "coords": [1, 2]}]})",
  };
  for (std::size_t i = 0; i < docs.size(); ++i) {
    try {
      (void)genome_from_json(docs[i], GenomeParams{}, "deep.json");
      ADD_FAILURE() << "document " << i << " accepted";
    } catch (const GenomeError& e) {
      EXPECT_LT(std::string(e.what()).size(), 2000u) << "document " << i;
    }
  }
}

TEST(GeneratedInput, DeeplyNestedCheckpointIsAnErrorNotAStackOverflow) {
  Evolution evo(catalogue_config(), stub_fitness);
  const std::string deep = nested(100'000);
  for (const std::string& text :
       {deep, R"({"checksum": )" + deep + R"(, "payload": "{}"})",
        rewrap(json::parse(R"({"format": "animat.checkpoint", "version": 1})"))}) {
    try {
      evo.restore(text, "deep.json");
      ADD_FAILURE() << "accepted";
    } catch (const CheckpointError&) {
    }
  }
  // A population genome nested 100,000 deep inside a payload with a valid checksum. The deep array
  // is spliced in as text: building it as a json value would recurse in dump() in this test
  // already.
  Evolution src(catalogue_config(), stub_fitness);
  src.initialize();
  const std::string body = json::parse(src.checkpoint())["payload"].get<std::string>();
  const std::string key = R"("genome":)";
  const auto at = body.find(key);
  ASSERT_NE(at, std::string::npos);
  // keys are sorted: cell_count, fitness, genome, stable
  const auto end = body.find(R"(,"stable")", at);
  ASSERT_NE(end, std::string::npos);
  const std::string spliced = body.substr(0, at + key.size()) + deep + body.substr(end);
  const std::string text =
      R"({"checksum":")" + fnv_hex(spliced) + R"(","payload":)" + json(spliced).dump() + "}";
  try {
    evo.restore(text, "deep.json");
    ADD_FAILURE() << "accepted";
  } catch (const Error& e) {
    EXPECT_LT(std::string(e.what()).size(), 2000u);
  }
}

TEST(GeneratedInput, OverrideCannotInjectFurtherTomlLines) {
  // --set takes one value; a newline must not smuggle in a second table.
  Config c;
  const double dt = c.physics.dt;
  EXPECT_THROW(apply_override(c, "evolution.population=10\n[physics]\ndt = 0.5"), ConfigError);
  EXPECT_EQ(c.physics.dt, dt);
}

/// Runs a shell command; returns its exit status and fills `err` with its stderr.
int shell(const std::string& command, std::string* err = nullptr) {
  const fs::path errfile = fresh_dir("stderr.txt");
  const int rc =
      std::system(("bash -c '" + command + "' 2>" + errfile.string() + " >/dev/null").c_str());
  if (err) *err = slurp(errfile);
  fs::remove(errfile);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : 128 + WTERMSIG(rc);
}

const std::string kSmallRun =
    " --quiet --threads 1 --seed 3 --set evolution.population=8 --set evaluation.steps=50 ";

// ---------------------------------------------------------------------------------------------------
// Checkpoints whose checksum is valid but whose content is not (hand edits, a buggy writer, a
// fuzzer)

json good_payload(int population = 2) {
  Evolution evo(stub_config(population), stub_fitness);
  evo.initialize();
  (void)evo.step();
  return json::parse(json::parse(evo.checkpoint())["payload"].get<std::string>());
}

/// restore() of the edited payload must throw CheckpointError (never crash, never accept).
void expect_refused(const json& payload, const std::string& what, int population = 2) {
  SCOPED_TRACE(what);
  Evolution evo(stub_config(population), stub_fitness);
  try {
    evo.restore(rewrap(payload), "edited.json");
    ADD_FAILURE() << what << ": accepted";
  } catch (const CheckpointError& e) {
    EXPECT_NE(std::string(e.what()).find("edited.json"), std::string::npos) << e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << what << ": " << error_class(e) << ": " << e.what();
  }
}

TEST(CheckpointSanity, ValidCheckpointRoundTrips) {
  Evolution evo(stub_config(2), stub_fitness);
  evo.restore(rewrap(good_payload()), "good.json");
  EXPECT_EQ(evo.generation(), 1);
  EXPECT_EQ(evo.history().size(), 2u);
}

TEST(CheckpointSanity, PopulationSizeMismatchIsRefused) {
  json p = good_payload();
  p["population"].push_back(p["population"][0]);
  Evolution evo(stub_config(2), stub_fitness);
  try {
    evo.restore(rewrap(p), "edited.json");
    FAIL();
  } catch (const CheckpointError& e) {
    EXPECT_STREQ(e.what(),
                 "edited.json: checkpoint holds 3 individuals, evolution.population is 2");
  }
}

TEST(CheckpointSanity, IntegerFieldsHoldingHugeFloatsAreRefused) {
  // nlohmann's get<int>() of 1e300 is a float-to-int conversion out of range: undefined behaviour.
  for (const char* key : {"generation", "stall"}) {
    json p = good_payload();
    p[key] = 1e300;
    expect_refused(p, std::string(key) + " = 1e300");
  }
  {
    json p = good_payload();
    p["population"][0]["cell_count"] = 1e300;
    expect_refused(p, "cell_count = 1e300");
  }
  {
    json p = good_payload();
    p["history"][0]["best_cells"] = -1e300;
    expect_refused(p, "best_cells = -1e300");
  }
}

TEST(CheckpointSanity, EmptyHistoryIsRefused) {
  // run_evolution reports history().back() right after restoring: an empty history must not get
  // there.
  json p = good_payload();
  p["history"] = json::array();
  expect_refused(p, "history = []");
}

TEST(CheckpointSanity, NegativeOrInconsistentGenerationIsRefused) {
  {
    json p = good_payload();
    p["generation"] = -1;
    expect_refused(p, "generation = -1");
  }
  {
    json p = good_payload();
    p["generation"] = 5;  // the history ends at generation 1
    expect_refused(p, "generation = 5 with a history ending at 1");
  }
}

TEST(CheckpointSanity, CliResumingAnEmptyHistoryCheckpointIsAnErrorNotACrash) {
  // The user's view of the above: animat_evolve --resume on such a run directory. The progress line
  // printed right after restoring reads history().back().
  const fs::path dir = fresh_dir("empty_history");
  fs::create_directories(dir);
  json p = good_payload();
  p["history"] = json::array();
  spit(dir / "config.toml", to_toml(stub_config(2)));
  spit(dir / "checkpoint.json", rewrap(p));
  std::string err;
  const int rc = shell(
      std::string(ANIMAT_EVOLVE_EXE) + " --resume " + dir.string() + " --generations 2", &err);
  EXPECT_EQ(rc, 2) << err;
  EXPECT_NE(err.find("animat_evolve: error: "), std::string::npos) << err;
  fs::remove_all(dir);
}

// ---------------------------------------------------------------------------------------------------
// Resource bounds

TEST(ResourceBounds, ConfigCapsAreEnforced) {
  struct Cap {
    const char* key;
    std::int64_t max;
  };
  for (const Cap cap : {Cap{"evaluation.steps", 10'000'000}, Cap{"development.max_cells", 4096},
                        Cap{"development.steps", 100'000}, Cap{"genome.max_elements", 1'000'000},
                        Cap{"physics.substeps", 1000}, Cap{"evolution.population", 100'000},
                        Cap{"development.morphogen_max_delay", 100'000},
                        Cap{"genome.dimensions", 16}, Cap{"evolution.threads", 1024}}) {
    SCOPED_TRACE(cap.key);
    Config c;
    EXPECT_NO_THROW(set_value(c, cap.key, cap.max));
    EXPECT_THROW(set_value(c, cap.key, cap.max + 1), ConfigError);
    EXPECT_THROW(apply_override(c, std::string(cap.key) + "=" + std::to_string(cap.max + 1)),
                 ConfigError);
    EXPECT_THROW(
        (void)config_from_toml(fmt::format(
            "[{}]\n{} = {}\n", std::string(cap.key).substr(0, std::string(cap.key).find('.')),
            std::string(cap.key).substr(std::string(cap.key).find('.') + 1), cap.max + 1)),
        ConfigError);
  }
}

TEST(ResourceBounds, GenomeLengthCapHoldsForLoaderMutationAndCrossover) {
  GenomeParams gp;
  gp.max_elements = 64;
  Rng rng(3);
  Genome g = random_genome(GenomeParams{}, rng);  // 30 elements
  while (g.size() < 64) g.elements.push_back(g.elements[g.size() % 30]);
  EXPECT_NO_THROW((void)genome_from_json(to_json(g), gp));
  Genome longer = g;
  longer.elements.push_back(g.elements[0]);
  EXPECT_THROW((void)genome_from_json(to_json(longer), gp), GenomeError);
  EXPECT_THROW(validate(longer, gp), GenomeError);
  // Duplication at every call never grows a genome past the cap.
  MutationParams m;
  m.duplicate_rate = 1.0;
  m.delete_rate = 0.0;
  m.max_series_length = 1000;
  Genome grown = g;
  for (int i = 0; i < 500; ++i) {
    mutate(grown, m, gp, rng);
    ASSERT_LE(grown.size(), 64u);
  }
  // Crossover children are never longer than the longer parent.
  Genome shorter = g;
  shorter.elements.resize(10);
  for (int i = 0; i < 200; ++i) {
    const Genome child = crossover(g, shorter, 1 + i % 5, rng);
    ASSERT_LE(child.size(), 64u);
  }
}

TEST(ResourceBounds, EvaluateRejectsAGenomeItsConfigWouldRefuse) {
  // evaluate() is the public entry point of the whole chain: a genome built in C++ that no loader
  // would accept (a channel out of range, a length above genome.max_elements) must be an error, not
  // an out-of-bounds access in the GRN or an unbounded development.
  Config c;
  c.evaluation.steps = 10;
  Rng rng(5);
  Genome bad_channel = random_genome(c.genome, rng);
  for (auto& e : bad_channel.elements)
    if (e.type == ElementType::output) e.channel = 99;
  EXPECT_THROW((void)evaluate(bad_channel, c), GenomeError);
  Genome too_long = random_genome(c.genome, rng);
  c.genome.max_elements = 20;
  EXPECT_THROW((void)evaluate(too_long, c), GenomeError);
}

TEST(ResourceBounds, DevelopmentNeverExceedsMaxCells) {
  // A few hundred random genomes at a tiny cap: no embryo is larger than development.max_cells.
  Config c;
  c.development.max_cells = 4;
  c.development.min_cells = 3;
  c.evaluation.steps = 20;
  std::vector<Genome> genomes;
  for (int i = 0; i < 300; ++i) {
    Rng rng = Rng::derive(77, i);
    genomes.push_back(random_genome(c.genome, rng));
  }
  const auto results = evaluate_all(
      genomes,
      [&](const Genome& g) {
        const EvaluationResult r = evaluate(g, c);
        return Fitness{r.fitness, r.viable, r.stable, r.cell_count};
      },
      2);
  for (const auto& r : results) EXPECT_LE(r.cell_count, 4);
}

// ---------------------------------------------------------------------------------------------------
// Soak: random and mutated genomes through the whole chain

int env_int(const char* name, int fallback) {
  const char* v = std::getenv(name);
  return v && *v ? std::atoi(v) : fallback;
}

/// Upper bound on any fitness from the config alone. physics.max_step_displacement caps how far a
/// cell may move in one Box2D step of h = dt / substeps (a larger step is flagged unstable, fitness
/// 0), so no cell, and hence not the centre of mass, is faster than v_max = max_step_displacement /
/// h; over the swim time T = steps·dt it travels at most v_max·T =
/// steps·substeps·max_step_displacement.
double fitness_bound(const Config& c) {
  const double h = c.physics.dt / c.physics.substeps;
  const double v_max = c.physics.max_step_displacement / h;
  return v_max * c.evaluation.steps * c.physics.dt;
}

struct SoakStats {
  int genomes = 0, viable = 0, unstable = 0, max_cells = 0;
  double max_fitness = 0.0, max_speed = 0.0, max_ratio_to_speed_bound = 0.0, seconds = 0.0;
  std::map<std::string, int> reasons;
};

/// Evaluates `genomes` with evaluate_all on 2 threads and checks every result.
void soak(const std::vector<Genome>& genomes, const Config& c, SoakStats& st,
          std::vector<bool>* viable_out = nullptr) {
  std::vector<EvaluationResult> details(genomes.size());
  const Genome* base = genomes.data();
  const auto t0 = std::chrono::steady_clock::now();
  const auto results = evaluate_all(
      genomes,
      [&](const Genome& g) {
        const EvaluationResult r = evaluate(g, c);
        details[static_cast<std::size_t>(&g - base)] = r;
        return Fitness{r.fitness, r.viable, r.stable, r.cell_count};
      },
      2);
  st.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double bound = fitness_bound(c);
  if (viable_out) viable_out->assign(genomes.size(), false);
  for (std::size_t i = 0; i < genomes.size(); ++i) {
    const EvaluationResult& r = details[i];
    SCOPED_TRACE(::testing::Message() << "genome " << i << ": " << to_json(genomes[i]));
    ++st.genomes;
    ASSERT_TRUE(std::isfinite(r.fitness));
    ASSERT_GE(r.fitness, 0.0);
    ASSERT_LE(r.fitness, bound);
    ASSERT_TRUE(std::isfinite(r.max_speed));
    // The per-swim form of the same bound: the centre of mass is never faster than the fastest
    // cell.
    ASSERT_LE(r.fitness, r.max_speed * r.simulated_time * (1.0 + 1e-3) + 1e-6)
        << "max_speed " << r.max_speed << ", simulated time " << r.simulated_time;
    ASSERT_LE(r.cell_count, c.development.max_cells);
    ASSERT_EQ(results[i].fitness, r.fitness);
    if (!r.viable) {
      ASSERT_EQ(r.fitness, 0.0);
    }
    if (!r.stable) {
      ASSERT_EQ(r.fitness, 0.0);
      ++st.unstable;
      ++st.reasons[r.reasons.empty() ? "?" : r.reasons.front().substr(0, 60)];
    }
    if (r.viable) {
      ++st.viable;
      if (viable_out) (*viable_out)[i] = true;
      st.max_cells = std::max(st.max_cells, r.cell_count);
      st.max_fitness = std::max(st.max_fitness, r.fitness);
      st.max_speed = std::max(st.max_speed, r.max_speed);
      if (r.max_speed * r.simulated_time > 0)
        st.max_ratio_to_speed_bound =
            std::max(st.max_ratio_to_speed_bound, r.fitness / (r.max_speed * r.simulated_time));
    }
  }
}

TEST(Soak, RandomAndMutatedGenomesNeverCrashNeverNaNNeverExceedTheSpeedBound) {
  // Default settings (the paper's d_N = 2, 32 cells, 4000 swim steps); fixed seeds.
  // ANIMAT_SOAK_GENOMES sets the total (default 20,000; 1,000 in sanitizer builds, where a swim is
  // ~10x slower).
  const int total = env_int("ANIMAT_SOAK_GENOMES", ANIMAT_TEST_SANITIZED ? 1000 : 20000);
  const int n_random = total / 2, n_mutated = total - n_random;
  const Config c;
  prepare_parallel_evaluation();

  SoakStats random_stats, mutated_stats, short_stats;
  std::vector<Genome> random;
  random.reserve(static_cast<std::size_t>(n_random));
  for (int i = 0; i < n_random; ++i) {
    Rng rng = Rng::derive(20'240'901, 0, i);
    random.push_back(random_genome(c.genome, rng));
  }
  std::vector<bool> viable;
  soak(random, c, random_stats, &viable);
  if (HasFatalFailure()) return;
  // About 0.7% of random genomes are viable: small soaks (sanitizer builds) draw more until one is.
  while (std::find(viable.begin(), viable.end(), true) == viable.end() && random.size() < 20'000) {
    std::vector<Genome> more;
    for (std::size_t i = random.size(); i < random.size() + 500; ++i) {
      Rng rng = Rng::derive(20'240'901, 0, i);
      more.push_back(random_genome(c.genome, rng));
    }
    std::vector<bool> more_viable;
    soak(more, c, random_stats, &more_viable);
    if (HasFatalFailure()) return;
    random.insert(random.end(), more.begin(), more.end());
    viable.insert(viable.end(), more_viable.begin(), more_viable.end());
  }
  std::vector<const Genome*> parents;
  for (std::size_t i = 0; i < random.size(); ++i)
    if (viable[i]) parents.push_back(&random[i]);
  ASSERT_FALSE(parents.empty()) << "no viable random genome among " << random.size();

  // Mutated genomes: 1-4 rounds of the GA's own operators on a viable parent, a fifth of them after
  // a crossover with a second viable parent, a quarter at 10x the default rates (farther from
  // viability).
  MutationParams strong = c.mutation;
  for (double* r : {&strong.type_rate, &strong.sign_rate, &strong.move_rate, &strong.duplicate_rate,
                    &strong.delete_rate})
    *r = std::min(1.0, 10 * *r);
  std::vector<Genome> mutated;
  mutated.reserve(static_cast<std::size_t>(n_mutated));
  for (int i = 0; i < n_mutated; ++i) {
    Rng rng = Rng::derive(20'240'901, 1, i);
    Genome g = *parents[rng.below(parents.size())];
    if (rng.bernoulli(0.2))
      g = crossover(g, *parents[rng.below(parents.size())], c.mutation.crossover_points, rng);
    const MutationParams& m = i % 4 == 3 ? strong : c.mutation;
    for (int r = 1 + static_cast<int>(rng.below(4)); r > 0; --r) mutate(g, m, c.genome, rng);
    mutated.push_back(std::move(g));
  }
  // Mutants of viable parents mostly swim, and a 4000-step swim is the whole cost (~55 ms): the
  // first 30% swim the default 4000 steps, the other 70% a shortened evaluation.steps = 1000 (all
  // other settings default), which keeps the soak near one minute on 2 cores.
  const std::size_t n_full = static_cast<std::size_t>(n_mutated) * 3 / 10;
  Config short_swim = c;
  short_swim.evaluation.steps = 1000;
  soak(std::vector<Genome>(mutated.begin(), mutated.begin() + static_cast<std::ptrdiff_t>(n_full)),
       c, mutated_stats);
  if (HasFatalFailure()) return;
  soak(std::vector<Genome>(mutated.begin() + static_cast<std::ptrdiff_t>(n_full), mutated.end()),
       short_swim, short_stats);
  if (HasFatalFailure()) return;

  auto report = [&](const char* name, const SoakStats& s, const Config& used) {
    std::cout << "[soak] " << name << ": " << s.genomes << " genomes, " << s.viable << " viable, "
              << s.unstable << " unstable (" << 100.0 * s.unstable / std::max(1, s.genomes)
              << "%), max fitness " << s.max_fitness << " (config bound " << fitness_bound(used)
              << "), max cell speed " << s.max_speed << ", max fitness/(max_speed*T) "
              << s.max_ratio_to_speed_bound << ", max cells " << s.max_cells << ", " << s.seconds
              << " s on 2 threads\n";
    for (const auto& [reason, n] : s.reasons)
      std::cout << "[soak]   unstable x" << n << ": " << reason << "\n";
  };
  report("random, 4000 steps ", random_stats, c);
  report("mutated, 4000 steps", mutated_stats, c);
  report("mutated, 1000 steps", short_stats, short_swim);
  const int unstable = random_stats.unstable + mutated_stats.unstable + short_stats.unstable;
  RecordProperty("unstable", unstable);
  RecordProperty("viable", random_stats.viable + mutated_stats.viable + short_stats.viable);
  EXPECT_EQ(unstable, 0) << "fraction flagged unstable must be 0 at default settings";
  EXPECT_GT(mutated_stats.viable + short_stats.viable, n_mutated / 10)
      << "mutants should mostly swim (else the soak tests little)";
}

// ---------------------------------------------------------------------------------------------------
// Extreme but valid configs: never a NaN, never a crash; an unstable swim is flagged with fitness 0

TEST(ExtremeConfigs, NeverANaNNeverACrash) {
  // A handful of viable genomes under configs at the edges of their ranges.
  Config base;
  base.evaluation.steps = 400;
  std::vector<Genome> viable;
  for (int i = 0; viable.size() < 4 && i < 5000; ++i) {
    Rng rng = Rng::derive(99, i);
    Genome g = random_genome(base.genome, rng);
    if (evaluate(g, base).viable) viable.push_back(std::move(g));
  }
  ASSERT_FALSE(viable.empty());
  std::vector<std::string> overrides = {"scene.drag_normal=1000000",
                                        "scene.drag_normal=0",
                                        "scene.pressure=1000000",
                                        "scene.spring_stiffness=1e9",
                                        "scene.spring_stiffness=0",
                                        "scene.spring_damping=1e9",
                                        "scene.cell_mass=1e-9",
                                        "scene.cell_mass=1e9",
                                        "physics.dt=1",
                                        "physics.drag_scheme=explicit",
                                        "physics.max_step_displacement=1e-9",
                                        "development.amplitude_max=0.45",
                                        "development.frequency_max=1e6",
                                        "scene.collision_stiffness=1e12",
                                        "physics.substeps=7",
                                        "scene.effects=[]",
                                        "development.effects=[]"};
  for (const auto& o : overrides) {
    Config c = base;
    apply_override(c, o);
    for (const Genome& g : viable) {
      SCOPED_TRACE(o);
      EvaluationResult r;
      try {
        r = evaluate(g, c);
      } catch (const Error& e) {
        ADD_FAILURE() << "evaluate threw " << error_class(e) << ": " << e.what();
        continue;
      }
      EXPECT_TRUE(std::isfinite(r.fitness));
      EXPECT_GE(r.fitness, 0.0);
      EXPECT_LE(r.fitness, fitness_bound(c));
      if (!r.stable) {
        EXPECT_EQ(r.fitness, 0.0);
        EXPECT_FALSE(r.reasons.empty());
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------------
// Parallel evaluation: scripts/reliability.sh runs these under ThreadSanitizer

/// Random genomes plus mutants of the first viable ones found: development for all, swims for some.
std::vector<Genome> parallel_workload(const Config& c, int random_count, int viable_wanted) {
  std::vector<Genome> out, viable;
  for (int i = 0; i < 3000 && static_cast<int>(viable.size()) < viable_wanted; ++i) {
    Rng rng = Rng::derive(4242, i);
    Genome g = random_genome(c.genome, rng);
    if (evaluate(g, c).viable) viable.push_back(g);
    if (i < random_count) out.push_back(std::move(g));
  }
  for (std::size_t k = 0; k < viable.size(); ++k) {
    out.push_back(viable[k]);
    for (int m = 0; m < 3; ++m) {
      Rng rng = Rng::derive(4243, k, m);
      Genome g = viable[k];
      mutate(g, c.mutation, c.genome, rng);
      out.push_back(std::move(g));
    }
  }
  return out;
}

FitnessFunction evaluate_fitness(const Config& c) {
  return [c](const Genome& g) {
    const EvaluationResult r = evaluate(g, c);
    return Fitness{r.fitness, r.viable, r.stable, r.cell_count};
  };
}

TEST(ParallelEvaluation, EvaluateAllOnTwoOpenMPThreadsMatchesOneThread) {
  Config c;
  c.evaluation.steps = 300;
  const auto genomes = parallel_workload(c, 24, 2);
  const auto one = evaluate_all(genomes, evaluate_fitness(c), 1);
  const auto two = evaluate_all(genomes, evaluate_fitness(c), 2);
  ASSERT_EQ(one.size(), two.size());
  int viable = 0;
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i], two[i]) << "genome " << i;
    viable += one[i].viable;
  }
  EXPECT_GE(viable, 2) << "the workload should include swims";
}

TEST(ParallelEvaluation, StdThreadsWithTheirOwnWorldsMatchSerial) {
  // The same per-thread worlds without OpenMP: what ThreadSanitizer checks here is our code (and
  // Box2D's use of shared state) independently of the OpenMP runtime's own synchronisation.
  Config c;
  c.evaluation.steps = 300;
  const auto genomes = parallel_workload(c, 24, 2);
  const FitnessFunction f = evaluate_fitness(c);
  std::vector<Fitness> serial;
  for (const auto& g : genomes) serial.push_back(f(g));
  prepare_parallel_evaluation();
  std::vector<Fitness> threaded(genomes.size());
  std::vector<std::thread> pool;
  for (std::size_t t = 0; t < 2; ++t)
    pool.emplace_back([&, t] {
      for (std::size_t i = t; i < genomes.size(); i += 2) threaded[i] = f(genomes[i]);
    });
  for (auto& th : pool) th.join();
  for (std::size_t i = 0; i < genomes.size(); ++i)
    EXPECT_EQ(serial[i], threaded[i]) << "genome " << i;
}

TEST(TsanCanary, APlantedRaceInAFitnessFunctionIsReported) {
  // Run only by scripts/reliability.sh in the ThreadSanitizer build (ANIMAT_TSAN_CANARY=1), which
  // expects this process to die with a data-race report: proof that the TSan run sees races in code
  // called from evaluate_all's OpenMP region (a setup that silently saw nothing would also "pass").
  if (std::getenv("ANIMAT_TSAN_CANARY") == nullptr)
    GTEST_SKIP() << "set ANIMAT_TSAN_CANARY=1 (ThreadSanitizer build only)";
  int counter = 0;  // deliberately unsynchronised
  const std::vector<Genome> genomes(64);
  const auto results = evaluate_all(
      genomes,
      [&](const Genome&) {
        ++counter;
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        return Fitness{};
      },
      2);
  EXPECT_EQ(results.size(), 64u);
}

// ---------------------------------------------------------------------------------------------------
// Disk and I/O faults

RunOptions run_options(const fs::path& out, bool resume = false) {
  RunOptions o;
  o.out = out;
  o.resume = resume;
  o.quiet = true;
  return o;
}

/// history.csv without the wall_seconds column (the only machine-dependent one).
std::string history_without_wall(const fs::path& dir) {
  std::istringstream in(slurp(dir / "history.csv"));
  std::string out, line;
  while (std::getline(in, line)) out += line.substr(0, line.rfind(',')) + "\n";
  return out;
}

TEST(DiskFaults, OutputUnderARegularFileIsAClearError) {
  const fs::path dir = fresh_dir("regular");
  fs::create_directories(dir);
  spit(dir / "file", "x");
  Config c = stub_config();
  c.evolution.generations = 2;
  try {
    (void)run_evolution(c, run_options(dir / "file" / "run"), stub_fitness);
    FAIL() << "no error";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot create run directory: Not a directory"),
              std::string::npos)
        << e.what();
  }
  fs::remove_all(dir);
}

TEST(DiskFaults, OutputInsideProcIsAClearError) {
  Config c = stub_config();
  c.evolution.generations = 2;
  EXPECT_THROW((void)run_evolution(c, run_options("/proc/animat_no_such_dir/run"), stub_fitness),
               IoError);
}

TEST(DiskFaults, ExistingRunIsNeverOverwritten) {
  const fs::path dir = fresh_dir("existing");
  Config c = stub_config();
  c.evolution.generations = 2;
  (void)run_evolution(c, run_options(dir), stub_fitness);
  const std::string before = slurp(dir / "checkpoint.json");
  try {
    (void)run_evolution(c, run_options(dir), stub_fitness);
    FAIL() << "overwrote a run";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("already holds a run"), std::string::npos) << e.what();
  }
  EXPECT_EQ(slurp(dir / "checkpoint.json"), before);
  fs::remove_all(dir);
}

TEST(DiskFaults, ResumeDirectoryWithoutCheckpointIsAClearError) {
  const fs::path dir = fresh_dir("no_ckpt");
  fs::create_directories(dir);
  try {
    (void)run_evolution(stub_config(), run_options(dir, true), stub_fitness);
    FAIL();
  } catch (const CheckpointError& e) {
    EXPECT_NE(std::string(e.what()).find("no checkpoint.json to resume from"), std::string::npos)
        << e.what();
  }
  fs::remove_all(dir);
}

/// Runs `generations` generations; at generation `fault_at`, `inject(dir)` sabotages the next
/// checkpoint write. Returns the error message of the failed run.
std::string run_with_fault(const fs::path& dir, const Config& c, int fault_at,
                           const std::function<void(const fs::path&)>& inject) {
  RunOptions o = run_options(dir);
  o.callback = [&](const GenerationStats& s, const Evolution&) {
    if (s.generation == fault_at) inject(dir);
    return true;
  };
  try {
    (void)run_evolution(c, o, stub_fitness);
  } catch (const IoError& e) {
    return e.what();
  }
  return "(no error)";
}

void expect_checkpoint_at(const fs::path& dir, const Config& c, int generation) {
  Evolution evo(c, stub_fitness);
  ASSERT_NO_THROW(evo.restore(slurp(dir / "checkpoint.json"), "checkpoint.json"));
  EXPECT_EQ(evo.generation(), generation);
}

void expect_resume_matches_uninterrupted(const fs::path& dir, const Config& c) {
  const fs::path ref = fs::path(dir.string() + "_ref");
  fs::remove_all(ref);
  const RunSummary a = run_evolution(c, run_options(ref), stub_fitness);
  const RunSummary b = run_evolution(c, run_options(dir, true), stub_fitness);
  EXPECT_EQ(history_without_wall(dir), history_without_wall(ref));
  // rows written after the checkpoint by the interrupted process are dropped, then rewritten
  EXPECT_EQ(slurp(dir / "genealogy.csv"), slurp(ref / "genealogy.csv"));
  EXPECT_TRUE(a.best.genome == b.best.genome);
  fs::remove_all(ref);
}

/// The temporary file this process writes a checkpoint through.
std::string checkpoint_temporary() {
  return "checkpoint.json." + std::to_string(::getpid()) + ".tmp";
}

TEST(DiskFaults, FullDiskDuringACheckpointKeepsThePreviousOne) {
  // checkpoint.json.PID.tmp (this process writes it) is a symlink to /dev/full: the next checkpoint
  // write fails with ENOSPC.
  const fs::path dir = fresh_dir("full");
  Config c = stub_config();
  c.evolution.generations = 8;
  const std::string err = run_with_fault(dir, c, 3, [](const fs::path& d) {
    fs::create_symlink("/dev/full", d / checkpoint_temporary());
  });
  EXPECT_NE(err.find("No space left on device"), std::string::npos) << err;
  expect_checkpoint_at(dir, c, 3);
  EXPECT_FALSE(fs::exists(fs::symlink_status(dir / checkpoint_temporary())))
      << "the failed temporary file is removed";
  expect_resume_matches_uninterrupted(dir, c);
  fs::remove_all(dir);
}

TEST(DiskFaults, UnwritableCheckpointKeepsThePreviousOne) {
  // checkpoint.json.PID.tmp is a directory: the write cannot even start.
  const fs::path dir = fresh_dir("blocked");
  Config c = stub_config();
  c.evolution.generations = 6;
  const std::string err = run_with_fault(
      dir, c, 2, [](const fs::path& d) { fs::create_directory(d / checkpoint_temporary()); });
  EXPECT_NE(err.find("cannot write"), std::string::npos) << err;
  expect_checkpoint_at(dir, c, 2);
  fs::remove(dir / checkpoint_temporary());
  expect_resume_matches_uninterrupted(dir, c);
  fs::remove_all(dir);
}

TEST(DiskFaults, CliFileSizeLimitIsAClearError) {
  // ulimit -f 8 (KiB) with SIGXFSZ ignored: writes fail with EFBIG, the binary reports and exits 2.
  const fs::path dir = fresh_dir("ulimit");
  std::string err;
  const int rc = shell("ulimit -f 8; trap \"\" XFSZ; exec " + std::string(ANIMAT_EVOLVE_EXE) +
                           kSmallRun + "--generations 3 --out " + dir.string(),
                       &err);
  EXPECT_EQ(rc, 2) << err;
  EXPECT_NE(err.find("animat_evolve: error: "), std::string::npos) << err;
  EXPECT_NE(err.find("File too large"), std::string::npos) << err;
  fs::remove_all(dir);
}

TEST(DiskFaults, CliMissingResumeDirectoryIsAClearError) {
  std::string err;
  const int rc = shell(std::string(ANIMAT_EVOLVE_EXE) + " --resume /nonexistent/animat_run", &err);
  EXPECT_EQ(rc, 2) << err;
  EXPECT_EQ(err,
            "animat_evolve: error: /nonexistent/animat_run: resume directory does not exist\n");
}

TEST(DiskFaults, CliTinyAndReadOnlyTmpfs) {
  // A 64 KiB tmpfs fills up mid-run; a read-only one refuses the run directory. Needs mount(2)
  // rights.
  const fs::path mnt = fresh_dir("tmpfs");
  fs::create_directories(mnt);
  if (::mount("tmpfs", mnt.c_str(), "tmpfs", 0, "size=64k") != 0) {
    fs::remove_all(mnt);
    GTEST_SKIP() << "cannot mount a tmpfs here (" << std::strerror(errno)
                 << "); the /dev/full and ulimit tests cover a full disk";
  }
  struct Unmount {
    fs::path dir;
    ~Unmount() {
      ::umount(dir.c_str());
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  } unmount{mnt};
  std::string err;
  int rc =
      shell(std::string(ANIMAT_EVOLVE_EXE) + kSmallRun +
                "--set evolution.population=100 --generations 50 --out " + (mnt / "run").string(),
            &err);
  EXPECT_EQ(rc, 2) << err;
  EXPECT_NE(err.find("No space left on device"), std::string::npos) << err;
  if (fs::exists(mnt / "run" / "checkpoint.json")) {
    const json left = json::parse(slurp(mnt / "run" / "checkpoint.json"), nullptr, false);
    EXPECT_FALSE(left.is_discarded()) << "a checkpoint left on a full disk is whole";
  }
  ASSERT_EQ(::mount("tmpfs", mnt.c_str(), "tmpfs", MS_REMOUNT | MS_RDONLY, "size=64k"), 0)
      << std::strerror(errno);
  rc = shell(std::string(ANIMAT_EVOLVE_EXE) + kSmallRun + "--generations 2 --out " +
                 (mnt / "run2").string(),
             &err);
  EXPECT_EQ(rc, 2) << err;
  EXPECT_NE(err.find("Read-only file system"), std::string::npos) << err;
}

// ---------------------------------------------------------------------------------------------------
// The run directory: one writer, no run silently replaced, refusals that change nothing

/// Every file and folder under `dir` with its content: equal snapshots = a byte-identical
/// directory.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> out;
  if (!fs::exists(dir)) return out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    const std::string rel = fs::relative(e.path(), dir).string();
    out[rel] = e.is_directory() ? std::string("<dir>") : slurp(e.path());
  }
  return out;
}

std::string listing(const std::map<std::string, std::string>& snap) {
  std::string s;
  for (const auto& [name, content] : snap)
    s += name + " (" + std::to_string(content.size()) + " bytes) ";
  return s;
}

#define EXPECT_SAME_DIRECTORY(before, dir, what)                                 \
  do {                                                                           \
    const auto after_ = snapshot(dir);                                           \
    EXPECT_TRUE(after_ == (before))                                              \
        << (what) << " changed the run directory:\n before: " << listing(before) \
        << "\n after:  " << listing(after_);                                     \
  } while (0)

/// A stub-fitness config whose real swims are short too (a CLI run on the same directory swims).
Config small_run_config(int generations) {
  Config c = stub_config(8, 3);
  c.evaluation.steps = 50;
  c.evolution.generations = generations;
  return c;
}

std::vector<int> history_generations(const fs::path& dir) {
  std::istringstream in(slurp(dir / "history.csv"));
  std::string line;
  std::vector<int> out;
  for (bool header = true; std::getline(in, line); header = false)
    if (!header && !line.empty()) out.push_back(std::stoi(line.substr(0, line.find(','))));
  return out;
}

TEST(RunDirectory, SecondWriterIsRefusedNamingTheHolderAndChangesNothing) {
  // While a run is paused in its callback (it holds the directory), every other writer is refused:
  // the CLI on --out and on --resume, and another run_evolution in this process. No sleeps: the
  // callback runs them and waits for them to end.
  const fs::path dir = fresh_dir("two_writers");
  const Config c = small_run_config(5);
  const std::string me = "pid " + std::to_string(::getpid()) + " on host ";
  bool checked = false;
  RunOptions o = run_options(dir);
  o.callback = [&](const GenerationStats& s, const Evolution&) {
    if (s.generation != 2) return true;
    checked = true;
    EXPECT_TRUE(fs::exists(dir / ".lock")) << "the run holds RUN/.lock";
    const auto before = snapshot(dir);
    for (const std::string& args :
         {std::string(" --quiet --resume ") + dir.string() + " --generations 9",
          kSmallRun + "--generations 9 --out " + dir.string()}) {
      std::string err;
      const int rc = shell(std::string(ANIMAT_EVOLVE_EXE) + args, &err);
      EXPECT_EQ(rc, 2) << args << ": " << err;
      EXPECT_NE(err.find("in use by another animat process (" + me), std::string::npos)
          << args << ": " << err;
      EXPECT_NE(err.find("Nothing was written"), std::string::npos) << err;
      EXPECT_SAME_DIRECTORY(before, dir, args);
    }
    try {
      RunOptions again = run_options(dir, true);
      (void)run_evolution(c, again, stub_fitness);
      ADD_FAILURE() << "a second run_evolution on the same directory was not refused";
    } catch (const RunDirectoryBusy& e) {
      EXPECT_NE(std::string(e.what()).find(me), std::string::npos) << e.what();
    }
    EXPECT_SAME_DIRECTORY(before, dir, "run_evolution(resume)");
    return true;
  };
  const RunSummary r = run_evolution(c, o, stub_fitness);
  ASSERT_TRUE(checked);
  EXPECT_EQ(r.history.back().generation, 5);
  EXPECT_EQ(history_generations(dir), (std::vector<int>{0, 1, 2, 3, 4, 5}))
      << "one writer, generations in order";
  EXPECT_FALSE(fs::exists(dir / ".lock")) << "a run that ends removes its lock file";
  for (const auto& e : fs::recursive_directory_iterator(dir))
    EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos)
        << "temporary file left: " << e.path();
  fs::remove_all(dir);
}

TEST(RunDirectory, LockFileOfAKilledRunIsTakenOver) {
  // A killed run leaves RUN/.lock naming a process that no longer holds it (the kernel drops an
  // flock with its process): the next run takes it over and removes it when it ends. A lock file
  // found by a refused command is left as it was.
  const fs::path dir = fresh_dir("stale_lock");
  Config c = small_run_config(2);
  (void)run_evolution(c, run_options(dir), stub_fitness);
  spit(dir / ".lock", "pid 999999999\nhost elsewhere\n");
  spit(dir / "checkpoint.json.4242.tmp", "half a checkpoint");  // a killed writer's temporary file
  Config changed = c;
  changed.evolution.population = 9;
  const auto before = snapshot(dir);
  EXPECT_THROW((void)run_evolution(changed, run_options(dir, true), stub_fitness), ConfigError);
  EXPECT_SAME_DIRECTORY(before, dir, "a refused resume");
  c.evolution.generations = 4;
  const RunSummary r = run_evolution(c, run_options(dir, true), stub_fitness);
  EXPECT_EQ(r.history.back().generation, 4);
  EXPECT_FALSE(fs::exists(dir / ".lock"));
  EXPECT_FALSE(fs::exists(dir / "checkpoint.json.4242.tmp"))
      << "temporary files of dead writers are removed";
  fs::remove_all(dir);
}

TEST(RunDirectory, TemporaryFilesAreNamedAfterTheirProcess) {
  // Two processes never share a temporary name: checkpoint.json.PID.tmp, not checkpoint.json.tmp.
  const fs::path dir = fresh_dir("tmp_names");
  Config c = small_run_config(3);
  const fs::path mine = dir / ("checkpoint.json." + std::to_string(::getpid()) + ".tmp");
  bool seen = false;
  RunOptions o = run_options(dir);
  o.callback = [&](const GenerationStats& s, const Evolution&) {
    if (s.generation == 1) {
      fs::create_directory(mine);  // blocks exactly this process's next checkpoint write
      fs::create_directory(dir / "checkpoint.json.tmp");
    }
    return true;
  };
  try {
    (void)run_evolution(c, o, stub_fitness);
  } catch (const IoError& e) {
    seen = std::string(e.what()).find(mine.string() + ": cannot write") != std::string::npos;
    EXPECT_TRUE(seen) << e.what();
  }
  EXPECT_TRUE(seen) << "the checkpoint write did not use " << mine;
  fs::remove_all(dir);
}

TEST(RunDirectory, RunFilesWithoutACheckpointAreNeverOverwritten) {
  // config.toml, history.csv and best/ of a run whose checkpoint.json is gone: a new run there
  // would shrink the history and mix two lineages. Refused, naming what is there; overwrite
  // replaces it.
  const fs::path dir = fresh_dir("no_ckpt_files");
  Config c = small_run_config(4);
  (void)run_evolution(c, run_options(dir), stub_fitness);
  fs::remove(dir / "checkpoint.json");
  const auto before = snapshot(dir);
  for (const std::int64_t seed : {std::int64_t{3}, std::int64_t{4}}) {
    // the same config, and another
    Config again = small_run_config(2);
    again.evolution.seed = seed;
    try {
      (void)run_evolution(again, run_options(dir), stub_fitness);
      ADD_FAILURE() << "seed " << seed << ": overwrote a run without a checkpoint";
    } catch (const RunExists& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("no checkpoint.json"), std::string::npos) << m;
      EXPECT_NE(m.find("history.csv (5 generations)"), std::string::npos) << m;
      EXPECT_NE(m.find("best/ ("), std::string::npos) << m;
      EXPECT_NE(m.find("overwrite"), std::string::npos) << m;
      // generations differs
      EXPECT_NE(m.find("config.toml (a different config: "), std::string::npos) << m;
      EXPECT_EQ(m.find("evolution.seed") != std::string::npos, seed == 4) << m;
    }
    EXPECT_SAME_DIRECTORY(before, dir, "a refused new run");
  }
  // The CLI says the same and exits 2.
  std::string err;
  EXPECT_EQ(
      shell(std::string(ANIMAT_EVOLVE_EXE) + kSmallRun + "--generations 2 --out " + dir.string(),
            &err),
      2)
      << err;
  EXPECT_NE(err.find("holds the files of a run but no checkpoint.json"), std::string::npos) << err;
  EXPECT_SAME_DIRECTORY(before, dir, "the CLI's refused new run");
  // Asked for explicitly, the old run is replaced entirely.
  Config fresh = small_run_config(1);
  RunOptions o = run_options(dir);
  o.overwrite = true;
  (void)run_evolution(fresh, o, stub_fitness);
  EXPECT_EQ(history_generations(dir), (std::vector<int>{0, 1}));
  EXPECT_EQ(slurp(dir / "config.toml"), to_toml(fresh));
  fs::remove_all(dir);
}

TEST(RunDirectory, TheSameCommandStoppedBeforeItsFirstCheckpointStartsOver) {
  // Killed between generation 0's history row and its first checkpoint, a run leaves config.toml,
  // one history row and best/gen_000000.json: the same command writes exactly these again.
  const fs::path dir = fresh_dir("restart"), ref = fresh_dir("restart_ref");
  const Config c = small_run_config(3);
  (void)run_evolution(c, run_options(ref), stub_fitness);
  RunOptions o = run_options(dir);
  // stop after generation 0
  o.callback = [](const GenerationStats&, const Evolution&) { return false; };
  (void)run_evolution(c, o, stub_fitness);
  fs::remove(dir / "checkpoint.json");
  (void)run_evolution(c, run_options(dir), stub_fitness);
  EXPECT_EQ(history_without_wall(dir), history_without_wall(ref));
  fs::remove_all(dir);
  fs::remove_all(ref);
}

TEST(RunDirectory, EveryRefusalOfTheCliLeavesTheDirectoryByteIdentical) {
  // A run directory with stopped.txt (a job that ended badly): each refused command changes no byte
  // of it, stopped.txt included. An accepted resume shows and removes stopped.txt.
  const fs::path dir = fresh_dir("refusals");
  const std::string exe = ANIMAT_EVOLVE_EXE;
  std::string err;
  ASSERT_EQ(shell(exe + kSmallRun + "--generations 2 --out " + dir.string(), &err), 0) << err;
  spit(dir / "stopped.txt", "animat_evolve: error: MPI job stopped: rank 1 lost\n");
  spit(dir / "resume.log", "earlier resume\n");
  const fs::path no_ckpt = fresh_dir("refusals_no_ckpt"), corrupt = fresh_dir("refusals_corrupt");
  fs::copy(dir, no_ckpt, fs::copy_options::recursive);
  fs::remove(no_ckpt / "checkpoint.json");
  fs::copy(dir, corrupt, fs::copy_options::recursive);
  std::string ckpt = slurp(corrupt / "checkpoint.json");
  ckpt[ckpt.size() / 2] = ckpt[ckpt.size() / 2] == 'x' ? 'y' : 'x';
  spit(corrupt / "checkpoint.json", ckpt);
  const std::vector<std::pair<fs::path, std::string>> refused = {
      // a change that defines the run
      {dir, "--resume " + dir.string() + " --set evolution.population=9"},
      {dir, "--resume " + dir.string() + " --set evolution.seed=5"},
      {dir, "--resume " + dir.string() + " --generations -1"},  // a bad flag value
      {dir, "--resume " + dir.string() + " --set evolution.elites=nine"},
      {dir, "--resume " + dir.string() + " --config " + (dir / "config.toml").string()},
      {dir, "--resume " + dir.string() + " --overwrite"},
      {dir, "--resume " + dir.string() + " --out " + no_ckpt.string()},
      {dir, kSmallRun + "--generations 2 --out " + dir.string()},  // an existing run
      {no_ckpt, "--resume " + no_ckpt.string()},                   // no checkpoint
      // a corrupt checkpoint
      {corrupt, "--resume " + corrupt.string()},
  };
  for (const auto& [target, args] : refused) {
    const auto before = snapshot(target);
    const int rc = shell(exe + " --quiet " + args, &err);
    EXPECT_NE(rc, 0) << args << ": accepted";
    EXPECT_SAME_DIRECTORY(before, target, args);
  }
  // the log too
  EXPECT_EQ(shell(exe + " --resume " + dir.string() + " --generations 3 1>&2", &err), 0) << err;
  EXPECT_NE(err.find("rank 1 lost"), std::string::npos)
      << "the accepted resume shows stopped.txt: " << err;
  EXPECT_FALSE(fs::exists(dir / "stopped.txt"));
  for (const auto& d : {dir, no_ckpt, corrupt}) fs::remove_all(d);
}

// ---------------------------------------------------------------------------------------------------
// Fuzz regressions: every input a fuzzer crashed on is kept as fuzz/corpus/<target>/regression-*
// (so each fuzz run replays it first) and replayed here through the same entry point, without
// clang.

std::vector<fs::path> regressions(const std::string& target) {
  std::vector<fs::path> out;
  const fs::path dir = fs::path(ANIMAT_SOURCE_DIR) / "fuzz" / "corpus" / target;
  if (fs::is_directory(dir))
    for (const auto& e : fs::directory_iterator(dir))
      if (e.path().filename().string().rfind("regression-", 0) == 0) out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

TEST(FuzzRegressions, GenomeJsonInputsRaiseOnlyAnimatErrors) {
  GenomeParams params;  // as fuzz/fuzz_genome_json.cpp
  params.max_elements = 256;
  const auto files = regressions("genome_json");
  ASSERT_FALSE(files.empty());
  for (const auto& f : files) {
    SCOPED_TRACE(f.filename().string());
    try {
      const Genome g = genome_from_json(slurp(f), params, "fuzz");
      EXPECT_TRUE(genome_from_json(to_json(g), params) == g);
    } catch (const Error&) {
    } catch (const std::exception& e) {
      ADD_FAILURE() << error_class(e) << ": " << e.what();
    }
  }
}

TEST(FuzzRegressions, CheckpointInputsRaiseOnlyAnimatErrors) {
  // As fuzz/fuzz_checkpoint.cpp: the first byte mod 3 says how the rest reaches restore().
  Config c;
  c.evolution.population = 4;
  c.evolution.elites = 1;
  c.evolution.seed = 7;
  c.evolution.threads = 1;
  const auto files = regressions("checkpoint");
  ASSERT_FALSE(files.empty());
  for (const auto& f : files) {
    SCOPED_TRACE(f.filename().string());
    const std::string data = slurp(f);
    ASSERT_FALSE(data.empty());
    const std::string rest = data.substr(1);
    std::string text;
    switch (static_cast<unsigned char>(data[0]) % 3) {
      case 0: text = rest; break;
      case 1: {
        const std::string body =
            json::parse(json(rest).dump(-1, ' ', false, json::error_handler_t::replace))
                .get<std::string>();
        text = json{{"checksum", fnv_hex(body)}, {"payload", body}}.dump();
        break;
      }
      default: {
        json p = json::parse(rest, nullptr, false);
        if (p.is_discarded() || !p.is_object()) continue;
        p["identity"] = fmt::format("{:016x}", run_identity(c));
        p["identity_scheme"] = kRunIdentityScheme;
        p["format"] = "animat.checkpoint";
        p["version"] = 1;
        text = rewrap(p);
      }
    }
    Evolution evo(c, stub_fitness);
    try {
      evo.restore(text, "fuzz");
    } catch (const Error&) {
    } catch (const std::exception& e) {
      ADD_FAILURE() << error_class(e) << ": " << e.what();
    }
  }
}

}  // namespace
