// Config (include/animat/config.hpp): defaults validate, TOML round trips (default, non-default,
// after overrides), --set overrides, get/set by key, and every kind of bad TOML is a ConfigError
// naming the file, the line, the key, the value and what was expected.
#include <gtest/gtest.h>
#include <unistd.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "animat/config.hpp"
#include "animat/errors.hpp"

using namespace animat;
namespace fs = std::filesystem;

namespace {

std::string message_of(const auto& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "<no exception>";
}

fs::path bad_input(const std::string& name) {
  return fs::path(ANIMAT_SOURCE_DIR) / "tests" / "bad_inputs" / name;
}

// Values compared exactly (doubles by bit pattern).
bool same_value(const ConfigValue& a, const ConfigValue& b) {
  if (a.index() != b.index()) return false;
  if (const double* x = std::get_if<double>(&a))
    return std::bit_cast<std::uint64_t>(*x) == std::bit_cast<std::uint64_t>(std::get<double>(b));
  if (const auto* v = std::get_if<std::vector<double>>(&a)) {
    const auto& w = std::get<std::vector<double>>(b);
    if (v->size() != w.size()) return false;
    for (std::size_t i = 0; i < v->size(); ++i)
      if (std::bit_cast<std::uint64_t>((*v)[i]) != std::bit_cast<std::uint64_t>(w[i])) return false;
    return true;
  }
  return a == b;
}

void expect_identical(const Config& a, const Config& b) {
  for (const auto& key : config_keys())
    EXPECT_TRUE(same_value(get_value(a, key), get_value(b, key))) << key;
  EXPECT_TRUE(a == b);
  EXPECT_EQ(config_hash(a), config_hash(b));
}

std::string expect_config_error(const auto& f) {
  std::string msg;
  bool config_error = false;
  try {
    f();
    msg = "<accepted>";
  } catch (const ConfigError& e) {
    config_error = true;
    msg = e.what();
  } catch (const std::exception& e) {
    msg = std::string("<not a ConfigError> ") + e.what();
  }
  EXPECT_TRUE(config_error) << msg;
  return msg;
}

#define EXPECT_CONTAINS(haystack, needle)                          \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) \
      << "expected '" << (needle) << "' in: " << (haystack)

}  // namespace

// ---------------------------------------------------------------------------------------------------
// Defaults and keys

TEST(ConfigDefaults, DefaultConfigValidates) {
  EXPECT_NO_THROW(animat::validate(Config{}));
  EXPECT_NO_THROW(animat::validate(Config{}, "defaults"));
}

TEST(ConfigDefaults, PaperValues) {
  const Config c;
  EXPECT_EQ(c.grn.dt, 0.05);
  EXPECT_EQ(c.genome.dimensions, 2);
  EXPECT_EQ(c.genome.initial_units, 10);
  EXPECT_EQ(std::get<double>(get_value(c, "grn.dt")), 0.05);
  EXPECT_EQ(std::get<std::int64_t>(get_value(c, "genome.dimensions")), 2);
}

TEST(ConfigKeys, EveryKeyIsUniqueAndPrintedOnce) {
  const auto keys = config_keys();
  const std::set<std::string> unique(keys.begin(), keys.end());
  EXPECT_EQ(unique.size(), keys.size());
  for (const char* k : {"genome.dimensions", "genome.affinity_decay", "genome.affinity_cutoff",
                        "genome.max_elements", "mutation.type_rate", "mutation.crossover_points",
                        "grn.dt", "evolution.population", "evolution.seed", "scene.drag_normal",
                        "physics.drag_scheme", "development.max_cells"})
    EXPECT_TRUE(unique.count(k)) << k;
  // Every key appears as "key = value" in its section of to_toml.
  const std::string toml = to_toml(Config{});
  std::size_t assignments = 0;
  std::istringstream in(toml);
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] != '#' && line[0] != '[' && line.find(" = ") != std::string::npos)
      ++assignments;
  EXPECT_EQ(assignments, keys.size());
  for (const char* s : {"[genome]", "[mutation]", "[grn]", "[development]", "[body]", "[scene]",
                        "[physics]", "[evaluation]", "[evolution]"})
    EXPECT_CONTAINS(toml, s);
  EXPECT_CONTAINS(toml, "\ndt = 0.05\n");
}

TEST(ConfigKeys, DocNamesMeaningAndRange) {
  EXPECT_CONTAINS(config_doc("grn.dt"), "(0, 1]");
  EXPECT_CONTAINS(config_doc("evolution.population"), "[2, 100000]");
  const std::string m = expect_config_error([] { (void)config_doc("grn.dtt"); });
  EXPECT_CONTAINS(m, "grn.dtt");
}

// ---------------------------------------------------------------------------------------------------
// Round trips

TEST(ConfigRoundTrip, DefaultToTomlAndBack) {
  const Config c;
  const Config back = config_from_toml(to_toml(c), "printed.toml");
  expect_identical(back, c);
  EXPECT_EQ(to_toml(back), to_toml(c));
}

TEST(ConfigRoundTrip, EmptyAndPartialTomlKeepDefaults) {
  expect_identical(config_from_toml(""), Config{});
  expect_identical(config_from_toml("# nothing\n[grn]\n"), Config{});
  const Config c = config_from_toml("[evolution]\npopulation = 57\n[grn]\ndt = 0.1\n");
  EXPECT_EQ(c.evolution.population, 57);
  EXPECT_EQ(c.grn.dt, 0.1);
  Config expected;
  expected.evolution.population = 57;
  expected.grn.dt = 0.1;
  expect_identical(c, expected);
  // An integer literal is accepted for a float key.
  EXPECT_EQ(config_from_toml("[scene]\ndrag_normal = 3\n").scene.drag_normal, 3.0);
}

TEST(ConfigRoundTrip, NonDefaultValuesForEveryKeyRoundTripBitExactly) {
  // Give every key a non-default value (awkward doubles where allowed), then print and re-read.
  Config c;
  const double awkward[] = {0.1,        1.0 / 3.0, 1e-300, 0.7000000000000001,
                            123456.789, 2.5e-7,    1.0,    0.0};
  int changed = 0;
  // Two passes: a key whose new value is valid only together with a later key's (control.mode =
  // "grn" needs grn_rate·update_interval·h <= 1, and physics.dt comes earlier) gets its second
  // chance.
  std::vector<std::string> done;
  for (int pass = 0; pass < 2; ++pass)
    for (const auto& key : config_keys()) {
      if (std::find(done.begin(), done.end(), key) != done.end()) continue;
      const ConfigValue def = get_value(Config{}, key);
      std::vector<ConfigValue> candidates;
      if (const double* d = std::get_if<double>(&def)) {
        for (double a : awkward) candidates.push_back(a);
        candidates.push_back(*d * 0.7000000000000001);
        candidates.push_back(std::nextafter(*d, 0.0));
      } else if (const auto* i = std::get_if<std::int64_t>(&def)) {
        candidates.push_back(*i + 1);
        candidates.push_back(*i - 1);
        candidates.push_back(std::int64_t{3});
        candidates.push_back(*i + 1000);  // search.samples: at least search.cells
      } else if (const bool* b = std::get_if<bool>(&def)) {
        candidates.push_back(!*b);
      } else if (const auto* s = std::get_if<std::vector<std::string>>(&def)) {
        auto shorter = *s;
        if (!shorter.empty()) shorter.pop_back();
        candidates.push_back(shorter);
        candidates.push_back(std::vector<std::string>{});
      } else if (const auto* v = std::get_if<std::vector<double>>(&def)) {
        auto w = *v, whole = *v;
        for (double& x : w) x = x * 1.1 + 0.1;
        for (double& x : whole) x += 1;  // search.bins: whole numbers only
        candidates.push_back(w);
        candidates.push_back(whole);
        if (v->empty()) {  // search.ranges: a lo < hi pair per descriptor, one or two of them
          candidates.push_back(std::vector<double>{0.1, 1.0 / 3.0});
          candidates.push_back(std::vector<double>{0.1, 1.0 / 3.0, 2.5e-7, 123456.789});
        }
      } else if (std::holds_alternative<std::string>(def)) {
        for (const char* word :
             {"explicit", "stable", "off", "select", "distance_per_size", "chemical", "actuation",
              "grn", "point", "distance", "front", "amplitude", "morphogen_gradient", "compliant",
              "min", "map_elites", "fixed", "cvt"})
          candidates.push_back(std::string(word));
      }
      for (const auto& cand : candidates) {
        if (same_value(cand, def)) continue;
        Config trial = c;
        try {
          set_value(trial, key, cand);
          animat::validate(trial);
        } catch (const ConfigError&) {
          continue;
        }
        c = trial;
        ++changed;
        done.push_back(key);
        break;
      }
    }
  EXPECT_GE(changed, static_cast<int>(config_keys().size()) - 3) << "too few keys could be changed";
  EXPECT_FALSE(c == Config{});
  const Config back = config_from_toml(to_toml(c), "nondefault.toml");
  expect_identical(back, c);
}

TEST(ConfigRoundTrip, NegativeZeroAndTinyValuesSurvive) {
  Config c;
  c.scene.drag_tangential = -0.0;  // allowed by ">= 0"
  c.scene.drag_normal = 5e-324;
  c.genome.affinity_decay = 999999.9999999999;  // the largest double below the bound 1e6
  const Config back = config_from_toml(to_toml(c));
  EXPECT_TRUE(std::signbit(back.scene.drag_tangential));
  EXPECT_EQ(back.scene.drag_normal, 5e-324);
  EXPECT_EQ(back.genome.affinity_decay, 999999.9999999999);
}

TEST(ConfigRoundTrip, AfterOverrides) {
  Config c;
  apply_override(c, "evolution.population=64");
  apply_override(c, "grn.dt = 0.025");
  apply_override(c, "genome.affinity_cutoff=0.30000000000000004");
  apply_override(c, "physics.drag_scheme=explicit");
  apply_override(c, "mutation.max_series_length=7");
  EXPECT_EQ(c.evolution.population, 64);
  EXPECT_EQ(c.grn.dt, 0.025);
  EXPECT_EQ(c.genome.affinity_cutoff, 0.30000000000000004);
  EXPECT_EQ(c.physics.drag_scheme, "explicit");
  EXPECT_EQ(c.mutation.max_series_length, 7);
  const Config back = config_from_toml(to_toml(c));
  expect_identical(back, c);
  EXPECT_FALSE(back == Config{});
  EXPECT_NE(config_hash(back), config_hash(Config{}));
  // Quoted strings and arrays work too.
  apply_override(c, "physics.drag_scheme=\"stable\"");
  EXPECT_EQ(c.physics.drag_scheme, "stable");
  apply_override(c, "scene.effects=[\"springs\", \"drag\"]");
  EXPECT_EQ(c.scene.effects, (std::vector<std::string>{"springs", "drag"}));
  expect_identical(config_from_toml(to_toml(c)), c);
}

TEST(ConfigRoundTrip, LoadConfigFromFile) {
  const fs::path path =
      fs::temp_directory_path() / ("animat_test_config_" + std::to_string(::getpid()) + ".toml");
  Config c;
  c.evolution.population = 33;
  c.grn.dt = 0.07;
  {
    std::ofstream out(path);
    out << to_toml(c);
  }
  expect_identical(load_config(path), c);
  fs::remove(path);
  const std::string m = message_of([&] { (void)load_config(path); });
  EXPECT_CONTAINS(m, path.string());
  EXPECT_THROW((void)load_config(path), IoError);
}

TEST(ConfigRoundTrip, HashAndEqualityTrackEveryKey) {
  Config a, b;
  EXPECT_EQ(config_hash(a), config_hash(b));
  b.scene.drag_normal = std::nextafter(b.scene.drag_normal, 100.0);
  EXPECT_FALSE(a == b);
  EXPECT_NE(config_hash(a), config_hash(b));
}

// ---------------------------------------------------------------------------------------------------
// get_value / set_value / apply_override

TEST(ConfigAccess, SetAndGetByKeyWithTypeAndRangeChecks) {
  Config c;
  set_value(c, "evolution.population", std::int64_t{80});
  EXPECT_EQ(c.evolution.population, 80);
  set_value(c, "scene.drag_normal", std::int64_t{4});  // int accepted for a float key
  EXPECT_EQ(c.scene.drag_normal, 4.0);
  set_value(c, "scene.drag_normal", 2.5);
  EXPECT_EQ(std::get<double>(get_value(c, "scene.drag_normal")), 2.5);

  std::string m = expect_config_error([&] { set_value(c, "evolution.population", 2.5); });
  EXPECT_CONTAINS(m, "evolution.population");
  EXPECT_CONTAINS(m, "expected an integer");
  m = expect_config_error([&] { set_value(c, "evolution.population", std::int64_t{0}); });
  EXPECT_CONTAINS(m, "evolution.population = 0");
  EXPECT_CONTAINS(m, "out of range");
  m = expect_config_error([&] { set_value(c, "evolution.population", std::int64_t{1} << 40); });
  EXPECT_CONTAINS(m, "evolution.population");
  m = expect_config_error([&] { set_value(c, "grn.dt", std::nan("")); });
  EXPECT_CONTAINS(m, "grn.dt");
  EXPECT_CONTAINS(m, "finite");
  m = expect_config_error([&] { set_value(c, "physics.drag_scheme", std::string("magic")); });
  EXPECT_CONTAINS(m, "explicit, stable");
  m = expect_config_error([&] { set_value(c, "evolution.populaton", std::int64_t{5}); });
  EXPECT_CONTAINS(m, "unknown config key 'evolution.populaton'");
  EXPECT_CONTAINS(m, "did you mean 'evolution.population'");
  m = expect_config_error([&] { (void)get_value(c, "grn"); });
  EXPECT_CONTAINS(m, "'grn'");
  // Failed sets leave the config unchanged.
  EXPECT_EQ(c.evolution.population, 80);
  EXPECT_EQ(c.grn.dt, 0.05);
}

TEST(ConfigOverride, BadOverridesNameTheAssignmentAndProblem) {
  Config c;
  std::string m = expect_config_error([&] { apply_override(c, "genome.dimensons=3"); });
  EXPECT_CONTAINS(m, "--set genome.dimensons=3");
  EXPECT_CONTAINS(m, "unknown key 'genome.dimensons'");
  EXPECT_CONTAINS(m, "did you mean 'dimensions'");

  m = expect_config_error([&] { apply_override(c, "genoem.dimensions=3"); });
  EXPECT_CONTAINS(m, "unknown section [genoem]");
  EXPECT_CONTAINS(m, "did you mean 'genome'");

  m = expect_config_error([&] { apply_override(c, "evolution.population=0"); });
  EXPECT_CONTAINS(m, "--set evolution.population=0");
  EXPECT_CONTAINS(m, "out of range");
  EXPECT_CONTAINS(m, "[2, 100000]");

  m = expect_config_error([&] { apply_override(c, "grn.dt=0"); });
  EXPECT_CONTAINS(m, "grn.dt = 0");
  EXPECT_CONTAINS(m, "(0, 1]");

  m = expect_config_error([&] { apply_override(c, "grn.dt=fast"); });
  EXPECT_CONTAINS(m, "--set grn.dt=fast");

  m = expect_config_error([&] { apply_override(c, "grn.dt=\"0.1\""); });
  EXPECT_CONTAINS(m, "wrong type, expected a number");

  m = expect_config_error([&] { apply_override(c, "grn.dt=nan"); });
  EXPECT_CONTAINS(m, "must be finite");

  for (const char* bad : {"population=5", "evolution.population", "=5", "evolution.population 5"}) {
    m = expect_config_error([&] { apply_override(c, bad); });
    EXPECT_CONTAINS(m, "expected section.key=value");
  }
  EXPECT_TRUE(c == Config{}) << "failed overrides must not change the config";
}

TEST(ConfigOverride, CrossFieldViolationIsReportedAndLeavesConfigUnchanged) {
  Config c;
  const std::string m = expect_config_error([&] { apply_override(c, "evolution.elites=100"); });
  EXPECT_CONTAINS(m, "evolution.elites = 100 must be smaller than evolution.population");
  EXPECT_EQ(c.evolution.elites, Config{}.evolution.elites)
      << "a rejected --set must not leave its value behind";
  EXPECT_NO_THROW(animat::validate(c));
}

TEST(ConfigOverride, OneAssignmentSetsOneKey) {
  // A value must not smuggle in further TOML: a newline in the value is not a second assignment.
  Config c;
  bool threw = false;
  try {
    apply_override(c, "grn.dt=0.1\n[evolution]\npopulation=7");
  } catch (const ConfigError&) {
    threw = true;
  }
  EXPECT_TRUE(threw || c.evolution.population == Config{}.evolution.population)
      << "--set grn.dt=... also set evolution.population = " << c.evolution.population;
}

// ---------------------------------------------------------------------------------------------------
// Bad TOML files

struct BadTomlCase {
  const char* file;
  int line;  // expected in the message as "file:line"; 0 = no line
  std::vector<std::string> expect;
};
void PrintTo(const BadTomlCase& c, std::ostream* os) { *os << c.file; }

class BadToml : public ::testing::TestWithParam<BadTomlCase> {};

TEST_P(BadToml, IsAConfigErrorNamingFileLineKeyAndExpectation) {
  const auto& c = GetParam();
  const fs::path path = bad_input(c.file);
  ASSERT_TRUE(fs::exists(path)) << path;
  const std::string msg = expect_config_error([&] { (void)load_config(path); });
  if (c.line > 0)
    EXPECT_CONTAINS(msg, path.string() + ":" + std::to_string(c.line));
  else
    EXPECT_CONTAINS(msg, path.string());
  for (const auto& s : c.expect) EXPECT_CONTAINS(msg, s);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BadToml,
    ::testing::Values(
        BadTomlCase{"config_unknown_key.toml",
                    6,
                    {"unknown key 'evolution.populaton'", "did you mean 'population'"}},
        BadTomlCase{"config_unknown_section.toml",
                    5,
                    {"unknown section [evolutoin]", "did you mean 'evolution'"}},
        BadTomlCase{"config_wrong_type.toml",
                    6,
                    {"evolution.population = \"many\"", "wrong type", "expected an integer"}},
        BadTomlCase{"config_float_for_integer.toml",
                    6,
                    {"evolution.population = 10.5", "expected an integer"}},
        BadTomlCase{"config_population_zero.toml",
                    6,
                    {"evolution.population = 0", "out of range", "[2, 100000]"}},
        BadTomlCase{"config_population_negative.toml",
                    6,
                    {"evolution.population = -5", "out of range", "[2, 100000]"}},
        BadTomlCase{"config_dt_zero.toml", 6, {"grn.dt = 0.0", "out of range", "(0, 1]"}},
        BadTomlCase{"config_dt_negative.toml", 6, {"grn.dt = -0.05", "out of range", "(0, 1]"}},
        BadTomlCase{"config_dt_nan.toml", 6, {"grn.dt = nan", "must be finite"}},
        BadTomlCase{"config_dt_inf.toml", 6, {"grn.dt = inf", "must be finite"}},
        BadTomlCase{"config_integer_overflow.toml",
                    6,
                    {"evolution.population = 10000000000", "integer range"}},
        BadTomlCase{"config_malformed.toml", 5, {"malformed TOML"}},
        BadTomlCase{"config_section_not_table.toml", 3, {"'grn' must be a table"}},
        BadTomlCase{
            "config_bad_choice.toml",
            6,
            {"physics.drag_scheme = \"magic\"", "expected one of semi_implicit, explicit, stable"}},
        BadTomlCase{"config_bad_list_entry.toml", 6, {"scene.effects", "\"buoyancy\""}},
        BadTomlCase{"config_elites_not_below_population.toml",
                    0,
                    {"evolution.elites = 10", "evolution.population = 10"}},
        BadTomlCase{"config_duplicate_key.toml", 7, {"malformed TOML", "dt"}}),
    [](const ::testing::TestParamInfo<BadTomlCase>& info) {
      std::string n = info.param.file;
      n = n.substr(0, n.find('.'));
      for (char& ch : n)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
      return n;
    });

TEST(BadTomlString, SourceNameIsUsedForStrings) {
  const std::string m =
      expect_config_error([] { (void)config_from_toml("[grn]\n\ndt = -1\n", "my.toml"); });
  EXPECT_CONTAINS(m, "my.toml:3");
  EXPECT_CONTAINS(m, "grn.dt = -1");
  EXPECT_CONTAINS(m, "(0, 1]");
  const std::string m2 = expect_config_error([] { (void)config_from_toml("[grn\n", "x.toml"); });
  EXPECT_CONTAINS(m2, "x.toml:1");
  EXPECT_CONTAINS(m2, "malformed TOML");
}

TEST(BadTomlString, BinaryGarbageIsMalformed) {
  const std::string garbage("\x00\xff\xfe[\x01grn]\n\x89PNG", 12);
  const std::string m =
      expect_config_error([&] { (void)config_from_toml(garbage, "garbage.toml"); });
  EXPECT_CONTAINS(m, "garbage.toml");
  EXPECT_CONTAINS(m, "malformed TOML");
}

TEST(BadTomlString, NothingFallsBackSilently) {
  // Each of these has one bad key and otherwise valid content; none may load.
  for (const char* text :
       {"[genome]\ndimensions = 0\n", "[genome]\ndimensions = 17\n",
        "[mutation]\ntype_rate = 1.5\n", "[mutation]\nmove_sigma = -0.1\n", "[grn]\ndt = 1.5\n",
        "[genome]\naffinity_cutoff = 0\n", "[evolution]\nseed = -1\n",
        "[evolution]\npopulation = true\n", "[grn]\ndt = [0.05]\n", "[grn]\ndt = \"0.05\"\n",
        "[development]\nmin_cells = 40\nmax_cells = 32\n", "[scene]\ndrag_normal = -inf\n",
        "[grn]\nDt = 0.05\n", "[Grn]\ndt = 0.05\n"}) {
    const std::string m = expect_config_error([&] { (void)config_from_toml(text, "t.toml"); });
    EXPECT_CONTAINS(m, "t.toml");
  }
}

TEST(ConfigSearch, TheSearchKeysAreCheckedTogetherNamingTheKey) {
  Config c;
  EXPECT_EQ(c.search.algorithm, "ga");  // the paper's GA unless a config says otherwise
  c.search.descriptors = {"cells", "elongation", "frequency"};
  c.search.bins = {4.0, 6.0, 8.0};
  EXPECT_NO_THROW(animat::validate(c));
  c.search.bins = {5.0};  // one count for every descriptor
  EXPECT_NO_THROW(animat::validate(c));
  const auto refused = [](const Config& bad, const std::string& words) {
    try {
      animat::validate(bad);
      ADD_FAILURE() << "accepted: " << words;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  Config two = c;
  two.search.bins = {4.0, 6.0};
  refused(two,
          "search.bins = [4.0, 6.0]: give one count for every descriptor or one for each of "
          "the 3");
  Config half = c;
  half.search.bins = {2.5};
  refused(half, "search.bins = [2.5]: entry 2.5 is not a whole number");
  Config none = c;
  none.search.objectives = {};
  refused(none, "search.objectives = []: name at least one");
  Config spaced = c;
  spaced.search.descriptors = {"elongation", "two words"};
  refused(spaced, "entry \"two words\" is not a name");
  EXPECT_THROW(apply_override(c, "search.algorithm=\"cma_es\""), ConfigError);
}
