// animat_evolve: run an evolution experiment (paper §5) from the embedded default or a TOML config.
// animat_evolve_main() is the whole command line; src/cli/main.cpp calls it, and so does the Python
// module (animat._core.evolve_cli, `animat evolve`), which links the same library (animat_cli).
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <CLI/CLI.hpp>
#include <atomic>
#include <charconv>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <memory>

#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/evaluator.hpp"
#include "animat/evolution.hpp"
#include "animat/log.hpp"
#include "animat/mpi.hpp"
#include "animat/objective_table.hpp"
#include "animat/run.hpp"
#include "animat/search.hpp"

namespace {

// Set by SIGINT/SIGTERM; the run finishes its generation, writes a checkpoint and exits cleanly.
std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop.store(true); }

// [mpi] Rank 0 after a lost rank or a signal mid-evaluation: say what happened and what is on disk,
// then leave at once (the launcher ends the other ranks; waiting for them could hang). mpirun stops
// forwarding output as soon as a rank dies, so the message also goes to RUN_DIR/stopped.txt, first.
[[noreturn]] void mpi_stopped(const animat::Error& e, const std::filesystem::path& out,
                              const animat::Config& config) {
  std::signal(SIGPIPE, SIG_IGN);  // the launcher may have closed our stderr
  std::string text = fmt::format("animat_evolve: error: MPI job stopped: {}\n", e.what());
  const auto ckpt = out / "checkpoint.json";
  try {
    const auto probe =
        animat::make_search(config, [](const animat::Genome&) { return animat::Fitness{}; });
    std::ifstream in(ckpt, std::ios::binary);
    probe->restore(
        std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()),
        ckpt.string());
    text += fmt::format(
        "animat_evolve: {} is intact (generation {}; the generation being evaluated is lost).\n"
        "Continue with any number of ranks:  mpirun -np RANKS animat_evolve --resume {}\n",
        ckpt.string(), probe->generation(), out.string());
  } catch (const std::exception& c) {
    text += fmt::format("animat_evolve: no checkpoint to resume from ({})\n", c.what());
  }
  std::ofstream(out / "stopped.txt", std::ios::binary | std::ios::trunc) << text << std::flush;
  std::fputs(text.c_str(), stderr);
  animat::mpi::Job::abandon(4);
}

std::string default_run_dir(std::int64_t seed) {
  const std::time_t t = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", std::localtime(&t));
  return "runs/" + std::string(stamp) + "-seed" + std::to_string(seed);
}

// The configs of the source's configs/ folder, compiled in (cmake/embed_configs.cmake).
struct PackagedConfig {
  std::string_view name, text;
};
constexpr PackagedConfig kPackagedConfigs[] = {
#include "packaged_configs.inc"
};

// --config: a file, else a packaged config by name ("paper_dn10" or "paper_dn10.toml"). A file of
// that name wins, so a user's own paper_dn10 in the working directory is never shadowed.
animat::Config load_named_config(const std::string& given) {
  std::error_code ec;
  if (std::filesystem::exists(given, ec) || given.find('/') != std::string::npos)
    return animat::load_config(given);
  std::string_view name(given);
  if (name.ends_with(".toml")) name.remove_suffix(5);
  std::string names;
  for (const auto& c : kPackagedConfigs) {
    if (c.name == name)
      return animat::config_from_toml(c.text, fmt::format("packaged config {}", c.name));
    names += (names.empty() ? "" : ", ") + std::string(c.name);
  }
  throw animat::IoError(
      fmt::format("--config {}: no such file, and no packaged config of that name (packaged: {})",
                  given, names));
}

// The seed as given: digits only, within int64 (an error, never a clamp).
std::int64_t parse_seed(const std::string& text) {
  std::int64_t value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (ec == std::errc::result_out_of_range)
    throw animat::ConfigError(
        "--seed " + text +
        ": evolution.seed is out of range: expected an integer in [0, 9223372036854775807]");
  if (ec != std::errc() || ptr != end || value < 0)
    throw animat::ConfigError("--seed " + text +
                              ": evolution.seed must be an integer in [0, 9223372036854775807]");
  return value;
}

}  // namespace

int animat_evolve_main(int argc, char** argv) {
  CLI::App app{
      "animat_evolve: co-evolve the morphology and control of soft-bodied swimmers (Joachimczak & "
      "Wrobel 2012)"};
  std::string config_path, out_dir, resume_dir, log_level = "info", seed_text;
  std::vector<std::string> overrides;
  int generations = -1, threads = -1;
  bool print_config = false, quiet = false, use_mpi = false, overwrite = false;
  app.add_option("--config", config_path,
                 "TOML config file, or the name of a packaged one (paper_dn10, crawl, ...: "
                 "configs/ of the source; default: the embedded paper d_N = 2, 32-cell setting)");
  app.add_option("--set", overrides, "override one value: section.key=value (repeatable)");
  // Read as text: CLI11 would clamp a seed beyond int64 to 2^63-1 silently.
  app.add_option("--seed", seed_text, "run seed (evolution.seed), an integer in [0, 2^63-1]");
  app.add_option("--generations", generations, "generation cap, 0 = none (evolution.generations)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--threads", threads,
                 "OpenMP threads (per rank under mpirun), 0 = all cores (evolution.threads)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--out", out_dir, "run directory to write (default: runs/<time>-seed<seed>)");
  app.add_option("--resume", resume_dir,
                 "run directory to resume; its config.toml is the base config");
  app.add_flag("--overwrite", overwrite,
               "start afresh in --out even if it holds a run: removes its config.toml, "
               "history.csv, checkpoint.json, "
               "islands.csv, resume.log, stopped.txt, best/ and figures/ (nothing else)");
  app.add_flag("--print-config", print_config, "print the resolved config as TOML and exit");
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error, critical or off");
  app.add_flag("--quiet", quiet, "only warnings and errors");
  app.add_flag("--mpi", use_mpi,
               "require an MPI job (mpirun -np R animat_evolve ...; automatic under mpirun)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  // [mpi] Under mpirun rank 0 runs the GA below; every other rank only evaluates (animat/mpi.hpp).
  std::unique_ptr<animat::mpi::Job> mpi_job;
  const animat::mpi::Launch launch = animat::mpi::detect_launch();
  try {
    if (use_mpi && !launch.launched)
      throw animat::ConfigError(
          "--mpi: not started by an MPI launcher; run mpirun -np RANKS animat_evolve ...");
    if ((use_mpi || launch.size > 1) && !animat::mpi::built_with_mpi())
      throw animat::Error(fmt::format("started as one of {} MPI ranks ({}), but {}", launch.size,
                                      launch.variable, animat::mpi::how_to_get_mpi()));
    if (launch.launched && animat::mpi::built_with_mpi()) {
      mpi_job = std::make_unique<animat::mpi::Job>(argc, argv);
      if (mpi_job->rank() != 0) return mpi_job->serve();
    }
  } catch (const animat::Error& e) {
    if (launch.rank == 0)
      std::fprintf(stderr, "animat_evolve: error: %s\n", e.what());
    else
      std::fprintf(stderr, "animat_evolve (rank %d): error: %s\n", launch.rank, e.what());
    return 2;
  }

  try {
    animat::set_log_level(quiet ? "warn" : log_level);
    if (!resume_dir.empty() && !out_dir.empty() &&
        std::filesystem::path(resume_dir) != std::filesystem::path(out_dir))
      throw animat::ConfigError(
          "--resume and --out name different directories; --resume continues in place");
    if (!resume_dir.empty() && overwrite)
      throw animat::ConfigError(
          "--resume continues the run and --overwrite replaces it; pass one of them");
    if (!resume_dir.empty() && !config_path.empty())
      throw animat::ConfigError(
          "--resume takes its config from the run directory; do not also pass --config");
    animat::Config config;
    if (!resume_dir.empty()) {
      const auto base = std::filesystem::path(resume_dir) / "config.toml";
      std::error_code ec;
      if (!std::filesystem::is_directory(resume_dir, ec))
        throw animat::IoError(
            resume_dir + ": resume directory does not exist" +
            (ec && ec != std::errc::no_such_file_or_directory ? " (" + ec.message() + ")" : ""));
      config = animat::load_config(base);
    } else if (!config_path.empty()) {
      config = load_named_config(config_path);
    }
    // validated together: the order of the --set flags does not matter
    animat::apply_overrides(config, overrides);
    if (!seed_text.empty()) config.evolution.seed = parse_seed(seed_text);
    if (generations >= 0) config.evolution.generations = generations;
    if (threads >= 0) config.evolution.threads = threads;
    animat::validate(config, "command line");
    if (print_config) {
      std::cout << animat::to_toml(config);
      return 0;
    }

    animat::RunOptions options;
    options.resume = !resume_dir.empty();
    options.out = options.resume
                      ? resume_dir
                      : (out_dir.empty() ? default_run_dir(config.evolution.seed) : out_dir);
    options.overwrite = overwrite;
    options.quiet = quiet;
    options.stop_flag = &g_stop;
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    if (!quiet) {
      // The world as it is: d_N only where the scene has drag.
      const std::string world =
          animat::has_effect(config.scene.effects, "drag")
              ? fmt::format("d_N = {}", config.scene.drag_normal)
              : fmt::format("no drag ({})", fmt::join(config.scene.effects, ", "));
      spdlog::info(
          "animat {} | population {} | {} cells max | {} | objective {} | {} swim steps | seed {} "
          "| run dir {}",
          ANIMAT_VERSION, config.evolution.population, config.development.max_cells, world,
          config.evaluation.objective, config.evaluation.steps, config.evolution.seed,
          options.out.string());
      if (config.evolution.generations == 0 && config.evolution.wall_seconds == 0)
        spdlog::warn(
            "no generation cap (--generations, evolution.generations) and no wall-clock budget "
            "(evolution.wall_seconds): the run stops only after evolution.stall_generations = {} "
            "generations without improvement, hours at the paper's setting (Ctrl-C stops it with "
            "a checkpoint)",
            config.evolution.stall_generations);
    }
    if (mpi_job) {  // [mpi]
      // mpirun closes our output when a rank dies: a hang-up (output on a pty) or a broken pipe
      // must not kill rank 0 before it has said what is on disk.
      std::signal(SIGHUP, on_signal);
      std::signal(SIGPIPE, SIG_IGN);
      options.evaluator = mpi_job->start(config, &g_stop);
      if (!quiet) spdlog::info("evaluation: {}", options.evaluator->describe());
    }
    // Once every check has passed and the directory is locked: a refused command leaves
    // stopped.txt.
    options.on_start = [&options] {
      if (const auto stopped = options.out / "stopped.txt";
          options.resume && std::filesystem::exists(stopped)) {
        std::ifstream in(stopped, std::ios::binary);
        spdlog::warn(
            "the last job in {} ended so:\n{}", options.out.string(),
            std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()));
        std::filesystem::remove(stopped);
      }
    };
    if (config.search.algorithm != "ga") {  // MAP-Elites, NSGA-II (search.hpp)
      animat::SearchSummary found;
      try {
        found = animat::run_search(config, options);
      } catch (const animat::mpi::JobStopped& e) {
        mpi_stopped(e, options.out, config);
      } catch (const animat::mpi::RankFailure& e) {
        mpi_stopped(e, options.out, config);
      }
      std::printf("\nStopped at generation %d: %s\n", found.generation, found.stop_reason.c_str());
      if (!found.history.empty()) {
        std::printf("Last generation:");
        for (std::size_t c = 0; c < found.columns.size(); ++c)
          std::printf(" %s %g", found.columns[c].name.c_str(), found.history.back()[c]);
        std::printf("\n");
      }
      std::printf("Results in %s: config.toml, history.csv, checkpoint.json\n",
                  options.out.c_str());
      std::printf("Resume:     animat_evolve --resume %s --generations N\n", options.out.c_str());
      return found.stop_reason == "interrupted" ? 130 : 0;
    }
    animat::RunSummary summary;
    try {
      summary = animat::run_evolution(config, options);
    } catch (const animat::mpi::JobStopped& e) {  // [mpi] a rank died or the job was cancelled
      mpi_stopped(e, options.out, config);
    } catch (const animat::mpi::RankFailure& e) {
      mpi_stopped(e, options.out, config);
    }
    if (summary.history.empty()) {  // stopped while the initial population was drawn
      std::printf(
          "\nStopped: %s, before the initial population was complete; nothing to resume (run the "
          "same "
          "command again to start over)\n",
          summary.stop_reason.c_str());
      return 130;
    }
    const auto& best = summary.best;
    const std::string& objective = config.evaluation.objective;
    const animat::ObjectiveSpec* spec = animat::find_objective(objective);
    const std::string meaning =
        spec ? std::string(spec->meaning) : "evaluation.objective = " + objective;
    int found = 0;  // the generation that found the best: the last in which the best changed
    for (const auto& row : summary.history)
      if (row.best_changed) found = row.generation;
    std::printf("\nBest swimmer: fitness %.4f (%s), %d cells, found at generation %d of %d\n",
                best.result.fitness, meaning.c_str(), best.result.cell_count, found,
                summary.history.back().generation);
    std::printf("Stopped: %s\n", summary.stop_reason.c_str());
    std::printf(
        "Results in %s: config.toml, history.csv, best/ (lineage of best genomes), "
        "genealogy.csv, checkpoint.json\n",
        options.out.c_str());
    std::printf(
        "View them:  animat show %s   (in a source tree: PYTHONPATH=build/python .venv/bin/python "
        "-m animat show %s)\n",
        options.out.c_str(), options.out.c_str());
    std::printf("Resume:     animat_evolve --resume %s --generations N\n", options.out.c_str());
    return summary.stop_reason == "interrupted" ? 130 : 0;
  } catch (const animat::Error& e) {
    std::fprintf(stderr, "animat_evolve: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "animat_evolve: internal error: %s\n", e.what());
    return 3;
  }
}
