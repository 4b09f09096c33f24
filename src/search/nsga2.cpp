// NSGA-II over the criteria of search.objectives (search.hpp), as animat.moo.Nsga2 draws, sorts
// and selects.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include "../json_util.hpp"
#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/evaluator.hpp"
#include "animat/run_identity.hpp"
#include "animat/search.hpp"
#include "search_state.hpp"

namespace animat {

using namespace search_state;

namespace {

constexpr int kNsga2Version = 1;
constexpr const char* kNsga2Format = "animat.nsga2";
/// The sort compares every pair of parents and candidates (2 N members).
constexpr int kMaxNsga2Population = 10000;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool archivable(const Fitness& f) { return f.viable && f.stable && f.valid; }

json crowding_json(double x) { return std::isinf(x) ? json("inf") : json(x); }

double crowding_field(const json& j) {
  if (j.is_object() && j.contains("crowding") && j["crowding"] == "inf")
    return std::numeric_limits<double>::infinity();
  const double x = number_field(j, "crowding");
  if (x < 0.0) throw CheckpointError(fmt::format("field \"crowding\" is {}, expected >= 0", x));
  return x;
}

json values_json(const std::vector<double>& v) {
  json out = json::array();
  for (double x : v) out.push_back(nan_or(x));
  return out;
}

}  // namespace

namespace {

// The names of search.objectives' entries ("NAME", "NAME:max", "NAME:min").
std::vector<std::string> objective_names(const Config& config) {
  std::vector<std::string> out;
  for (const std::string& spec : config.search.objectives)
    out.push_back(spec.substr(0, spec.find(':')));
  return out;
}

}  // namespace

Nsga2::Nsga2(const Config& config, FitnessFunction fitness, FitnessFunction reference,
             std::shared_ptr<Evaluator> evaluator, const std::vector<std::string>& supplied)
    : config_(std::make_shared<const Config>(config)),
      identity_(run_identity(config)),
      supplied_(std::make_shared<const SuppliedMeasures>(supplied, objective_names(config),
                                                         "search.objectives", config)),
      size_(config.evolution.population),
      started_(now_seconds()) {
  if (size_ > kMaxNsga2Population)
    throw ConfigError(fmt::format(
        "evolution.population = {}: NSGA-II sorts parents and candidates together, comparing "
        "every pair; its population is at most {}",
        size_, kMaxNsga2Population));
  for (const std::string& spec : config.search.objectives) {
    const auto colon = spec.find(':');
    const std::string name = spec.substr(0, colon);
    const Measure* own = supplied_->find(name);
    // a supplied criterion outside the measures table has no sense of its own
    if (own != nullptr && colon == std::string::npos &&
        supplied_->table[supplied_->index_of(own)] == nullptr)
      throw ConfigError(fmt::format(
          "search.objectives: \"{}\" is supplied by the caller: give its sense, \"{}:max\" or "
          "\"{}:min\"",
          spec, name, name));
    const Measure& m = own != nullptr ? *own : find_measure(name, config, "search.objectives");
    bool maximize = m.maximize;
    if (colon != std::string::npos) {
      const std::string sense = spec.substr(colon + 1);
      if (sense != "max" && sense != "min")
        throw ConfigError(fmt::format(
            "search.objectives: \"{}\": the sense after ':' is \"max\" or \"min\", not \"{}\"",
            spec, sense));
      maximize = sense == "max";
    }
    for (std::size_t j = 0; j < criteria_.size(); ++j)
      if (criteria_[j] == &m)
        throw ConfigError(
            fmt::format("search.objectives: \"{}\" names the criterion {} twice", spec, m.name));
    criteria_.push_back(&m);
    names_.push_back(name);
    maximize_.push_back(maximize);
  }
  if (config.evaluation.reference_check != "off") reference_ = std::move(reference);
  select_ = reference_ && config.evaluation.reference_check == "select";
  evaluator_ = evaluator ? std::move(evaluator)
                         : (fitness ? make_local_evaluator(config, std::move(fitness)) : nullptr);
}

std::vector<double> Nsga2::criteria_of(const Fitness& f, std::span<const double> own) const {
  std::vector<double> out;
  if (!archivable(f)) return std::vector<double>(criteria_.size(), kNaN);
  for (const Measure* c : criteria_) out.push_back(c->of ? c->of(f) : own[supplied_->index_of(c)]);
  return out;
}

std::vector<double> Nsga2::minimised(const std::vector<double>& values) const {
  std::vector<double> out(values.size());
  for (std::size_t j = 0; j < values.size(); ++j) out[j] = maximize_[j] ? -values[j] : values[j];
  return out;
}

void Nsga2::compare_reference(Solution& s) const {
  // "select": the selection compares the reference criteria; a candidate with none, or one that
  // is not finite (its reference swim was not valid), is not feasible.
  bool finite = !s.reference.empty();
  for (double x : s.reference) finite = finite && std::isfinite(x);
  if (!s.reference.empty()) s.objectives = s.reference;
  s.feasible = finite;
}

std::vector<Genome> Nsga2::ask() {
  if (asked_) return *asked_;
  const int g = generation_ + 1;
  const auto seed = static_cast<std::uint64_t>(config_->evolution.seed);
  const auto n = static_cast<std::size_t>(size_);
  std::vector<Genome> out(n);
  if (population_.empty()) {
    parallel_for(n, config_->evolution.threads, [&](std::size_t i) {
      Rng rng = Rng::derive(seed, static_cast<std::uint64_t>(g), i);
      out[i] = random_viable_genome(*config_, rng);
    });
  } else {
    const auto top = static_cast<std::int64_t>(population_.size()) - 1;
    // Binary tournament: lower rank, then larger crowding distance, then the first drawn.
    const auto pick = [&](Rng& rng) -> const Genome& {
      const Solution& a = population_[static_cast<std::size_t>(rng.integer(0, top))];
      const Solution& b = population_[static_cast<std::size_t>(rng.integer(0, top))];
      if (b.rank < a.rank || (b.rank == a.rank && b.crowding > a.crowding)) return b.genome;
      return a.genome;
    };
    for (std::size_t i = 0; i < n; ++i)
      out[i] = offspring(*config_, seed, g, i, config_->evolution.crossover_fraction, pick);
  }
  asked_ = std::move(out);
  return *asked_;
}

std::vector<Solution> Nsga2::select(std::vector<Solution> pool,
                                    const std::vector<bool>& copy) const {
  const auto n = static_cast<std::size_t>(size_);
  std::vector<std::size_t> feasible;
  for (std::size_t i = 0; i < pool.size(); ++i)
    if (pool[i].feasible && !copy[i]) feasible.push_back(i);
  std::vector<std::vector<double>> values, raw;
  for (std::size_t i : feasible) {
    values.push_back(minimised(pool[i].objectives));
    raw.push_back(pool[i].objectives);
  }
  const auto fronts = non_dominated_sort(values);
  std::vector<bool> chosen(pool.size(), false);
  std::size_t count = 0;
  for (std::size_t k = 0; k < fronts.size() && count < n; ++k) {
    std::vector<std::vector<double>> front_values;
    for (std::size_t i : fronts[k]) front_values.push_back(raw[i]);
    // on the criteria's own values, as animat.moo (the order of equal values decides the ends)
    const std::vector<double> d = crowding_distance(front_values);
    std::vector<std::size_t> members;
    for (std::size_t j = 0; j < fronts[k].size(); ++j) {
      const std::size_t i = feasible[fronts[k][j]];
      pool[i].rank = static_cast<int>(k);
      pool[i].crowding = d[j];
      members.push_back(i);
    }
    if (count + members.size() <= n) {
      for (std::size_t i : members) chosen[i] = true;
      count += members.size();
    } else {
      std::vector<std::size_t> order(members.size());
      std::iota(order.begin(), order.end(), 0);
      std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        if (d[a] != d[b]) return d[a] > d[b];
        return members[a] < members[b];
      });
      for (std::size_t j = 0; count < n; ++j, ++count) chosen[members[order[j]]] = true;
    }
  }
  for (std::size_t i = 0; i < pool.size(); ++i)
    if (!pool[i].feasible || copy[i]) {
      pool[i].rank = static_cast<int>(fronts.size());
      pool[i].crowding = 0.0;
      if (count < n) {
        chosen[i] = true;
        ++count;
      }
    }
  std::vector<Solution> out;
  for (std::size_t i = 0; i < pool.size(); ++i)
    if (chosen[i]) out.push_back(std::move(pool[i]));
  return out;
}

bool Nsga2::tell(const std::vector<Fitness>& fitness,
                 const std::vector<std::vector<double>>& supplied) {
  if (!asked_) throw Error("Nsga2.tell: nothing was asked (call ask() first)");
  const std::vector<Genome>& genomes = *asked_;
  if (fitness.size() != genomes.size())
    throw Error(fmt::format("Nsga2.tell: {} fitness values for the {} genomes of the last ask()",
                            fitness.size(), genomes.size()));
  const std::size_t own = supplied_->names.size();
  check_supplied_rows("Nsga2", own, supplied.size(), genomes.size());
  // 1. Check every value; nothing changes before the commit below.
  const int g = generation_ + 1;
  std::vector<Solution> candidates;
  for (std::size_t k = 0; k < fitness.size(); ++k) {
    const Fitness& f = fitness[k];
    if (!std::isfinite(f.fitness))
      refuse("Nsga2", k, fmt::format("fitness {} (a fitness must be finite)", f.fitness));
    if (f.cell_count < 0) refuse("Nsga2", k, fmt::format("cell_count {}", f.cell_count));
    if (own > 0 && archivable(f) && supplied[k].size() != own)
      refuse("Nsga2", k,
             fmt::format("{} supplied criterion values for the {} supplied criteria",
                         supplied[k].size(), own));
    Solution s{genomes[k], f, {}, {}, {}, g, archivable(f)};
    if (own > 0 && s.feasible) s.supplied = supplied[k];
    s.objectives = criteria_of(f, s.supplied);
    if (s.feasible)
      for (std::size_t j = 0; j < criteria_.size(); ++j)
        if (!std::isfinite(s.objectives[j]))
          refuse("Nsga2", k,
                 fmt::format("criterion {} = {} (a criterion must be finite)", criteria_[j]->name,
                             s.objectives[j]));
    candidates.push_back(std::move(s));
  }
  // 2. The exploit guard "select": the reference criteria of every feasible candidate, which the
  // selection then compares (a copy of a genome seen before takes its reference: the same swim).
  std::int64_t referenced = 0;
  // The reference swims of `members`, their criteria there stored with each (the hook's supplied
  // values where it gives them, else the member's own).
  const auto swim_references = [&](const std::vector<Solution*>& members) {
    std::vector<const Genome*> todo;
    for (const Solution* s : members) todo.push_back(&s->genome);
    const auto refs =
        evaluate_references(reference_, reference_hook_, *config_, todo, own, "Nsga2.tell");
    for (std::size_t r = 0; r < members.size(); ++r)
      members[r]->reference = criteria_of(
          refs.fitness[r], refs.supplied.empty() ? members[r]->supplied : refs.supplied[r]);
    return static_cast<std::int64_t>(members.size());
  };
  if (select_) {
    // by hash, in order: the first of equal genomes is the one a copy takes its reference from
    std::unordered_map<std::uint64_t, std::vector<const Solution*>> known;
    for (const Solution& s : population_) known[genome_hash(s.genome)].push_back(&s);
    const auto find = [&](const Genome& g) -> const Solution* {
      if (auto it = known.find(genome_hash(g)); it != known.end())
        for (const Solution* s : it->second)
          if (s->genome == g) return s;
      return nullptr;
    };
    std::vector<Solution*> first;
    for (Solution& c : candidates)
      if (c.feasible && find(c.genome) == nullptr) {
        known[genome_hash(c.genome)].push_back(&c);
        first.push_back(&c);
      }
    referenced = swim_references(first);
    for (Solution& s : candidates) {
      if (!s.feasible) continue;
      if (const Solution* seen = find(s.genome); seen != &s) s.reference = seen->reference;
      compare_reference(s);
    }
  }
  std::vector<double> reference_point = reference_point_;
  if (reference_point.empty()) {
    for (const Solution& s : candidates) {
      if (!s.feasible) continue;
      if (reference_point.empty()) {
        reference_point = s.objectives;
        continue;
      }
      for (std::size_t j = 0; j < criteria_.size(); ++j)
        reference_point[j] = maximize_[j] ? std::min(reference_point[j], s.objectives[j])
                                          : std::max(reference_point[j], s.objectives[j]);
    }
  }
  std::vector<Solution> pool = population_;
  const std::size_t parents = pool.size();
  for (Solution& s : candidates) pool.push_back(std::move(s));
  // Copies: a genome equal to an earlier member's adds no point to the front.
  std::vector<bool> copy(pool.size(), false);
  std::unordered_multimap<std::uint64_t, std::size_t> seen;
  int copies = 0, discarded = 0;
  for (std::size_t i = 0; i < pool.size(); ++i) {
    const std::uint64_t h = genome_hash(pool[i].genome);
    auto [lo, hi] = seen.equal_range(h);
    for (auto it = lo; it != hi; ++it)
      if (pool[it->second].genome == pool[i].genome) copy[i] = true;
    seen.emplace(h, i);
    if (i >= parents) {
      copies += copy[i] ? 1 : 0;
      discarded += pool[i].feasible ? 0 : 1;
    }
  }
  std::vector<Solution> population = select(std::move(pool), copy);
  // 3. The exploit guard "record": the front's new members at the reference step (may throw:
  // nothing has changed yet).
  if (reference_ && !select_) {
    std::vector<Solution*> pending;
    for (Solution& m : population)
      if (m.rank == 0 && m.feasible && m.reference.empty()) pending.push_back(&m);
    referenced = swim_references(pending);
  }
  // 4. Commit.
  population_ = std::move(population);
  reference_point_ = std::move(reference_point);
  reference_evaluations_ += referenced;
  evaluations_ += static_cast<std::int64_t>(fitness.size());
  generation_ = g;
  asked_.reset();
  history_.push_back(row(population_, reference_point_, discarded, copies));
  history_.back().back() = wall_offset_ + now_seconds() - started_;
  return true;
}

void Nsga2::set_reference_point(std::vector<double> point) {
  if (generation_ >= 0)
    throw Error(fmt::format(
        "Nsga2.set_reference_point: the reference point is fixed before the first generation (this "
        "search is at generation {})",
        generation_));
  if (point.size() != criteria_.size())
    throw Error(fmt::format("Nsga2.set_reference_point: {} values for the {} criteria",
                            point.size(), criteria_.size()));
  for (std::size_t j = 0; j < point.size(); ++j)
    if (!std::isfinite(point[j]))
      throw Error(fmt::format("Nsga2.set_reference_point: {} = {} (it must be finite)", names_[j],
                              point[j]));
  reference_point_ = std::move(point);
}

std::vector<const Solution*> Nsga2::front() const {
  std::vector<const Solution*> out;
  for (const Solution& s : population_)
    if (s.feasible && s.rank == 0) out.push_back(&s);
  std::stable_sort(out.begin(), out.end(), [&](const Solution* a, const Solution* b) {
    return minimised(a->objectives) < minimised(b->objectives);
  });
  return out;
}

std::vector<double> Nsga2::row(const std::vector<Solution>& population,
                               const std::vector<double>& reference_point, int discarded,
                               int copies) const {
  std::vector<std::vector<double>> front, front_minimised;
  int disagreements = 0, feasible = 0;
  for (const Solution& s : population) {
    feasible += s.feasible ? 1 : 0;
    if (!s.feasible || s.rank != 0) continue;
    front.push_back(s.objectives);
    front_minimised.push_back(minimised(s.objectives));
    if (s.reference.empty()) continue;
    for (std::size_t j = 0; j < criteria_.size(); ++j)
      if (std::isnan(s.reference[j]) || reference_disagrees(criteria_of(s.result, s.supplied)[j],
                                                            s.reference[j], config_->evaluation)) {
        ++disagreements;
        break;
      }
  }
  double hv = kNaN;
  if (!reference_point.empty() && criteria_.size() <= 2)
    hv = hypervolume(front_minimised, minimised(reference_point));
  std::vector<double> out = {static_cast<double>(generation_), static_cast<double>(evaluations_),
                             static_cast<double>(front.size()), hv};
  for (std::size_t j = 0; j < criteria_.size(); ++j) {
    double best = kNaN;
    for (const auto& v : front)
      if (std::isnan(best) || (maximize_[j] ? v[j] > best : v[j] < best)) best = v[j];
    out.push_back(best);
  }
  for (const int x : {feasible, discarded, copies}) out.push_back(static_cast<double>(x));
  out.push_back(static_cast<double>(reference_evaluations_));
  out.push_back(static_cast<double>(disagreements));
  out.push_back(0.0);  // wall_seconds, set by the caller
  return out;
}

std::vector<HistoryColumn> Nsga2::history_columns() const {
  return search_history_columns("nsga2", names_);
}

std::string Nsga2::stop_reason() const {
  // The stall: generations since the hypervolume last rose above every earlier one (with three or
  // more criteria there is none, and no stall).
  int stalled = 0;
  double best = kNaN;
  for (const auto& row : history_) {
    const double hv = row[3];
    if (!std::isnan(hv) && (std::isnan(best) || hv > best)) {
      best = hv;
      stalled = 0;
    } else {
      ++stalled;
    }
  }
  if (criteria_.size() > 2) stalled = 0;
  return stop_rule(*config_, generation_, wall_offset_ + now_seconds() - started_, stalled,
                   "hypervolume not increased");
}

std::string Nsga2::checkpoint() const {
  if (generation_ < 0) throw Error("Nsga2.checkpoint: no generation completed yet");
  json p =
      payload_head(kNsga2Format, kNsga2Version, identity_,
                   {generation_, evaluations_, reference_evaluations_, history_.back().back()});
  p["reference_point"] = reference_point_.empty() ? json(nullptr) : values_json(reference_point_);
  json members = json::array();
  for (const Solution& s : population_) {
    json j{{"genome", json::parse(to_json(s.genome))},
           {"result", fitness_to_json(s.result)},
           {"generation", s.generation},
           {"rank", s.rank},
           {"crowding", crowding_json(s.crowding)}};
    if (!s.reference.empty()) j["reference"] = values_json(s.reference);
    // the values of the caller's criteria, which the result does not hold
    if (!s.supplied.empty()) j["supplied"] = values_json(s.supplied);
    members.push_back(std::move(j));
  }
  p["population"] = std::move(members);
  p["history"] = history_to_json(history_, history_columns());
  return seal(p);
}

void Nsga2::restore(std::string_view text, std::string_view source) {
  const json p = unseal(text, source, kNsga2Format, kNsga2Version, identity_);
  auto fail = [&](const std::string& what) { inconsistent(source, what); };
  reading_checkpoint(source, [&] {
    const auto [generation, evaluations, reference_evaluations, wall] = read_counters(p);
    const std::size_t m = criteria_.size();
    auto read_values = [&](const json& j, const char* what, bool allow_nan) {
      if (!j.is_array() || j.size() != m) fail(fmt::format("{} must list {} values", what, m));
      std::vector<double> v;
      for (const json& x : j) {
        if (allow_nan && x.is_null()) {
          v.push_back(kNaN);
          continue;
        }
        if (!x.is_number() || !std::isfinite(x.get<double>()))
          fail(fmt::format("{} holds {}, expected a finite number", what, detail::describe(x)));
        v.push_back(x.get<double>());
      }
      return v;
    };
    std::vector<double> reference_point;
    if (!p.contains("reference_point")) fail("no reference_point");
    if (!p["reference_point"].is_null())
      reference_point = read_values(p["reference_point"], "reference_point", false);
    if (!p.contains("population") || !p["population"].is_array()) fail("no population");
    if (p["population"].size() != static_cast<std::size_t>(size_))
      fail(fmt::format("{} members, evolution.population is {}", p["population"].size(), size_));
    std::vector<Solution> population;
    for (const json& j : p["population"]) {
      Solution s;
      if (!j.contains("genome") || !j.contains("result"))
        fail(fmt::format("member {} has no genome or result", population.size()));
      s.genome = genome_from_json(j["genome"].dump(), config_->genome, source);
      s.result = fitness_from_json(j["result"]);
      s.feasible = archivable(s.result);
      const std::size_t own = supplied_->names.size();
      if (own > 0 && s.feasible) {
        json supplied = j.contains("supplied") ? j["supplied"] : json();
        if (supplied.is_null())  // a search that measured them itself (animat_evolve)
          if (const auto measured = supplied_->from_table(s.result)) supplied = *measured;
        if (!supplied.is_array() || supplied.size() != own)
          fail(fmt::format("member {} has no list of its {} supplied criterion values",
                           population.size(), own));
        for (const json& x : supplied) s.supplied.push_back(x.is_number() ? x.get<double>() : kNaN);
      }
      s.objectives = criteria_of(s.result, s.supplied);
      if (s.feasible)
        for (std::size_t c = 0; c < m; ++c)
          if (!std::isfinite(s.objectives[c]))
            fail(fmt::format("member {} has {} = {}", population.size(), criteria_[c]->name,
                             s.objectives[c]));
      s.generation = static_cast<int>(int_field(j, "generation", 0, generation));
      s.rank = static_cast<int>(int_field(j, "rank", 0, 2 * static_cast<long long>(size_)));
      s.crowding = crowding_field(j);
      if (j.contains("reference")) s.reference = read_values(j["reference"], "reference", true);
      if (select_ && s.feasible) compare_reference(s);
      population.push_back(std::move(s));
    }
    const auto columns = history_columns();
    const auto hist = history_from_json(p.contains("history") ? p["history"] : json(), columns);
    check_history(hist, generation, source);
    // The last row is what the engine computes from the population.
    Nsga2 probe(*this);
    probe.generation_ = generation;
    probe.evaluations_ = evaluations;
    probe.reference_evaluations_ = reference_evaluations;
    const std::vector<double>& last = hist.back();
    const std::size_t at = 4 + m;  // feasible, discarded, copies, ...
    std::vector<double> expected =
        probe.row(population, reference_point, static_cast<int>(last[at + 1]),
                  static_cast<int>(last[at + 2]));
    expected.back() = wall;
    check_last_row(last, expected, columns, "the population", source);
    population_ = std::move(population);
    reference_point_ = std::move(reference_point);
    generation_ = generation;
    evaluations_ = evaluations;
    reference_evaluations_ = reference_evaluations;
    history_ = hist;
    wall_offset_ = wall;
    started_ = now_seconds();
    asked_.reset();
  });
}

}  // namespace animat
