// Where the time of a GA generation goes, and what that means on many cores (docs/performance.md).
//
//   build/bench_ga_profile POPULATION GENERATIONS [SEED]      (embedded default config, 1 thread)
//
// Runs the GA with a profiling evaluator (evaluator.hpp) that times every task one after the other
// (thread CPU time, so a loaded machine does not inflate them):
// an initial individual (its random tries until viable, then its swim) or one offspring's
// evaluation. The rest of a generation is the serial part on rank 0: breeding, bookkeeping, and the
// checkpoint (serialised, written and fsync'ed like run_evolution does; its per-individual part,
// which rank 0 runs on its threads, is timed apart). Then it replays the measured task times
// through the scheduler of each path, task by task in index order to the first free worker:
//   threads  OpenMP schedule(dynamic, 1) on W threads of one process
//   mpi      W workers with the MPI hand-out (mpi_job.cpp), each holding up to 2 tasks, one message
//            round trip of LATENCY per hand-out
// and prints the projected speedup for W = 1..64, with the serial part included. Output: one JSON
// object per line (bench/mpi_scaling.py reads them).
#include <fmt/format.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <numeric>
#include <queue>
#include <string>
#include <vector>

#include "animat/config.hpp"
#include "animat/evaluator.hpp"
#include "animat/evolution.hpp"
#include "animat/run.hpp"
#include "animat/wire.hpp"

using namespace animat;
using Clock = std::chrono::steady_clock;

namespace {

double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// CPU time of the calling thread: task times do not depend on what else runs on a shared machine.
double cpu_now() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

class ProfilingEvaluator final : public Evaluator {
 public:
  explicit ProfilingEvaluator(const Config& c) : fitness_(swim_fitness(c)) {}
  std::vector<Fitness> evaluate(std::span<const Genome* const> genomes,
                                const StopRequest&) override {
    std::vector<Fitness> out;
    for (const Genome* g : genomes) {
      const double t0 = cpu_now();
      out.push_back(fitness_(*g));
      tasks.push_back(cpu_now() - t0);
      viable.push_back(out.back().viable);
      bytes += wire::genome_bytes(*g) + 4;  // genome + task index; the result is 4 + 14 bytes
    }
    return out;
  }
  std::string describe() const override { return "profiling, 1 thread"; }

  std::vector<double> tasks;  // seconds of each task of the current call
  std::vector<bool> viable;
  std::size_t bytes = 0;

 private:
  FitnessFunction fitness_;
};

// Makespan of `tasks` (index order) on `workers`, each taking the next task when free.
double dynamic_makespan(const std::vector<double>& tasks, int workers) {
  std::priority_queue<double, std::vector<double>, std::greater<>> free_at;
  for (int w = 0; w < workers; ++w) free_at.push(0.0);
  double end = 0.0;
  for (double t : tasks) {
    const double start = free_at.top();
    free_at.pop();
    free_at.push(start + t);
    end = std::max(end, start + t);
  }
  return end;
}

// The MPI hand-out: every worker keeps up to `depth` tasks (one running); a finished task is
// reported and a new one arrives one round trip later (while plenty remain it was already queued).
double mpi_makespan(const std::vector<double>& tasks, int workers, double latency) {
  // A worker with a queued task starts it at once; without one it waits `latency`. While more tasks
  // remain than workers, every worker has a queued task; near the end only idle workers get one.
  std::priority_queue<double, std::vector<double>, std::greater<>> free_at;
  for (int w = 0; w < workers; ++w) free_at.push(latency);  // the first hand-out
  double end = 0.0;
  const std::size_t n = tasks.size();
  for (std::size_t i = 0; i < n; ++i) {
    double start = free_at.top();
    free_at.pop();
    const bool queued = n - i > static_cast<std::size_t>(workers);
    if (!queued && i >= static_cast<std::size_t>(workers)) start += latency;
    free_at.push(start + tasks[i]);
    end = std::max(end, start + tasks[i]);
  }
  return end;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s POPULATION GENERATIONS [SEED]\n", argv[0]);
    return 2;
  }
  Config c;
  c.evolution.population = std::atoi(argv[1]);
  const int generations = std::atoi(argv[2]);
  c.evolution.seed = argc > 3 ? std::atoll(argv[3]) : 1;
  c.evolution.threads = 1;
  auto prof = std::make_shared<ProfilingEvaluator>(c);
  Evolution evo(c, {}, {}, prof);
  const std::string ckpt_path = fmt::format("/tmp/bench_ga_profile_{}.json", ::getpid());

  struct Generation {
    std::vector<double> tasks;
    std::vector<bool> viable;
    double serial = 0.0, checkpoint = 0.0, fsync = 0.0, eval = 0.0;
    // the per-individual part of checkpoint(), spread over rank 0's threads
    double checkpoint_parallel = 0.0;
    std::size_t checkpoint_bytes = 0, work_bytes = 0;
  };
  std::vector<Generation> gens;
  for (int g = 0; g <= generations; ++g) {
    prof->tasks.clear();
    prof->viable.clear();
    prof->bytes = 0;
    const double t0 = cpu_now();
    if (g == 0)
      evo.initialize();
    else
      evo.step();
    const double total = cpu_now() - t0;
    Generation G;
    G.tasks = prof->tasks;
    G.viable = prof->viable;
    G.eval = std::accumulate(G.tasks.begin(), G.tasks.end(), 0.0);
    G.serial = total - G.eval;
    G.work_bytes = prof->bytes;
    const double c0 = cpu_now();
    // serialised as run_evolution does, then written and fsync'ed
    const std::string text = evo.checkpoint();
    FILE* f = std::fopen(ckpt_path.c_str(), "wb");
    std::fwrite(text.data(), 1, text.size(), f);
    std::fflush(f);
    G.checkpoint = cpu_now() - c0;
    const auto s0 = Clock::now();
    ::fsync(fileno(f));
    std::fclose(f);
    G.fsync = seconds(Clock::now() - s0);
    const double p0 = cpu_now();  // the same work as checkpoint()'s per-individual loop
    std::size_t items = 0;
    for (const auto& ind : evo.population())
      items += nlohmann::json::parse(to_json(ind.genome)).size();
    if (items == 0) std::fprintf(stderr, "empty genomes?\n");
    G.checkpoint_parallel = std::min(G.checkpoint, cpu_now() - p0);
    G.checkpoint_bytes = text.size();
    gens.push_back(std::move(G));
  }
  std::remove(ckpt_path.c_str());

  for (std::size_t g = 0; g < gens.size(); ++g) {
    const auto& G = gens[g];
    std::vector<double> sorted = G.tasks;
    std::sort(sorted.begin(), sorted.end());
    auto q = [&](double p) {
      return sorted.empty() ? 0.0 : sorted[static_cast<std::size_t>(p * (sorted.size() - 1))];
    };
    std::size_t nv = 0;
    for (bool v : G.viable) nv += v;
    std::printf(
        "{\"kind\": \"generation\", \"population\": %d, \"generation\": %zu, \"tasks\": %zu, "
        "\"viable_tasks\": %zu, "
        "\"eval_s\": %.6f, \"serial_s\": %.6f, \"checkpoint_s\": %.6f, \"checkpoint_parallel_s\": "
        "%.6f, \"fsync_s\": %.6f, \"checkpoint_bytes\": %zu, "
        "\"work_bytes\": %zu, \"task_min_s\": %.6f, \"task_median_s\": %.6f, \"task_p90_s\": %.6f, "
        "\"task_max_s\": %.6f}\n",
        c.evolution.population, g, G.tasks.size(), nv, G.eval, G.serial, G.checkpoint,
        G.checkpoint_parallel, G.fsync, G.checkpoint_bytes, G.work_bytes, q(0.0), q(0.5), q(0.9),
        q(1.0));
  }
  // Projected speedup over one worker of the whole run (seeding + generations), serial part
  // included, with a checkpoint every generation (the default) or every 10th
  // (evolution.checkpoint_every = 10). spread = 0: the whole checkpoint on one thread
  // (as it once was); 1: its per-individual part on rank 0's threads (as now).
  for (int spread : {0, 1})
    for (int every : {1, 10})
      for (const char* path : {"threads", "mpi"}) {
        for (int w : {1, 2, 4, 8, 16, 32, 64}) {
          double t1 = 0.0, tw = 0.0, t_seed1 = 0.0, t_seedw = 0.0;
          for (std::size_t g = 0; g < gens.size(); ++g) {
            const auto& G = gens[g];
            // Rank 0 spreads the per-individual part of the checkpoint over its threads (at most
            // 16: one node).
            const double ckpt = spread ? G.checkpoint - G.checkpoint_parallel +
                                             G.checkpoint_parallel / std::min(w, 16)
                                       : G.checkpoint;
            const double serial = G.serial + (ckpt + G.fsync) / every;
            const double one = G.eval + serial;
            const double many =
                (std::string(path) == "threads" ? dynamic_makespan(G.tasks, w)
                                                : mpi_makespan(G.tasks, w, 100e-6)) +
                serial;
            t1 += one;
            tw += many;
            if (g == 0) {
              t_seed1 = one;
              t_seedw = many;
            }
          }
          std::printf(
              "{\"kind\": \"projection\", \"path\": \"%s\", \"checkpoint_spread\": %d, "
              "\"checkpoint_every\": %d, \"population\": %d, "
              "\"workers\": %d, \"speedup\": %.3f, \"speedup_seeding\": %.3f, \"speedup_later\": "
              "%.3f}\n",
              path, spread, every, c.evolution.population, w, t1 / tw, t_seed1 / t_seedw,
              (t1 - t_seed1) / (tw - t_seedw));
        }
      }
  return 0;
}
