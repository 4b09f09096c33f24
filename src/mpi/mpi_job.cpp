// The MPI evaluator (mpi.hpp). Only the main thread of a process calls MPI (MPI_THREAD_FUNNELED):
// it is OpenMP thread 0 of a team of threads + 1, and polls (MPI_Iprobe, then a short sleep) while
// threads 1..T evaluate. Polling instead of blocking calls keeps an idle rank off the CPU: Open MPI
// busy-waits in a blocking receive, which would take a core from the evaluations.
//
// Protocol (point to point on MPI_COMM_WORLD, every message a byte string, wire.hpp):
//   0 -> r  kConfig  u8 run (0 = no run: exit), string config TOML
//   r -> 0  kHello   u8 ok, i32 threads, string host (or the error)
//   0 -> r  kWork    u8 kind, u32 n, n x (u32 task, genome if kind = evaluate)
//   r -> 0  kResult  u8 kind, u32 n, n x (u32 task, u8 ok, fitness | string error)
//   0 -> r  kStop    (empty): finish, answer kBye
//   r -> 0  kBye     (empty): nothing more comes from this rank
//   0 -> r  kPing    (empty): answer kPong at once (the comm thread answers even while all
//                     threads evaluate)
//
// A lost rank. mpirun ends the whole job when a rank dies: SIGCONT to every rank at once, SIGTERM a
// second later, SIGKILL a second after that; and Open MPI aborts a rank as soon as it hears of the
// failure, so rank 0 cannot count on surviving the SIGTERM. Rank 0 therefore pings every rank as
// soon as it gets a SIGCONT (also sent when a suspended job resumes: then every rank answers and
// nothing happens); a rank that does not answer within kPingAfterSignal is lost, and rank 0 stops
// with a message while it still can. Launchers that do not end the job (srun without
// --kill-on-bad-exit) are covered by a heartbeat: a rank silent for kSilence while it holds work is
// pinged, and lost if it does not answer within kSilence either.
#define OMPI_SKIP_MPICXX 1
#include <fmt/format.h>
#include <mpi.h>
#include <omp.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

#include "animat/config.hpp"
#include "animat/evaluator.hpp"
#include "animat/mpi.hpp"
#include "animat/wire.hpp"

namespace animat::mpi {

bool built_with_mpi() { return true; }

namespace {

enum Tag : int {
  kConfig = 101,
  kHello = 102,
  kWork = 103,
  kResult = 104,
  kStop = 105,
  kBye = 106,
  kPing = 107,
  kPong = 108
};
using Clock = std::chrono::steady_clock;
constexpr auto kPingAfterSignal = std::chrono::milliseconds(400);
constexpr auto kSilence = std::chrono::seconds(20);

std::atomic<unsigned> g_sigcont{0};
extern "C" void on_sigcont(int) { g_sigcont.fetch_add(1); }
// the only task kind (the byte keeps the protocol extensible)
enum class Kind : std::uint8_t { evaluate = 1 };

std::string error_string(int code) {
  char text[MPI_MAX_ERROR_STRING];
  int len = 0;
  if (MPI_Error_string(code, text, &len) != MPI_SUCCESS) return fmt::format("MPI error {}", code);
  return std::string(text, static_cast<std::size_t>(len));
}

void check(int rc, const char* what) {
  if (rc != MPI_SUCCESS) throw RankFailure(fmt::format("{} failed: {}", what, error_string(rc)));
}

// Sleeps 20 us after activity, doubling up to 1 ms while nothing happens.
class Backoff {
 public:
  void reset() { us_ = 20; }
  void wait() {
    std::this_thread::sleep_for(std::chrono::microseconds(us_));
    us_ = std::min(us_ * 2, 1000);
  }

 private:
  int us_ = 20;
};

using Bytes = std::vector<unsigned char>;

// A received message.
struct Message {
  int source = -1, tag = -1;
  Bytes bytes;
};

// Non-blocking probe and receive of the next message from `source` (MPI_ANY_SOURCE for any).
bool poll(int source, Message& m) {
  int flag = 0;
  MPI_Status st;
  check(MPI_Iprobe(source, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &st), "MPI_Iprobe");
  if (!flag) return false;
  int count = 0;
  check(MPI_Get_count(&st, MPI_BYTE, &count), "MPI_Get_count");
  m.source = st.MPI_SOURCE;
  m.tag = st.MPI_TAG;
  m.bytes.resize(static_cast<std::size_t>(count));
  check(MPI_Recv(m.bytes.data(), count, MPI_BYTE, st.MPI_SOURCE, st.MPI_TAG, MPI_COMM_WORLD,
                 MPI_STATUS_IGNORE),
        "MPI_Recv");
  return true;
}

void send(int dest, int tag, const Bytes& bytes) {
  check(MPI_Send(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, dest, tag, MPI_COMM_WORLD),
        "MPI_Send");
}

}  // namespace

struct Job::State {
  int rank = 0, size = 1, local_ranks = 1;
  std::string host;
  bool started = false;       // rank 0: the config went out
  bool broken = false;        // a rank may be gone: never wait for the others again
  unsigned sigcont_seen = 0;  // SIGCONTs already answered by a ping
  // Rank 0
  const std::atomic<bool>* stop = nullptr;
  std::shared_ptr<const Config> config;
  FitnessFunction fitness;
  int threads = 1;                 // this rank's evaluation threads
  std::vector<int> rank_threads;   // every rank's
  std::vector<std::string> hosts;  // every rank's
  // Isends in flight (rank 0 never blocks on a worker) with their buffers.
  std::deque<std::pair<MPI_Request, std::shared_ptr<Bytes>>> sends;

  bool stopping() const { return stop && stop->load(); }

  void isend(int dest, int tag, Bytes bytes) {
    auto buffer = std::make_shared<Bytes>(std::move(bytes));
    MPI_Request req;
    check(MPI_Isend(buffer->data(), static_cast<int>(buffer->size()), MPI_BYTE, dest, tag,
                    MPI_COMM_WORLD, &req),
          "MPI_Isend");
    sends.emplace_back(req, std::move(buffer));
  }
  void progress_sends() {
    while (!sends.empty()) {
      int done = 0;
      check(MPI_Test(&sends.front().first, &done, MPI_STATUS_IGNORE), "MPI_Test");
      if (!done) return;
      sends.pop_front();
    }
  }
  void wait_sends() {
    Backoff backoff;
    while (!sends.empty()) {
      progress_sends();
      if (stopping()) throw JobStopped("stopped by a signal while sending to the other ranks");
      if (!sends.empty()) backoff.wait();
    }
  }

  // Rank 0 at the end: every other rank finishes and says goodbye.
  void shutdown() {
    for (int r = 1; r < size; ++r) isend(r, kStop, {});
    int byes = 0;
    Message m;
    Backoff backoff;
    while (byes < size - 1) {
      if (stopping()) throw JobStopped("stopped by a signal while the other ranks were finishing");
      progress_sends();
      if (poll(MPI_ANY_SOURCE, m)) {
        if (m.tag == kBye) ++byes;  // results of an abandoned evaluation are dropped
        backoff.reset();
      } else {
        backoff.wait();
      }
    }
    wait_sends();
  }

  // Rank 0: runs `count` tasks on every rank; results are stored by the callbacks, by task index.
  struct Tasks {
    Kind kind;
    std::size_t count;
    std::function<void(wire::Writer&, std::size_t)> encode;  // the task's payload for another rank
    std::function<void(std::size_t)> run_local;              // evaluate here and store
    std::function<void(wire::Reader&, std::size_t)> decode;  // store another rank's result
  };
  void run(const Tasks& t);
};

// ---------------------------------------------------------------------------------------------------
void Job::State::run(const Tasks& t) {
  if (broken) throw RankFailure("the MPI job lost a rank earlier; it cannot evaluate any more");
  const std::size_t n = t.count;
  std::mutex mutex;      // guards next
  std::size_t next = 0;  // first task not handed out
  std::atomic<std::size_t> completed{0};
  std::atomic<bool> abort{false};
  std::vector<std::exception_ptr> errors(n);
  std::vector<std::size_t> outstanding(static_cast<std::size_t>(size), 0);
  int total_threads = 0;
  for (int th : rank_threads) total_threads += th;
  std::exception_ptr comm_error;
  bool interrupted = false;
  const Clock::time_point began = Clock::now();
  // last message from each rank
  std::vector<Clock::time_point> heard(static_cast<std::size_t>(size), began);
  // pong deadline
  std::vector<Clock::time_point> ping_due(static_cast<std::size_t>(size), Clock::time_point::max());
  auto ping = [&](int r, Clock::duration within) {
    auto& due = ping_due[static_cast<std::size_t>(r)];
    if (due != Clock::time_point::max()) return;  // one ping at a time
    isend(r, kPing, {});
    due = Clock::now() + within;
  };
  auto check_alive = [&]() {
    const auto now = Clock::now();
    if (const unsigned c = g_sigcont.load(); c != sigcont_seen) {
      // maybe mpirun is ending the job (also between calls)
      sigcont_seen = c;
      for (int r = 1; r < size; ++r) ping(r, kPingAfterSignal);
    }
    for (int r = 1; r < size; ++r) {
      const auto ru = static_cast<std::size_t>(r);
      if (outstanding[ru] > 0 && now - heard[ru] > kSilence) ping(r, kSilence);
      if (now > ping_due[ru])
        throw RankFailure(fmt::format(
            "rank {} ({}) stopped answering ({:.1f} s without a sign of life): it died or "
            "hangs",
            r, hosts[ru], std::chrono::duration<double>(now - heard[ru]).count()));
    }
  };

  auto take = [&](std::size_t want, std::size_t& first) {
    std::lock_guard<std::mutex> lock(mutex);
    first = next;
    const std::size_t got = std::min(want, n - next);
    next += got;
    return got;
  };
  auto run_one_local = [&]() {
    std::size_t i = 0;
    if (take(1, i) == 0) return false;
    try {
      t.run_local(i);
    } catch (...) {
      errors[i] = std::current_exception();
    }
    completed.fetch_add(1);
    return true;
  };
  // A rank gets as many tasks as it has threads, and as many again while plenty remain, so that a
  // thread never waits for a round trip; near the end only idle threads get work (a short tail).
  auto refill = [&](int r) {
    std::size_t remaining;
    {
      std::lock_guard<std::mutex> lock(mutex);
      remaining = n - next;
    }
    const auto th = static_cast<std::size_t>(rank_threads[static_cast<std::size_t>(r)]);
    const std::size_t target = th + (remaining > static_cast<std::size_t>(total_threads) ? th : 0);
    if (outstanding[static_cast<std::size_t>(r)] >= target) return;
    std::size_t first = 0;
    const std::size_t got = take(target - outstanding[static_cast<std::size_t>(r)], first);
    if (got == 0) return;
    wire::Writer w;
    w.put(static_cast<std::uint8_t>(t.kind));
    w.put(static_cast<std::uint32_t>(got));
    for (std::size_t i = first; i < first + got; ++i) {
      w.put(static_cast<std::uint32_t>(i));
      t.encode(w, i);
    }
    isend(r, kWork, w.take());
    outstanding[static_cast<std::size_t>(r)] += got;
  };

  prepare_parallel_evaluation();
#pragma omp parallel num_threads(threads + 1)
  {
    if (omp_get_thread_num() == 0) {
      // no evaluation thread: evaluate between polls
      const bool alone = omp_get_num_threads() == 1;
      try {
        for (int r = 1; r < size; ++r) refill(r);
        Backoff backoff;
        Message m;
        while (completed.load() < n) {
          bool active = false;
          progress_sends();
          while (poll(MPI_ANY_SOURCE, m)) {
            active = true;
            heard[static_cast<std::size_t>(m.source)] = Clock::now();
            if (m.tag == kPong) {
              ping_due[static_cast<std::size_t>(m.source)] = Clock::time_point::max();
              continue;
            }
            if (m.tag != kResult)
              throw RankFailure(
                  fmt::format("rank {} sent message tag {} during an evaluation", m.source, m.tag));
            wire::Reader rd(m.bytes);
            if (rd.get<std::uint8_t>() != static_cast<std::uint8_t>(t.kind))
              throw RankFailure(fmt::format("rank {} answered a different kind of task", m.source));
            const auto k = rd.get<std::uint32_t>();
            for (std::uint32_t j = 0; j < k; ++j) {
              const auto i = rd.get<std::uint32_t>();
              if (i >= n)
                throw RankFailure(fmt::format("rank {} answered task {} of {}", m.source, i, n));
              if (rd.get<std::uint8_t>()) {
                t.decode(rd, i);
              } else {
                const std::string what = rd.string();
                errors[i] = std::make_exception_ptr(
                    Error(fmt::format("rank {} ({}): {}", m.source,
                                      hosts[static_cast<std::size_t>(m.source)], what)));
              }
            }
            auto& out = outstanding[static_cast<std::size_t>(m.source)];
            if (k > out)
              throw RankFailure(
                  fmt::format("rank {} answered more tasks than it was given", m.source));
            out -= k;
            completed.fetch_add(k);
            refill(m.source);
          }
          if (stopping()) {
            interrupted = true;
            break;
          }
          check_alive();
          if (alone && run_one_local()) active = true;
          if (active)
            backoff.reset();
          else
            backoff.wait();
        }
      } catch (...) {
        comm_error = std::current_exception();
      }
      abort.store(true);
    } else {
      while (!abort.load() && run_one_local()) {
      }
    }
  }
  if (interrupted) {
    broken = true;
    throw JobStopped(fmt::format(
        "stopped by a signal during an evaluation on {} ranks ({} of {} tasks done); under "
        "mpirun this means that a rank died (see mpirun's message above) or that the job "
        "was cancelled",
        size, completed.load(), n));
  }
  if (comm_error) {
    broken = true;
    std::rethrow_exception(comm_error);
  }
  wait_sends();
  for (auto& e : errors)
    if (e) std::rethrow_exception(e);
}

// ---------------------------------------------------------------------------------------------------
namespace {

class MpiEvaluator final : public Evaluator {
 public:
  explicit MpiEvaluator(std::shared_ptr<Job::State> state) : state_(std::move(state)) {}

  // The job honours its own stop flag (Job::start), which the CLI sets from the same signal.
  std::vector<Fitness> evaluate(std::span<const Genome* const> genomes,
                                const StopRequest&) override {
    std::vector<Fitness> out(genomes.size());
    Job::State::Tasks t{Kind::evaluate, genomes.size(),
                        [&](wire::Writer& w, std::size_t i) { w.genome(*genomes[i]); },
                        [&](std::size_t i) { out[i] = state_->fitness(*genomes[i]); },
                        [&](wire::Reader& r, std::size_t i) { out[i] = r.fitness(); }};
    state_->run(t);
    return out;
  }

  std::string describe() const override {
    int total = 0;
    for (int th : state_->rank_threads) total += th;
    std::vector<std::string> hosts = state_->hosts;
    std::sort(hosts.begin(), hosts.end());
    hosts.erase(std::unique(hosts.begin(), hosts.end()), hosts.end());
    return fmt::format("MPI, {} rank{} on {} host{}, {} evaluation threads ({} on rank 0)",
                       state_->size, state_->size == 1 ? "" : "s", hosts.size(),
                       hosts.size() == 1 ? "" : "s", total, state_->threads);
  }

 private:
  std::shared_ptr<Job::State> state_;
};

// A worker (rank > 0): evaluates what rank 0 hands out until it says stop.
struct Task {
  Kind kind;
  std::uint32_t index;
  Genome genome;
};

struct Done {
  Kind kind;
  std::uint32_t index;
  bool ok;
  std::string error;
  Fitness result;
};

void serve_tasks(const FitnessFunction& fitness, int threads) {
  std::mutex mutex;
  std::condition_variable ready;
  std::deque<Task> queue;
  std::vector<Done> done;
  bool quit = false;
  prepare_parallel_evaluation();

  auto compute = [&](Task& task) {
    Done d{task.kind, task.index, true, {}, {}};
    try {
      d.result = fitness(task.genome);
    } catch (const std::exception& e) {
      d.ok = false;
      d.error = e.what();
    }
    std::lock_guard<std::mutex> lock(mutex);
    done.push_back(std::move(d));
  };
  std::exception_ptr comm_error;

#pragma omp parallel num_threads(threads + 1)
  {
    if (omp_get_thread_num() == 0) {
      const bool alone = omp_get_num_threads() == 1;
      try {
        Backoff backoff;
        Message m;
        bool stop = false;
        while (!stop) {
          bool active = false;
          while (!stop && poll(0, m)) {
            active = true;
            if (m.tag == kStop) {
              stop = true;
              break;
            }
            if (m.tag == kPing) {
              send(0, kPong, {});
              continue;
            }
            if (m.tag != kWork)
              throw RankFailure(fmt::format("unexpected message tag {} from rank 0", m.tag));
            wire::Reader rd(m.bytes);
            const auto kind = rd.get<std::uint8_t>();
            if (kind != static_cast<std::uint8_t>(Kind::evaluate))
              throw RankFailure(fmt::format("unexpected task kind {} from rank 0", kind));
            const auto k = rd.get<std::uint32_t>();
            std::vector<Task> tasks;
            for (std::uint32_t j = 0; j < k; ++j) {
              Task task{Kind::evaluate, rd.get<std::uint32_t>(), {}};
              task.genome = rd.genome();
              tasks.push_back(std::move(task));
            }
            {
              std::lock_guard<std::mutex> lock(mutex);
              for (auto& task : tasks) queue.push_back(std::move(task));
            }
            ready.notify_all();
          }
          std::vector<Done> finished;
          {
            std::lock_guard<std::mutex> lock(mutex);
            finished.swap(done);
          }
          if (!finished.empty() && !stop) {  // one evaluation call at a time: one kind
            const Kind kind = finished.front().kind;
            wire::Writer w;
            w.put(static_cast<std::uint8_t>(kind));
            w.put(static_cast<std::uint32_t>(finished.size()));
            for (const Done& d : finished) {
              w.put(d.index);
              w.put(static_cast<std::uint8_t>(d.ok));
              if (!d.ok) {
                w.string(d.error);
              } else {
                w.fitness(d.result);
              }
            }
            send(0, kResult, w.take());
            active = true;
          }
          if (alone && !stop) {
            std::unique_lock<std::mutex> lock(mutex);
            if (!queue.empty()) {
              Task task = std::move(queue.front());
              queue.pop_front();
              lock.unlock();
              compute(task);
              active = true;
            }
          }
          if (active)
            backoff.reset();
          else
            backoff.wait();
        }
      } catch (...) {
        comm_error = std::current_exception();
      }
      {
        std::lock_guard<std::mutex> lock(mutex);
        quit = true;
      }
      ready.notify_all();
    } else {
      while (true) {
        std::unique_lock<std::mutex> lock(mutex);
        ready.wait(lock, [&] { return quit || !queue.empty(); });
        if (quit) break;
        Task task = std::move(queue.front());
        queue.pop_front();
        lock.unlock();
        compute(task);
      }
    }
  }
  if (comm_error) std::rethrow_exception(comm_error);
}

}  // namespace

// ---------------------------------------------------------------------------------------------------
Job::Job(int& argc, char**& argv) : state_(std::make_shared<State>()) {
  int provided = 0;
  if (MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS)
    throw Error("MPI_Init_thread failed: this process could not join the MPI job");
  // errors become RankFailure with a message
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  MPI_Comm_rank(MPI_COMM_WORLD, &state_->rank);
  MPI_Comm_size(MPI_COMM_WORLD, &state_->size);
  MPI_Comm node;
  if (MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node) ==
      MPI_SUCCESS) {
    MPI_Comm_size(node, &state_->local_ranks);
    MPI_Comm_free(&node);
  }
  char name[MPI_MAX_PROCESSOR_NAME];
  int len = 0;
  MPI_Get_processor_name(name, &len);
  state_->host.assign(name, static_cast<std::size_t>(len));
}

Job::~Job() {
  State& s = *state_;
  try {
    if (s.rank == 0 && !s.broken && !s.stopping()) {
      if (s.started) {
        s.shutdown();
      } else {  // no run (an error, --print-config): release the waiting ranks
        wire::Writer w;
        w.put(static_cast<std::uint8_t>(0));
        w.string("");
        const Bytes b = w.take();
        for (int r = 1; r < s.size; ++r) s.isend(r, kConfig, b);
        s.wait_sends();
      }
    }
  } catch (const std::exception& e) {
    s.broken = true;
    std::fprintf(stderr, "animat_evolve (rank 0): %s\n", e.what());
  }
  // a rank may be gone: MPI_Finalize could wait for it forever
  if (s.broken || s.stopping()) return;
  MPI_Finalize();
}

int Job::rank() const { return state_->rank; }
int Job::size() const { return state_->size; }

void Job::abandon(int status) {
  std::fflush(stdout);
  std::fflush(stderr);
  std::_Exit(status);
}

std::shared_ptr<Evaluator> Job::start(const Config& config, const std::atomic<bool>* stop) {
  State& s = *state_;
  if (s.rank != 0) throw Error("Job::start: only rank 0 runs the GA");
  s.stop = stop;
  s.sigcont_seen = g_sigcont.load();
  std::signal(SIGCONT, on_sigcont);  // see "A lost rank" above
  s.config = std::make_shared<const Config>(config);
  s.fitness = swim_fitness(config);
  s.threads = threads_per_rank(config.evolution.threads, s.local_ranks);
  s.rank_threads.assign(static_cast<std::size_t>(s.size), s.threads);
  s.hosts.assign(static_cast<std::size_t>(s.size), s.host);
  wire::Writer w;
  w.put(static_cast<std::uint8_t>(1));
  w.string(to_toml(config));
  const Bytes b = w.take();
  for (int r = 1; r < s.size; ++r) s.isend(r, kConfig, b);
  s.started = true;
  s.wait_sends();
  int hellos = 0;
  Message m;
  Backoff backoff;
  while (hellos < s.size - 1) {
    if (s.stopping()) {
      s.broken = true;
      throw JobStopped("stopped by a signal while the ranks were starting");
    }
    if (!poll(MPI_ANY_SOURCE, m)) {
      backoff.wait();
      continue;
    }
    if (m.tag != kHello)
      throw RankFailure(
          fmt::format("rank {} sent message tag {} instead of its hello", m.source, m.tag));
    wire::Reader rd(m.bytes);
    const bool ok = rd.get<std::uint8_t>() != 0;
    const int threads = rd.get<std::int32_t>();
    const std::string text = rd.string();
    if (!ok) throw Error(fmt::format("rank {} could not start: {}", m.source, text));
    s.rank_threads[static_cast<std::size_t>(m.source)] = std::max(1, threads);
    s.hosts[static_cast<std::size_t>(m.source)] = text;
    ++hellos;
  }
  return std::make_shared<MpiEvaluator>(state_);
}

int Job::serve() {
  State& s = *state_;
  if (s.rank == 0) throw Error("Job::serve: rank 0 runs the GA");
  s.broken = true;  // until the goodbye: an error leaves without MPI_Finalize
  Message m;
  Backoff backoff;
  while (!poll(0, m)) backoff.wait();
  if (m.tag != kConfig)
    throw RankFailure(fmt::format("rank 0 sent message tag {} instead of the config", m.tag));
  wire::Reader rd(m.bytes);
  if (rd.get<std::uint8_t>() == 0) {  // rank 0 ended without a run
    s.broken = false;
    return 0;
  }
  const std::string toml = rd.string();
  Config config;
  FitnessFunction fitness;
  int threads = 1;
  std::string error;
  try {
    config = config_from_toml(toml, "the config from rank 0");
    threads = threads_per_rank(config.evolution.threads, s.local_ranks);
    fitness = swim_fitness(config);
  } catch (const std::exception& e) {
    error = e.what();
  }
  wire::Writer w;
  w.put(static_cast<std::uint8_t>(error.empty()));
  w.put(static_cast<std::int32_t>(threads));
  w.string(error.empty() ? s.host : error);
  send(0, kHello, w.take());
  if (!error.empty()) throw Error(error);
  serve_tasks(fitness, threads);
  send(0, kBye, {});
  s.broken = false;
  return 0;
}

}  // namespace animat::mpi
