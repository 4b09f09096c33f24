// MAP-Elites over a grid archive (search.hpp), as animat.qd.MapElites draws and archives.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/evaluator.hpp"
#include "animat/objective_table.hpp"
#include "animat/run_identity.hpp"
#include "animat/search.hpp"
#include "search_state.hpp"

namespace animat {

using namespace search_state;

namespace {

constexpr int kMapElitesVersion = 1;
constexpr const char* kMapElitesFormat = "animat.map_elites";

std::string bins_text(const std::vector<int>& bins) {
  return fmt::format("[{}]", fmt::join(bins, ", "));
}

bool nonnegative_objective(const Config& c) {
  const ObjectiveSpec* spec = find_objective(c.evaluation.objective);
  return spec != nullptr && spec->nonnegative;
}

// A candidate may enter the archive: viable, stable and valid (the engine scores the others 0).
bool archivable(const Fitness& f) { return f.viable && f.stable && f.valid; }

}  // namespace

// ---------------------------------------------------------------------------------------------------
namespace {

// `ranges`, or empty: each descriptor's own; ConfigError naming search.ranges unless one finite
// lo < hi per descriptor.
std::vector<Range> checked_ranges(const std::vector<const Measure*>& descriptors,
                                  std::vector<Range> ranges) {
  if (ranges.empty())
    for (const Measure* d : descriptors) ranges.push_back({d->lo, d->hi});
  if (ranges.size() != descriptors.size())
    throw ConfigError(fmt::format("search.ranges: {} ranges for {} descriptors; give one each",
                                  ranges.size(), descriptors.size()));
  for (std::size_t j = 0; j < ranges.size(); ++j)
    if (!std::isfinite(ranges[j].lo) || !std::isfinite(ranges[j].hi) ||
        !(ranges[j].lo < ranges[j].hi))
      throw ConfigError(fmt::format(
          "search.ranges: the range of \"{}\", [{}, {}], is not finite lo < hi (a measure "
          "without a range in the table needs one in search.ranges)",
          descriptors[j]->name, ranges[j].lo, ranges[j].hi));
  return ranges;
}

}  // namespace

Archive::Archive(std::vector<const Measure*> descriptors, std::vector<int> bins,
                 std::vector<Range> ranges)
    : descriptors_(std::move(descriptors)),
      bins_(std::move(bins)),
      ranges_(checked_ranges(descriptors_, std::move(ranges))) {
  if (bins_.size() != descriptors_.size())
    throw ConfigError(fmt::format("search.bins = {}: one count per descriptor ({}) is needed",
                                  bins_text(bins_), descriptors_.size()));
  double product = 1.0;
  for (int b : bins_) {
    if (b < 1)
      throw ConfigError(
          fmt::format("search.bins = {}: every count must be >= 1", bins_text(bins_)));
    product *= b;
  }
  // Checked in floating point first: the integer product of 4 x 100000 bins would wrap.
  if (product > static_cast<double>(kMaxArchiveCells))
    throw ConfigError(fmt::format(
        "search.bins = {} over {} descriptors makes {:.6g} cells; an archive holds at most {} "
        "(fewer bins, or fewer descriptors)",
        bins_text(bins_), descriptors_.size(), product, kMaxArchiveCells));
  cells_ = 1;
  for (int b : bins_) cells_ *= static_cast<std::size_t>(b);
}

Archive Archive::cvt(std::vector<const Measure*> descriptors, std::vector<Range> ranges,
                     std::vector<std::vector<double>> centroids) {
  // a grid of one cell checks the descriptors and ranges; the centroids then replace its bins
  const std::size_t dims = descriptors.size();
  Archive a(std::move(descriptors), std::vector<int>(dims, 1), std::move(ranges));
  a.bins_.clear();
  a.centroids_ = std::move(centroids);
  a.check_centroids();
  a.cells_ = a.centroids_.size();
  return a;
}

void Archive::check_centroids() const {
  if (centroids_.empty() || centroids_.size() > static_cast<std::size_t>(kMaxArchiveCells))
    throw ConfigError(fmt::format("centroids: {} rows; a CVT archive has 1 to {} cells",
                                  centroids_.size(), kMaxArchiveCells));
  for (std::size_t c = 0; c < centroids_.size(); ++c) {
    if (centroids_[c].size() != dims())
      throw ConfigError(fmt::format("centroids: row {} has {} values for the {} descriptors", c,
                                    centroids_[c].size(), dims()));
    for (double x : centroids_[c])
      if (!(x >= 0.0 && x <= 1.0))  // NaN too
        throw ConfigError(fmt::format(
            "centroids: row {} holds {}; a centroid lies in the unit cube [0, 1]", c, x));
  }
}

std::size_t Archive::index_of(std::span<const double> values) const {
  if (!centroids_.empty()) {
    std::vector<double> unit(dims());
    for (std::size_t j = 0; j < dims(); ++j)
      unit[j] = std::clamp((values[j] - ranges_[j].lo) / (ranges_[j].hi - ranges_[j].lo), 0.0, 1.0);
    return nearest_centroid(unit, centroids_);
  }
  std::size_t index = 0;
  for (std::size_t j = 0; j < descriptors_.size(); ++j) {
    const int n = bins_[j];
    const double lo = ranges_[j].lo, hi = ranges_[j].hi, x = values[j];
    // numpy.linspace(lo, hi, n + 1): edge k is k * step + lo, the last one hi exactly
    const double step = (hi - lo) / n;
    auto edge = [&](int k) { return k == n ? hi : k * step + lo; };
    int b = 0;
    if (x >= hi) {
      b = n - 1;
    } else if (x >= lo) {
      b = std::clamp(static_cast<int>(std::floor((x - lo) / step)), 0, n - 1);
      while (b + 1 < n && edge(b + 1) <= x) ++b;
      while (b > 0 && edge(b) > x) --b;
    }
    index = index * static_cast<std::size_t>(n) + static_cast<std::size_t>(b);
  }
  return index;
}

bool Archive::add(Elite elite) {
  const std::size_t cell = index_of(elite.descriptors);
  auto it = elites_.find(cell);
  if (it != elites_.end() && !(elite.objective > it->second.objective)) return false;
  elites_[cell] = std::move(elite);
  return true;
}

double Archive::qd_score() const {
  std::vector<double> terms;
  terms.reserve(elites_.size());
  for (const auto& [cell, e] : elites_) terms.push_back(e.objective);
  return exact_sum(terms);
}

double Archive::coverage() const {
  return static_cast<double>(elites_.size()) / static_cast<double>(cells_);
}

const Elite* Archive::best() const {
  const Elite* best = nullptr;
  for (const auto& [cell, e] : elites_)
    if (best == nullptr || e.objective > best->objective) best = &e;
  return best;
}

// ---------------------------------------------------------------------------------------------------
namespace {

// search.descriptors' measures: those named in `supplied` (the caller's), the others the table's.
std::vector<const Measure*> descriptors_of(const Config& config,
                                           const std::vector<Measure>& supplied) {
  std::vector<const Measure*> out;
  for (const std::string& name : config.search.descriptors) {
    const auto own = std::find_if(supplied.begin(), supplied.end(),
                                  [&](const Measure& m) { return m.name == name; });
    if (own != supplied.end()) {
      if (config.search.ranges.empty() && !(own->lo < own->hi))
        throw ConfigError(fmt::format(
            "search.descriptors: \"{}\" is supplied by the caller and has no range in the measures "
            "table: give the descriptors' ranges in search.ranges",
            name));
      out.push_back(&*own);
      continue;
    }
    const Measure& m = find_measure(name, config, "search.descriptors");
    if (!(m.lo < m.hi) && config.search.ranges.empty())
      throw ConfigError(fmt::format(
          "search.descriptors: \"{}\" has no range in the measures table (a criterion of "
          "NSGA-II only): give the descriptors' ranges in search.ranges, or use those with a "
          "range: fitness, cells",
          name));
    out.push_back(&m);
  }
  return out;
}

// search.ranges as pairs; empty: the measures' own ranges (Archive).
std::vector<Range> ranges_of(const Config& config) {
  const auto& r = config.search.ranges;
  std::vector<Range> out;
  if (r.size() % 2 != 0)
    throw ConfigError(
        fmt::format("search.ranges: {} numbers; give lo and hi for each descriptor", r.size()));
  for (std::size_t j = 0; j < r.size(); j += 2) out.push_back({r[j], r[j + 1]});
  return out;
}

std::vector<int> bins_of(const Config& config) {
  const auto& b = config.search.bins;
  const std::size_t dims = config.search.descriptors.size();
  std::vector<int> out;
  for (std::size_t j = 0; j < dims; ++j)
    out.push_back(static_cast<int>(b.size() == 1 ? b[0] : b.at(j)));
  return out;
}

// search.archive's archive: a grid of search.bins, or a CVT of the caller's centroids or
// search.cells centroids computed from evolution.seed's samples.
Archive archive_of(const Config& config, std::vector<const Measure*> descriptors,
                   const std::vector<std::vector<double>>& centroids) {
  const SearchParams& s = config.search;
  if (s.archive != "cvt") {
    if (!centroids.empty())
      throw ConfigError(fmt::format(
          "centroids: given for search.archive = \"{}\"; centroids are a CVT archive's (\"cvt\")",
          s.archive));
    return Archive(std::move(descriptors), bins_of(config), ranges_of(config));
  }
  if (!centroids.empty()) return Archive::cvt(std::move(descriptors), ranges_of(config), centroids);
  const std::size_t dims = descriptors.size();
  const auto cells = static_cast<std::size_t>(s.cells);
  const auto samples = static_cast<std::size_t>(s.samples);
  check_cvt_size(dims, cells, samples, "search.cells", "search.samples");
  return Archive::cvt(
      std::move(descriptors), ranges_of(config),
      cvt_centroids(dims, cells, static_cast<std::uint64_t>(config.evolution.seed), samples));
}

}  // namespace

MapElites::MapElites(const Config& config, FitnessFunction fitness, FitnessFunction reference,
                     std::shared_ptr<Evaluator> evaluator, const std::vector<std::string>& supplied,
                     const std::vector<std::vector<double>>& centroids)
    : config_(std::make_shared<const Config>(config)),
      identity_(run_identity(config)),
      supplied_(std::make_shared<const SuppliedMeasures>(supplied, config.search.descriptors,
                                                         "search.descriptors", config)),
      archive_(archive_of(config, descriptors_of(config, supplied_->measures), centroids)),
      batch_(config.search.batch > 0 ? config.search.batch : config.evolution.population),
      started_(now_seconds()) {
  if (config.evaluation.reference_check != "off") reference_ = std::move(reference);
  select_ = reference_ && config.evaluation.reference_check == "select";
  evaluator_ = evaluator ? std::move(evaluator)
                         : (fitness ? make_local_evaluator(config, std::move(fitness)) : nullptr);
}

std::vector<Genome> MapElites::ask() {
  if (asked_) return *asked_;
  const int g = generation_ + 1;
  const auto seed = static_cast<std::uint64_t>(config_->evolution.seed);
  const auto n = static_cast<std::size_t>(batch_);
  std::vector<Genome> out(n);
  if (archive_.elites().empty()) {
    parallel_for(n, config_->evolution.threads, [&](std::size_t i) {
      Rng rng = Rng::derive(seed, static_cast<std::uint64_t>(g), i);
      out[i] = random_viable_genome(*config_, rng);
    });
  } else {
    std::vector<const Genome*> parents;
    for (const auto& [cell, e] : archive_.elites()) parents.push_back(&e.genome);
    const auto top = static_cast<std::int64_t>(parents.size()) - 1;
    const auto pick = [&](Rng& rng) -> const Genome& {
      return *parents[static_cast<std::size_t>(rng.integer(0, top))];
    };
    for (std::size_t i = 0; i < n; ++i)
      out[i] = offspring(*config_, seed, g, i, config_->evolution.crossover_fraction, pick);
  }
  asked_ = std::move(out);
  return *asked_;
}

bool MapElites::tell(const std::vector<Fitness>& fitness,
                     const std::vector<std::vector<double>>& supplied) {
  if (!asked_) throw Error("MapElites.tell: nothing was asked (call ask() first)");
  const std::vector<Genome>& genomes = *asked_;
  if (fitness.size() != genomes.size())
    throw Error(
        fmt::format("MapElites.tell: {} fitness values for the {} genomes of the last ask()",
                    fitness.size(), genomes.size()));
  const std::size_t own = supplied_->names.size();
  check_supplied_rows("MapElites", own, supplied.size(), genomes.size());
  const bool nonnegative = nonnegative_objective(*config_);
  // 1. Check every value and find where each candidate would go; nothing changes yet.
  std::vector<std::vector<double>> values(fitness.size());
  for (std::size_t k = 0; k < fitness.size(); ++k) {
    const Fitness& f = fitness[k];
    if (!std::isfinite(f.fitness) || (nonnegative && f.fitness < 0.0))
      refuse("MapElites", k,
             fmt::format("fitness {} (a fitness must be finite{})", f.fitness,
                         nonnegative ? fmt::format(" and >= 0 under evaluation.objective = \"{}\"",
                                                   config_->evaluation.objective)
                                     : std::string()));
    // The QD-score sums one objective per cell: beyond this bound the sum could overflow.
    const double limit = std::numeric_limits<double>::max() / static_cast<double>(archive_.cells());
    if (std::abs(f.fitness) > limit)
      refuse("MapElites", k,
             fmt::format("fitness {} is beyond +-{:.6g}, where the QD-score of {} cells could "
                         "overflow",
                         f.fitness, limit, archive_.cells()));
    if (f.cell_count < 0) refuse("MapElites", k, fmt::format("cell_count {}", f.cell_count));
    if (!archivable(f)) continue;
    if (own > 0 && supplied[k].size() != own)
      refuse("MapElites", k,
             fmt::format("{} supplied descriptor values for the {} supplied descriptors",
                         supplied[k].size(), own));
    for (const Measure* d : archive_.descriptors()) {
      const double x = d->of ? d->of(f) : supplied[k][supplied_->index_of(d)];
      if (!std::isfinite(x))
        refuse("MapElites", k,
               fmt::format("descriptor {} = {} (a descriptor must be finite)", d->name, x));
      values[k].push_back(x);
    }
  }
  const int g = generation_ + 1;
  // 2. The exploit guard "select": every candidate's reference fitness, which the archive then
  // compares, before anything changes (it may throw).
  std::vector<std::size_t> candidates;
  for (std::size_t k = 0; k < fitness.size(); ++k)
    if (archivable(fitness[k])) candidates.push_back(k);
  std::vector<double> objective(fitness.size(), std::numeric_limits<double>::quiet_NaN());
  std::vector<double> reference = objective;
  for (std::size_t k : candidates) objective[k] = fitness[k].fitness;
  if (select_) {
    std::vector<const Genome*> todo;
    for (std::size_t k : candidates) todo.push_back(&genomes[k]);
    const auto refs = evaluate_references(reference_, reference_hook_, *config_, todo,
                                          supplied_->names.size(), "MapElites.tell")
                          .fitness;
    for (std::size_t r = 0; r < candidates.size(); ++r)
      objective[candidates[r]] = reference[candidates[r]] = refs[r].fitness;
  }
  // 3. Where each candidate goes, in the order of ask(): a cell's elite gives way to a strictly
  // greater objective.
  std::map<std::size_t, std::size_t> winner;  // cell -> the candidate that holds it at the end
  int added = 0;
  for (std::size_t k : candidates) {
    const std::size_t cell = archive_.index_of(values[k]);
    double current = -std::numeric_limits<double>::infinity();
    bool held = false;
    if (auto w = winner.find(cell); w != winner.end()) {
      current = objective[w->second];
      held = true;
    } else if (auto e = archive_.elites().find(cell); e != archive_.elites().end()) {
      current = e->second.objective;
      held = true;
    }
    if (held && !(objective[k] > current)) continue;
    winner[cell] = k;
    ++added;
  }
  // 4. The exploit guard "record": the reference of every elite that entered (may throw: still
  // nothing changed).
  if (reference_ && !select_) {
    std::vector<const Genome*> todo;
    for (const auto& [cell, k] : winner) todo.push_back(&genomes[k]);
    const auto refs = evaluate_references(reference_, reference_hook_, *config_, todo,
                                          supplied_->names.size(), "MapElites.tell")
                          .fitness;
    std::size_t r = 0;
    for (const auto& [cell, k] : winner) reference[k] = refs[r++].fitness;
  }
  // 5. Commit.
  for (const auto& [cell, k] : winner)
    archive_.elites()[cell] =
        Elite{genomes[k], fitness[k], values[k], objective[k], reference[k], g};
  if (reference_)
    reference_evaluations_ +=
        static_cast<std::int64_t>(select_ ? candidates.size() : winner.size());
  evaluations_ += static_cast<std::int64_t>(fitness.size());
  generation_ = g;
  asked_.reset();
  history_.push_back(row(added, static_cast<int>(fitness.size() - candidates.size())));
  return true;
}

int MapElites::disagreements(const Archive& archive) const {
  int n = 0;
  for (const auto& [cell, e] : archive.elites())
    if (!std::isnan(e.reference) &&
        reference_disagrees(e.result.fitness, e.reference, config_->evaluation))
      ++n;
  return n;
}

std::vector<double> MapElites::row(int added, int discarded) const {
  const Elite* best = archive_.best();
  return {static_cast<double>(generation_),
          static_cast<double>(evaluations_),
          archive_.qd_score(),
          archive_.coverage(),
          best ? best->objective : std::numeric_limits<double>::quiet_NaN(),
          static_cast<double>(archive_.elites().size()),
          static_cast<double>(added),
          static_cast<double>(discarded),
          static_cast<double>(reference_evaluations_),
          static_cast<double>(disagreements(archive_)),
          wall_offset_ + now_seconds() - started_};
}

std::vector<HistoryColumn> MapElites::history_columns() const {
  return search_history_columns("map_elites");
}

std::string MapElites::stop_reason() const {
  // The stall: generations since one added an elite or improved one (history's "added").
  int stalled = 0;
  for (const auto& row : history_) stalled = row[6] > 0 ? 0 : stalled + 1;
  return stop_rule(*config_, generation_, wall_offset_ + now_seconds() - started_, stalled,
                   "no elite added or improved");
}

std::string MapElites::checkpoint() const {
  if (generation_ < 0) throw Error("MapElites.checkpoint: no generation completed yet");
  json p =
      payload_head(kMapElitesFormat, kMapElitesVersion, identity_,
                   {generation_, evaluations_, reference_evaluations_, history_.back().back()});
  json elites = json::array();
  for (const auto& [cell, e] : archive_.elites()) {
    elites.push_back(json{{"cell", cell},
                          {"genome", json::parse(to_json(e.genome))},
                          {"result", fitness_to_json(e.result)},
                          {"reference", nan_or(e.reference)},
                          {"generation", e.generation}});
    // the values of the caller's descriptors, which the result does not hold
    if (!supplied_->names.empty()) {
      json own = json::array();
      for (std::size_t j = 0; j < archive_.dims(); ++j)
        if (archive_.descriptors()[j]->of == nullptr) own.push_back(e.descriptors[j]);
      elites.back()["supplied"] = std::move(own);
    }
  }
  p["elites"] = std::move(elites);
  if (!archive_.centroids().empty()) p["centroids"] = archive_.centroids();
  p["history"] = history_to_json(history_, history_columns());
  return seal(p);
}

void MapElites::restore(std::string_view text, std::string_view source) {
  const json p = unseal(text, source, kMapElitesFormat, kMapElitesVersion, identity_);
  auto fail = [&](const std::string& what) { inconsistent(source, what); };
  reading_checkpoint(source, [&] {
    const auto [generation, evaluations, reference_evaluations, wall] = read_counters(p);
    if (!archive_.centroids().empty() &&
        (!p.contains("centroids") || p["centroids"] != json(archive_.centroids())))
      fail(
          "the CVT archive's centroids are not this search's (search.cells, search.samples, "
          "evolution.seed or the caller's centroids differ)");
    Archive archive = archive_;
    archive.elites().clear();
    if (!p.contains("elites") || !p["elites"].is_array()) fail("no list of elites");
    if (p["elites"].size() > archive.cells())
      fail(fmt::format("{} elites for {} cells", p["elites"].size(), archive.cells()));
    const bool nonnegative = nonnegative_objective(*config_);
    for (const json& je : p["elites"]) {
      Elite e;
      const auto cell = static_cast<std::size_t>(
          int_field(je, "cell", 0, static_cast<long long>(archive.cells()) - 1));
      if (!je.contains("genome")) fail(fmt::format("the elite of cell {} has no genome", cell));
      e.genome = genome_from_json(je["genome"].dump(), config_->genome, source);
      if (!je.contains("result")) fail(fmt::format("the elite of cell {} has no result", cell));
      e.result = fitness_from_json(je["result"]);
      if (!archivable(e.result))
        fail(fmt::format("the elite of cell {} is not viable, stable and valid", cell));
      if (nonnegative && e.result.fitness < 0.0)
        fail(fmt::format("the elite of cell {} has fitness {} (a fitness is >= 0)", cell,
                         e.result.fitness));
      const std::size_t own = supplied_->names.size();
      json supplied = je.contains("supplied") ? je["supplied"] : json();
      if (own > 0 && supplied.is_null())  // a search that measured them itself (animat_evolve)
        if (const auto measured = supplied_->from_table(e.result)) supplied = *measured;
      if (own > 0 && (!supplied.is_array() || supplied.size() != own))
        fail(fmt::format("the elite of cell {} has no list of its {} supplied descriptor values",
                         cell, own));
      for (const Measure* d : archive.descriptors()) {
        double x = std::numeric_limits<double>::quiet_NaN();
        if (d->of) {
          x = d->of(e.result);
        } else if (const json& v = supplied[supplied_->index_of(d)]; v.is_number()) {
          x = v.get<double>();
        }
        if (!std::isfinite(x))
          fail(fmt::format("the elite of cell {} has {} = {}", cell, d->name, x));
        e.descriptors.push_back(x);
      }
      if (archive.index_of(e.descriptors) != cell)
        fail(fmt::format("the elite of cell {} belongs to cell {} by its descriptors", cell,
                         archive.index_of(e.descriptors)));
      if (archive.elites().contains(cell)) fail(fmt::format("cell {} holds two elites", cell));
      e.reference = nan_or_number(je, "reference");
      // under "select" the archive compares the reference fitness
      e.objective = select_ ? e.reference : e.result.fitness;
      if (std::isnan(e.objective))
        fail(
            fmt::format("the elite of cell {} has no reference fitness (evaluation.reference_check "
                        "= \"select\")",
                        cell));
      e.generation = static_cast<int>(int_field(je, "generation", 0, generation));
      archive.elites()[cell] = std::move(e);
    }
    const auto columns = history_columns();
    const auto hist = history_from_json(p.contains("history") ? p["history"] : json(), columns);
    check_history(hist, generation, source);
    // The last row is what the engine computes from the archive.
    MapElites probe(*this);
    probe.archive_ = archive;
    probe.generation_ = generation;
    probe.evaluations_ = evaluations;
    probe.reference_evaluations_ = reference_evaluations;
    const std::vector<double>& last = hist.back();
    std::vector<double> expected = probe.row(static_cast<int>(last[6]), static_cast<int>(last[7]));
    expected.back() = wall;
    check_last_row(last, expected, columns, "the archive", source);
    archive_ = std::move(archive);
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
