#include "animat/evolution.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <omp.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <limits>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <numeric>
#include <sstream>
#include <unordered_map>

#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/evaluator.hpp"
#include "animat/islands.hpp"
#include "animat/physics.hpp"
#include "json_util.hpp"

namespace animat {

using nlohmann::json;

namespace {

constexpr int kCheckpointVersion = 1;

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::uint64_t fnv1a(std::string_view s) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : s) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  return h;
}

std::string hex(std::uint64_t x) { return fmt::format("{:016x}", x); }

int thread_count(int requested) { return requested > 0 ? requested : omp_get_num_procs(); }

// Runs body(i) for i in [0, n) in parallel; rethrows the first exception (by index) afterwards.
template <class Body>
void parallel_for(std::size_t n, int threads, Body&& body) {
  std::vector<std::exception_ptr> errors(n);
#pragma omp parallel for schedule(dynamic, 1) num_threads(thread_count(threads))
  for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(n); ++i) {
    try {
      body(static_cast<std::size_t>(i));
    } catch (...) {
      errors[static_cast<std::size_t>(i)] = std::current_exception();
    }
  }
  for (auto& e : errors)
    if (e) std::rethrow_exception(e);
}

bool fitter(const Individual& a, const Individual& b) {
  if (a.result.viable != b.result.viable) return a.result.viable;
  return a.result.fitness > b.result.fitness;
}

}  // namespace

double tournament_probability(const EvolutionParams& p, int generation) {
  if (p.tournament_ramp_generations <= 0) return p.tournament_p_end;
  const double t = std::clamp(static_cast<double>(generation) / p.tournament_ramp_generations, 0.0, 1.0);
  return p.tournament_p_start + (p.tournament_p_end - p.tournament_p_start) * t;
}

std::size_t tournament(const std::vector<Individual>& pop, const std::vector<std::size_t>& eligible, double p_fitter,
                       Rng& rng) {
  if (eligible.empty()) throw Error("tournament: no eligible individual");
  if (eligible.size() == 1) return eligible[0];
  const std::size_t a = eligible[rng.below(eligible.size())];
  std::size_t b = eligible[rng.below(eligible.size() - 1)];
  if (b == a) b = eligible.back();  // two distinct individuals, uniformly
  const bool a_fitter = fitter(pop[a], pop[b]) || (!fitter(pop[b], pop[a]) && a < b);
  const std::size_t winner = a_fitter ? a : b, loser = a_fitter ? b : a;
  return rng.bernoulli(p_fitter) ? winner : loser;
}

void prepare_parallel_evaluation() { warm_up_box2d(); }

std::vector<Fitness> evaluate_all(const std::vector<Genome>& genomes, const FitnessFunction& fitness, int threads) {
  prepare_parallel_evaluation();
  std::vector<Fitness> out(genomes.size());
  parallel_for(genomes.size(), threads, [&](std::size_t i) { out[i] = fitness(genomes[i]); });
  return out;
}

std::uint64_t run_identity(const Config& config) {
  Config c = config;
  const EvolutionParams defaults;
  c.evolution.generations = defaults.generations;
  c.evolution.stall_generations = defaults.stall_generations;
  c.evolution.wall_seconds = defaults.wall_seconds;
  c.evolution.threads = defaults.threads;
  c.evolution.checkpoint_every = defaults.checkpoint_every;
  // [islands] Without islands the island keys change nothing: hash the config without their lines
  // (each key with its comment line), so runs checkpointed before islands existed resume.
  if (c.evolution.islands <= 1) {
    std::string text = to_toml(c);
    const auto key = text.find("\nislands = ");
    const auto last = text.find("\nmigrants = ", key == std::string::npos ? 0 : key);
    if (key != std::string::npos && last != std::string::npos) {
      const auto begin = text.rfind('\n', key - 1) + 1;  // the comment line of `islands`
      const auto end = text.find('\n', last + 1);       // the end of the `migrants` line
      text.erase(begin, end == std::string::npos ? std::string::npos : end + 1 - begin);
      return fnv1a(text);
    }
  }
  return config_hash(c);
}

// ---------------------------------------------------------------------------------------------------
Evolution::Evolution(const Config& config, FitnessFunction fitness, std::shared_ptr<Evaluator> evaluator)
    : config_(std::make_shared<const Config>(config)), identity_(run_identity(config)), fitness_(std::move(fitness)),
      evaluator_(std::move(evaluator)), started_(now_seconds()) {
  validate(*config_);
  if (!evaluator_) {
    if (!fitness_) throw Error("Evolution: no fitness function");
    evaluator_ = make_local_evaluator(*config_, fitness_);
  }
}

void Evolution::initialize() {
  const EvolutionParams& ep = config_->evolution;
  population_ = evaluator_->seed(0, static_cast<std::size_t>(ep.population));  // seed_individual(i) for every i
  for (const auto& ind : population_) evaluations_ += ind.tries;
  generation_ = 0;
  best_ever_ = best().result.fitness;
  stall_ = 0;
  history_.push_back(statistics(true, wall_offset_ + now_seconds() - started_));
}

const Individual& Evolution::best() const {
  if (population_.empty()) throw Error("Evolution::best: the population is empty (call initialize first)");
  // The first of the fittest, by index: ties resolve the same way on every machine.
  return *std::min_element(population_.begin(), population_.end(),
                           [](const Individual& a, const Individual& b) { return fitter(a, b); });
}

std::vector<int> Evolution::initial_tries() const {
  std::vector<int> out;
  for (const auto& ind : population_) out.push_back(ind.tries);
  return out;
}

GenerationStats Evolution::step() {
  if (generation_ < 0) throw Error("Evolution::step: call initialize() first");
  const EvolutionParams& ep = config_->evolution;
  const int g = generation_ + 1;
  const std::size_t n = population_.size();

  // [islands] Selection and elitism act within each island; one island is the paper's population.
  const IslandLayout layout = island_layout(n, ep.islands);
  std::vector<std::vector<std::size_t>> eligible(layout.count());
  std::vector<std::size_t> copied(layout.count(), 0);
  std::vector<Individual> next(n);
  std::vector<bool> needs_eval(n, false);
  for (std::size_t isl = 0; isl < layout.count(); ++isl) {
    const std::vector<std::size_t> order = island_ranking(population_, layout, isl);
    for (std::size_t i = layout.begin(isl); i < layout.end(isl); ++i)
      if (population_[i].result.viable) eligible[isl].push_back(i);
    if (eligible[isl].empty()) {  // nobody viable (possible only without elites): fall back to everyone
      eligible[isl].resize(layout.size(isl));
      std::iota(eligible[isl].begin(), eligible[isl].end(), layout.begin(isl));
    }
    const std::size_t elites = std::min<std::size_t>(static_cast<std::size_t>(ep.elites), order.size());
    for (std::size_t k = 0; k < order.size() && copied[isl] < elites; ++k) {
      if (!population_[order[k]].result.viable) break;
      Individual& elite = next[layout.begin(isl) + copied[isl]++];
      elite = population_[order[k]];
      elite.tries = 0;
    }
  }
  const double p = tournament_probability(ep, g);
  int crossovers = 0;
  // Previous genomes by hash: an unchanged offspring keeps its parent's fitness (never evaluated twice).
  std::unordered_multimap<std::uint64_t, std::size_t> known;
  for (std::size_t i = 0; i < n; ++i) known.emplace(genome_hash(population_[i].genome), i);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t isl = layout.island_of(i);        // [islands]
    if (i < layout.begin(isl) + copied[isl]) continue;  // an elite
    Rng rng = Rng::derive(static_cast<std::uint64_t>(ep.seed), static_cast<std::uint64_t>(g), i);
    Individual& child = next[i];
    if (rng.bernoulli(ep.crossover_fraction)) {
      const std::size_t a = tournament(population_, eligible[isl], p, rng);
      const std::size_t b = tournament(population_, eligible[isl], p, rng);
      ++crossovers;
      child.genome = crossover(population_[a].genome, population_[b].genome, config_->mutation.crossover_points, rng);
    } else {
      child.genome = population_[tournament(population_, eligible[isl], p, rng)].genome;
    }
    mutate(child.genome, config_->mutation, config_->genome, rng);
    needs_eval[i] = true;
    auto [lo, hi] = known.equal_range(genome_hash(child.genome));
    for (auto it = lo; it != hi; ++it)
      if (population_[it->second].genome == child.genome) {
        child.result = population_[it->second].result;
        needs_eval[i] = false;
        break;
      }
  }
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < n; ++i)
    if (needs_eval[i]) todo.push_back(i);
  std::vector<const Genome*> genomes;  // evaluated by the evaluator: this process's threads or MPI ranks
  for (std::size_t i : todo) genomes.push_back(&next[i].genome);
  const std::vector<Fitness> results = evaluator_->evaluate(genomes);
  for (std::size_t k = 0; k < todo.size(); ++k) next[todo[k]].result = results[k];
  evaluations_ += static_cast<std::int64_t>(todo.size());

  const Genome previous_best = best().genome;
  population_ = std::move(next);
  generation_ = g;
  migrations_.clear();  // [islands] copies of evaluated individuals: nothing to evaluate
  if (is_migration_generation(ep, g)) migrations_ = migrate(population_, layout, ep.migrants, g);
  const Individual& b = best();
  if (b.result.fitness > best_ever_) {
    best_ever_ = b.result.fitness;
    stall_ = 0;
  } else {
    ++stall_;
  }
  history_.push_back(statistics(!(b.genome == previous_best), wall_offset_ + now_seconds() - started_));
  history_.back().crossovers = crossovers;
  return history_.back();
}

GenerationStats Evolution::statistics(bool best_changed, double wall) const {
  GenerationStats s;
  s.generation = generation_;
  std::vector<double> viable;
  for (const auto& ind : population_)
    if (ind.result.viable) viable.push_back(ind.result.fitness);
  const Individual& b = best();
  s.best = b.result.fitness;
  s.best_cells = b.result.cell_count;
  s.viable_fraction = static_cast<double>(viable.size()) / static_cast<double>(population_.size());
  if (!viable.empty()) {
    s.mean = std::accumulate(viable.begin(), viable.end(), 0.0) / static_cast<double>(viable.size());
    std::sort(viable.begin(), viable.end());
    const std::size_t m = viable.size() / 2;
    s.median = viable.size() % 2 ? viable[m] : 0.5 * (viable[m - 1] + viable[m]);
  }
  s.evaluations = evaluations_;
  s.wall_seconds = wall;
  s.evaluations_per_second = wall > 0 ? static_cast<double>(evaluations_) / wall : 0.0;
  s.best_changed = best_changed;
  return s;
}

std::string Evolution::stop_reason() const {
  const EvolutionParams& ep = config_->evolution;
  if (generation_ < 0) return {};
  if (ep.generations > 0 && generation_ >= ep.generations)
    return fmt::format("generation cap evolution.generations = {} reached", ep.generations);
  if (ep.stall_generations > 0 && stall_ >= ep.stall_generations)
    return fmt::format("no improvement for evolution.stall_generations = {} generations", ep.stall_generations);
  if (ep.wall_seconds > 0 && wall_offset_ + now_seconds() - started_ >= ep.wall_seconds)
    return fmt::format("wall-clock budget evolution.wall_seconds = {} s used", ep.wall_seconds);
  return {};
}

// ---------------------------------------------------------------------------------------------------
// Checkpoints
namespace {

json stats_to_json(const GenerationStats& s) {
  return json{{"generation", s.generation}, {"best", s.best}, {"mean", s.mean}, {"median", s.median},
              {"viable_fraction", s.viable_fraction}, {"best_cells", s.best_cells}, {"evaluations", s.evaluations},
              {"wall_seconds", s.wall_seconds}, {"best_changed", s.best_changed}};
}

// Integer and number fields of a checkpoint: type- and range-checked, never converted out of range.
long long int_field(const json& j, const char* key, long long lo, long long hi) {
  const auto v = detail::int_in(j.at(key), lo, hi);
  if (!v) throw CheckpointError(fmt::format("field \"{}\" is {}, expected an integer in [{}, {}]", key, detail::describe(j.at(key)), lo, hi));
  return *v;
}

double number_field(const json& j, const char* key) {
  const auto v = detail::finite_number(j.at(key));
  if (!v) throw CheckpointError(fmt::format("field \"{}\" is {}, expected a finite number", key, detail::describe(j.at(key))));
  return *v;
}

bool bool_field(const json& j, const char* key) {
  if (!j.at(key).is_boolean()) throw CheckpointError(fmt::format("field \"{}\" is {}, expected true or false", key, detail::describe(j.at(key))));
  return j.at(key).get<bool>();
}

constexpr long long kIntMax = std::numeric_limits<int>::max();
constexpr long long kInt64Max = std::numeric_limits<std::int64_t>::max();

GenerationStats stats_from_json(const json& j) {
  GenerationStats s;
  s.generation = static_cast<int>(int_field(j, "generation", 0, kIntMax));
  s.best = number_field(j, "best");
  s.mean = number_field(j, "mean");
  s.median = number_field(j, "median");
  s.viable_fraction = number_field(j, "viable_fraction");
  s.best_cells = static_cast<int>(int_field(j, "best_cells", 0, kIntMax));
  s.evaluations = int_field(j, "evaluations", 0, kInt64Max);
  s.wall_seconds = number_field(j, "wall_seconds");
  s.best_changed = bool_field(j, "best_changed");
  s.evaluations_per_second = s.wall_seconds > 0 ? static_cast<double>(s.evaluations) / s.wall_seconds : 0.0;
  return s;
}

}  // namespace

std::string Evolution::checkpoint() const {
  json payload;
  payload["format"] = "animat.checkpoint";
  payload["version"] = kCheckpointVersion;
  payload["identity"] = hex(identity_);
  payload["generation"] = generation_;
  payload["stall"] = stall_;
  payload["best_ever"] = best_ever_;
  payload["evaluations"] = evaluations_;
  payload["wall_seconds"] = history_.empty() ? 0.0 : history_.back().wall_seconds;
  // The individuals are serialised on the evaluation threads: on many cores the checkpoint is most of
  // the serial part of a generation, and two thirds of it is this loop (docs/performance.md, issue 20).
  std::vector<json> individuals(population_.size());
#pragma omp parallel for schedule(static) num_threads(thread_count(config_->evolution.threads))
  for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(population_.size()); ++i) {
    const Individual& ind = population_[static_cast<std::size_t>(i)];
    individuals[static_cast<std::size_t>(i)] = json{{"genome", json::parse(to_json(ind.genome))},
                                                    {"fitness", ind.result.fitness},
                                                    {"viable", ind.result.viable},
                                                    {"stable", ind.result.stable},
                                                    {"cell_count", ind.result.cell_count},
                                                    {"tries", ind.tries}};
  }
  json pop = json::array();
  for (auto& j : individuals) pop.push_back(std::move(j));
  payload["population"] = std::move(pop);
  json hist = json::array();
  for (const auto& s : history_) hist.push_back(stats_to_json(s));
  payload["history"] = std::move(hist);
  const std::string body = payload.dump();
  return json{{"checksum", hex(fnv1a(body))}, {"payload", body}}.dump();
}

void Evolution::restore(std::string_view text, std::string_view source) {
  json outer;
  try {
    outer = detail::parse_bounded(text, 64);
  } catch (const detail::JsonLimit& e) {
    throw CheckpointError(fmt::format("{}: not an animat checkpoint ({})", source, e.what()));
  } catch (const json::parse_error& e) {
    throw CheckpointError(fmt::format("{}: corrupt checkpoint (not valid JSON at byte {}; truncated?)", source, e.byte));
  } catch (const json::exception& e) {
    throw CheckpointError(fmt::format("{}: corrupt checkpoint ({})", source, e.what()));
  }
  try {
    if (!outer.is_object() || !outer.contains("checksum") || !outer.contains("payload") || !outer["payload"].is_string())
      throw CheckpointError(fmt::format("{}: not an animat checkpoint (missing checksum/payload)", source));
    const std::string body = outer["payload"].get<std::string>();
    if (outer["checksum"] != hex(fnv1a(body)))
      throw CheckpointError(fmt::format("{}: corrupt checkpoint: checksum {} does not match its content ({})", source,
                                        detail::describe(outer["checksum"]), hex(fnv1a(body))));
    const json p = detail::parse_bounded(body, 64);
    if (p.value("format", "") != "animat.checkpoint")
      throw CheckpointError(fmt::format("{}: not an animat checkpoint (format {})", source, p.value("format", "?")));
    if (!detail::int_in(p.at("version"), kCheckpointVersion, kCheckpointVersion))
      throw CheckpointError(fmt::format("{}: checkpoint version {} is not supported (this build reads version {})", source,
                                        detail::describe(p.at("version")), kCheckpointVersion));
    if (!p.at("identity").is_string()) throw CheckpointError(fmt::format("{}: field \"identity\" must be a string", source));
    if (p.at("identity").get<std::string>() != hex(identity_))
      throw CheckpointError(fmt::format(
          "{}: checkpoint belongs to a different run configuration (identity {} vs {} for the current config); "
          "only evolution.generations, stall_generations, wall_seconds, threads and checkpoint_every may change on resume",
          source, p.at("identity").get<std::string>(), hex(identity_)));
    std::vector<Individual> pop;
    for (const json& ji : p.at("population")) {
      Individual ind;
      ind.genome = genome_from_json(ji.at("genome").dump(), config_->genome, source);
      ind.result.fitness = number_field(ji, "fitness");
      ind.result.viable = bool_field(ji, "viable");
      ind.result.stable = bool_field(ji, "stable");
      ind.result.cell_count = static_cast<int>(int_field(ji, "cell_count", 0, kIntMax));
      ind.tries = static_cast<int>(int_field(ji, "tries", 0, kIntMax));
      pop.push_back(std::move(ind));
    }
    if (pop.size() != static_cast<std::size_t>(config_->evolution.population))
      throw CheckpointError(fmt::format("{}: checkpoint holds {} individuals, evolution.population is {}", source, pop.size(),
                                        config_->evolution.population));
    std::vector<GenerationStats> hist;
    for (const json& js : p.at("history")) hist.push_back(stats_from_json(js));
    const int generation = static_cast<int>(int_field(p, "generation", 0, kIntMax));
    if (hist.empty()) throw CheckpointError(fmt::format("{}: checkpoint has an empty history", source));
    if (hist.back().generation != generation)
      throw CheckpointError(fmt::format("{}: checkpoint generation {} does not match its history, which ends at generation {}",
                                        source, generation, hist.back().generation));
    population_ = std::move(pop);
    history_ = std::move(hist);
    generation_ = generation;
    stall_ = static_cast<int>(int_field(p, "stall", 0, kIntMax));
    best_ever_ = number_field(p, "best_ever");
    evaluations_ = int_field(p, "evaluations", 0, kInt64Max);
    wall_offset_ = number_field(p, "wall_seconds");
    started_ = now_seconds();
  } catch (const CheckpointError& e) {
    if (std::string_view(e.what()).starts_with(source)) throw;
    throw CheckpointError(fmt::format("{}: malformed checkpoint: {}", source, e.what()));
  } catch (const json::exception& e) {
    throw CheckpointError(fmt::format("{}: malformed checkpoint: {}", source, e.what()));
  } catch (const detail::JsonLimit& e) {
    throw CheckpointError(fmt::format("{}: malformed checkpoint: {}", source, e.what()));
  }
}

// ---------------------------------------------------------------------------------------------------
// Run directory
namespace {

// Writes via a temporary file, fsync and rename: the target is either the old or the new file.
void write_atomically(const std::filesystem::path& path, std::string_view content) {
  const std::filesystem::path tmp = path.string() + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw IoError(fmt::format("{}: cannot write: {}", tmp.string(), std::strerror(errno)));
  std::size_t done = 0;
  while (done < content.size()) {
    const ssize_t w = ::write(fd, content.data() + done, content.size() - done);
    if (w < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      ::unlink(tmp.c_str());
      throw IoError(fmt::format("{}: write failed: {}", tmp.string(), std::strerror(err)));
    }
    done += static_cast<std::size_t>(w);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw IoError(fmt::format("{}: flush failed: {}", tmp.string(), std::strerror(err)));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw IoError(fmt::format("{}: rename failed: {}", path.string(), std::strerror(err)));
  }
}

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(fmt::format("{}: cannot open", path.string()));
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

constexpr std::string_view kHistoryHeader =
    "generation,best,mean,median,viable_fraction,best_cells,evaluations,wall_seconds\n";

std::string history_row(const GenerationStats& s) {
  return fmt::format("{},{},{},{},{},{},{},{:.3f}\n", s.generation, s.best, s.mean, s.median, s.viable_fraction,
                     s.best_cells, s.evaluations, s.wall_seconds);
}

void append(const std::filesystem::path& path, std::string_view text) {
  std::ofstream out(path, std::ios::app | std::ios::binary);
  if (!out || !(out << text) || !out.flush()) throw IoError(fmt::format("{}: cannot append", path.string()));
}

void write_lineage(const std::filesystem::path& dir, const Evolution& evo) {
  const Individual& b = evo.best();
  json j{{"generation", evo.generation()},
         {"fitness", b.result.fitness},
         {"cell_count", b.result.cell_count},
         {"genome", json::parse(to_json(b.genome))}};
  write_atomically(dir / "best" / fmt::format("gen_{:06d}.json", evo.generation()), j.dump(1) + "\n");
}

std::string duration(double s) {
  const auto t = static_cast<long long>(std::max(0.0, s));
  return fmt::format("{}:{:02d}:{:02d}", t / 3600, (t / 60) % 60, t % 60);
}

}  // namespace

RunSummary run_evolution(const Config& config, const RunOptions& opt, FitnessFunction fitness) {
  validate(config);
  if (!fitness) fitness = swim_fitness(config);
  Evolution evo(config, std::move(fitness), opt.evaluator);
  const bool writing = !opt.out.empty();
  IslandLog island_log(writing ? opt.out : std::filesystem::path{}, config.evolution);  // [islands] islands.csv
  const std::filesystem::path ckpt = opt.out / "checkpoint.json", hist = opt.out / "history.csv";

  if (writing) {
    std::error_code ec;
    if (opt.resume) {
      if (!std::filesystem::is_directory(opt.out))
        throw IoError(fmt::format("{}: resume directory does not exist", opt.out.string()));
      if (!std::filesystem::exists(ckpt))
        throw CheckpointError(fmt::format("{}: no checkpoint.json to resume from", opt.out.string()));
    } else if (std::filesystem::exists(ckpt)) {
      throw IoError(fmt::format("{}: already holds a run (checkpoint.json); use --resume {} or another --out",
                                opt.out.string(), opt.out.string()));
    }
    std::filesystem::create_directories(opt.out / "best", ec);
    if (ec) throw IoError(fmt::format("{}: cannot create run directory: {}", opt.out.string(), ec.message()));
    write_atomically(opt.out / "config.toml", to_toml(config));
  }

  if (opt.resume) {
    if (!writing) throw Error("run_evolution: resume needs a run directory");
    evo.restore(read_file(ckpt), ckpt.string());
    std::string rows(kHistoryHeader);
    for (const auto& s : evo.history()) rows += history_row(s);
    write_atomically(hist, rows);  // drops rows written after the checkpoint
    island_log.resume(evo.generation());
    // Lineage files of generations after the checkpoint belong to the lost future; they are rewritten.
    for (const auto& entry : std::filesystem::directory_iterator(opt.out / "best")) {
      const std::string name = entry.path().filename().string();
      int g = -1;
      if (std::sscanf(name.c_str(), "gen_%d.json", &g) == 1 && g > evo.generation()) std::filesystem::remove(entry.path());
    }
    if (!opt.quiet) spdlog::info("resumed {} at generation {}", opt.out.string(), evo.generation());
  } else {
    if (!opt.quiet) spdlog::info("drawing {} viable random individuals...", config.evolution.population);
    evo.initialize();
    const auto tries = evo.initial_tries();
    const double mean_tries = std::accumulate(tries.begin(), tries.end(), 0.0) / static_cast<double>(tries.size());
    if (!opt.quiet)
      spdlog::info("initial population: {:.0f} random genomes per viable individual on average (paper: \"a few hundred\")",
                   mean_tries);
    if (writing) {
      write_atomically(hist, std::string(kHistoryHeader) + history_row(evo.history().back()));
      write_lineage(opt.out, evo);
      island_log.start(evo);
      write_atomically(ckpt, evo.checkpoint());
    }
  }

  RunSummary summary;
  double last_print = 0.0;
  int last_printed = -1;
  auto report = [&](const GenerationStats& s, bool force) {
    if (opt.quiet || s.generation == last_printed) return;
    const double t = now_seconds();
    if (!force && t - last_print < opt.progress_interval) return;
    last_print = t;
    last_printed = s.generation;
    std::string left;
    if (config.evolution.wall_seconds > 0) left = fmt::format(", {} left of budget", duration(config.evolution.wall_seconds - s.wall_seconds));
    else if (config.evolution.generations > 0 && s.generation > 0)
      left = fmt::format(", ~{} left", duration(s.wall_seconds / s.generation * (config.evolution.generations - s.generation)));
    spdlog::info("gen {:5d} | best {:8.4f} mean {:8.4f} median {:8.4f} | viable {:5.1f}% | {:6.1f} eval/s | {} elapsed{}",
                 s.generation, s.best, s.mean, s.median, 100.0 * s.viable_fraction, s.evaluations_per_second,
                 duration(s.wall_seconds), left);
  };
  report(evo.history().back(), true);
  int since_checkpoint = 0;
  bool dirty = false;
  while (true) {
    summary.stop_reason = evo.stop_reason();
    if (summary.stop_reason.empty() && opt.stop_flag && opt.stop_flag->load()) summary.stop_reason = "interrupted";
    if (!summary.stop_reason.empty()) break;
    const GenerationStats s = evo.step();
    report(s, false);
    if (writing) {
      append(hist, history_row(s));
      island_log.append(evo);
      if (s.best_changed) write_lineage(opt.out, evo);
      dirty = true;
      if (++since_checkpoint >= config.evolution.checkpoint_every) {
        write_atomically(ckpt, evo.checkpoint());
        since_checkpoint = 0;
        dirty = false;
      }
    }
    if (opt.callback && !opt.callback(s, evo)) {
      summary.stop_reason = "stopped by callback";
      break;
    }
  }
  if (writing && dirty) write_atomically(ckpt, evo.checkpoint());
  report(evo.history().back(), true);
  if (!opt.quiet) spdlog::info("stopped: {}", summary.stop_reason);
  summary.history = evo.history();
  summary.best = evo.best();
  return summary;
}

}  // namespace animat
