// Hostile input, refused commands and stop requests: no refused command may damage a run, no
// accepted value may crash, every stop signal is honoured. docs/reliability.md lists each attack
// with its count and test.
//
//   ConfigSweep.*      every config key (iterated through visit_fields, so new keys are covered)
//                      at its bounds and just beyond: refused values name the key (set_value,
//                      TOML, the CLI) and change no file of a run; accepted values evaluate and
//                      evolve without a signal, in a child process
//   ResumeSettings.*   --resume with changed settings: refused before any write, naming the keys;
//                      resumable keys accepted and recorded
//   StopRequests.*     stops honoured within one evaluation (counted, not timed): seeding,
//                      evaluation, the CLI
//   CheckpointMeaning.* checkpoints with a valid checksum but a content the engine cannot have
//                      written
//   Rows.*             the other attacks of docs/reliability.md
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#include <nlohmann/json.hpp>

#include <atomic>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/evaluate.hpp"
#include "animat/evolution.hpp"
#include "animat/genome.hpp"
#include "animat/random.hpp"
#include "animat/run.hpp"
#include "animat/run_identity.hpp"
#include "test_support.hpp"

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

namespace fs = std::filesystem;
using namespace animat;
using animat::test::slurp;
using animat::test::spit;
using animat::test::stub_fitness;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

fs::path fresh_dir(const std::string& name) {
  return animat::test::fresh_dir("animat_hard_", name);
}

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// Every file under `dir` with its content: a refused command must leave this unchanged.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    out[fs::relative(e.path(), dir).string()] =
        e.is_regular_file() ? slurp(e.path()) : std::string("<dir>");
  return out;
}

struct Shell {
  int rc = 0;
  std::string err;
  double seconds = 0.0;
};

/// Runs argv (no shell) with stdout discarded; returns the exit status (128 + signal if killed).
Shell run_exe(const std::vector<std::string>& args) {
  const fs::path errfile = fresh_dir("stderr.txt");
  const auto t0 = Clock::now();
  std::fflush(nullptr);  // the child must not write the parent's buffered output again
  const pid_t pid = fork();
  if (pid == 0) {
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    if (!freopen("/dev/null", "w", stdout) || !freopen(errfile.c_str(), "w", stderr)) _exit(125);
    execv(argv[0], argv.data());
    _exit(126);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  Shell r;
  r.seconds = seconds_since(t0);
  r.rc = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.err = slurp(errfile);
  fs::remove(errfile);
  return r;
}

const std::string kExe = ANIMAT_EVOLVE_EXE;

/// A directory removed when the test process exits (forked children leave by _exit and keep it).
struct RemovedAtExit {
  fs::path dir;
  ~RemovedAtExit() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

/// A small real run on disk (the CLI), made once per test process.
const fs::path& small_run() {
  static const RemovedAtExit run = [] {
    const fs::path d = fresh_dir("run");
    const Shell r = run_exe({kExe, "--quiet", "--threads", "1", "--seed", "3", "--set",
                             "evolution.population=4", "--set", "evaluation.steps=50",
                             "--generations", "1", "--out", d.string()});
    EXPECT_EQ(r.rc, 0) << r.err;
    return RemovedAtExit{d};
  }();
  return run.dir;
}

// ---------------------------------------------------------------------------------------------------
// Child processes: a crash (signal) in the code under test must fail the test, not kill it.

struct ChildResult {
  enum Kind { ok, error, foreign, crashed, hung } kind = ok;
  std::string message;  // what the child wrote (its note, an animat::Error message) or the signal
};

/// Only keeps a broken build from hanging the suite: every child's work is bounded (see the sweep
/// below), so a child still running after this long is a hang, and a failure. Never a verdict on
/// speed.
constexpr double kHangGuardSeconds = 900.0;

/// Runs f in a forked child; f returns a note (e.g. which work budget it reached). The parent must
/// not have used OpenMP before (each test runs in its own process under ctest), so the child's
/// runtime starts clean.
template <class F>
ChildResult in_child(F&& f) {
  int fds[2];
  if (pipe(fds) != 0) return {ChildResult::foreign, "pipe failed"};
  std::fflush(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    int code = 0;
    std::string msg;
    try {
      msg = f();
    } catch (const Error& e) {
      code = 3;
      msg = e.what();
    } catch (const std::exception& e) {
      code = 4;
      msg = std::string("foreign exception: ") + e.what();
    }
    if (!msg.empty() && write(fds[1], msg.data(), msg.size()) < 0) code = 5;
    _exit(code);
  }
  close(fds[1]);
  const auto t0 = Clock::now();
  int status = 0;
  bool hung = false;
  while (waitpid(pid, &status, WNOHANG) == 0) {
    // polls for the exit; the time decides nothing but a hang
    if (seconds_since(t0) > kHangGuardSeconds) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      hung = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  std::string msg;
  char buf[4096];
  for (ssize_t n; (n = read(fds[0], buf, sizeof buf)) > 0;)
    msg.append(buf, static_cast<std::size_t>(n));
  close(fds[0]);
  if (hung)
    return {ChildResult::hung,
            fmt::format("still running after {} s (hang guard)", kHangGuardSeconds)};
  if (WIFSIGNALED(status))
    return {ChildResult::crashed,
            fmt::format("signal {} ({})", WTERMSIG(status), strsignal(WTERMSIG(status)))};
  switch (WEXITSTATUS(status)) {
    case 0: return {ChildResult::ok, msg};
    case 3: return {ChildResult::error, msg};
    default: return {ChildResult::foreign, fmt::format("exit {}: {}", WEXITSTATUS(status), msg)};
  }
}

// ---------------------------------------------------------------------------------------------------
// The sweep's values for one field.

struct Probe {
  std::string text;  // as written in TOML and after --set
  ConfigValue value;
  bool inside = true;  // within the field's declared bounds
};

std::string toml_double(double x) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  std::string s = fmt::format("{}", x);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

std::vector<Probe> probes_for(const FieldInfo& info, double) {
  std::vector<Probe> out;
  const Bounds& b = info.bounds;
  auto add = [&](double x, bool inside) { out.push_back({toml_double(x), x, inside}); };
  constexpr double inf = std::numeric_limits<double>::infinity();
  // Every numeric field must state a finite range: an unbounded value reaches arithmetic or Box2D.
  EXPECT_TRUE(std::isfinite(b.lo) && std::isfinite(b.hi))
      << info.name << " has an unbounded range " << b.describe();
  const double lo_in = b.lo_open ? std::nextafter(b.lo, inf) : b.lo;
  const double hi_in = b.hi_open ? std::nextafter(b.hi, -inf) : b.hi;
  const double lo_out = b.lo_open ? b.lo : std::nextafter(b.lo, -inf);
  const double hi_out = b.hi_open ? b.hi : std::nextafter(b.hi, inf);
  if (std::isfinite(lo_in)) add(lo_in, true);
  if (std::isfinite(hi_in)) add(hi_in, true);
  if (std::isfinite(lo_out)) add(lo_out, false);
  if (std::isfinite(hi_out)) add(hi_out, false);
  for (double x : {inf, -inf, std::nan(""), DBL_MAX, -DBL_MAX}) add(x, false);
  return out;
}

std::vector<Probe> probes_for(const FieldInfo& info, std::int64_t) {
  std::vector<Probe> out;
  const Bounds& b = info.bounds;
  auto add = [&](std::int64_t x, bool inside) { out.push_back({std::to_string(x), x, inside}); };
  constexpr auto kMax = std::numeric_limits<std::int64_t>::max();
  const auto lo = static_cast<std::int64_t>(std::ceil(b.lo + (b.lo_open ? 0.5 : 0.0)));
  const bool hi_finite = std::isfinite(b.hi) && b.hi < 9.2e18;
  const std::int64_t hi =
      hi_finite ? static_cast<std::int64_t>(std::floor(b.hi - (b.hi_open ? 0.5 : 0.0))) : kMax;
  add(lo, true);
  add(hi, true);
  add(lo - 1, false);
  if (hi_finite) add(hi + 1, false);
  return out;
}

std::vector<Probe> probes_for(const FieldInfo& info, int) {
  auto out = probes_for(info, std::int64_t{});
  // An int field also refuses what int cannot hold.
  out.push_back({"2147483648", std::int64_t{2147483648LL}, false});
  out.push_back({"-9223372036854775808", std::numeric_limits<std::int64_t>::min(), false});
  return out;
}

std::vector<Probe> probes_for(const FieldInfo& info, const std::string&) {
  std::vector<Probe> out;
  for (auto c : info.choices) out.push_back({fmt::format("\"{}\"", c), std::string(c), true});
  out.push_back({"\"no_such_choice\"", std::string("no_such_choice"), false});
  return out;
}

std::vector<Probe> probes_for(const FieldInfo& info, const std::vector<std::string>&) {
  std::vector<Probe> out;
  if (info.choices.empty()) {  // names owned by a Python table (search.descriptors): any one word
    out.push_back({"[\"a_name\"]", std::vector<std::string>{"a_name"}, true});
    out.push_back({"[]", std::vector<std::string>{}, false});
    out.push_back({"[\"\"]", std::vector<std::string>{""}, false});
    out.push_back({"[\"a b\"]", std::vector<std::string>{"a b"}, false});
    out.push_back({"[\"a\", \"a\"]", std::vector<std::string>{"a", "a"}, false});
    return out;
  }
  out.push_back({"[]", std::vector<std::string>{}, true});
  std::vector<std::string> all;
  for (auto c : info.choices) all.emplace_back(c);
  out.push_back({fmt::format("[\"{}\"]", fmt::join(all, "\", \"")), all, true});
  out.push_back({"[\"no_such_effect\"]", std::vector<std::string>{"no_such_effect"}, false});
  if (!all.empty())
    out.push_back({fmt::format("[\"{}\", \"{}\"]", all[0], all[0]),
                   std::vector<std::string>{all[0], all[0]}, false});
  return out;
}

std::vector<Probe> probes_for(const FieldInfo& info, const std::vector<double>& current) {
  std::vector<Probe> out;
  auto with = [&](std::size_t i, double x, bool inside) {
    std::vector<double> v = current;
    v[i] = x;
    std::vector<std::string> parts;
    for (double d : v) parts.push_back(toml_double(d));
    out.push_back({fmt::format("[{}]", fmt::join(parts, ", ")), v, inside});
  };
  if (current.empty()) {  // search.ranges: free lo < hi pairs, one per descriptor (two by default)
    out.push_back({"[]", current, true});
    out.push_back(
        {"[0.5, 2.5, -1e300, 1e300]", std::vector<double>{0.5, 2.5, -1e300, 1e300}, true});
    out.push_back({"[0.5, 2.5]", std::vector<double>{0.5, 2.5}, false});  // one pair of two
    out.push_back({"[2.5, 0.5, 0.0, 4.0]", std::vector<double>{2.5, 0.5, 0.0, 4.0}, false});
    out.push_back({"[0.5, 0.5, 0.0, 4.0]", std::vector<double>{0.5, 0.5, 0.0, 4.0}, false});
    out.push_back(
        {"[nan, 2.5, 0.0, 4.0]", std::vector<double>{std::nan(""), 2.5, 0.0, 4.0}, false});
    out.push_back({"[0.5, inf, 0.0, 4.0]", std::vector<double>{0.5, INFINITY, 0.0, 4.0}, false});
    return out;
  }
  const Bounds& b = info.bounds;
  EXPECT_TRUE(std::isfinite(b.lo) && std::isfinite(b.hi))
      << info.name << " has an unbounded range " << b.describe();
  for (std::size_t i : {std::size_t{0}, current.size() - 1}) {
    with(i, b.lo, true);
    with(i, b.hi, true);
    with(i, std::nextafter(b.lo, -INFINITY), false);
    with(i, std::nextafter(b.hi, INFINITY), false);
    with(i, std::nan(""), false);
  }
  out.push_back({"[]", std::vector<double>{}, false});  // the wrong length
  return out;
}

[[maybe_unused]] std::vector<Probe> probes_for(const FieldInfo&, bool) {
  return {{"true", true, true}, {"false", false, true}, {"1", std::int64_t{1}, false}};
}

struct KeyProbes {
  std::string section, key;
  std::vector<Probe> probes;
};

std::vector<KeyProbes> all_probes() {
  std::vector<KeyProbes> out;
  Config c;
  visit_sections(c, [&](std::string_view section, auto& params) {
    visit_fields(params, [&](const FieldInfo& info, auto& value) {
      using T = std::decay_t<decltype(value)>;
      std::vector<Probe> p;
      if constexpr (std::is_same_v<T, double>)
        p = probes_for(info, 0.0);
      else if constexpr (std::is_same_v<T, std::int64_t>)
        p = probes_for(info, std::int64_t{});
      else if constexpr (std::is_same_v<T, int>)
        p = probes_for(info, 0);
      else
        p = probes_for(info, value);
      out.push_back({std::string(section), std::string(info.name), std::move(p)});
    });
  });
  return out;
}

/// The base of the sweep's evaluations: small and fast, every stage still runs.
Config sweep_base() {
  Config c;
  c.evaluation.steps = 100;
  c.evolution.population = 4;
  c.evolution.elites = 1;
  c.evolution.threads = 1;
  c.evolution.seed = 5;
  return c;
}

const Genome& viable_genome() {
  static const Genome g = [] {
    const Config c = sweep_base();
    for (int i = 0; i < 20000; ++i) {
      Rng rng = Rng::derive(2024, i);
      Genome candidate = random_genome(c.genome, rng);
      if (evaluate(candidate, c).viable) return candidate;
    }
    ADD_FAILURE() << "no viable genome";
    return Genome{};
  }();
  return g;
}

/// A viable genome with a small body (at most 12 cells; the first one, viable_genome(), has 32):
/// what the probes of evaluation.settle_steps swim (see the sweep).
const Genome& small_viable_genome() {
  static const Genome g = [] {
    const Config c = sweep_base();
    for (int i = 0; i < 20000; ++i) {
      Rng rng = Rng::derive(2024, i);
      Genome candidate = random_genome(c.genome, rng);
      const EvaluationResult r = evaluate(candidate, c);
      if (r.viable && r.cell_count <= 12) return candidate;
    }
    ADD_FAILURE() << "no viable genome of at most 12 cells";
    return Genome{};
  }();
  return g;
}

/// The sweep's work budgets (see EveryKeyAtItsBoundsEvaluatesAndEvolvesWithoutASignal).
// control steps of evaluate()'s swim: the paper's horizon
constexpr long kSwimStepBudget = 4000;
// fitness evaluations of the GA: 400 generations of the base
constexpr long kEvaluationBudget = 5000;
struct SwimBudgetReached {};  // thrown by SwimBudget; no library code catches it

/// Stops evaluate()'s swim once it has run kSwimStepBudget control steps (sampled every 1000 steps:
/// splitting a swim's steps changes nothing in its motion).
struct SwimBudget final : EvaluationObserver {
  [[nodiscard]] long sample_every() const override { return 1000; }
  void on_sample(const Simulation& sim) override {
    if (sim.steps_done() >= kSwimStepBudget) throw SwimBudgetReached{};
  }
};

/// The shared stub (mean first coordinate) can go negative when a sweep moves coordinates far; a
/// fitness is a distance, so the sweep uses its magnitude.
Fitness sweep_fitness(const Genome& g) {
  Fitness f = stub_fitness(g);
  f.fitness = std::abs(f.fitness);
  return f;
}

bool names_key(const std::string& message, const std::string& dotted) {
  return message.find(dotted) != std::string::npos;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------
// The generated sweep

TEST(ConfigSweep, EveryKeyOutsideItsBoundsIsRefusedNamingTheKey) {
  int refused = 0;
  for (const auto& kp : all_probes()) {
    const std::string dotted = kp.section + "." + kp.key;
    for (const auto& p : kp.probes) {
      if (p.inside) continue;
      SCOPED_TRACE(dotted + " = " + p.text);
      Config c;
      try {
        set_value(c, dotted, p.value);
        validate(c);
        ADD_FAILURE() << "set_value accepted it";
      } catch (const ConfigError& e) {
        EXPECT_TRUE(names_key(e.what(), dotted)) << e.what();
      }
      try {
        (void)config_from_toml(fmt::format("[{}]\n{} = {}\n", kp.section, kp.key, p.text),
                               "sweep.toml");
        ADD_FAILURE() << "TOML accepted it";
      } catch (const ConfigError& e) {
        EXPECT_TRUE(names_key(e.what(), dotted)) << e.what();
      }
      ++refused;
    }
  }
  std::printf(
      "[ sweep    ] %d out-of-bounds values refused by set_value and by TOML, each naming its "
      "key\n",
      refused);
}

TEST(ConfigSweep, RefusedValuesOnTheCommandLineChangeNoFileOfARun) {
  // `--resume R --set key=value` with every refused value, and with every in-bounds value of a key
  // that defines the run: exit 2, the key in the message, R byte-for-byte unchanged.
  const fs::path& run = small_run();
  const auto before = snapshot(run);
  const auto& resumable = resumable_keys();
  const Config stored = load_config(run / "config.toml");
  int tried = 0;
  for (const auto& kp : all_probes()) {
    const std::string dotted = kp.section + "." + kp.key;
    const bool may_change =
        std::find(resumable.begin(), resumable.end(), dotted) != resumable.end();
    for (const auto& p : kp.probes) {
      if (p.inside && may_change) continue;  // accepted on resume: it would run
      if (p.inside && get_value(stored, dotted) == p.value) continue;  // no change at all
      std::string text = p.text;
      if (text.size() > 1 && text.front() == '"') text = text.substr(1, text.size() - 2);
      SCOPED_TRACE(dotted + " = " + text);
      const Shell r =
          run_exe({kExe, "--quiet", "--resume", run.string(), "--set", dotted + "=" + text});
      EXPECT_EQ(r.rc, 2) << r.err;
      EXPECT_TRUE(names_key(r.err, dotted)) << r.err;
      ++tried;
    }
  }
  EXPECT_EQ(snapshot(run), before);
  std::printf(
      "[ sweep    ] %d refused --resume --set commands: exit 2, key named, no file changed\n",
      tried);
}

TEST(ConfigSweep, EveryKeyAtItsBoundsEvaluatesAndEvolvesWithoutASignal) {
  // In a child per value: evaluate() of a viable genome and two generations of the GA (stub
  // fitness), a checkpoint and its restore. A signal is a failure; an animat::Error must name
  // something clear (the genome not fitting the config).
  //
  // The work of each child is bounded, not its time (a 3 s limit used to decide which values were
  // checked, so a loaded machine checked fewer, and a crash after the limit passed): the swim stops
  // after kSwimStepBudget control steps (an observer; only evaluation.steps = 10^7 gets there), the
  // GA after kEvaluationBudget evaluations (a stop request; only evolution.population = 100,000).
  // Development and settling run before the first step an observer sees and always run to their
  // end: development.steps = 100,000 (1.5 to 4 s) and development.max_cells = 4096 (a 4096-cell
  // embryo, 6 to 14 s) as they are; evaluation.settle_steps = 10^7 on the small body of
  // small_viable_genome() (11 cells: 8 s; 20 to 38 s on the 32-cell one). Which values reach a
  // budget is fixed by the values, never by the machine; the children's time limit is only a hang
  // guard.
  const Genome& genome = viable_genome();
  const Genome& small = small_viable_genome();
  ASSERT_FALSE(genome.elements.empty());
  ASSERT_FALSE(small.elements.empty());
  int accepted = 0, cross_refused = 0, errors = 0;
  std::map<std::string, std::vector<std::string>> budgets;  // budget -> the values that reached it
  for (const auto& kp : all_probes()) {
    const std::string dotted = kp.section + "." + kp.key;
    for (const auto& p : kp.probes) {
      if (!p.inside) continue;
      SCOPED_TRACE(dotted + " = " + p.text);
      Config c = sweep_base();
      try {
        set_value(c, dotted, p.value);
        validate(c);
      } catch (const ConfigError& e) {
        // a cross-field rule (elites < population, min_cells <= max_cells...)
        EXPECT_TRUE(names_key(e.what(), dotted)) << e.what();
        ++cross_refused;
        continue;
      }
      ++accepted;
      const Genome& swimmer = dotted == "evaluation.settle_steps" ? small : genome;
      const ChildResult r = in_child([&]() -> std::string {
        std::string note;
        try {
          SwimBudget budget;
          const EvaluationResult e = evaluate(swimmer, c, &budget);
          if (!std::isfinite(e.fitness) || e.fitness < 0.0) _exit(6);
          if (e.cell_count > c.development.max_cells) _exit(7);
        } catch (const GenomeError&) {
          // the sweep's genome does not fit this config (genome.dimensions): refused cleanly
        } catch (const SwimBudgetReached&) {
          note += "swim";
        }
        const Config& g = c;
        std::atomic<long> evaluations{0};
        std::atomic<bool> spent{false};
        Evolution evo(g, [&](const Genome& x) {
          if (evaluations.fetch_add(1) + 1 >= kEvaluationBudget) spent = true;
          return sweep_fitness(x);
        });
        evo.set_stop(StopRequest{&spent, {}});
        try {
          evo.initialize();
          (void)evo.step();
          (void)evo.step();
        } catch (const Interrupted&) {
          if (!spent) throw;
          return note + (note.empty() ? "" : ",") + "evaluations";
        }
        for (const auto& ind : evo.population()) validate(ind.genome, g.genome, "offspring");
        Evolution again(g, sweep_fitness);
        again.restore(evo.checkpoint());
        return note;
      });
      switch (r.kind) {
        case ChildResult::ok:
          if (!r.message.empty()) budgets[r.message].push_back(dotted + " = " + p.text);
          break;
        case ChildResult::error:  // clean, but it must say which setting caused it
          ++errors;
          std::printf("[ sweep    ] %s = %s: %s\n", dotted.c_str(), p.text.c_str(),
                      r.message.c_str());
          EXPECT_TRUE(names_key(r.message, dotted)) << r.message;
          break;
        default: ADD_FAILURE() << r.message;
      }
    }
  }
  // The values that reach a budget are known: a new one is either a slow new key (give it a budget
  // or a small body above) or a regression that makes an old one slow.
  const std::map<std::string, std::vector<std::string>> expected = {
      {"swim", {"evaluation.steps = 10000000"}},
      {"evaluations", {"evolution.population = 100000"}}};
  EXPECT_EQ(budgets, expected);
  for (const auto& [budget, values] : budgets)
    std::printf("[ sweep    ] stopped at the %s budget: %s\n", budget.c_str(),
                fmt::format("{}", fmt::join(values, "; ")).c_str());
  std::printf(
      "[ sweep    ] %d in-bounds values run in a child (%d animat errors naming the key, no "
      "signal); "
      "%d refused by a cross-field rule naming the key\n",
      accepted, errors, cross_refused);
}

TEST(ConfigSweep, ResumableKeysAreExactlyTheKeysOutsideTheRunIdentity) {
  // Every key: changing it changes run_identity() if and only if it may not change on resume.
  const auto& resumable = resumable_keys();
  for (const auto& kp : all_probes()) {
    const std::string dotted = kp.section + "." + kp.key;
    const bool may_change =
        std::find(resumable.begin(), resumable.end(), dotted) != resumable.end();
    // The migration keys act only with islands (and are left out of the identity without them, so
    // that runs checkpointed before islands existed resume): probe them in a run with islands.
    Config base;
    if (dotted.starts_with("evolution.migra")) base.evolution.islands = 2;
    for (const auto& p : kp.probes) {
      if (!p.inside || get_value(base, dotted) == p.value) continue;
      Config c = base;
      set_value(c, dotted, p.value);
      EXPECT_EQ(run_identity(c) == run_identity(base), may_change) << dotted << " = " << p.text;
      EXPECT_EQ(run_identity_v1(c) == run_identity_v1(base), may_change)
          << dotted << " = " << p.text << " (scheme 1)";
      break;
    }
  }
}

// ---------------------------------------------------------------------------------------------------
// The other attacks of docs/reliability.md

TEST(Rows, Box2DAssertValuesAreRefused) {
  // Both were accepted and then aborted in b2Body's constructor (exit 134).
  for (const std::string o :
       {"development.damping=1e39", "development.cell_radius=1e39", "scene.cell_mass=1e-300",
        "development.cell_mass=1e39", "physics.dt=1e-300", "development.time_step=1e-300"}) {
    Config c;
    EXPECT_THROW(apply_override(c, o), ConfigError) << o;
  }
  const fs::path out = fresh_dir("damping");
  const Shell r =
      run_exe({kExe, "--quiet", "--set", "development.damping=1e39", "--out", out.string()});
  EXPECT_EQ(r.rc, 2) << r.err;
  EXPECT_NE(r.err.find("development.damping"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out)) << "a refused run created its --out";
}

TEST(Rows, MoveSigmaCannotOverflowACoordinate) {
  Config c;
  EXPECT_THROW(apply_override(c, "mutation.move_sigma=1e308"), ConfigError);
  // At its bound every mutation keeps coordinates finite (the largest normal deviate is
  // about 12.1).
  apply_override(c, "mutation.move_sigma=1000000");
  apply_override(c, "mutation.move_rate=1");
  Rng rng(3);
  Genome g = random_genome(c.genome, rng);
  for (int i = 0; i < 2000; ++i) mutate(g, c.mutation, c.genome, rng);
  EXPECT_NO_THROW(validate(g, c.genome));
}

TEST(Rows, SeedBeyondInt64IsAnErrorNotAClamp) {
  for (const std::string seed :
       {"99999999999999999999", "9223372036854775808", "-1", "1e3", "12abc"}) {
    const Shell r = run_exe({kExe, "--print-config", "--seed", seed});
    EXPECT_NE(r.rc, 0) << seed;
    EXPECT_NE(r.err.find("--seed"), std::string::npos) << r.err;
  }
  const Shell ok = run_exe({kExe, "--print-config", "--seed", "9223372036854775807"});
  EXPECT_EQ(ok.rc, 0) << ok.err;
}

TEST(Rows, LongOutPathIsAClearError) {
  const fs::path base = fresh_dir("long");
  for (const auto& [out, want] : std::vector<std::pair<fs::path, std::string>>{
           {base / std::string(300, 'a'), "NAME_MAX"},
           {base / fs::path(std::string(200, 'b')) / std::string(200, 'c') / std::string(200, 'd') /
                std::string(200, 'e') / std::string(200, 'f') / std::string(200, 'g') /
                std::string(200, 'h') / std::string(200, 'i') / std::string(200, 'j') /
                std::string(200, 'k') / std::string(200, 'l') / std::string(200, 'm') /
                std::string(200, 'n') / std::string(200, 'o') / std::string(200, 'p') /
                std::string(200, 'q') / std::string(200, 'r') / std::string(200, 's') /
                std::string(200, 't') / std::string(200, 'u') / std::string(200, 'v') /
                std::string(200, 'w'),
            "PATH_MAX"}}) {
    const Shell r = run_exe({kExe, "--quiet", "--out", out.string(), "--generations", "1"});
    EXPECT_EQ(r.rc, 2) << r.err;
    EXPECT_NE(r.err.find(want), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(base)) << "a refused --out created a directory";
}

TEST(Rows, RngIntegerCoversTheWholeInt64Range) {
  Rng rng(1);
  constexpr auto lo = std::numeric_limits<std::int64_t>::min(),
                 hi = std::numeric_limits<std::int64_t>::max();
  bool negative = false, positive = false;
  for (int i = 0; i < 64; ++i) {
    const std::int64_t x = rng.integer(lo, hi);  // was below(0): SIGFPE
    negative |= x < 0;
    positive |= x > 0;
  }
  EXPECT_TRUE(negative && positive);
  for (int i = 0; i < 200; ++i) {
    const std::int64_t x = rng.integer(lo, lo + 1);
    EXPECT_TRUE(x == lo || x == lo + 1);
    const std::int64_t y = rng.integer(hi - 2, hi);
    EXPECT_TRUE(y >= hi - 2);
    const std::int64_t z = rng.integer(-3, 3);
    EXPECT_TRUE(z >= -3 && z <= 3);
  }
  EXPECT_EQ(rng.below(0), 0u);
}

TEST(Rows, LoadConfigOfADirectoryOrUnreadableFileIsAnError) {
  const fs::path dir = fresh_dir("cfgdir");
  fs::create_directories(dir);
  try {
    (void)load_config(dir);
    FAIL() << "a directory was read as the default config";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("Is a directory"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)load_config(dir / "missing.toml"), IoError);
  EXPECT_THROW((void)load_genome(dir), IoError);
  if (geteuid() != 0) {  // root reads anything
    const fs::path f = dir / "unreadable.toml";
    spit(f, "[evolution]\npopulation = 10\n");
    fs::permissions(f, fs::perms::none);
    EXPECT_THROW((void)load_config(f), IoError);
  }
  fs::remove_all(dir);
}

TEST(Rows, AFitnessFunctionReturningANegativeOrNonFiniteFitnessIsAnError) {
  // Such a run would write a checkpoint that the semantic checks below refuse to resume.
  Config c;
  c.evolution.population = 4;
  c.evolution.elites = 1;
  c.evolution.threads = 1;
  for (double bad : {-1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    Evolution evo(c, [bad](const Genome&) { return Fitness{bad, true, true, 3}; });
    try {
      evo.initialize();
      FAIL() << bad;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("finite and >= 0"), std::string::npos) << e.what();
    }
  }
}

TEST(Rows, ASignedObjectiveMayBeNegativeAndItsCheckpointResumes) {
  // speed_toward (and a Python objective) is signed: a body swimming backwards scores < 0. Such a
  // run runs, checkpoints and resumes; only non-finite values are refused.
  Config c;
  c.evolution.population = 4;
  c.evolution.elites = 1;
  c.evolution.threads = 1;
  c.evaluation.objective = "speed_toward";
  auto signed_fitness = [](const Genome& g) {
    return Fitness{-1.0 - 0.01 * static_cast<double>(g.elements.size()), true, true, 3};
  };
  Evolution evo(c, signed_fitness);
  evo.initialize();
  (void)evo.step();
  EXPECT_LT(evo.history().back().best, 0.0);
  Evolution resumed(c, signed_fitness);
  resumed.restore(evo.checkpoint());
  (void)resumed.step();
  (void)evo.step();
  EXPECT_EQ(resumed.history().back().best, evo.history().back().best);
  Evolution nan_run(c, [](const Genome&) { return Fitness{std::nan(""), true, true, 3}; });
  EXPECT_THROW(nan_run.initialize(), Error);
}

// ---------------------------------------------------------------------------------------------------
// --resume with changed settings

TEST(ResumeSettings, ChangedSettingsAreRefusedBeforeAnyWriteAndNamed) {
  const fs::path run = fresh_dir("resume");
  fs::copy(small_run(), run, fs::copy_options::recursive);
  const auto before = snapshot(run);
  const Shell r = run_exe(
      {kExe, "--quiet", "--resume", run.string(), "--set", "scene.drag_normal=10", "--seed", "99"});
  EXPECT_EQ(r.rc, 2) << r.err;
  EXPECT_NE(r.err.find("scene.drag_normal (the run has 2.0, this command gives 10.0)"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("evolution.seed (the run has 3, this command gives 99)"), std::string::npos)
      << r.err;
  EXPECT_EQ(snapshot(run), before) << "a refused --resume changed the run directory";
  // ... so the run still resumes, and still repeats from its own config.
  const Shell again = run_exe({kExe, "--quiet", "--resume", run.string(), "--generations", "2"});
  EXPECT_EQ(again.rc, 0) << again.err;
  fs::remove_all(run);
}

TEST(ResumeSettings, ResumableKeysAreAcceptedAndRecorded) {
  const fs::path run = fresh_dir("resume_ok");
  fs::copy(small_run(), run, fs::copy_options::recursive);
  const Shell r =
      run_exe({kExe, "--quiet", "--resume", run.string(), "--generations", "2", "--threads", "2",
               "--set", "evolution.checkpoint_every=3", "--set", "evolution.wall_seconds=1000",
               "--set", "evolution.stall_generations=7"});
  ASSERT_EQ(r.rc, 0) << r.err;
  const Config recorded = load_config(run / "config.toml");
  EXPECT_EQ(recorded.evolution.generations, 2);
  EXPECT_EQ(recorded.evolution.threads, 2);
  EXPECT_EQ(recorded.evolution.checkpoint_every, 3);
  EXPECT_EQ(recorded.evolution.stall_generations, 7);
  const std::string log = slurp(run / "resume.log");
  for (const char* s :
       {"resumed at generation 1:", "evolution.generations 1 -> 2", "evolution.threads 1 -> 2",
        "evolution.checkpoint_every 1 -> 3", "evolution.wall_seconds 0.0 -> 1000.0",
        "evolution.stall_generations 500 -> 7"})
    EXPECT_NE(log.find(s), std::string::npos) << log;
  fs::remove_all(run);
}

TEST(ResumeSettings, AResumeThatStopsAtOnceWritesNothing) {
  // A run at generation 3 resumed with a cap of 2 has nothing to evolve: its config.toml keeps the
  // cap it ran under (a rewrite to 2 would misstate the run), and no other file changes either.
  const fs::path run = fresh_dir("resume_past_cap");
  fs::copy(small_run(), run, fs::copy_options::recursive);
  ASSERT_EQ(run_exe({kExe, "--quiet", "--resume", run.string(), "--generations", "3"}).rc, 0);
  const auto before = snapshot(run);
  const Shell r = run_exe({kExe, "--quiet", "--resume", run.string(), "--generations", "2"});
  EXPECT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(snapshot(run), before) << "a resume past the cap changed the run directory";
  EXPECT_EQ(load_config(run / "config.toml").evolution.generations, 3);

  Config c = load_config(run / "config.toml");
  RunOptions opt;
  opt.out = run;
  opt.resume = true;
  opt.quiet = true;
  for (const int cap : {1, 3}) {  // below the run's generation, and at it
    c.evolution.generations = cap;
    const RunSummary summary = run_evolution(c, opt, stub_fitness);
    EXPECT_EQ(summary.stop_reason,
              fmt::format("generation cap evolution.generations = {} reached", cap));
    ASSERT_EQ(summary.history.size(), 4u);
    EXPECT_EQ(summary.history.back().generation, 3);
    EXPECT_EQ(summary.population.size(), 4u);
    EXPECT_EQ(snapshot(run), before) << cap;
  }
  c.evolution.generations = 4;  // a higher cap evolves again
  EXPECT_EQ(run_evolution(c, opt, stub_fitness).history.back().generation, 4);
  EXPECT_EQ(load_config(run / "config.toml").evolution.generations, 4);
  fs::remove_all(run);
}

TEST(ResumeSettings, InProcessResumeWithAnotherConfigWritesNothing) {
  const fs::path run = fresh_dir("resume_api");
  fs::copy(small_run(), run, fs::copy_options::recursive);
  const auto before = snapshot(run);
  Config c = load_config(run / "config.toml");
  c.grn.dt = 0.025;
  RunOptions opt;
  opt.out = run;
  opt.resume = true;
  opt.quiet = true;
  try {
    (void)run_evolution(c, opt, stub_fitness);
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("grn.dt (the run has 0.05, this command gives 0.025)"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(snapshot(run), before);
  fs::remove_all(run);
}

// ---------------------------------------------------------------------------------------------------
// Stop requests

// Deterministic: the stop is raised by the fitness function itself on its k-th call, and the tests
// count the evaluations started after it (was: a stop from a timer thread and bounds in seconds,
// which failed on a loaded machine).

TEST(StopRequests, AStopDuringAGenerationIsHonouredWithinOneEvaluationAndLosesNothing) {
  Config c;
  c.evolution.population = 16;
  c.evolution.elites = 1;
  c.evolution.threads = 1;
  c.genome.initial_units = 30;  // no duplicates among offspring: every child is evaluated
  Evolution reference(c, stub_fitness);
  reference.initialize();
  (void)reference.step();
  (void)reference.step();

  std::atomic<bool> stop{false};
  std::atomic<int> calls{0};
  int stop_at = -1;  // the call that raises the stop (-1: never)
  Evolution evo(c, [&](const Genome& g) {
    if (++calls == stop_at) stop = true;
    return stub_fitness(g);
  });
  evo.set_stop(StopRequest{&stop, {}});
  evo.initialize();
  (void)evo.step();
  calls = 0;
  stop_at = 3;  // the third evaluation of generation 2 (of 15)
  EXPECT_THROW((void)evo.step(), Interrupted);
  EXPECT_EQ(calls.load(), 3) << "evaluations started after the stop (one thread: none)";
  EXPECT_EQ(evo.generation(), 1)
      << "an interrupted generation must leave the state at the previous one";
  stop = false;
  stop_at = -1;
  // the same generation again, from (seed, g, i): identical to the uninterrupted run
  (void)evo.step();
  EXPECT_EQ(evo.history().back().best, reference.history().back().best);
  EXPECT_EQ(evo.population()[3].genome, reference.population()[3].genome);
}

TEST(StopRequests, AStopWhileSeedingIsHonouredWithinOneEvaluation) {
  Config c;
  c.evolution.population = 4;
  c.evolution.threads = 2;
  c.evolution.max_init_tries = 1000000000;
  // Never viable: seeding would take years. The stop comes from the flag (set by the 50th
  // evaluation) and from the poll (true from its 3rd call on): at most one evaluation per other
  // thread starts after it.
  for (const bool by_poll : {false, true}) {
    std::atomic<bool> stop{false};
    std::atomic<int> calls{0}, after{0};
    Evolution evo(c, [&](const Genome&) {
      if (stop.load()) ++after;
      if (++calls == 50 && !by_poll) stop = true;
      return Fitness{};
    });
    int polls = 0;
    evo.set_stop(by_poll ? StopRequest{nullptr, [&] { return ++polls >= 3 && (stop = true); }}
                         : StopRequest{&stop, {}});
    EXPECT_THROW(evo.initialize(), Interrupted) << (by_poll ? "poll" : "flag");
    EXPECT_LE(after.load(), c.evolution.threads - 1) << (by_poll ? "poll" : "flag");
    if (by_poll) {
      EXPECT_EQ(polls, 3);
    }
    EXPECT_EQ(evo.generation(), -1);
    EXPECT_TRUE(evo.population().empty());
  }
}

namespace {
// Starts the CLI, waits until `ready` (a condition on its files), sends `sig`; returns the exit
// status and the seconds from the signal to the exit (printed, never asserted: the in-process tests
// above count the evaluations after a stop instead).
std::pair<int, double> signal_cli(const std::vector<std::string>& args, int sig,
                                  const std::function<bool()>& ready) {
  std::fflush(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    if (!freopen("/dev/null", "w", stdout)) _exit(125);
    execv(argv[0], argv.data());
    _exit(126);
  }
  const auto started = Clock::now();
  int status = 0;
  // on its own, before the signal: reaped, so never signalled (its pid may be reused)
  bool exited = false;
  // Polls the condition; the 900 s only keep a broken build from hanging the suite.
  while (!ready() && seconds_since(started) < 900 &&
         !(exited = waitpid(pid, &status, WNOHANG) == pid))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const auto t0 = Clock::now();
  if (!exited) {
    kill(pid, sig);
    waitpid(pid, &status, 0);
  }
  return {WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), seconds_since(t0)};
}
}  // namespace

TEST(StopRequests, CliSignalWhileSeedingEndsTheRunWithNothingToResume) {
  // quiet_steps = steps forbids every division: no random genome is ever viable, seeding runs
  // forever. Before, the signal was ignored until the population was complete: here, never.
  for (int sig : {SIGTERM, SIGINT}) {
    const fs::path out = fresh_dir("seed_signal");
    // config.toml is written after the signal handlers are installed, before seeding starts.
    const auto [rc, seconds] =
        signal_cli({kExe, "--quiet", "--threads", "2", "--set", "development.quiet_steps=400",
                    "--set", "evolution.population=100", "--out", out.string()},
                   sig, [&] { return fs::exists(out / "config.toml"); });
    std::printf("[ stop     ] %s while seeding: exit %d, %.3f s after the signal\n", strsignal(sig),
                rc, seconds);
    EXPECT_EQ(rc, 130) << strsignal(sig);
    EXPECT_FALSE(fs::exists(out / "checkpoint.json"));
    // Nothing to resume: another run may replace it when asked (--overwrite; without it, a
    // different config is refused since the run directory guard:
    // RunDirectory.RunFilesWithoutACheckpoint...).
    const Shell again = run_exe({kExe, "--quiet", "--threads", "1", "--set",
                                 "evolution.population=4", "--set", "evaluation.steps=50",
                                 "--generations", "1", "--overwrite", "--out", out.string()});
    EXPECT_EQ(again.rc, 0) << again.err;
    fs::remove_all(out);
  }
}

TEST(StopRequests, CliSignalDuringAGenerationEndsWithAResumableCheckpoint) {
  // The signal is sent as soon as generation 0's checkpoint exists, so it lands in generation 1 (or
  // in a later one: nothing here depends on when). The latency is printed only: the in-process
  // tests above count the evaluations after a stop.
  const fs::path out = fresh_dir("gen_signal");
  const auto [rc, seconds] =
      signal_cli({kExe, "--quiet", "--threads", "2", "--seed", "4", "--set",
                  "evolution.population=30", "--set", "evaluation.steps=2000", "--set",
                  "evolution.checkpoint_every=5", "--out", out.string()},
                 SIGTERM, [&] { return fs::exists(out / "checkpoint.json"); });
  std::printf(
      "[ stop     ] SIGTERM during a generation (population 30, 2000 swim steps): exit %d, %.3f s "
      "after the "
      "signal\n",
      rc, seconds);
  EXPECT_EQ(rc, 130);
  ASSERT_TRUE(fs::exists(out / "checkpoint.json"));
  Config c = load_config(out / "config.toml");
  Evolution evo(c, stub_fitness);
  ASSERT_NO_THROW(evo.restore(slurp(out / "checkpoint.json")));
  // The checkpoint is the last row of history.csv.
  const std::string hist = slurp(out / "history.csv");
  const auto last = hist.substr(hist.rfind('\n', hist.size() - 2) + 1);
  EXPECT_EQ(std::stoi(last), evo.generation()) << hist;
  fs::remove_all(out);
}

// ---------------------------------------------------------------------------------------------------
// Checkpoints with a valid checksum and a meaningless content

namespace {

Config cp_config() {
  Config c;
  c.evolution.population = 4;
  c.evolution.elites = 1;
  c.evolution.threads = 1;
  c.evolution.seed = 8;
  return c;
}

json cp_payload() {
  Evolution evo(cp_config(), stub_fitness);
  evo.initialize();
  for (int i = 0; i < 3; ++i) (void)evo.step();
  return json::parse(json::parse(evo.checkpoint())["payload"].get<std::string>());
}

std::string fnv_hex(std::string_view s) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char ch : s) {
    h ^= ch;
    h *= 0x100000001b3ULL;
  }
  return fmt::format("{:016x}", h);
}

std::string rewrap(const json& payload) {
  const std::string body = payload.dump();
  return json{{"checksum", fnv_hex(body)}, {"payload", body}}.dump();
}

/// Finds a viable individual's index.
std::size_t viable_index(const json& p) {
  for (std::size_t i = 0; i < p["population"].size(); ++i)
    if (p["population"][i]["viable"].get<bool>()) return i;
  return 0;
}

}  // namespace

TEST(CheckpointMeaning, AnUneditedCheckpointIsAccepted) {
  Evolution evo(cp_config(), stub_fitness);
  ASSERT_NO_THROW(evo.restore(rewrap(cp_payload()), "good.json"));
  EXPECT_EQ(evo.generation(), 3);
}

TEST(CheckpointMeaning, HandEditedContentIsRefusedNamingWhatIsWrong) {
  const json good = cp_payload();
  const std::size_t v = viable_index(good);
  struct Edit {
    std::string name, expect;
    std::function<void(json&)> apply;
  };
  const std::vector<Edit> edits = {
      {"negative fitness", "fitness -1", [&](json& p) { p["population"][v]["fitness"] = -1.0; }},
      {"empty genome of a viable individual", "viable with an empty genome",
       [&](json& p) { p["population"][v]["genome"]["elements"] = json::array(); }},
      {"history out of order", "history row 0 is generation 1",
       [](json& p) { std::swap(p["history"][0], p["history"][1]); }},
      {"a gap in the history", "history row 2 is generation 3",
       [](json& p) { p["history"].erase(2); }},
      {"viable fraction above 1", "viable_fraction 1.5",
       [](json& p) { p["history"][1]["viable_fraction"] = 1.5; }},
      {"decreasing evaluations", "evaluations decrease",
       [](json& p) { p["history"][1]["evaluations"] = 0; }},
      {"negative wall time", "wall_seconds -1",
       [](json& p) { p["history"][0]["wall_seconds"] = -1.0; }},
      {"best_ever above the history", "best_ever is 1000",
       [](json& p) { p["best_ever"] = 1000.0; }},
      {"stall counter", "stall is 99", [](json& p) { p["stall"] = 99; }},
      {"evaluations counter", "evaluations is 1", [](json& p) { p["evaluations"] = 1; }},
      {"last row not the population", "does not describe the population",
       [&](json& p) {
         p["population"][v]["fitness"] = p["population"][v]["fitness"].get<double>() + 0.5;
       }},
      {"a genome that does not validate", "sign",
       [&](json& p) { p["population"][v]["genome"]["elements"][0]["sign"] = 2; }},
      {"population size", "individuals", [](json& p) { p["population"].erase(0); }},
  };
  for (const auto& e : edits) {
    SCOPED_TRACE(e.name);
    json p = good;
    e.apply(p);
    Evolution evo(cp_config(), stub_fitness);
    try {
      evo.restore(rewrap(p), "edited.json");
      ADD_FAILURE() << "accepted";
    } catch (const Error& err) {
      EXPECT_NE(std::string(err.what()).find("edited.json"), std::string::npos) << err.what();
      EXPECT_NE(std::string(err.what()).find(e.expect), std::string::npos) << err.what();
    }
    EXPECT_EQ(evo.generation(), -1) << "a refused checkpoint must leave the engine untouched";
  }
}

TEST(CheckpointMeaning, CliResumeOfAHandEditedCheckpointIsRefusedAndChangesNothing) {
  const fs::path run = fresh_dir("edited_run");
  fs::copy(small_run(), run, fs::copy_options::recursive);
  json outer = json::parse(slurp(run / "checkpoint.json"));
  json p = json::parse(outer["payload"].get<std::string>());
  p["population"][0]["fitness"] = -3.0;
  spit(run / "checkpoint.json", rewrap(p));
  const auto before = snapshot(run);
  const Shell r = run_exe({kExe, "--quiet", "--resume", run.string(), "--generations", "3"});
  EXPECT_EQ(r.rc, 2) << r.err;
  EXPECT_NE(r.err.find("inconsistent checkpoint"), std::string::npos) << r.err;
  EXPECT_EQ(snapshot(run), before);
  fs::remove_all(run);
}
