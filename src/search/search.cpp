// The search interface (search.hpp): the variation step, the checkpoint envelope shared by
// MAP-Elites and NSGA-II, the GA behind the interface, and make_search().
#include "animat/search.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "../json_util.hpp"
#include "animat/config.hpp"
#include "animat/development.hpp"
#include "animat/evaluator.hpp"
#include "animat/run_identity.hpp"
#include "search_state.hpp"

namespace animat {

double exact_sum(std::span<const double> values) {
  // Shewchuk's partials, rounded as CPython's math.fsum rounds them.
  std::vector<double> p;
  double special = 0.0;
  bool any_special = false;
  for (double x : values) {
    if (!std::isfinite(x)) {
      special += x;
      any_special = true;
      continue;
    }
    std::size_t i = 0;
    for (double y : p) {
      if (std::abs(x) < std::abs(y)) std::swap(x, y);
      const double hi = x + y;
      const double lo = y - (hi - x);
      if (lo != 0.0) p[i++] = lo;
      x = hi;
    }
    p.resize(i);
    p.push_back(x);
  }
  if (any_special) return special;
  double hi = 0.0;
  std::size_t n = p.size();
  if (n > 0) {
    hi = p[--n];
    double lo = 0.0;
    while (n > 0) {
      const double x = hi, y = p[--n];
      hi = x + y;
      lo = y - (hi - x);
      if (lo != 0.0) break;
    }
    if (n > 0 && ((lo < 0.0 && p[n - 1] < 0.0) || (lo > 0.0 && p[n - 1] > 0.0))) {
      const double y = lo * 2.0, x = hi + y;
      if (y == x - hi) hi = x;
    }
  }
  return hi;
}

// ---------------------------------------------------------------------------------------------------
// Breeding

Genome random_viable_genome(const Config& config, Rng& rng) {
  for (int tries = 1; tries <= config.evolution.max_init_tries; ++tries) {
    Genome g = random_genome(config.genome, rng);
    if (develop(g, config.genome, config.grn, config.development).viable) return g;
  }
  throw Error(fmt::format(
      "initial population: no viable random genome in evolution.max_init_tries = {} tries; the "
      "development or genome settings make viability too rare",
      config.evolution.max_init_tries));
}

Genome offspring(const Config& config, std::uint64_t seed, int g, std::size_t i,
                 double crossover_fraction, const std::function<const Genome&(Rng&)>& pick) {
  Rng rng = Rng::derive(seed, static_cast<std::uint64_t>(g), i);
  Genome child = pick(rng);
  if (rng.uniform() < crossover_fraction) {
    const Genome& other = pick(rng);
    child = crossover(child, other, config.mutation.crossover_points, rng);
  }
  mutate(child, config.mutation, config.genome, rng);
  return child;
}

// ---------------------------------------------------------------------------------------------------
// The interface

SuppliedMeasures::SuppliedMeasures(std::vector<std::string> names_in,
                                   const std::vector<std::string>& allowed, std::string_view key,
                                   const Config& config)
    : names(std::move(names_in)) {
  for (const std::string& name : names) {
    if (std::count(names.begin(), names.end(), name) > 1)
      throw ConfigError(fmt::format("{}: \"{}\" is supplied by the caller twice", key, name));
    if (std::find(allowed.begin(), allowed.end(), name) == allowed.end())
      throw ConfigError(
          fmt::format("{}: the caller supplies \"{}\", which is not one of its entries ({})", key,
                      name, fmt::join(allowed, ", ")));
    // `name` lives in `names`, which no longer changes: the pointer stays valid
    // a name of the measures table keeps its range and sense (the caller computes its values)
    const Measure* entry = nullptr;
    for (const Measure& m : animat::measures())
      if (name == m.name ||
          (name == config.evaluation.objective && &m == animat::measures().data()))
        entry = &m;
    table.push_back(entry);
    measures.push_back(
        entry == nullptr ? Measure{name.c_str(), "supplied by the caller", 0.0, 0.0, true, nullptr}
                         : Measure{name.c_str(), entry->meaning, entry->lo, entry->hi,
                                   entry->maximize, nullptr});
  }
}

std::optional<std::vector<double>> SuppliedMeasures::from_table(const Fitness& f) const {
  std::vector<double> out;
  for (const Measure* m : table) {
    if (m == nullptr || m->of == nullptr) return std::nullopt;
    out.push_back(m->of(f));
  }
  return out;
}

const Measure* SuppliedMeasures::find(std::string_view name) const {
  for (const Measure& m : measures)
    if (m.name == name) return &m;
  return nullptr;
}

bool Search::tell(const std::vector<Fitness>& fitness,
                  const std::vector<std::vector<double>>& supplied) {
  if (!supplied.empty())
    throw Error(fmt::format(
        "{}.tell: supplied values, but this search has no measure supplied by the caller",
        algorithm()));
  return tell(fitness);
}

std::vector<HistoryColumn> search_history_columns(std::string_view algorithm,
                                                  const std::vector<std::string>& criteria) {
  if (algorithm == "map_elites")
    return {{"generation", true},    {"evaluations", true},  {"qd_score", false},
            {"coverage", false},     {"best", false},        {"elites", true},
            {"added", true},         {"discarded", true},    {"reference_evaluations", true},
            {"disagreements", true}, {"wall_seconds", false}};
  if (algorithm == "nsga2") {
    std::vector<HistoryColumn> out = {
        {"generation", true}, {"evaluations", true}, {"front_size", true}, {"hypervolume", false}};
    // named as search.objectives names them ("best_distance" for the objective "distance")
    for (const std::string& name : criteria) out.push_back({"best_" + name, false});
    for (const char* name :
         {"feasible", "discarded", "copies", "reference_evaluations", "disagreements"})
      out.push_back({name, true});
    out.push_back({"wall_seconds", false});
    return out;
  }
  throw Error(fmt::format(
      "search_history_columns: \"{}\" is not \"map_elites\" or \"nsga2\" (the GA's history is "
      "the run's)",
      algorithm));
}

void Search::set_reference_hook(ReferenceHook hook) {
  if (algorithm() == "ga")
    throw Error(
        "set_reference_hook: the GA's exploit guard swims with the config's own evaluation; a "
        "reference hook is MAP-Elites' or NSGA-II's");
  reference_hook_ = std::move(hook);
}

const std::vector<std::string>& Search::supplied() const {
  static const std::vector<std::string> none;
  return none;
}

void Search::step(const EvaluateHook& evaluate, const DescribeHook& describe) {
  if (!evaluator_ && !evaluate)
    throw Error("Search::step: no evaluator (drive this search with ask and tell)");
  while (true) {
    const std::vector<Genome> genomes = ask();
    std::vector<Fitness> fitness;
    if (evaluate) {
      fitness = evaluate(genomes);
    } else {
      try {
        fitness = evaluator_->evaluate(genomes, stop_);
      } catch (const Interrupted&) {
        throw Interrupted(fmt::format("interrupted during generation {}", generation() + 1));
      }
    }
    if (fitness.size() != genomes.size())
      throw Error(fmt::format("{}: the evaluation gave {} fitness values for {} genomes",
                              algorithm(), fitness.size(), genomes.size()));
    std::vector<std::vector<double>> values;
    if (describe) values = describe(genomes, fitness);
    if (tell(fitness, values)) return;
  }
}

GaSearch::GaSearch(const Config& config, FitnessFunction fitness, FitnessFunction reference,
                   std::shared_ptr<Evaluator> evaluator, GenomeKey key)
    : evo_(config, fitness, std::move(reference), evaluator) {
  evo_.set_fitness_key(std::move(key));
  // step() evaluates as Evolution::step() would: with the given evaluator, else on this process's
  // threads.
  evaluator_ = evaluator ? std::move(evaluator)
                         : (fitness ? make_local_evaluator(config, std::move(fitness)) : nullptr);
}

std::vector<Genome> GaSearch::ask() {
  // The initial population's speculative draws, as Evolution::initialize() makes them (the result
  // does not depend on the lookahead).
  int lookahead = 1;
  if (evo_.generation() < 0) lookahead = 4;
  return evo_.ask(lookahead);
}

bool GaSearch::tell(const std::vector<Fitness>& fitness) { return evo_.tell(fitness); }

std::vector<HistoryColumn> GaSearch::history_columns() const {
  std::vector<HistoryColumn> out;
  const GenerationStats probe;
  visit_fields(probe, [&](const StatsField& f, const auto& value) {
    if (f.csv && !f.protection_only)
      out.push_back({f.name, !std::is_floating_point_v<std::decay_t<decltype(value)>>});
  });
  return out;
}

std::vector<std::vector<double>> GaSearch::history() const {
  std::vector<std::vector<double>> out;
  for (const GenerationStats& s : evo_.history()) {
    std::vector<double> row;
    visit_fields(s, [&](const StatsField& f, const auto& value) {
      if (f.csv && !f.protection_only) row.push_back(static_cast<double>(value));
    });
    out.push_back(std::move(row));
  }
  return out;
}

std::unique_ptr<Search> make_search(const Config& config, FitnessFunction fitness,
                                    FitnessFunction reference, std::shared_ptr<Evaluator> evaluator,
                                    const std::vector<std::string>& supplied,
                                    const std::vector<std::vector<double>>& centroids) {
  validate(config);
  if (!supplied.empty() && config.search.algorithm == "ga")
    throw ConfigError(
        "search.algorithm = \"ga\": measures supplied by the caller are MAP-Elites' descriptors "
        "or NSGA-II's criteria; the GA has none");
  if (!centroids.empty() && config.search.algorithm != "map_elites")
    throw ConfigError(
        fmt::format("search.algorithm = \"{}\": centroids are a MAP-Elites CVT archive's",
                    config.search.algorithm));
  GenomeKey key;  // the genome itself, for a caller's fitness function
  if (!fitness) {
    fitness = swim_fitness(config);
    if (config.evaluation.reference_check != "off")
      reference = swim_fitness(reference_config(config));
    key = evaluation_key(config);
  }
  if (!evaluator) evaluator = make_local_evaluator(config, fitness);
  const std::string& algorithm = config.search.algorithm;
  if (algorithm == "ga")
    return std::make_unique<GaSearch>(config, std::move(fitness), std::move(reference),
                                      std::move(evaluator), std::move(key));
  if (algorithm == "map_elites")
    return std::make_unique<MapElites>(config, std::move(fitness), std::move(reference),
                                       std::move(evaluator), supplied, centroids);
  if (algorithm == "nsga2")
    return std::make_unique<Nsga2>(config, std::move(fitness), std::move(reference),
                                   std::move(evaluator), supplied);
  throw ConfigError(fmt::format("search.algorithm = \"{}\": no such search", algorithm));
}

// ---------------------------------------------------------------------------------------------------
// Shared state helpers

namespace search_state {

namespace {
std::string hex(std::uint64_t x) { return fmt::format("{:016x}", x); }
}  // namespace

std::string seal(const json& payload) {
  const std::string body = payload.dump();
  return json{{"checksum", hex(fnv1a(body))}, {"payload", body}}.dump();
}

json unseal(std::string_view text, std::string_view source, std::string_view format, int version,
            std::uint64_t identity) {
  json outer;
  try {
    outer = detail::parse_bounded(text, 64);
  } catch (const detail::JsonLimit& e) {
    throw CheckpointError(fmt::format("{}: not an animat checkpoint ({})", source, e.what()));
  } catch (const json::exception&) {
    throw CheckpointError(
        fmt::format("{}: corrupt checkpoint (not valid JSON; truncated?)", source));
  }
  if (!outer.is_object() || !outer.contains("checksum") || !outer.contains("payload") ||
      !outer["payload"].is_string())
    throw CheckpointError(
        fmt::format("{}: not an animat checkpoint (missing checksum/payload)", source));
  const std::string body = outer["payload"].get<std::string>();
  if (outer["checksum"] != hex(fnv1a(body)))
    throw CheckpointError(
        fmt::format("{}: corrupt checkpoint: checksum {} does not match its content ({})", source,
                    detail::describe(outer["checksum"]), hex(fnv1a(body))));
  json p;
  try {
    p = detail::parse_bounded(body, 64);
  } catch (const std::exception& e) {
    throw CheckpointError(fmt::format("{}: corrupt checkpoint payload ({})", source, e.what()));
  }
  if (!p.is_object() || !p.contains("format") || p["format"] != std::string(format))
    throw CheckpointError(fmt::format(
        "{}: not a {} checkpoint (format {}); search.algorithm must be the run's own", source,
        format, p.is_object() && p.contains("format") ? detail::describe(p["format"]) : "none"));
  if (!p.contains("version") || !detail::int_in(p["version"], version, version))
    throw CheckpointError(fmt::format(
        "{}: checkpoint version {} is not supported (this build reads version {})", source,
        p.contains("version") ? detail::describe(p["version"]) : "none", version));
  if (!p.contains("identity") || p["identity"] != hex(identity))
    throw CheckpointError(fmt::format(
        "{}: checkpoint belongs to a different run configuration (identity {} vs {} for the "
        "current config); only {} may change on resume",
        source, p.contains("identity") ? detail::describe(p["identity"]) : "none", hex(identity),
        fmt::join(resumable_keys(), ", ")));
  return p;
}

json payload_head(std::string_view format, int version, std::uint64_t identity, const Counters& c) {
  json p;
  p["format"] = std::string(format);
  p["version"] = version;
  p["identity"] = hex(identity);
  p["generation"] = c.generation;
  p["evaluations"] = c.evaluations;
  p["reference_evaluations"] = c.reference_evaluations;
  p["wall_seconds"] = c.wall_seconds;
  return p;
}

Counters read_counters(const json& p) {
  Counters c;
  c.generation = static_cast<int>(int_field(p, "generation", 0, 100000000));
  c.evaluations = int_field(p, "evaluations", 0, 1LL << 53);
  c.reference_evaluations = int_field(p, "reference_evaluations", 0, 1LL << 53);
  c.wall_seconds = number_field(p, "wall_seconds");
  return c;
}

long long int_field(const json& j, const char* key, long long lo, long long hi) {
  if (!j.is_object() || !j.contains(key))
    throw CheckpointError(fmt::format("field \"{}\" is missing", key));
  const auto v = detail::int_in(j.at(key), lo, hi);
  if (!v)
    throw CheckpointError(fmt::format("field \"{}\" is {}, expected an integer in [{}, {}]", key,
                                      detail::describe(j.at(key)), lo, hi));
  return *v;
}

double number_field(const json& j, const char* key) {
  if (!j.is_object() || !j.contains(key))
    throw CheckpointError(fmt::format("field \"{}\" is missing", key));
  const auto v = detail::finite_number(j.at(key));
  if (!v)
    throw CheckpointError(fmt::format("field \"{}\" is {}, expected a finite number", key,
                                      detail::describe(j.at(key))));
  return *v;
}

bool bool_field(const json& j, const char* key) {
  if (!j.is_object() || !j.contains(key) || !j.at(key).is_boolean())
    throw CheckpointError(fmt::format(
        "field \"{}\" is {}, expected true or false", key,
        j.is_object() && j.contains(key) ? detail::describe(j.at(key)) : std::string("missing")));
  return j.at(key).get<bool>();
}

json nan_or(double x) { return std::isnan(x) ? json(nullptr) : json(x); }

double nan_or_number(const json& j, const char* key) {
  if (j.is_object() && j.contains(key) && j.at(key).is_null())
    return std::numeric_limits<double>::quiet_NaN();
  return number_field(j, key);
}

json fitness_to_json(const Fitness& f) {
  json j = json::object();
  visit_fields(f, [&](const char* name, const char*, const auto& value) { j[name] = value; });
  return j;
}

Fitness fitness_from_json(const json& j) {
  Fitness f;
  // A count is >= 0; a field whose default is below 0 (a "none" value) may also hold that value.
  visit_fields(f, [&](const char* name, const char*, auto& value) {
    using T = std::decay_t<decltype(value)>;
    if constexpr (std::is_same_v<T, bool>)
      value = bool_field(j, name);
    else if constexpr (std::is_same_v<T, int>)
      value =
          static_cast<int>(int_field(j, name, std::min(0, value), std::numeric_limits<int>::max()));
    else if constexpr (std::is_same_v<T, long>)
      value = static_cast<long>(int_field(j, name, 0, std::numeric_limits<long>::max()));
    else
      value = number_field(j, name);
  });
  return f;
}

json history_to_json(const std::vector<std::vector<double>>& rows,
                     const std::vector<HistoryColumn>& columns) {
  json out = json::array();
  for (const auto& row : rows) {
    json r = json::object();
    for (std::size_t c = 0; c < columns.size(); ++c)
      r[columns[c].name] =
          columns[c].integer ? json(static_cast<std::int64_t>(row[c])) : nan_or(row[c]);
    out.push_back(std::move(r));
  }
  return out;
}

std::vector<std::vector<double>> history_from_json(const json& j,
                                                   const std::vector<HistoryColumn>& columns) {
  if (!j.is_array()) throw CheckpointError("field \"history\" must be a list");
  std::vector<std::vector<double>> out;
  for (const json& r : j) {
    std::vector<double> row;
    for (const HistoryColumn& c : columns)
      row.push_back(c.integer ? static_cast<double>(int_field(r, c.name.c_str(), 0, 1LL << 53))
                              : nan_or_number(r, c.name.c_str()));
    out.push_back(std::move(row));
  }
  return out;
}

void inconsistent(std::string_view source, const std::string& what) {
  throw CheckpointError(fmt::format("{}: inconsistent checkpoint: {}", source, what));
}

void check_history(const std::vector<std::vector<double>>& rows, int generation,
                   std::string_view source) {
  if (rows.size() != static_cast<std::size_t>(generation) + 1)
    inconsistent(source, fmt::format("{} history rows for generation {}", rows.size(), generation));
  for (std::size_t k = 0; k < rows.size(); ++k)
    if (rows[k][0] != static_cast<double>(k))
      inconsistent(source, fmt::format("history row {} is generation {}", k, rows[k][0]));
}

void check_last_row(const std::vector<double>& last, const std::vector<double>& expected,
                    const std::vector<HistoryColumn>& columns, std::string_view state,
                    std::string_view source) {
  for (std::size_t c = 0; c < columns.size(); ++c)
    if (!(expected[c] == last[c] || (std::isnan(expected[c]) && std::isnan(last[c]))))
      inconsistent(source, fmt::format("the last history row has {} = {}, {} gives {}",
                                       columns[c].name, last[c], state, expected[c]));
}

std::string stop_rule(const Config& config, int generation, double wall, int stalled,
                      std::string_view improvement) {
  const EvolutionParams& ep = config.evolution;
  if (generation < 0) return {};
  if (ep.stall_generations > 0 && stalled >= ep.stall_generations)
    return fmt::format("{} for evolution.stall_generations = {} generations", improvement,
                       ep.stall_generations);
  if (ep.generations > 0 && generation >= ep.generations)
    return fmt::format("generation cap evolution.generations = {} reached", ep.generations);
  if (ep.wall_seconds > 0 && wall >= ep.wall_seconds)
    return fmt::format("wall-clock budget evolution.wall_seconds = {} s used", ep.wall_seconds);
  return {};
}

void check_supplied_rows(std::string_view who, std::size_t own, std::size_t rows,
                         std::size_t genomes) {
  if (own == 0 && rows > 0)
    throw Error(
        fmt::format("{}.tell: supplied values, but no measure is supplied by the caller", who));
  if (own > 0 && rows != genomes)
    throw Error(
        fmt::format("{}.tell: {} rows of supplied values for the {} genomes of the last ask()", who,
                    rows, genomes));
}

void refuse(std::string_view who, std::size_t k, const std::string& what) {
  throw Error(fmt::format("{}.tell: value {} (genome {} of the last ask()) is refused: {}", who, k,
                          k, what));
}

Search::ReferenceSwims evaluate_references(const FitnessFunction& reference,
                                           const Search::ReferenceHook& hook, const Config& config,
                                           const std::vector<const Genome*>& genomes,
                                           std::size_t supplied, std::string_view who) {
  Search::ReferenceSwims out;
  if (genomes.empty()) return out;
  if (hook) {
    std::vector<Genome> copies;
    copies.reserve(genomes.size());
    for (const Genome* g : genomes) copies.push_back(*g);
    out = hook(copies);
    if (out.fitness.size() != genomes.size())
      throw Error(fmt::format("{}: the reference hook gave {} fitness values for {} genomes", who,
                              out.fitness.size(), genomes.size()));
    if (!out.supplied.empty() && out.supplied.size() != genomes.size())
      throw Error(
          fmt::format("{}: the reference hook gave {} rows of supplied values for {} genomes", who,
                      out.supplied.size(), genomes.size()));
    for (std::size_t k = 0; k < out.supplied.size(); ++k)
      if (out.supplied[k].size() != supplied)
        throw Error(fmt::format(
            "{}: the reference hook gave {} supplied values for genome {}; the search supplies {}",
            who, out.supplied[k].size(), k, supplied));
  } else {
    out.fitness.resize(genomes.size());
    parallel_for(genomes.size(), config.evolution.threads,
                 [&](std::size_t k) { out.fitness[k] = reference(*genomes[k]); });
  }
  for (std::size_t k = 0; k < out.fitness.size(); ++k)
    if (!std::isfinite(out.fitness[k].fitness))
      throw Error(fmt::format("{}: the exploit guard's reference evaluation {} gave fitness {}",
                              who, k, out.fitness[k].fitness));
  return out;
}

}  // namespace search_state

}  // namespace animat
