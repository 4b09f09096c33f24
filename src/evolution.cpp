#include "animat/evolution.hpp"

#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
#include <nlohmann/json.hpp>
#include <numeric>
#include <sstream>
#include <string>
#include <tuple>
#include <unordered_map>

#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/evaluator.hpp"
#include "animat/islands.hpp"
#include "animat/objective_table.hpp"
#include "animat/physics.hpp"
#include "animat/run_identity.hpp"
#include "json_util.hpp"

namespace animat {

using nlohmann::json;

namespace {

constexpr int kCheckpointVersion = 1;

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string hex(std::uint64_t x) { return fmt::format("{:016x}", x); }

// The built-in objectives that are never negative, for messages: "distance, distance_per_size,
// ...".
std::string nonnegative_names() {
  std::string out;
  for (const auto& spec : kObjectives)
    if (spec.nonnegative) out += (out.empty() ? "" : ", ") + std::string(spec.name);
  return out;
}

// Built-in objectives whose every value is >= 0 by construction (kObjectives' sign rule); others
// (speed_toward, a Python objective) may be negative.
bool nonnegative_objective(const Config& c) {
  const ObjectiveSpec* spec = find_objective(c.evaluation.objective);
  return spec != nullptr && spec->nonnegative;
}

// A fitness the GA can rank and a checkpoint can hold (restore() refuses anything else): finite,
// and >= 0 under an objective that is never negative; cell_count, drag_limited and morphology_kind
// >= 0. "" = acceptable, else what is wrong. The one rule for every way a fitness reaches the
// engine: its own evaluations, tell() (animat.GA) and the exploit guard's reference evaluations.
std::string fitness_problem(const Fitness& f, bool nonnegative) {
  if (!std::isfinite(f.fitness) || (nonnegative && f.fitness < 0.0))
    return fmt::format(
        "fitness {} (a fitness must be finite{})", f.fitness,
        nonnegative ? " and >= 0 under an objective that is never negative: " + nonnegative_names()
                    : "");
  if (f.cell_count < 0) return fmt::format("cell_count {} (must be >= 0)", f.cell_count);
  if (f.drag_limited < 0) return fmt::format("drag_limited {} (must be >= 0)", f.drag_limited);
  if (f.morphology_kind < 0)
    return fmt::format("morphology_kind {} (must be >= 0)", f.morphology_kind);
  return {};
}

void check_fitness(const Fitness& f, std::string_view where, bool nonnegative) {
  if (const std::string problem = fitness_problem(f, nonnegative); !problem.empty())
    throw Error(fmt::format("{}: the fitness function returned {}", where, problem));
}

// The mean of finite values, never overflowing: their plain sum / n (bit for bit the value every
// run so far recorded) when that sum is finite; otherwise the sum of the values scaled by 2^-(k+1),
// with 2^k > n, which cannot overflow (|sum| <= n max|x| 2^-(k+1) < max|x| / 2), clamped to [min,
// max], where the true mean lies. So a generation of finite fitnesses has a finite mean
// (docs/reliability.md).
double finite_mean(const std::vector<double>& v) {
  const double n = static_cast<double>(v.size());
  const double sum = std::accumulate(v.begin(), v.end(), 0.0);
  if (std::isfinite(sum)) return sum / n;
  int k = 0;
  std::frexp(n, &k);  // n < 2^k
  double scaled = 0.0;
  for (double x : v) scaled += std::ldexp(x, -(k + 1));
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  return std::clamp(std::ldexp(scaled / n, k + 1), *lo, *hi);
}

// The midpoint of two finite values, never overflowing: 0.5 (a + b) (bit for bit today's) when a +
// b is finite, else 0.5 a + 0.5 b.
double finite_midpoint(double a, double b) {
  const double sum = a + b;
  return std::isfinite(sum) ? 0.5 * sum : 0.5 * a + 0.5 * b;
}

bool fitter(const Individual& a, const Individual& b) {
  if (a.result.viable != b.result.viable) return a.result.viable;
  return a.result.fitness > b.result.fitness;
}

// The best individual: the first of the fittest by nominal fitness (ties resolve the same way on
// every machine). Under the exploit guard's "select" the elites are ranked by their reference
// fitness, so the best is the first of the best reference among the viable individuals that have
// one (the elite candidates, referenced when their generation completed): a genome whose fitness
// the reference step does not confirm is never reported as the run's best.
std::size_t best_index(const std::vector<Individual>& pop, bool by_reference) {
  std::size_t best =
      static_cast<std::size_t>(std::min_element(pop.begin(), pop.end(), fitter) - pop.begin());
  if (!by_reference) return best;
  bool found = false;
  for (std::size_t i = 0; i < pop.size(); ++i) {
    if (!pop[i].result.viable || std::isnan(pop[i].reference)) continue;
    if (!found || pop[i].reference > pop[best].reference) best = i;
    found = true;
  }
  return best;
}

bool selects_by_reference(const Config& c) { return c.evaluation.reference_check == "select"; }

}  // namespace

double tournament_probability(const EvolutionParams& p, int generation) {
  if (p.tournament_ramp_generations <= 0) return p.tournament_p_end;
  const double t =
      std::clamp(static_cast<double>(generation) / p.tournament_ramp_generations, 0.0, 1.0);
  return p.tournament_p_start + (p.tournament_p_end - p.tournament_p_start) * t;
}

std::size_t tournament(const std::vector<Individual>& pop, const std::vector<std::size_t>& eligible,
                       double p_fitter, Rng& rng, int protection) {
  if (eligible.empty()) throw Error("tournament: no eligible individual");
  if (eligible.size() == 1) return eligible[0];
  const std::size_t a = eligible[rng.below(eligible.size())];
  std::size_t b = eligible[rng.below(eligible.size() - 1)];
  if (b == a) b = eligible.back();  // two distinct individuals, uniformly
  const bool a_fitter = fitter(pop[a], pop[b]) || (!fitter(pop[b], pop[a]) && a < b);
  const std::size_t winner = a_fitter ? a : b, loser = a_fitter ? b : a;
  // Morphological innovation protection: a new body plan usually swims worse than the established
  // ones until evolution has tuned its control, so it does not compete with an older kind yet.
  // One draw either way: the random stream does not depend on who is protected.
  if (protection > 0) {
    const Individual &f = pop[winner], &o = pop[loser];
    if (o.morphology_age < protection && o.result.morphology_kind != f.result.morphology_kind &&
        o.morphology_age < f.morphology_age)
      return rng.bernoulli(0.5) ? winner : loser;
  }
  return rng.bernoulli(p_fitter) ? winner : loser;
}

void prepare_parallel_evaluation() { warm_up_box2d(); }

bool reference_disagrees(double fitness, double reference, const EvaluationParams& params) {
  const double diff = std::abs(fitness - reference);
  return diff > params.reference_abs_tolerance &&
         diff > params.reference_tolerance * std::abs(reference);
}

// ---------------------------------------------------------------------------------------------------
Evolution::Evolution(const Config& config, FitnessFunction fitness, FitnessFunction reference,
                     std::shared_ptr<Evaluator> evaluator)
    : config_(std::make_shared<const Config>(config)),
      identity_(run_identity(config)),
      fitness_(std::move(fitness)),
      evaluator_(std::move(evaluator)),
      started_(now_seconds()) {
  validate(*config_);
  if (config_->evaluation.reference_check != "off") reference_ = std::move(reference);
  // One evaluation path: every evaluation of the GA goes through an Evaluator.
  if (!evaluator_ && fitness_) evaluator_ = make_local_evaluator(*config_, fitness_);
  if (reference_) reference_evaluator_ = make_local_evaluator(*config_, reference_);
}

void Evolution::check_reference() {
  if (!reference_ || population_.empty() || history_.empty()) return;
  const Individual& b = best();
  if (!b.result.viable) return;
  Individual& mutable_best = population_[static_cast<std::size_t>(&b - population_.data())];
  if (std::isnan(mutable_best.reference)) {
    if (const double* known = remembered_reference(mutable_best.genome)) {
      mutable_best.reference = *known;
      history_.back().best_reference = mutable_best.reference;
      return;
    }
    const Fitness r = reference_(mutable_best.genome);
    check_fitness(r,
                  fmt::format("exploit guard, generation {}: the reference evaluation of the best",
                              generation_),
                  nonnegative_objective(*config_));
    mutable_best.reference = r.fitness;
  }
  history_.back().best_reference = mutable_best.reference;
}

std::vector<std::size_t> Evolution::reference_ranked(const std::vector<std::size_t>& order,
                                                     std::size_t elites) {
  // Candidates: the 2·elites fittest viable individuals by their nominal fitness.
  std::vector<std::size_t> cand;
  for (std::size_t k = 0; k < order.size() && cand.size() < 2 * elites; ++k)
    if (population_[order[k]].result.viable) cand.push_back(order[k]);
  std::vector<std::size_t> todo;
  std::vector<std::pair<std::size_t, double>> remembered;
  for (std::size_t c : cand) {
    if (!std::isnan(population_[c].reference)) continue;
    if (const double* r = remembered_reference(population_[c].genome))
      remembered.emplace_back(c, *r);
    else
      todo.push_back(c);
  }
  std::vector<const Genome*> genomes;
  for (std::size_t c : todo) genomes.push_back(&population_[c].genome);
  // inside tell(): not stoppable
  const std::vector<Fitness> refs = reference_evaluator_->evaluate(genomes, StopRequest{});
  for (std::size_t k = 0; k < todo.size(); ++k)
    check_fitness(
        refs[k],
        fmt::format("exploit guard (select): the reference evaluation of individual {}", todo[k]),
        nonnegative_objective(*config_));
  // Stored only once every one is known and acceptable: an exception leaves the population as it
  // was.
  for (std::size_t k = 0; k < todo.size(); ++k) population_[todo[k]].reference = refs[k].fitness;
  for (const auto& [c, r] : remembered) population_[c].reference = r;
  std::stable_sort(cand.begin(), cand.end(), [&](std::size_t a, std::size_t b) {
    return population_[a].reference > population_[b].reference;
  });
  if (cand.size() > elites) cand.resize(elites);
  return cand;
}

const double* Evolution::remembered_reference(const Genome& genome) const {
  for (const auto& [g, r] : reference_memo_)
    if (g == genome) return &r;
  if (!key_ || reference_memo_.empty()) return nullptr;
  const std::string key = key_(genome);
  for (std::size_t k = 0; k < reference_memo_.size(); ++k)
    if (reference_memo_keys_[k] == key) return &reference_memo_[k].second;
  return nullptr;
}

void Evolution::remember_references() {
  reference_memo_.clear();
  reference_memo_keys_.clear();
  if (!reference_) return;
  for (const Individual& ind : population_)
    if (!std::isnan(ind.reference)) {
      reference_memo_.emplace_back(ind.genome, ind.reference);
      if (key_) reference_memo_keys_.push_back(key_(ind.genome));
    }
}

void Evolution::reference_elite_candidates() {
  if (!reference_ || !selects_by_reference(*config_)) return;
  const IslandLayout layout = island_layout(population_.size(), config_->evolution.islands);
  for (std::size_t isl = 0; isl < layout.count(); ++isl) {
    const std::vector<std::size_t> order = island_ranking(population_, layout, isl);
    (void)reference_ranked(
        order,
        std::min<std::size_t>(static_cast<std::size_t>(config_->evolution.elites), order.size()));
  }
}

void Evolution::initialize() {
  if (!evaluator_)
    throw Error(
        "Evolution::initialize: no fitness function (drive this engine with ask() and tell())");
  if (generation_ >= 0) throw Error("Evolution::initialize: the initial population exists already");
  const EvolutionParams& ep = config_->evolution;
  while (generation_ < 0) {
    // Rounds of about four populations of speculative draws: few rounds (each ends at a barrier of
    // the parallel evaluation), and few discarded draws (about 1% of the initial evaluations).
    std::size_t open = 0;
    for (const auto& slot : slots_) open += slot.filled ? 0 : 1;
    if (slots_.empty()) open = static_cast<std::size_t>(ep.population);
    const auto width = 4 * static_cast<std::size_t>(ep.population);
    const int lookahead = static_cast<int>(
        std::max<std::size_t>(1, (width + open - 1) / std::max<std::size_t>(open, 1)));
    const std::vector<Genome> genomes = ask(lookahead);
    tell(evaluate_genomes(genomes, "initial population"));
  }
}

const Individual& Evolution::best() const {
  if (generation_ < 0 || population_.empty())
    throw Error("Evolution::best: no generation yet (the initial population is not complete)");
  return population_[best_index(population_, selects_by_reference(*config_))];
}

std::vector<int> Evolution::initial_tries() const {
  std::vector<int> out;
  for (const auto& ind : population_) out.push_back(ind.tries);
  return out;
}

GenerationStats Evolution::step() {
  if (!evaluator_)
    throw Error("Evolution::step: no fitness function (drive this engine with ask() and tell())");
  if (generation_ < 0) throw Error("Evolution::step: call initialize() first");
  const std::vector<Genome> genomes = ask();
  tell(evaluate_genomes(genomes, fmt::format("generation {}", generation_ + 1)));
  return history_.back();
}

std::vector<Fitness> Evolution::evaluate_genomes(const std::vector<Genome>& genomes,
                                                 const std::string& what) {
  std::vector<Fitness> out;
  try {
    out = evaluator_->evaluate(genomes, stop_);
  } catch (const Interrupted&) {
    throw Interrupted(generation_ < 0
                          ? std::string("interrupted while drawing the initial population")
                          : fmt::format("interrupted during {}", what));
  }
  for (std::size_t k = 0; k < out.size(); ++k)
    check_fitness(out[k], fmt::format("{}, genome {}", what, k), nonnegative_objective(*config_));
  return out;
}

std::vector<Genome> Evolution::ask(int lookahead) {
  if (lookahead < 1)
    throw Error(fmt::format("Evolution::ask: lookahead must be >= 1, got {}", lookahead));
  if (pending_) return asked_;
  asked_ = generation_ < 0 ? ask_initial(lookahead) : ask_generation();
  pending_ = true;
  return asked_;
}

bool Evolution::tell(const std::vector<Fitness>& fitness) {
  if (!pending_) throw Error("Evolution::tell: nothing was asked (call ask() first)");
  if (fitness.size() != asked_.size())
    throw Error(
        fmt::format("Evolution::tell: {} fitness values for the {} genomes of the last ask()",
                    fitness.size(), asked_.size()));
  // The engine's own rule for its evaluations (check_fitness): what tell() accepts, a checkpoint
  // holds and restore() reads back.
  for (std::size_t k = 0; k < fitness.size(); ++k)
    if (const std::string problem = fitness_problem(fitness[k], nonnegative_objective(*config_));
        !problem.empty())
      throw Error(fmt::format(
          "Evolution::tell: value {} (genome {} of the last ask()) is refused: {}", k, k, problem));
  bool done = false;
  if (!reference_) {
    done = generation_ < 0 ? tell_initial(fitness) : tell_generation(fitness);
  } else {
    // The exploit guard evaluates the new best at the end of the tell; if that throws (an
    // interrupted Python objective, a refused reference fitness), the engine is put back as it was
    // before this tell, the ask still pending: the same tell can be repeated.
    auto saved_population = population_;
    auto saved_slots = slots_;
    auto saved_next = next_;
    auto saved_history = history_;
    auto saved_migrations = migrations_;
    auto saved_asked = asked_;  // tell_initial moves the viable genomes out of it
    const auto saved = std::make_tuple(generation_, stall_, best_ever_, evaluations_);
    try {
      done = generation_ < 0 ? tell_initial(fitness) : tell_generation(fitness);
    } catch (...) {
      population_ = std::move(saved_population);
      slots_ = std::move(saved_slots);
      next_ = std::move(saved_next);
      history_ = std::move(saved_history);
      migrations_ = std::move(saved_migrations);
      asked_ = std::move(saved_asked);
      std::tie(generation_, stall_, best_ever_, evaluations_) = saved;
      throw;
    }
  }
  pending_ = false;
  asked_.clear();
  asked_index_.clear();
  return done;
}

std::vector<Genome> Evolution::ask_initial(int lookahead) {
  const EvolutionParams& ep = config_->evolution;
  if (slots_.empty()) {
    const auto n = static_cast<std::size_t>(ep.population);
    slots_.clear();
    for (std::size_t i = 0; i < n; ++i)
      slots_.push_back(
          InitialSlot{Rng::derive(static_cast<std::uint64_t>(ep.seed), kInitialStreamKey, i), 0,
                      false, Individual{}});
  }
  std::vector<Genome> out;
  asked_index_.clear();
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    InitialSlot& slot = slots_[i];
    if (slot.filled) continue;
    const int draws = std::min(lookahead, ep.max_init_tries - slot.tries);
    for (int k = 0; k < draws; ++k) {
      out.push_back(random_genome(config_->genome, slot.rng));
      asked_index_.push_back(i);
    }
  }
  return out;
}

bool Evolution::tell_initial(const std::vector<Fitness>& fitness) {
  const EvolutionParams& ep = config_->evolution;
  for (std::size_t k = 0; k < fitness.size(); ++k) {
    InitialSlot& slot = slots_[asked_index_[k]];
    if (slot.filled) continue;  // a speculative draw after this slot's first viable one: discarded
    ++slot.tries;
    ++evaluations_;
    if (!fitness[k].viable) continue;
    Individual& ind = slot.individual;
    ind.genome = std::move(asked_[k]);
    ind.result = fitness[k];
    ind.tries = slot.tries;
    slot.filled = true;
  }
  for (std::size_t i = 0; i < slots_.size(); ++i)
    if (!slots_[i].filled && slots_[i].tries >= ep.max_init_tries)
      throw Error(fmt::format(
          "initial population: no viable random genome in evolution.max_init_tries = {} tries "
          "(individual {}); the development or genome settings make viability too rare",
          ep.max_init_tries, i));
  for (const auto& slot : slots_)
    if (!slot.filled) return false;
  population_.clear();
  for (auto& slot : slots_) {
    slot.individual.id = static_cast<std::int64_t>(population_.size());
    population_.push_back(std::move(slot.individual));
  }
  slots_.clear();
  generation_ = 0;
  reference_elite_candidates();
  best_ever_ = best().result.fitness;
  stall_ = 0;
  // Every initial individual is a viable draw that was swum once.
  history_.push_back(statistics(true, wall_offset_ + now_seconds() - started_,
                                static_cast<int>(population_.size())));
  check_reference();
  remember_references();
  return true;
}

std::vector<Genome> Evolution::ask_generation() {
  const EvolutionParams& ep = config_->evolution;
  const int g = generation_ + 1;
  const std::size_t n = population_.size();

  // [islands] Selection and elitism act within each island; one island is the paper's population.
  const IslandLayout layout = island_layout(n, ep.islands);
  std::vector<std::vector<std::size_t>> eligible(layout.count());
  std::vector<std::size_t> copied(layout.count(), 0);
  std::vector<Individual>& next = next_;
  next.assign(n, Individual{});
  next_origin_.assign(n, Origin{});
  std::vector<bool> needs_eval(n, false);
  const bool select_by_reference = reference_ && config_->evaluation.reference_check == "select";
  for (std::size_t isl = 0; isl < layout.count(); ++isl) {
    const std::vector<std::size_t> order = island_ranking(population_, layout, isl);
    for (std::size_t i = layout.begin(isl); i < layout.end(isl); ++i)
      if (population_[i].result.viable) eligible[isl].push_back(i);
    if (eligible[isl].empty()) {
      // nobody viable (possible only without elites): fall back to everyone
      eligible[isl].resize(layout.size(isl));
      std::iota(eligible[isl].begin(), eligible[isl].end(), layout.begin(isl));
    }
    const std::size_t elites =
        std::min<std::size_t>(static_cast<std::size_t>(ep.elites), order.size());
    if (select_by_reference) {
      // exploit guard "select": the elites are the best at the reference step
      for (std::size_t i : reference_ranked(order, elites)) {
        next_origin_[layout.begin(isl) + copied[isl]] = Origin{i, Origin::none, true};
        Individual& elite = next[layout.begin(isl) + copied[isl]++];
        elite = population_[i];
        elite.tries = 0;
      }
      continue;
    }
    for (std::size_t k = 0; k < order.size() && copied[isl] < elites; ++k) {
      if (!population_[order[k]].result.viable) break;
      next_origin_[layout.begin(isl) + copied[isl]] = Origin{order[k], Origin::none, true};
      Individual& elite = next[layout.begin(isl) + copied[isl]++];
      elite = population_[order[k]];
      elite.tries = 0;
    }
  }
  const double p = tournament_probability(ep, g);
  const int protection = ep.protection_generations;
  int crossovers = 0;
  // Previous genomes by hash: an unchanged offspring keeps its parent's fitness (never evaluated
  // twice); with a fitness key, so does an offspring whose key one of them has (e.g. a mutation of
  // an element that takes part in no interaction of the network).
  std::unordered_multimap<std::uint64_t, std::size_t> known;
  for (std::size_t i = 0; i < n; ++i) known.emplace(genome_hash(population_[i].genome), i);
  std::unordered_map<std::string, std::size_t> known_keys;
  if (key_)
    for (std::size_t i = 0; i < n; ++i) known_keys.emplace(key_(population_[i].genome), i);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t isl = layout.island_of(i);        // [islands]
    if (i < layout.begin(isl) + copied[isl]) continue;  // an elite
    Rng rng = Rng::derive(static_cast<std::uint64_t>(ep.seed), static_cast<std::uint64_t>(g), i);
    Individual& child = next[i];
    child.id =
        static_cast<std::int64_t>(g) * static_cast<std::int64_t>(n) + static_cast<std::int64_t>(i);
    if (rng.bernoulli(ep.crossover_fraction)) {
      const std::size_t a = tournament(population_, eligible[isl], p, rng, protection);
      const std::size_t b = tournament(population_, eligible[isl], p, rng, protection);
      next_origin_[i] = Origin{a, b, false};
      ++crossovers;
      child.genome = crossover(population_[a].genome, population_[b].genome,
                               config_->mutation.crossover_points, rng);
      child.parent_a = population_[a].id;
      child.parent_b = population_[b].id;
    } else {
      const std::size_t a = tournament(population_, eligible[isl], p, rng, protection);
      next_origin_[i] = Origin{a, Origin::none, false};
      child.genome = population_[a].genome;
      child.parent_a = population_[a].id;
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
    if (needs_eval[i] && key_)
      if (const auto it = known_keys.find(key_(child.genome)); it != known_keys.end()) {
        child.result = population_[it->second].result;
        needs_eval[i] = false;
      }
  }
  next_crossovers_ = crossovers;
  std::vector<Genome> out;
  asked_index_.clear();
  for (std::size_t i = 0; i < n; ++i)
    if (needs_eval[i]) {
      out.push_back(next[i].genome);
      asked_index_.push_back(i);
    }
  return out;
}

bool Evolution::tell_generation(const std::vector<Fitness>& fitness) {
  int swims = 0;
  for (std::size_t k = 0; k < fitness.size(); ++k) {
    next_[asked_index_[k]].result = fitness[k];
    if (fitness[k].viable) ++swims;
  }
  evaluations_ += static_cast<std::int64_t>(fitness.size());
  // Morphology ages, now that every offspring's kind is known (next_origin_ is only read: a tell
  // that the exploit guard undoes can be repeated).
  for (std::size_t i = 0; i < next_.size(); ++i) {
    const Origin& o = next_origin_[i];
    Individual& child = next_[i];
    child.morphology_age = 0;  // a kind neither parent had (or no parent)
    for (const std::size_t parent : {o.a, o.b}) {
      if (parent >= population_.size()) continue;
      const Individual& p = population_[parent];
      if (o.elite || p.result.morphology_kind == child.result.morphology_kind) {
        const int age = p.morphology_age + 1;
        child.morphology_age = child.morphology_age > 0 ? std::min(child.morphology_age, age) : age;
      }
    }
  }

  const Genome previous_best = best().genome;
  population_ = std::move(next_);
  next_.clear();
  generation_ += 1;
  const EvolutionParams& ep = config_->evolution;
  migrations_.clear();  // [islands] copies of evaluated individuals: nothing to evaluate
  if (is_migration_generation(ep, generation_))
    migrations_ = migrate(population_, island_layout(population_.size(), ep.islands), ep.migrants,
                          generation_);
  reference_elite_candidates();
  const Individual& b = best();
  if (b.result.fitness > best_ever_) {
    best_ever_ = b.result.fitness;
    stall_ = 0;
  } else {
    ++stall_;
  }
  history_.push_back(
      statistics(!(b.genome == previous_best), wall_offset_ + now_seconds() - started_, swims));
  history_.back().crossovers = next_crossovers_;
  check_reference();
  remember_references();
  return true;
}

namespace {
// The population columns of a history row: best, best_cells, viable_fraction, mean, median.
GenerationStats population_statistics(const std::vector<Individual>& population,
                                      bool by_reference) {
  GenerationStats s;
  std::vector<double> viable;
  for (const auto& ind : population) {
    if (ind.result.viable) viable.push_back(ind.result.fitness);
    if (ind.result.viable && (!ind.result.valid || !ind.result.stable)) ++s.invalid;
    if (ind.result.drag_limited > 0) ++s.drag_limited;
  }
  const Individual& b = population[best_index(population, by_reference)];  // Evolution::best()
  s.best = b.result.fitness;
  s.best_cells = b.result.cell_count;
  s.viable_fraction = static_cast<double>(viable.size()) / static_cast<double>(population.size());
  if (!viable.empty()) {
    s.mean = finite_mean(viable);
    std::sort(viable.begin(), viable.end());
    const std::size_t m = viable.size() / 2;
    s.median = viable.size() % 2 ? viable[m] : finite_midpoint(viable[m - 1], viable[m]);
  }
  return s;
}
}  // namespace

GenerationStats Evolution::statistics(bool best_changed, double wall, int swims) const {
  if (population_.empty()) throw Error("Evolution::statistics: the population is empty");
  GenerationStats s = population_statistics(population_, selects_by_reference(*config_));
  s.generation = generation_;
  s.evaluations = evaluations_;
  s.wall_seconds = wall;
  // The rate of this generation alone (a cumulative average would drag the initial draws along).
  const double seconds = history_.empty() ? wall : wall - history_.back().wall_seconds;
  const auto evaluated = evaluations_ - (history_.empty() ? 0 : history_.back().evaluations);
  s.evaluations_per_second = seconds > 0 ? static_cast<double>(evaluated) / seconds : 0.0;
  s.swims = swims;
  s.swims_per_second = seconds > 0 ? swims / seconds : 0.0;
  s.best_changed = best_changed;
  if (const int protection = config_->evolution.protection_generations; protection > 0)
    for (const auto& ind : population_)
      if (ind.result.viable && ind.morphology_age < protection) ++s.protected_count;
  return s;
}

std::string Evolution::stop_reason() const {
  const EvolutionParams& ep = config_->evolution;
  if (generation_ < 0) return {};
  if (ep.generations > 0 && generation_ >= ep.generations)
    return fmt::format("generation cap evolution.generations = {} reached", ep.generations);
  if (ep.stall_generations > 0 && stall_ >= ep.stall_generations)
    return fmt::format("no improvement for evolution.stall_generations = {} generations",
                       ep.stall_generations);
  if (ep.wall_seconds > 0 && wall_offset_ + now_seconds() - started_ >= ep.wall_seconds)
    return fmt::format("wall-clock budget evolution.wall_seconds = {} s used", ep.wall_seconds);
  return {};
}

// ---------------------------------------------------------------------------------------------------
// Checkpoints
namespace {

json stats_to_json(const GenerationStats& s) {
  json j = json::object();
  visit_fields(s, [&](const StatsField& f, const auto& value) {
    using T = std::decay_t<decltype(value)>;
    if (f.checkpoint == StatsField::Checkpoint::none) return;
    if (f.checkpoint == StatsField::Checkpoint::when_set) {
      if constexpr (std::is_floating_point_v<T>) {
        if (std::isnan(value)) return;
      } else {
        if (value == T{}) return;
      }
    }
    j[f.name] = value;
  });
  return j;
}

// Integer and number fields of a checkpoint: type- and range-checked, never converted out of range.
long long int_field(const json& j, const char* key, long long lo, long long hi) {
  const auto v = detail::int_in(j.at(key), lo, hi);
  if (!v)
    throw CheckpointError(fmt::format("field \"{}\" is {}, expected an integer in [{}, {}]", key,
                                      detail::describe(j.at(key)), lo, hi));
  return *v;
}

double number_field(const json& j, const char* key) {
  const auto v = detail::finite_number(j.at(key));
  if (!v)
    throw CheckpointError(fmt::format("field \"{}\" is {}, expected a finite number", key,
                                      detail::describe(j.at(key))));
  return *v;
}

bool bool_field(const json& j, const char* key) {
  if (!j.at(key).is_boolean())
    throw CheckpointError(fmt::format("field \"{}\" is {}, expected true or false", key,
                                      detail::describe(j.at(key))));
  return j.at(key).get<bool>();
}

constexpr long long kIntMax = std::numeric_limits<int>::max();
constexpr long long kInt64Max = std::numeric_limits<std::int64_t>::max();

GenerationStats stats_from_json(const json& j) {
  GenerationStats s;
  visit_fields(s, [&](const StatsField& f, auto& value) {
    using T = std::decay_t<decltype(value)>;
    if (f.checkpoint == StatsField::Checkpoint::none) return;
    // its default
    if (f.checkpoint != StatsField::Checkpoint::required && !j.contains(f.name)) return;
    if constexpr (std::is_same_v<T, bool>)
      value = bool_field(j, f.name);
    else if constexpr (std::is_same_v<T, int>)
      value = static_cast<int>(int_field(j, f.name, 0, kIntMax));
    else if constexpr (std::is_same_v<T, std::int64_t>)
      value = int_field(j, f.name, 0, kInt64Max);
    else
      value = number_field(j, f.name);
  });
  return s;
}

// What a checksum cannot catch: a hand-edited checkpoint whose content the engine could never have
// written. Everything is compared with what the engine computes from the same population and
// history.
void check_semantics(const std::vector<Individual>& pop, const std::vector<GenerationStats>& hist,
                     int stall, double best_ever, std::int64_t evaluations, double wall,
                     bool nonnegative, bool by_reference, std::string_view source) {
  auto fail = [&](const std::string& what) {
    throw CheckpointError(fmt::format("{}: inconsistent checkpoint: {}", source, what));
  };
  for (std::size_t i = 0; i < pop.size(); ++i) {
    const Fitness& f = pop[i].result;
    if (nonnegative && f.fitness < 0.0)
      fail(fmt::format("individual {} has fitness {} (a fitness is >= 0)", i, f.fitness));
    if (f.viable && pop[i].genome.elements.empty())
      fail(fmt::format("individual {} is viable with an empty genome", i));
    if (!hist.empty() && pop[i].morphology_age > hist.back().generation)
      fail(fmt::format("individual {} has morphology_age {}, older than the run (generation {})", i,
                       pop[i].morphology_age, hist.back().generation));
  }
  double best_so_far = -std::numeric_limits<double>::infinity();
  int expected_stall = 0;
  for (std::size_t k = 0; k < hist.size(); ++k) {
    const GenerationStats& s = hist[k];
    if (s.generation != static_cast<int>(k))
      fail(fmt::format(
          "history row {} is generation {}; the history must count 0, 1, 2, ... without gaps", k,
          s.generation));
    if (nonnegative && (s.best < 0.0 || s.mean < 0.0 || s.median < 0.0))
      fail(fmt::format("history row {} has a negative fitness statistic", k));
    if (!(s.viable_fraction >= 0.0 && s.viable_fraction <= 1.0))
      fail(fmt::format("history row {} has viable_fraction {} (expected in [0, 1])", k,
                       s.viable_fraction));
    if (s.wall_seconds < 0.0)
      fail(fmt::format("history row {} has wall_seconds {} (expected >= 0)", k, s.wall_seconds));
    if (k > 0 && s.evaluations < hist[k - 1].evaluations)
      fail(fmt::format("history row {}: evaluations decrease ({} after {})", k, s.evaluations,
                       hist[k - 1].evaluations));
    if (k > 0 && s.wall_seconds < hist[k - 1].wall_seconds)
      fail(fmt::format("history row {}: wall_seconds decrease ({} after {})", k, s.wall_seconds,
                       hist[k - 1].wall_seconds));
    if (k == 0 || s.best > best_so_far) {
      best_so_far = s.best;
      expected_stall = 0;
    } else {
      ++expected_stall;
    }
  }
  if (best_ever != best_so_far)
    fail(fmt::format("best_ever is {}, but the best of the history is {}", best_ever, best_so_far));
  if (stall != expected_stall)
    fail(fmt::format("stall is {}, but the history has {} generations without improvement", stall,
                     expected_stall));
  const GenerationStats& last = hist.back();
  if (evaluations != last.evaluations)
    fail(fmt::format("evaluations is {}, but the last history row counts {}", evaluations,
                     last.evaluations));
  if (wall != last.wall_seconds)
    fail(fmt::format("wall_seconds is {}, but the last history row has {}", wall,
                     last.wall_seconds));
  // Under "select", checkpoints written before the best was chosen by reference name the nominal
  // best: either describes the population.
  const GenerationStats now = population_statistics(pop, by_reference);
  const GenerationStats nominal = population_statistics(pop, false);
  const auto describes = [&](const GenerationStats& p) {
    return p.best == last.best && p.best_cells == last.best_cells &&
           p.viable_fraction == last.viable_fraction && p.mean == last.mean &&
           p.median == last.median;
  };
  if (!describes(now) && !(by_reference && describes(nominal)))
    fail(fmt::format(
        "the last history row (generation {}: best {}, mean {}, median {}, viable {}, {} cells) "
        "does not "
        "describe the population (best {}, mean {}, median {}, viable {}, {} cells)",
        last.generation, last.best, last.mean, last.median, last.viable_fraction, last.best_cells,
        now.best, now.mean, now.median, now.viable_fraction, now.best_cells));
}

}  // namespace

std::string Evolution::checkpoint() const {
  if (generation_ < 0)
    throw Error(
        "Evolution::checkpoint: no generation completed yet (the initial population is being "
        "drawn)");
  json payload;
  payload["format"] = "animat.checkpoint";
  payload["version"] = kCheckpointVersion;
  payload["identity"] = hex(identity_);
  payload["identity_scheme"] = kRunIdentityScheme;
  payload["generation"] = generation_;
  payload["stall"] = stall_;
  payload["best_ever"] = best_ever_;
  payload["evaluations"] = evaluations_;
  payload["wall_seconds"] = history_.empty() ? 0.0 : history_.back().wall_seconds;
  // The individuals are serialised on the evaluation threads: on many cores the checkpoint is most
  // of the serial part of a generation, and two thirds of it is this loop (docs/performance.md,
  // "Scale-out with MPI").
  std::vector<json> individuals(population_.size());
#pragma omp parallel for schedule(static) num_threads(resolve_threads(config_->evolution.threads))
  for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(population_.size()); ++i) {
    const Individual& ind = population_[static_cast<std::size_t>(i)];
    json ji{{"genome", json::parse(to_json(ind.genome))},
            {"fitness", ind.result.fitness},
            {"viable", ind.result.viable},
            {"stable", ind.result.stable},
            {"valid", ind.result.valid},
            {"cell_count", ind.result.cell_count},
            {"tries", ind.tries},
            {"id", ind.id}};
    if (ind.parent_a != kNoParent) ji["parent_a"] = ind.parent_a;
    if (ind.parent_b != kNoParent) ji["parent_b"] = ind.parent_b;
    if (!std::isnan(ind.reference)) ji["reference"] = ind.reference;
    if (ind.result.drag_limited > 0) ji["drag_limited"] = ind.result.drag_limited;
    // Absent when 0 (also in checkpoints written before morphology kinds and ages existed).
    if (ind.result.morphology_kind > 0) ji["morphology_kind"] = ind.result.morphology_kind;
    if (ind.morphology_age > 0) ji["morphology_age"] = ind.morphology_age;
    individuals[static_cast<std::size_t>(i)] = std::move(ji);
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
    throw CheckpointError(fmt::format(
        "{}: corrupt checkpoint (not valid JSON at byte {}; truncated?)", source, e.byte));
  } catch (const json::exception& e) {
    throw CheckpointError(fmt::format("{}: corrupt checkpoint ({})", source, e.what()));
  }
  try {
    if (!outer.is_object() || !outer.contains("checksum") || !outer.contains("payload") ||
        !outer["payload"].is_string())
      throw CheckpointError(
          fmt::format("{}: not an animat checkpoint (missing checksum/payload)", source));
    const std::string body = outer["payload"].get<std::string>();
    if (outer["checksum"] != hex(fnv1a(body)))
      throw CheckpointError(
          fmt::format("{}: corrupt checkpoint: checksum {} does not match its content ({})", source,
                      detail::describe(outer["checksum"]), hex(fnv1a(body))));
    const json p = detail::parse_bounded(body, 64);
    if (p.value("format", "") != "animat.checkpoint")
      throw CheckpointError(
          fmt::format("{}: not an animat checkpoint (format {})", source, p.value("format", "?")));
    if (!detail::int_in(p.at("version"), kCheckpointVersion, kCheckpointVersion))
      throw CheckpointError(
          fmt::format("{}: checkpoint version {} is not supported (this build reads version {})",
                      source, detail::describe(p.at("version")), kCheckpointVersion));
    if (!p.at("identity").is_string())
      throw CheckpointError(fmt::format("{}: field \"identity\" must be a string", source));
    // Checkpoints without "identity_scheme" were identified by scheme 1 (run_identity.hpp).
    const bool scheme_1 = !p.contains("identity_scheme");
    if (!scheme_1 &&
        !detail::int_in(p.at("identity_scheme"), kRunIdentityScheme, kRunIdentityScheme))
      throw CheckpointError(
          fmt::format("{}: identity scheme {} is not supported (this build reads 1 and {})", source,
                      detail::describe(p.at("identity_scheme")), kRunIdentityScheme));
    const std::string expected = hex(scheme_1 ? run_identity_v1(*config_) : identity_);
    if (p.at("identity").get<std::string>() != expected)
      throw CheckpointError(
          fmt::format("{}: checkpoint belongs to a different run configuration (identity {} vs {} "
                      "for the current config); "
                      "only {} may change on resume",
                      source, p.at("identity").get<std::string>(), expected,
                      fmt::join(resumable_keys(), ", ")));
    std::vector<Individual> pop;
    bool ids_known = true;
    for (const json& ji : p.at("population")) {
      Individual ind;
      ind.genome = genome_from_json(ji.at("genome").dump(), config_->genome, source);
      ind.result.fitness = number_field(ji, "fitness");
      ind.result.viable = bool_field(ji, "viable");
      ind.result.stable = bool_field(ji, "stable");
      if (ji.contains("valid")) ind.result.valid = bool_field(ji, "valid");
      if (ji.contains("reference")) ind.reference = number_field(ji, "reference");
      if (ji.contains("drag_limited"))
        ind.result.drag_limited = static_cast<long>(int_field(ji, "drag_limited", 0, kInt64Max));
      ind.result.cell_count = static_cast<int>(int_field(ji, "cell_count", 0, kIntMax));
      if (ji.contains("morphology_kind"))
        ind.result.morphology_kind = static_cast<int>(int_field(ji, "morphology_kind", 0, kIntMax));
      if (ji.contains("morphology_age"))
        ind.morphology_age = static_cast<int>(int_field(ji, "morphology_age", 0, kIntMax));
      ind.tries = static_cast<int>(int_field(ji, "tries", 0, kIntMax));
      // Checkpoints written before the genealogy hold no ids: each individual is then taken as
      // born at the checkpoint's generation, with unknown parents.
      if (ji.contains("id")) ind.id = int_field(ji, "id", 0, kInt64Max);
      if (ji.contains("parent_a")) ind.parent_a = int_field(ji, "parent_a", 0, kInt64Max);
      if (ji.contains("parent_b")) ind.parent_b = int_field(ji, "parent_b", 0, kInt64Max);
      ids_known = ids_known && ji.contains("id");
      pop.push_back(std::move(ind));
    }
    if (pop.size() != static_cast<std::size_t>(config_->evolution.population))
      throw CheckpointError(
          fmt::format("{}: checkpoint holds {} individuals, evolution.population is {}", source,
                      pop.size(), config_->evolution.population));
    std::vector<GenerationStats> hist;
    for (const json& js : p.at("history")) {
      GenerationStats st = stats_from_json(js);
      const double seconds =
          hist.empty() ? st.wall_seconds : st.wall_seconds - hist.back().wall_seconds;
      const auto evaluated = st.evaluations - (hist.empty() ? 0 : hist.back().evaluations);
      st.evaluations_per_second = seconds > 0 ? static_cast<double>(evaluated) / seconds : 0.0;
      st.swims_per_second = seconds > 0 ? st.swims / seconds : 0.0;
      hist.push_back(st);
    }
    const int generation = static_cast<int>(int_field(p, "generation", 0, kIntMax));
    if (!ids_known)
      for (std::size_t i = 0; i < pop.size(); ++i)
        pop[i].id = static_cast<std::int64_t>(generation) * static_cast<std::int64_t>(pop.size()) +
                    static_cast<std::int64_t>(i);
    if (hist.empty())
      throw CheckpointError(fmt::format("{}: checkpoint has an empty history", source));
    if (hist.back().generation != generation)
      throw CheckpointError(fmt::format(
          "{}: checkpoint generation {} does not match its history, which ends at generation {}",
          source, generation, hist.back().generation));
    const int stall = static_cast<int>(int_field(p, "stall", 0, kIntMax));
    const double best_ever = number_field(p, "best_ever");
    const std::int64_t evaluations = int_field(p, "evaluations", 0, kInt64Max);
    const double wall = number_field(p, "wall_seconds");
    check_semantics(pop, hist, stall, best_ever, evaluations, wall, nonnegative_objective(*config_),
                    selects_by_reference(*config_), source);
    population_ = std::move(pop);
    remember_references();
    slots_.clear();
    next_.clear();
    next_origin_.clear();
    pending_ = false;
    asked_.clear();
    asked_index_.clear();
    history_ = std::move(hist);
    generation_ = generation;
    stall_ = stall;
    best_ever_ = best_ever;
    evaluations_ = evaluations;
    wall_offset_ = wall;
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

}  // namespace animat
