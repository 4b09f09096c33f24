// The search interface's run layer (search.hpp, run_search in run.hpp) with a cheap stub fitness:
// the GA behind the interface is the GA; MAP-Elites and NSGA-II runs resume identically after a
// stop, and every refused command (a size, a changed [search] key, a corrupt checkpoint) changes no
// file.
#include <gtest/gtest.h>

#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>

#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/evaluator.hpp"
#include "animat/run.hpp"
#include "animat/search.hpp"
#include "search_support.hpp"
#include "test_support.hpp"

using namespace animat;
using animat::test::csv_without_wall;
using animat::test::search_stub;
namespace fs = std::filesystem;
using animat::test::fresh_dir;
using animat::test::slurp;
using animat::test::spit;

namespace {

Config search_config(const std::string& algorithm) {
  Config c;
  c.search.algorithm = algorithm;
  c.search.descriptors = {"cells", "fitness"};
  c.search.bins = {8.0, 5.0};
  c.search.batch = 10;
  c.evolution.population = 10;
  c.evolution.seed = 11;
  c.evolution.threads = 1;
  c.evolution.generations = 6;
  c.evaluation.reference_check = "off";
  return c;
}

RunOptions quiet_in(const fs::path& dir) {
  RunOptions o;
  o.out = dir;
  o.quiet = true;
  return o;
}

// Every file of a directory with its content.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) out[fs::relative(e.path(), dir).string()] = slurp(e.path());
  return out;
}

}  // namespace

TEST(GaSearch, IsTheGaItself) {
  Config c;
  c.evolution.population = 16;
  c.evolution.seed = 4;
  c.evolution.threads = 1;
  c.evaluation.reference_check = "off";
  Evolution evo(c, search_stub);
  evo.initialize();
  GaSearch ga(c, search_stub, {}, nullptr);
  ga.step();
  for (int g = 0; g < 5; ++g) {
    (void)evo.step();
    ga.step();
  }
  ASSERT_EQ(ga.evolution().history().size(), evo.history().size());
  for (std::size_t k = 0; k < evo.history().size(); ++k) {
    EXPECT_EQ(ga.evolution().history()[k].best, evo.history()[k].best);
    EXPECT_EQ(ga.evolution().history()[k].mean, evo.history()[k].mean);
    EXPECT_EQ(ga.evolution().history()[k].evaluations, evo.history()[k].evaluations);
  }
  for (std::size_t i = 0; i < evo.population().size(); ++i)
    EXPECT_EQ(ga.evolution().population()[i].genome, evo.population()[i].genome);
  EXPECT_EQ(ga.history().size(), 6U);
  EXPECT_EQ(ga.history_columns().front().name, "generation");
}

TEST(SearchRun, AStoppedRunResumesToTheSameResults) {
  for (const char* algorithm : {"map_elites", "nsga2"}) {
    SCOPED_TRACE(algorithm);
    const Config c = search_config(algorithm);
    const fs::path straight = fresh_dir("search_run", std::string(algorithm) + "_straight");
    const fs::path stopped = fresh_dir("search_run", std::string(algorithm) + "_stopped");
    const SearchSummary s = run_search(c, quiet_in(straight), search_stub);
    EXPECT_EQ(s.generation, 6);
    // A stop in the middle of generation 3's evaluations: that generation is dropped.
    std::atomic<int> evaluated{0};
    const FitnessFunction stopping = [&](const Genome& g) {
      ++evaluated;
      return search_stub(g);
    };
    RunOptions o = quiet_in(stopped);
    o.stop_poll = [&] { return evaluated.load() > 35; };
    const SearchSummary first = run_search(c, o, stopping);
    EXPECT_EQ(first.stop_reason, "interrupted");
    EXPECT_LT(first.generation, 6);
    RunOptions again = quiet_in(stopped);
    again.resume = true;
    const SearchSummary resumed = run_search(c, again, search_stub);
    EXPECT_EQ(resumed.generation, 6);
    EXPECT_EQ(csv_without_wall(slurp(stopped / "history.csv")),
              csv_without_wall(slurp(straight / "history.csv")));
    // The same state (the checkpoints differ only in wall-clock seconds).
    const auto a = make_search(c, search_stub), b = make_search(c, search_stub);
    a->restore(slurp(straight / "checkpoint.json"), "straight");
    b->restore(slurp(stopped / "checkpoint.json"), "stopped");
    EXPECT_EQ(a->ask(), b->ask());
    fs::remove_all(straight);
    fs::remove_all(stopped);
  }
}

TEST(SearchRun, TheCallersSearchRunsAsTheOneItWouldMake) {
  // animat.MapElites and animat.Nsga2 run their own search (RunOptions::search): the same run
  // directory as run_search's own, and a resume restores into a new caller's search.
  for (const char* algorithm : {"map_elites", "nsga2"}) {
    SCOPED_TRACE(algorithm);
    Config c = search_config(algorithm);
    const fs::path own = fresh_dir("search_run", std::string(algorithm) + "_own");
    const fs::path callers = fresh_dir("search_run", std::string(algorithm) + "_callers");
    (void)run_search(c, quiet_in(own), search_stub);
    c.evolution.generations = 3;
    auto first = make_search(c, search_stub);
    RunOptions o = quiet_in(callers);
    o.search = first.get();
    EXPECT_EQ(run_search(c, o).generation, 3);
    EXPECT_EQ(first->generation(), 3);  // the caller's search is the one that ran
    c.evolution.generations = 6;
    auto second = make_search(c, search_stub);
    o.search = second.get();
    o.resume = true;
    EXPECT_EQ(run_search(c, o).generation, 6);
    EXPECT_EQ(csv_without_wall(slurp(callers / "history.csv")),
              csv_without_wall(slurp(own / "history.csv")));
    // A search already told a generation, or of another algorithm, is refused and writes nothing.
    const auto before = snapshot(callers);
    o.resume = false;
    o.overwrite = true;
    EXPECT_THROW((void)run_search(c, o), Error);
    auto other = make_search(
        search_config(std::string(algorithm) == "nsga2" ? "map_elites" : "nsga2"), search_stub);
    o.search = other.get();
    EXPECT_THROW((void)run_search(c, o), Error);
    EXPECT_EQ(snapshot(callers), before);
    fs::remove_all(own);
    fs::remove_all(callers);
  }
}

TEST(SearchRun, RefusedCommandsChangeNoFile) {
  const Config c = search_config("map_elites");
  const fs::path dir = fresh_dir("search_run", "refused");
  // A size refused before the directory exists.
  Config huge = c;
  huge.search.bins = {100000.0};
  EXPECT_THROW((void)run_search(huge, quiet_in(dir), search_stub), ConfigError);
  EXPECT_FALSE(fs::exists(dir));
  Config two = c;
  two.evolution.generations = 2;
  (void)run_search(two, quiet_in(dir), search_stub);
  const auto before = snapshot(dir);
  // A new run into it, a resume that changes a [search] key, a corrupt checkpoint.
  EXPECT_THROW((void)run_search(c, quiet_in(dir), search_stub), RunExists);
  RunOptions resume = quiet_in(dir);
  resume.resume = true;
  Config changed = c;
  changed.search.bins = {4.0};
  try {
    (void)run_search(changed, resume, search_stub);
    ADD_FAILURE() << "resumed with changed search.bins";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("search.bins"), std::string::npos) << e.what();
  }
  EXPECT_EQ(snapshot(dir), before);
  std::string text = slurp(dir / "checkpoint.json");
  const std::size_t digit = text.find_first_of("0123456789", text.size() / 2);
  text[digit] = text[digit] == '9' ? '0' : static_cast<char>(text[digit] + 1);
  spit(dir / "checkpoint.json", text);
  const auto corrupt = snapshot(dir);
  EXPECT_THROW((void)run_search(c, resume, search_stub), CheckpointError);
  EXPECT_EQ(snapshot(dir), corrupt);
  fs::remove_all(dir);
}

TEST(SearchRun, TheGaIsRunEvolutionsAndASearchRunIsNot) {
  const fs::path dir = fresh_dir("search_run", "ga");
  EXPECT_THROW((void)run_search(Config{}, quiet_in(dir), search_stub), ConfigError);
  EXPECT_THROW((void)run_evolution(search_config("nsga2"), quiet_in(dir), search_stub),
               ConfigError);
  EXPECT_FALSE(fs::exists(dir));
}

TEST(SearchRun, ASecondWriterIsRefusedWhileARunHoldsItsDirectory) {
  // While a run is paused in its callback (it holds the directory), another run_search and the CLI
  // are refused naming the holder, and nothing changes. No sleeps: the callback runs them.
  const Config c = search_config("nsga2");
  const fs::path dir = fresh_dir("search_run", "two_writers");
  bool checked = false;
  RunOptions o = quiet_in(dir);
  o.search_callback = [&](const Search& s) {
    if (s.generation() != 2) return true;
    checked = true;
    const auto before = snapshot(dir);
    RunOptions again = quiet_in(dir);
    again.resume = true;
    EXPECT_THROW((void)run_search(c, again, search_stub), RunDirectoryBusy);
    const std::string cmd = std::string("'") + ANIMAT_EVOLVE_EXE + "' --quiet --resume '" +
                            dir.string() + "' --generations 9 2>&1";
    std::string output;
    if (FILE* p = ::popen(cmd.c_str(), "r")) {
      char buf[4096];
      for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) output.append(buf, n);
      EXPECT_NE(::pclose(p), 0) << output;
    }
    EXPECT_NE(output.find("in use by another animat process (pid " + std::to_string(::getpid())),
              std::string::npos)
        << output;
    EXPECT_EQ(snapshot(dir), before);
    return true;
  };
  const SearchSummary s = run_search(c, o, search_stub);
  EXPECT_TRUE(checked);
  EXPECT_EQ(s.generation, 6);
  EXPECT_FALSE(fs::exists(dir / ".lock")) << "a run that ends removes its lock file";
  fs::remove_all(dir);
}
