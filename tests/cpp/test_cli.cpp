// animat_evolve command line: --print-config prints the resolved config as TOML that parses back to
// the same config; --config/--set/--seed/--generations/--threads change it; every bad option exits
// non-zero with a message on stderr naming the problem.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <utility>

#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "search_support.hpp"

using namespace animat;
using animat::test::csv_without_wall;
namespace fs = std::filesystem;

namespace {

struct Result {
  int exit_code = -1;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

fs::path scratch_dir() {
  static const fs::path dir = [] {
    fs::path d = fs::temp_directory_path() / ("animat_test_cli_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

// Runs animat_evolve with `args` (already shell-quoted where needed), in a scratch directory so
// that nothing it might write lands in the source tree.
Result run(const std::string& args) {
  const fs::path out = scratch_dir() / "stdout.txt", err = scratch_dir() / "stderr.txt";
  const std::string cmd = "cd '" + scratch_dir().string() + "' && '" + ANIMAT_EVOLVE_EXE + "' " +
                          args + " >'" + out.string() + "' 2>'" + err.string() + "'";
  const int status = std::system(cmd.c_str());
  Result r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

// Removes the scratch directory after the last test.
struct ScratchCleanup : ::testing::Environment {
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(scratch_dir(), ec);
  }
};
[[maybe_unused]] ::testing::Environment* const scratch_cleanup =
    ::testing::AddGlobalTestEnvironment(new ScratchCleanup);

fs::path write_file(const std::string& name, const std::string& text) {
  const fs::path p = scratch_dir() / name;
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

#define EXPECT_CONTAINS(haystack, needle)                          \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) \
      << "expected '" << (needle) << "' in: " << (haystack)

}  // namespace

TEST(Cli, ExecutableExists) { ASSERT_TRUE(fs::exists(ANIMAT_EVOLVE_EXE)) << ANIMAT_EVOLVE_EXE; }

TEST(Cli, PrintConfigParsesBackToTheDefault) {
  const Result r = run("--print-config");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Config printed = config_from_toml(r.out, "--print-config output");
  EXPECT_TRUE(printed == Config{});
  EXPECT_TRUE(r.out == to_toml(Config{})) << "--print-config differs from to_toml(Config{})";
  EXPECT_CONTAINS(r.out, "[grn]");
  EXPECT_CONTAINS(r.out, "dt = 0.05");
}

TEST(Cli, SetOverridesAreReflected) {
  const Result r =
      run("--print-config --set evolution.population=50 --set grn.dt=0.025 --set "
          "physics.drag_scheme=explicit");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Config c = config_from_toml(r.out, "stdout");
  EXPECT_EQ(c.evolution.population, 50);
  EXPECT_EQ(c.grn.dt, 0.025);
  EXPECT_EQ(c.physics.drag_scheme, "explicit");
  Config expected;
  apply_override(expected, "evolution.population=50");
  apply_override(expected, "grn.dt=0.025");
  apply_override(expected, "physics.drag_scheme=explicit");
  EXPECT_TRUE(c == expected);
}

TEST(Cli, SetCrossKeyChecksDoNotDependOnTheOrderOfTheFlags) {
  // elites < population is checked once every --set is applied: raising both works in either order.
  const std::string up_a = "--set evolution.elites=150 --set evolution.population=200";
  const std::string up_b = "--set evolution.population=200 --set evolution.elites=150";
  const Result a = run("--print-config " + up_a), b = run("--print-config " + up_b);
  ASSERT_EQ(a.exit_code, 0) << a.err;
  ASSERT_EQ(b.exit_code, 0) << b.err;
  EXPECT_EQ(a.out, b.out);
  const Config c = config_from_toml(a.out, "stdout");
  EXPECT_EQ(c.evolution.elites, 150);
  EXPECT_EQ(c.evolution.population, 200);
  // A pair that violates it fails in either order with the same message, naming both values.
  const Result d = run("--print-config --set evolution.elites=30 --set evolution.population=20");
  const Result e = run("--print-config --set evolution.population=20 --set evolution.elites=30");
  EXPECT_EQ(d.exit_code, 2);
  EXPECT_EQ(e.exit_code, 2);
  EXPECT_TRUE(d.out.empty() && e.out.empty());
  EXPECT_EQ(d.err, e.err);
  EXPECT_CONTAINS(d.err, "evolution.elites = 30 must be smaller than evolution.population = 20");
  // The library call the CLI makes: all or nothing.
  Config lib;
  apply_overrides(lib, {"evolution.elites=150", "evolution.population=200"});
  EXPECT_TRUE(lib == c);
  Config untouched;
  EXPECT_THROW(apply_overrides(untouched, {"evolution.population=20", "evolution.elites=30"}),
               ConfigError);
  EXPECT_TRUE(untouched == Config{}) << "a rejected set of overrides leaves the config unchanged";
}

TEST(Cli, SeedGenerationsThreadsOptions) {
  const Result r = run("--print-config --seed 1234 --generations 7 --threads 1");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Config c = config_from_toml(r.out, "stdout");
  EXPECT_EQ(c.evolution.seed, 1234);
  EXPECT_EQ(c.evolution.generations, 7);
  EXPECT_EQ(c.evolution.threads, 1);
}

TEST(Cli, ConfigFileThenSetOverridesIt) {
  Config file_cfg;
  file_cfg.evolution.population = 60;
  file_cfg.scene.drag_normal = 3.5;
  const fs::path p = write_file("good.toml", to_toml(file_cfg));
  Result r = run("--print-config --config '" + p.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(config_from_toml(r.out, "stdout") == file_cfg);
  r = run("--print-config --config '" + p.string() + "' --set evolution.population=70");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Config c = config_from_toml(r.out, "stdout");
  EXPECT_EQ(c.evolution.population, 70);
  EXPECT_EQ(c.scene.drag_normal, 3.5);
  // A partial file keeps the defaults for everything else.
  const fs::path partial = write_file("partial.toml", "[grn]\ndt = 0.1\n");
  r = run("--print-config --config '" + partial.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  Config expected;
  expected.grn.dt = 0.1;
  EXPECT_TRUE(config_from_toml(r.out, "stdout") == expected);
}

TEST(Cli, PackagedConfigsResolveByNameAndAFileOfThatNameWins) {
  const Config dn10 = load_config(fs::path(ANIMAT_SOURCE_DIR) / "configs" / "paper_dn10.toml");
  for (const char* name : {"paper_dn10", "paper_dn10.toml"}) {
    const Result r = run(std::string("--print-config --config ") + name);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(config_from_toml(r.out, "stdout") == dn10) << name;
  }
  // The scratch directory is the working directory: its own paper_dn10.toml is read instead.
  Config own;
  own.evolution.population = 42;
  write_file("paper_dn10.toml", to_toml(own));
  const Result r = run("--print-config --config paper_dn10.toml");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(config_from_toml(r.out, "stdout").evolution.population, 42);
  fs::remove(scratch_dir() / "paper_dn10.toml");
}

TEST(Cli, ProgressCountsSwimsAndTheClosingLineNamesTheBestsGeneration) {
  const fs::path out = scratch_dir() / "progress_run";
  const Result r =
      run("--set evolution.population=6 --set evolution.elites=1 --set evaluation.steps=40 "
          "--generations 3 --threads 1 --seed 5 --out '" +
          out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string log = r.out + r.err;
  EXPECT_CONTAINS(log, "| d_N = 2 | objective distance |");
  EXPECT_CONTAINS(log, "random genomes drawn");
  EXPECT_CONTAINS(log, "swims/s");
  EXPECT_TRUE(log.find("eval/s") == std::string::npos) << log;
  EXPECT_TRUE(log.find("no generation cap") == std::string::npos) << log;
  // The generation that found the best: the last lineage file.
  int found = -1;
  for (const auto& e : fs::directory_iterator(out / "best"))
    found = std::max(found, std::stoi(e.path().stem().string().substr(4)));
  EXPECT_CONTAINS(log, "stopped at generation 3: generation cap");
  EXPECT_CONTAINS(log, ", found at generation " + std::to_string(found));
  fs::remove_all(out);
}

TEST(Cli, AnUncappedRunIsWarnedAboutAndADriftlessSceneHasNoDN) {
  // The warning comes before the run starts; the run itself is refused (no such directory).
  const Result r = run("--config crawl --generations 0 --out /dev/null/run");
  EXPECT_NE(r.exit_code, 0);
  const std::string log = r.out + r.err;
  EXPECT_CONTAINS(log, "no generation cap");
  EXPECT_CONTAINS(log, "evolution.stall_generations = 500");
  EXPECT_CONTAINS(log, "| no drag (");
  EXPECT_TRUE(log.find("d_N =") == std::string::npos) << log;
}

TEST(CliErrors, UnknownConfigNameListsThePackagedOnes) {
  const Result r = run("--print-config --config paper_dn11");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_CONTAINS(r.err, "--config paper_dn11: no such file, and no packaged config of that name");
  EXPECT_CONTAINS(r.err, "paper_dn10");
  EXPECT_CONTAINS(r.err, "crawl");
  EXPECT_EQ(r.out, "");
}

TEST(Cli, PackagedConfigsWithADotInTheirNameResolveByName) {
  // Run from the scratch directory, where no such file exists: the packaged configs answer.
  for (const auto& [name, drag] : {std::pair<std::string, std::string>{"paper_dn0.5", "0.5"},
                                   {"paper_dn0.2_64cells", "0.2"},
                                   {"regime_dn0.5", "0.5"}}) {
    const Result r = run("--print-config --config " + name);
    ASSERT_EQ(r.exit_code, 0) << name << ": " << r.err;
    EXPECT_CONTAINS(r.out, "drag_normal = " + drag);
  }
  const Result r = run("--print-config --config paper_dn11");
  EXPECT_CONTAINS(r.err, "paper_dn0.2_64cells, paper_dn0.5, paper_dn10");
}

TEST(CliErrors, SearchSettingsAnimatEvolveCannotRunAreRefusedBeforeAnyFileIsWritten) {
  // an unknown measure is refused; a grid
  // too large for memory is refused by its size; the GA must not fill a run directory whose
  // config.toml says otherwise.
  const fs::path out = scratch_dir() / "map_elites_run";
  for (const auto& [flags, message] : std::initializer_list<std::pair<std::string, std::string>>{
           {"--set search.algorithm=map_elites --set "
            "'search.descriptors=[\"gait\",\"cells\"]'",
            "search.descriptors: no measure \"gait\""},
           {"--set search.algorithm=map_elites --set 'search.descriptors=[\"cells\",\"fitness\"]' "
            "--set 'search.bins=[100000]'",
            "search.bins = [100000, 100000]"},
           {"--set search.algorithm=nsga2 --set 'search.objectives=[\"distance\",\"smoothness\"]'",
            "search.objectives: no measure \"smoothness\""}}) {
    const Result r = run(flags + " --generations 1 --out map_elites_run");
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_CONTAINS(r.err, message);
    EXPECT_FALSE(fs::exists(out)) << "a refused command wrote " << out;
  }
}

TEST(Cli, MapElitesAndNsga2RunIdenticallyOnAnyThreadCountAndAcrossAResume) {
  const std::string small =
      "--set evolution.population=6 --set search.batch=6 --set evaluation.steps=40 --seed 3 "
      "--set 'search.descriptors=[\"cells\",\"fitness\"]' --set 'search.bins=[8,5]' ";
  for (const char* algorithm : {"map_elites", "nsga2"}) {
    SCOPED_TRACE(algorithm);
    const std::string flags = small + "--set search.algorithm=" + algorithm + " ";
    const fs::path one = scratch_dir() / "search_one", two = scratch_dir() / "search_two";
    const fs::path resumed = scratch_dir() / "search_resumed";
    Result r = run(flags + "--generations 3 --threads 1 --out '" + one.string() + "'");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_CONTAINS(r.out, "Stopped at generation 3: generation cap");
    r = run(flags + "--generations 3 --threads 2 --out '" + two.string() + "'");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = run(flags + "--generations 1 --threads 2 --out '" + resumed.string() + "'");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = run("--resume '" + resumed.string() + "' --generations 3 --threads 1");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string history = csv_without_wall(slurp(one / "history.csv"));
    EXPECT_EQ(std::count(history.begin(), history.end(), '\n'), 5);  // the header, generations 0-3
    EXPECT_EQ(csv_without_wall(slurp(two / "history.csv")), history);
    EXPECT_EQ(csv_without_wall(slurp(resumed / "history.csv")), history);
    EXPECT_CONTAINS(slurp(resumed / "resume.log"), "evolution.generations 1 -> 3");
    for (const auto& d : {one, two, resumed}) fs::remove_all(d);
  }
}

TEST(Cli, AKilledSearchResumesToTheSameResults) {
  // A MAP-Elites run without a generation cap is killed (SIGKILL) once its checkpoint holds
  // generation 2, wherever it then is; resumed, its generations 0-5 equal the uninterrupted run's.
  // No sleeps on the way: the conditions are polled (a hang guard of 600 s only catches a hang).
  const std::string flags =
      "--set search.algorithm=map_elites --set search.batch=6 --set evaluation.steps=40 --seed 4 "
      "--set 'search.descriptors=[\"cells\",\"fitness\"]' --set 'search.bins=[8,5]' --quiet ";
  const fs::path straight = scratch_dir() / "kill_straight", killed = scratch_dir() / "kill_killed";
  Result r = run(flags + "--generations 5 --threads 1 --out '" + straight.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const fs::path pid_file = scratch_dir() / "kill.pid";
  const std::string start = "cd '" + scratch_dir().string() + "' && '" + ANIMAT_EVOLVE_EXE + "' " +
                            flags + "--threads 2 --out '" + killed.string() +
                            "' >/dev/null 2>&1 & echo $! > '" + pid_file.string() + "'";
  ASSERT_EQ(std::system(start.c_str()), 0);
  const pid_t pid = static_cast<pid_t>(std::stol(slurp(pid_file)));
  const auto hang_guard = std::chrono::steady_clock::now() + std::chrono::seconds(600);
  auto checkpoint_generation = [&] {
    try {
      const auto outer = nlohmann::json::parse(slurp(killed / "checkpoint.json"));
      return nlohmann::json::parse(outer.at("payload").get<std::string>())
          .at("generation")
          .get<int>();
    } catch (const std::exception&) {
      return -1;  // not written yet (the rename makes a written one whole)
    }
  };
  while (checkpoint_generation() < 2) {
    ASSERT_LT(std::chrono::steady_clock::now(), hang_guard) << "hang guard: no checkpoint";
    std::this_thread::sleep_for(std::chrono::milliseconds(20));  // polling the condition
  }
  ASSERT_EQ(::kill(pid, SIGKILL), 0);
  // The kernel drops the dead process's lock: wait until the lock file can be locked.
  for (bool free = false; !free;) {
    ASSERT_LT(std::chrono::steady_clock::now(), hang_guard) << "hang guard: the lock is held";
    const int fd = ::open((killed / ".lock").c_str(), O_RDONLY);
    free = fd < 0 || ::flock(fd, LOCK_EX | LOCK_NB) == 0;
    if (fd >= 0) ::close(fd);
  }
  // A fast machine may be past generation 5 by the kill: the resume then goes one generation past
  // the checkpoint, so that it always evolves (and drops any row written after the checkpoint; a
  // resume already at its cap writes no file), and the first six generations are compared.
  const int target = std::max(5, checkpoint_generation() + 1);
  r = run("--quiet --resume '" + killed.string() + "' --generations " + std::to_string(target) +
          " --threads 1");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(checkpoint_generation(), target);
  const std::string resumed = csv_without_wall(slurp(killed / "history.csv"));
  const std::string expected = csv_without_wall(slurp(straight / "history.csv"));
  EXPECT_EQ(std::count(resumed.begin(), resumed.end(), '\n'), target + 2);  // the header, 0-target
  EXPECT_EQ(resumed.substr(0, expected.size()), expected);
  fs::remove_all(straight);
  fs::remove_all(killed);
}

TEST(CliErrors, UnknownOption) {
  const Result r = run("--print-config --bogus-option");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_CONTAINS(r.err, "--bogus-option");
  EXPECT_TRUE(r.out.find("[grn]") == std::string::npos) << "printed a config despite the error";
}

TEST(CliErrors, UnknownSetKeyWithSuggestion) {
  const Result r = run("--print-config --set genome.dimensons=3");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_CONTAINS(r.err, "genome.dimensons");
  EXPECT_CONTAINS(r.err, "did you mean 'dimensions'");
  EXPECT_EQ(r.out, "");
}

TEST(CliErrors, BadSetValues) {
  Result r = run("--print-config --set evolution.population=0");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_CONTAINS(r.err, "evolution.population");
  EXPECT_CONTAINS(r.err, "out of range");
  EXPECT_CONTAINS(r.err, "[2, 100000]");
  r = run("--print-config --set grn.dt=abc");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_CONTAINS(r.err, "grn.dt=abc");
  r = run("--print-config --set grn.dt=-1");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_CONTAINS(r.err, "grn.dt");
  EXPECT_CONTAINS(r.err, "(0, 1]");
  r = run("--print-config --set nodotatall");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_CONTAINS(r.err, "section.key=value");
  r = run("--print-config --set grn.dt=nan");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_CONTAINS(r.err, "finite");
}

TEST(CliErrors, MissingConfigFile) {
  const std::string missing = (scratch_dir() / "does_not_exist.toml").string();
  const Result r = run("--print-config --config '" + missing + "'");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_CONTAINS(r.err, missing);
  EXPECT_EQ(r.out, "");
}

TEST(CliErrors, BadConfigFileNamesFileLineAndKey) {
  const fs::path p = write_file("bad.toml", "# comment\n[evolution]\npopulaton = 50\n");
  const Result r = run("--print-config --config '" + p.string() + "'");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_CONTAINS(r.err, p.string() + ":3");
  EXPECT_CONTAINS(r.err, "evolution.populaton");
  EXPECT_CONTAINS(r.err, "did you mean 'population'");
  EXPECT_EQ(r.out, "");
  const fs::path bad_file =
      fs::path(ANIMAT_SOURCE_DIR) / "tests" / "bad_inputs" / "config_dt_nan.toml";
  const Result r2 = run("--print-config --config '" + bad_file.string() + "'");
  EXPECT_NE(r2.exit_code, 0);
  EXPECT_CONTAINS(r2.err, bad_file.string() + ":6");
  EXPECT_CONTAINS(r2.err, "grn.dt = nan");
}

TEST(CliErrors, BadLogLevel) {
  const Result r = run("--print-config --log-level loud");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_CONTAINS(r.err, "loud");
  EXPECT_CONTAINS(r.err, "--log-level");
  EXPECT_EQ(r.out, "");
  for (const char* ok : {"trace", "debug", "info", "warn", "error", "critical", "off"}) {
    const Result good = run(std::string("--print-config --log-level ") + ok);
    EXPECT_EQ(good.exit_code, 0) << ok << ": " << good.err;
  }
}

TEST(CliErrors, BadNumericOptions) {
  Result r = run("--print-config --seed -1");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_CONTAINS(r.err, "--seed");
  r = run("--print-config --generations many");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_CONTAINS(r.err, "--generations");
  r = run("--print-config --threads 5000");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_CONTAINS(r.err, "evolution.threads");
  EXPECT_EQ(r.out, "");
}
