#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/function.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/shared_ptr.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/string_view.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <fmt/format.h>

#include <atomic>
#include <cmath>
#include <mutex>
#include <unordered_set>

#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/evaluator.hpp"
#include "animat/evolution.hpp"
#include "animat/objective.hpp"
#include "animat/run.hpp"
#include "animat/search.hpp"
#include "bindings.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace animat::py {
namespace {

// GenerationStats' fields, pickling and dicts from its one descriptor (visit_fields in
// evolution.hpp).
nb::dict stats_dict(const GenerationStats& s) {
  nb::dict d;
  visit_fields(s, [&](const StatsField& f, const auto& value) { d[f.name] = value; });
  return d;
}

// Every field is required but those a checkpoint may lack (they keep their defaults), as in a
// checkpoint.
GenerationStats stats_from_dict(const nb::dict& d) {
  GenerationStats s;
  visit_fields(s, [&](const StatsField& f, auto& value) {
    using T = std::decay_t<decltype(value)>;
    const bool optional = f.checkpoint == StatsField::Checkpoint::later ||
                          f.checkpoint == StatsField::Checkpoint::when_set;
    if (optional && !d.contains(f.name)) return;
    value = nb::cast<T>(d[f.name]);
  });
  return s;
}

// An Evolution's ask() and tell() run without the GIL (the exploit guard's reference swims, a
// Python objective scoring them on the evaluation threads): every method holds a lease on its
// engine, and a second thread gets a RuntimeError instead of a data race.
// The C++ searches (search.hpp) behind one class: ask/tell/step/checkpoint of the config's
// search.algorithm, with the config's own evaluation (swim_fitness) and exploit guard.
struct SearchEngine {
  std::unique_ptr<Search> search;
};

// MAP-Elites' archive on its own (animat.qd's GridArchive and CVTArchive keep one): the engine's
// cells and insertion rule over descriptors named by the caller.
struct ArchiveCore {
  std::shared_ptr<const SuppliedMeasures> measures;
  Archive archive;
};

ArchiveCore make_archive_core(const std::vector<std::string>& names,
                              const std::vector<std::pair<double, double>>& ranges,
                              const std::vector<int>& bins,
                              const std::vector<std::vector<double>>& centroids) {
  auto measures = std::make_shared<const SuppliedMeasures>(names, names, "descriptors", Config{});
  std::vector<const Measure*> descriptors;
  for (const Measure& m : measures->measures) descriptors.push_back(&m);
  std::vector<Range> r;
  for (const auto& [lo, hi] : ranges) r.push_back(Range{lo, hi});
  if (centroids.empty()) return ArchiveCore{measures, Archive(descriptors, bins, r)};
  return ArchiveCore{measures, Archive::cvt(descriptors, r, centroids)};
}

class SearchLease : public ThreadLease<SearchEngine> {
 public:
  SearchLease(const SearchEngine& s, const char* method)
      : ThreadLease(s, "SearchEngine", method,
                    "this search is in use by another thread (an ask() or tell() is running); "
                    "drive it from one thread at a time") {}
};

// The engine's search as the algorithm `A` that a method needs; an error naming the method and
// the engine's algorithm otherwise.
template <class A>
A& engine_as(const SearchEngine& e, const char* method, const char* algorithm) {
  auto* out = dynamic_cast<A*>(e.search.get());
  if (out == nullptr)
    throw Error(
        fmt::format("SearchEngine.{}: a {} search only; this one is search.algorithm = "
                    "\"{}\"",
                    method, algorithm, e.search->algorithm()));
  return *out;
}

nb::dict elite_dict(std::size_t cell, const Elite& e) {
  nb::dict d;
  d["index"] = cell;
  d["genome"] = e.genome;
  d["fitness"] = e.result;
  d["values"] = e.descriptors;
  d["objective"] = e.objective;
  d["reference"] = e.reference;
  d["generation"] = e.generation;
  return d;
}

nb::dict archive_dict(const Archive& a) {
  nb::dict d;
  std::vector<std::string> names;
  std::vector<double> lower, upper;
  for (std::size_t j = 0; j < a.dims(); ++j) {
    names.emplace_back(a.descriptors()[j]->name);
    lower.push_back(a.ranges()[j].lo);
    upper.push_back(a.ranges()[j].hi);
  }
  d["kind"] = std::string(a.kind());
  d["descriptors"] = names;
  d["lower"] = lower;
  d["upper"] = upper;
  d["cells"] = a.cells();
  if (a.centroids().empty())
    d["bins"] = a.bins();
  else
    d["centroids"] = a.centroids();
  return d;
}

nb::dict solution_dict(const Nsga2& nsga, const Solution& s) {
  nb::dict d;
  d["genome"] = s.genome;
  d["fitness"] = s.result;
  d["objectives"] = s.objectives;
  d["measured"] = nsga.measured(s);
  d["supplied"] = s.supplied;
  d["reference"] = s.reference;
  d["generation"] = s.generation;
  d["feasible"] = s.feasible;
  d["rank"] = s.rank;
  d["crowding"] = s.crowding;
  return d;
}

// run_search from Python: the hooks run on the calling thread with the GIL; what they raise stops
// the run as it is. `engine`: the caller's search (SearchEngine.run), free for the callback's use
// between generations.
nb::dict run_search_hooked(const Config& c, std::filesystem::path out, bool resume, bool overwrite,
                           bool quiet, RunOptions opt, nb::object evaluate, nb::object describe,
                           nb::object callback, SearchEngine* engine) {
  opt.out = std::move(out);
  opt.resume = resume;
  opt.overwrite = overwrite;
  opt.quiet = quiet;
  if (!evaluate.is_none())
    opt.evaluate = [evaluate](const std::vector<Genome>& genomes) {
      nb::gil_scoped_acquire gil;
      return nb::cast<std::vector<Fitness>>(evaluate(genomes));
    };
  if (!describe.is_none())
    opt.describe = [describe](const std::vector<Genome>& genomes,
                              const std::vector<Fitness>& fitness) {
      nb::gil_scoped_acquire gil;
      return nb::cast<std::vector<std::vector<double>>>(describe(genomes, fitness));
    };
  std::optional<SearchLease> lease;
  if (engine != nullptr) {
    lease.emplace(*engine, "run");
    opt.search = engine->search.get();
  }
  if (!callback.is_none())
    opt.search_callback = [&](const Search& s) {
      nb::gil_scoped_acquire gil;
      lease.reset();  // the callback reads the engine (elites, population)
      const nb::object answer = callback(s.generation());
      const bool go_on = answer.is_none() || nb::cast<bool>(nb::bool_(answer));
      if (engine != nullptr) lease.emplace(*engine, "run");
      return go_on;
    };
  bool interrupted = false;
  // Polled between evaluations (about every 20 ms): Ctrl-C stops the run with a checkpoint.
  opt.stop_poll = [&interrupted] {
    nb::gil_scoped_acquire gil;
    interrupted = interrupted || PyErr_CheckSignals() != 0;
    return interrupted;
  };
  SearchSummary summary;
  {
    nb::gil_scoped_release release;
    summary = run_search(c, opt);
  }
  if (interrupted) throw nb::python_error();  // the KeyboardInterrupt, after the checkpoint
  nb::dict d;
  d["algorithm"] = summary.algorithm;
  nb::list columns;
  for (const auto& col : summary.columns) columns.append(col.name);
  d["columns"] = columns;
  d["history"] = summary.history;
  d["stop_reason"] = summary.stop_reason;
  d["generation"] = summary.generation;
  return d;
}

void bind_search(nb::module_& m) {
  // The key of cvt_centroids' sample stream: Rng.derive(seed, CVT_SAMPLES_KEY, 0).
  m.attr("CVT_SAMPLES_KEY") = kCvtSamplesKey;
  m.def(
      "cvt_centroids",
      [](std::size_t dims, std::size_t cells, std::uint64_t seed, std::size_t samples,
         int iterations) {
        nb::gil_scoped_release release;
        return cvt_centroids(dims, cells, seed, samples, iterations);
      },
      "dims"_a, "cells"_a, "seed"_a, "samples"_a = 0, "iterations"_a = 100,
      "The centroids of a CVT archive (search.archive = \"cvt\") in the unit cube, cells rows "
      "of dims: Lloyd's\nk-means of samples uniform points (0: max(1000, 20 cells)) drawn from "
      "Rng.derive(seed, CVT_SAMPLES_KEY,\n0), started from the first cells of them, as "
      "animat.qd.CVTArchive computes its centroids from its\nsamples (docs/search.md).");
  m.def(
      "measures",
      [] {
        std::vector<std::tuple<std::string, std::string, double, double, bool>> out;
        for (const Measure& x : measures())
          out.emplace_back(x.name, x.meaning, x.lo, x.hi, x.maximize);
        return out;
      },
      "The engine's measures table (search.hpp), in order: (name, meaning, lo, hi, maximize) of "
      "every\nmeasure a swim records; lo == hi: a criterion only (no descriptor range). "
      "animat.DESCRIPTORS'\nranges and animat.CRITERIA's senses of these names are these.");
  m.def(
      "search_history_columns",
      [](std::string_view algorithm, const std::vector<std::string>& criteria) {
        std::vector<std::pair<std::string, bool>> out;
        for (const auto& c : search_history_columns(algorithm, criteria))
          out.emplace_back(c.name, c.integer);
        return out;
      },
      "algorithm"_a, "criteria"_a = std::vector<std::string>{},
      "(name, integer) of every history column of a \"map_elites\" or \"nsga2\" search (its "
      "criteria's names:\na best_<name> column each), in order; the last is wall_seconds.");
  // NSGA-II's pieces on minimised rows (animat.moo wraps them with senses and NaN rows).
  m.def(
      "non_dominated_sort",
      [](const std::vector<std::vector<double>>& points) { return non_dominated_sort(points); },
      "points"_a,
      "The fronts of points (rows of equal length, every objective minimised), best first, each "
      "listing row\nindices in increasing order (Deb et al.'s fast non-dominated sort).");
  m.def(
      "crowding_distance",
      [](const std::vector<std::vector<double>>& points) { return crowding_distance(points); },
      "points"_a,
      "Deb et al.'s crowding distance of the rows of one front: per objective a stable sort, both "
      "ends\ninfinity, every other row adds (next - previous) / (max - min); one or two rows: all "
      "infinity.");
  m.def(
      "hypervolume",
      [](const std::vector<std::vector<double>>& points, const std::vector<double>& reference) {
        return hypervolume(points, reference);
      },
      "points"_a, "reference"_a,
      "The hypervolume that points (minimised rows) dominate up to reference, one or two "
      "objectives; only\nrows better than the reference in every objective count; the rectangles "
      "summed exactly.");
  nb::class_<ArchiveCore>(m, "Archive",
                          "MAP-Elites' archive (search.hpp's Archive) on its own: a grid or a CVT "
                          "over named descriptors,\nthe cells and the insertion rule the engine's "
                          "searches use (animat.GridArchive and animat.CVTArchive\nkeep one).")
      .def(
          "__init__",
          [](ArchiveCore* a, const std::vector<std::string>& names,
             const std::vector<std::pair<double, double>>& ranges, const std::vector<int>& bins,
             const std::vector<std::vector<double>>& centroids) {
            new (a) ArchiveCore(make_archive_core(names, ranges, bins, centroids));
          },
          "names"_a, "ranges"_a, "bins"_a = std::vector<int>{},
          "centroids"_a = std::vector<std::vector<double>>{},
          "A grid of bins per descriptor, or (bins empty) a CVT of centroids (rows of the unit "
          "cube); ranges:\n(lo, hi) per descriptor. A ValueError names what it refuses (more than "
          "1e6 cells, a range that\nis not finite lo < hi, a centroid outside the unit cube).")
      .def_prop_ro("cells", [](const ArchiveCore& a) { return a.archive.cells(); })
      .def(
          "index_of",
          [](const ArchiveCore& a, const std::vector<double>& values) {
            if (values.size() != a.archive.dims())
              throw Error(fmt::format("Archive.index_of: {} values for the {} descriptors",
                                      values.size(), a.archive.dims()));
            for (double x : values)
              if (std::isnan(x)) throw Error("Archive.index_of: a NaN value has no cell");
            return a.archive.index_of(values);
          },
          "values"_a,
          "The cell of descriptor values (not NaN; below a range: its first bin, at or above it: "
          "its last).")
      .def(
          "add",
          [](ArchiveCore& a, const Genome& genome, double fitness,
             const std::vector<double>& values, double objective, double reference,
             int generation) {
            if (values.size() != a.archive.dims())
              throw Error(fmt::format("Archive.add: {} values for the {} descriptors",
                                      values.size(), a.archive.dims()));
            Fitness f;
            f.fitness = fitness;
            return a.archive.add(Elite{genome, f, values, objective, reference, generation});
          },
          "genome"_a, "fitness"_a, "values"_a, "objective"_a, "reference"_a, "generation"_a,
          "Offers a candidate: it enters when its cell is empty or its objective is strictly "
          "greater than the\nelite's; returns whether it entered.")
      .def("clear", [](ArchiveCore& a) { a.archive.elites().clear(); });
  nb::class_<SearchEngine>(m, "SearchEngine",
                           "The search of a config's search.algorithm as animat_evolve runs it "
                           "(search.hpp): \"ga\",\n\"map_elites\" or \"nsga2\", driven by "
                           "ask()/tell() or step().")
      .def(
          "__init__",
          [](SearchEngine* e, const Config& c, const std::vector<std::string>& supplied,
             const std::optional<std::vector<std::vector<double>>>& centroids,
             nb::object reference) {
            // A Python objective's values are told by the caller: the engine never swims with it.
            FitnessFunction told;
            if (c.evaluation.objective.starts_with(kPythonObjectivePrefix))
              told = [name = c.evaluation.objective](const Genome&) -> Fitness {
                throw Error(fmt::format(
                    "evaluation.objective = \"{}\" is a Python objective: the caller evaluates "
                    "and tells its values (the engine cannot call it)",
                    name));
              };
            new (e)
                SearchEngine{make_search(c, told, told, nullptr, supplied,
                                         centroids.value_or(std::vector<std::vector<double>>{}))};
            if (!reference.is_none())
              // called from tell() (GIL released) with the GIL; never copied without it
              e->search->set_reference_hook([reference](const std::vector<Genome>& genomes) {
                nb::gil_scoped_acquire gil;
                auto [fitness, values] =
                    nb::cast<std::pair<std::vector<Fitness>, std::vector<std::vector<double>>>>(
                        reference(genomes));
                return Search::ReferenceSwims{std::move(fitness), std::move(values)};
              });
          },
          "config"_a, "supplied"_a = std::vector<std::string>{}, "centroids"_a = nb::none(),
          "reference"_a = nb::none(),
          "The search of config (search.algorithm); a [search] setting it cannot run is a "
          "ValueError naming\nthe key and value. supplied: names of search.descriptors "
          "(MAP-Elites; their ranges in\nsearch.ranges) or of search.objectives entries (NSGA-II; "
          "each entry NAME:max or NAME:min) whose\nvalues the caller computes and passes to "
          "tell(fitness, values), a row per genome in supplied order. centroids:\na CVT "
          "archive's (search.archive = \"cvt\"), one row per cell in the unit cube; None: "
          "cvt_centroids of\nsearch.cells, evolution.seed and search.samples. reference: the "
          "exploit guard's reference swims by the\ncaller (MAP-Elites, NSGA-II), "
          "reference(genomes) "
          "-> (a Fitness per genome, a row of supplied\nvalues per genome), both at the reference "
          "step (animat.reference_config); None: the engine's.")
      .def_prop_ro("algorithm",
                   [](const SearchEngine& e) { return std::string(e.search->algorithm()); })
      .def(
          "ask",
          [](SearchEngine& e) {
            SearchLease lease(e, "ask");
            nb::gil_scoped_release release;  // draws the initial genomes on the threads
            return e.search->ask();
          },
          "The genomes that need a fitness next, in order (the same until tell()).")
      .def(
          "tell",
          [](SearchEngine& e, const std::vector<Fitness>& fitness,
             const std::vector<std::vector<double>>& values) {
            SearchLease lease(e, "tell");
            if (!values.empty() && e.search->supplied().empty())
              throw Error(
                  "SearchEngine.tell: values are for supplied descriptors or criteria; this search "
                  "has none");
            nb::gil_scoped_release release;  // the exploit guard's reference swims
            return e.search->tell(fitness, values);
          },
          "fitness"_a, "values"_a = std::vector<std::vector<double>>{},
          "The Fitness of every genome of the last ask(), in order; True when a generation "
          "completed. All or\nnothing: a refused value (an error naming its index and what is "
          "wrong) changes nothing.")
      .def(
          "step",
          [](SearchEngine& e) {
            SearchLease lease(e, "step");
            nb::gil_scoped_release release;
            e.search->step();
          },
          "Ask, evaluate with the config's own evaluation on evolution.threads, tell.")
      .def(
          "run",
          [](SearchEngine& e, const Config& c, std::filesystem::path out, bool resume,
             bool overwrite, bool quiet, nb::object evaluate, nb::object describe,
             nb::object callback) {
            return run_search_hooked(c, std::move(out), resume, overwrite, quiet, RunOptions{},
                                     std::move(evaluate), std::move(describe), std::move(callback),
                                     &e);
          },
          "config"_a, "out"_a, "resume"_a = false, "overwrite"_a = false, "quiet"_a = true,
          "evaluate"_a = nb::none(), "describe"_a = nb::none(), "callback"_a = nb::none(),
          "run_search with this search, made from config and not yet told a generation: the "
          "run directory out\nas animat_evolve writes it (a resume restores its checkpoint into "
          "this search). evaluate, describe:\nas run_search's; callback(generation) after every "
          "generation (the engine readable), False stops\nthe run (checkpointed). Returns "
          "run_search's dict.")
      .def_prop_ro("generation", [](const SearchEngine& e) { return e.search->generation(); })
      .def_prop_ro("evaluations", [](const SearchEngine& e) { return e.search->evaluations(); })
      .def_prop_ro(
          "history_columns",
          [](const SearchEngine& e) {
            std::vector<std::pair<std::string, bool>> out;
            for (const auto& c : e.search->history_columns()) out.emplace_back(c.name, c.integer);
            return out;
          },
          "(name, integer) of every history column, in order.")
      .def_prop_ro(
          "history", [](const SearchEngine& e) { return e.search->history(); },
          "One row per generation (history_columns' order), as floats.")
      .def(
          "checkpoint",
          [](const SearchEngine& e) {
            SearchLease lease(e, "checkpoint");
            return e.search->checkpoint();
          },
          "The whole state as checksummed JSON text (restore() reads it back).")
      .def(
          "restore",
          [](SearchEngine& e, std::string_view text, std::string_view source) {
            SearchLease lease(e, "restore");
            e.search->restore(text, source);
          },
          "text"_a, "source"_a = "checkpoint",
          "Restores a checkpoint() of the same config (an error for a corrupt, foreign or "
          "inconsistent one).")
      .def(
          "elites",
          [](const SearchEngine& e) {
            SearchLease lease(e, "elites");
            const auto& me = engine_as<MapElites>(e, "elites", "map_elites");
            nb::list out;
            for (const auto& [cell, elite] : me.archive().elites())
              out.append(elite_dict(cell, elite));
            return out;
          },
          "MAP-Elites: the archive's elites in cell order, each a dict: index (its cell), genome, "
          "fitness\n(Fitness), values (every descriptor, in search.descriptors order), objective "
          "(what the archive\ncompares), reference (the exploit guard's fitness; NaN = none), "
          "generation (the one that made it).")
      .def_prop_ro(
          "archive",
          [](const SearchEngine& e) {
            SearchLease lease(e, "archive");
            return archive_dict(engine_as<MapElites>(e, "archive", "map_elites").archive());
          },
          "MAP-Elites: the archive's geometry, a dict: kind (\"grid\" or \"cvt\"), descriptors "
          "(names), lower,\nupper (each descriptor's range), cells, and bins (a grid's, per "
          "descriptor) or centroids (a CVT's,\nrows in the unit cube).")
      .def(
          "index_of",
          [](const SearchEngine& e, const std::vector<double>& values) {
            SearchLease lease(e, "index_of");
            const Archive& a = engine_as<MapElites>(e, "index_of", "map_elites").archive();
            if (values.size() != a.dims())
              throw Error(fmt::format("SearchEngine.index_of: {} values for the {} descriptors",
                                      values.size(), a.dims()));
            for (std::size_t j = 0; j < values.size(); ++j)
              if (!std::isfinite(values[j]))
                throw Error(fmt::format(
                    "SearchEngine.index_of: descriptor {} = {} (a descriptor must be finite)",
                    a.descriptors()[j]->name, values[j]));
            return a.index_of(values);
          },
          "values"_a,
          "MAP-Elites: the archive cell of finite descriptor values (search.descriptors order).")
      .def(
          "population",
          [](const SearchEngine& e) {
            SearchLease lease(e, "population");
            nb::list out;
            const auto& nsga = engine_as<Nsga2>(e, "population", "nsga2");
            for (const Solution& s : nsga.population()) out.append(solution_dict(nsga, s));
            return out;
          },
          "NSGA-II: the population in order, each a dict: genome, fitness (Fitness), objectives "
          "(what the\nselection compares, one per criterion; NaN when infeasible), measured (the "
          "criteria of its own\nswim), supplied (the supplied criteria's values), reference (the "
          "criteria at the\nexploit guard's reference step; empty when not evaluated there), "
          "generation, feasible, rank,\ncrowding.")
      .def(
          "front",
          [](const SearchEngine& e) {
            SearchLease lease(e, "front");
            const auto& nsga = engine_as<Nsga2>(e, "front", "nsga2");
            std::vector<std::size_t> out;
            for (const Solution* s : nsga.front())
              out.push_back(static_cast<std::size_t>(s - nsga.population().data()));
            return out;
          },
          "NSGA-II: the population indices of the front (feasible members of rank 0), ordered by "
          "the first\ncriterion, best first (then the next ..., then population order).")
      .def_prop_ro(
          "reference_point",
          [](const SearchEngine& e) {
            SearchLease lease(e, "reference_point");
            return engine_as<Nsga2>(e, "reference_point", "nsga2").reference_point();
          },
          "NSGA-II: the hypervolume's reference point, one value per criterion (empty until "
          "set).")
      .def(
          "set_reference_point",
          [](SearchEngine& e, std::vector<double> point) {
            SearchLease lease(e, "set_reference_point");
            engine_as<Nsga2>(e, "set_reference_point", "nsga2")
                .set_reference_point(std::move(point));
          },
          "point"_a,
          "NSGA-II: fixes the hypervolume's reference point, one finite value per criterion, "
          "before the first\ngeneration (otherwise the worst of the first feasible candidates).")
      .def_prop_ro(
          "criteria",
          [](const SearchEngine& e) {
            const auto& nsga = engine_as<Nsga2>(e, "criteria", "nsga2");
            std::vector<std::pair<std::string, std::string>> out;
            for (std::size_t j = 0; j < nsga.criteria().size(); ++j)
              out.emplace_back(nsga.criteria()[j], nsga.maximized()[j] ? "max" : "min");
            return out;
          },
          "NSGA-II: (name, \"max\" or \"min\") of every criterion, in search.objectives "
          "order.");
}

class EngineLease : public ThreadLease<Evolution> {
 public:
  EngineLease(const Evolution& e, const char* method)
      : ThreadLease(e, "GA", method,
                    "this GA is in use by another thread (an ask() or tell() is running); drive a "
                    "GA from one thread "
                    "at a time") {}
};

std::string fitness_repr(const Fitness& f) {
  return fmt::format("animat.Fitness(fitness={}, viable={}, stable={}, cell_count={})", f.fitness,
                     f.viable ? "True" : "False", f.stable ? "True" : "False", f.cell_count);
}

}  // namespace

void bind_evolution(nb::module_& m) {
  nb::class_<Fitness> fitness_class(m, "Fitness", "What the GA knows about one evaluated genome.");
  fitness_class
      .def(
          "__init__",
          [](Fitness* f, double fitness, bool viable, bool stable, int cell_count, bool valid,
             long drag_limited, int morphology_kind, double actuation_work,
             double actuation_work_positive, double actuation_work_absolute, double max_speed) {
            if (drag_limited < 0) throw nb::value_error("Fitness: drag_limited must be >= 0");
            if (morphology_kind < 0) throw nb::value_error("Fitness: morphology_kind must be >= 0");
            new (f) Fitness{fitness,
                            viable,
                            stable,
                            cell_count,
                            valid,
                            drag_limited,
                            morphology_kind,
                            actuation_work,
                            actuation_work_positive,
                            actuation_work_absolute,
                            max_speed};
          },
          "fitness"_a = 0.0, "viable"_a = true, "stable"_a = true, "cell_count"_a = 0,
          "valid"_a = true, "drag_limited"_a = 0, "morphology_kind"_a = 0, "actuation_work"_a = 0.0,
          "actuation_work_positive"_a = 0.0, "actuation_work_absolute"_a = 0.0, "max_speed"_a = 0.0,
          "A fitness to tell() the GA: the objective's value, whether the genome was viable "
          "(non-viable ones\n"
          "are never selected before viable ones), whether its swim was stable, its cell count, "
          "whether the\n"
          "swim kept every invariant, how often the drag limiter altered it (drag_scheme "
          "\"stable\" only), and\n"
          "the body plan's coarse class (EvaluationResult.morphology_kind; what "
          "evolution.protection_generations\n"
          "compares; 0 = unknown), and the swim's measures that MAP-Elites' descriptors and "
          "NSGA-II's criteria\n"
          "read in animat_evolve (EvaluationResult's fields of the same names).")
      .def("__eq__", [](const Fitness& a, const Fitness& b) { return a == b; })
      // Float-like: `ind.fitness` is the record, and it formats, converts and orders as its value,
      // as LineageEntry.fitness and the history's floats do.
      .def("__float__", [](const Fitness& f) { return f.fitness; })
      .def("__format__",
           [](const Fitness& f, nb::str spec) {
             const nb::float_ value(f.fitness);
             nb::object out = nb::steal(PyObject_Format(value.ptr(), spec.ptr()));
             if (!out.is_valid()) throw nb::python_error();
             return out;
           })
      .def("__lt__", [](const Fitness& f, double x) { return f.fitness < x; })
      .def("__le__", [](const Fitness& f, double x) { return f.fitness <= x; })
      .def("__gt__", [](const Fitness& f, double x) { return f.fitness > x; })
      .def("__ge__", [](const Fitness& f, double x) { return f.fitness >= x; })
      .def("__lt__", [](const Fitness& a, const Fitness& b) { return a.fitness < b.fitness; })
      .def("__le__", [](const Fitness& a, const Fitness& b) { return a.fitness <= b.fitness; })
      .def("__gt__", [](const Fitness& a, const Fitness& b) { return a.fitness > b.fitness; })
      .def("__ge__", [](const Fitness& a, const Fitness& b) { return a.fitness >= b.fitness; })
      // The pickled state is the tuple of the descriptor's fields; 5 entries: pickled before
      // drag_limited, 6: before morphology_kind, 7: before the swim's measures.
      .def("__getstate__",
           [](const Fitness& f) {
             nb::list state;
             visit_fields(
                 f, [&](const char*, const char*, const auto& value) { state.append(value); });
             return nb::tuple(state);
           })
      .def("__setstate__",
           [](Fitness& f, const nb::tuple& t) {
             std::size_t fields = 0;
             const Fitness empty;
             visit_fields(empty, [&](const char*, const char*, const auto&) { ++fields; });
             if (t.size() < 5 || t.size() > fields)
               throw nb::value_error(
                   fmt::format("Fitness state: expected 5 to {} entries", fields).c_str());
             new (&f) Fitness{};
             std::size_t k = 0;
             visit_fields(f, [&](const char*, const char*, auto& value) {
               if (k < t.size()) value = nb::cast<std::decay_t<decltype(value)>>(t[k]);
               ++k;
             });
           })
      .def("__copy__", [](const Fitness& f) { return f; })
      .def(
          "__deepcopy__", [](const Fitness& f, nb::handle) { return f; }, "memo"_a)
      .def("__repr__", &fitness_repr);
  {
    const Fitness probe;
    visit_fields(probe, [&](const char* name, const char* doc, const auto& field) {
      def_field_property(fitness_class, probe, field, name, doc);
    });
  }

  nb::class_<GenerationStats> stats(m, "GenerationStats",
                                    "Statistics of one generation (a row of history.csv).");
  {
    const GenerationStats probe;
    nb::list columns, protected_columns;
    visit_fields(probe, [&](const StatsField& f, const auto& field) {
      using T = std::decay_t<decltype(field)>;
      def_field_property(stats, probe, field, f.name, f.doc);
      const auto column = nb::make_tuple(f.name, std::is_floating_point_v<T> ? "float64" : "int64");
      if (f.csv && !f.protection_only) columns.append(column);
      if (f.csv) protected_columns.append(column);
    });
    stats.attr("HISTORY_COLUMNS") = nb::tuple(columns);
    // a run with evolution.protection_generations > 0 has the protection's columns too
    stats.attr("PROTECTED_HISTORY_COLUMNS") = nb::tuple(protected_columns);
  }
  stats
      .def(
          "__init__",
          [](GenerationStats* s, const nb::dict& d) {
            new (s) GenerationStats(stats_from_dict(d));
          },
          "values"_a, "Statistics from a dict of every field (as to_dict() gives).")
      .def("to_dict", &stats_dict, "Every field as a dict.")
      .def("__getstate__", &stats_dict)
      .def("__setstate__", [](GenerationStats& s,
                              const nb::dict& d) { new (&s) GenerationStats(stats_from_dict(d)); })
      .def("__copy__", [](const GenerationStats& s) { return s; })
      .def(
          "__deepcopy__", [](const GenerationStats& s, nb::handle) { return s; }, "memo"_a)
      .def("__repr__", [](const GenerationStats& s) {
        return "<animat.GenerationStats gen " + std::to_string(s.generation) + " best " +
               std::to_string(s.best) + ">";
      });

  nb::class_<Individual>(
      m, "Individual",
      "A member of the population: its genome, Fitness and (initial population) tries.")
      .def(
          "__init__",
          [](Individual* i, const Genome& g, const Fitness& f, int tries) {
            new (i) Individual{g, f, tries};
          },
          "genome"_a, "fitness"_a, "tries"_a = 0)
      .def_ro("genome", &Individual::genome, "The Genome.")
      .def_ro("fitness", &Individual::result, "Its Fitness.")
      .def_ro("tries", &Individual::tries,
              "Random genomes drawn to find it (initial population only; else 0).")
      .def_ro("id", &Individual::id,
              "Its id in the run's genealogy: generation of birth x population + its index then "
              "(genealogy.csv); an elite keeps its id.")
      .def_ro("parent_a", &Individual::parent_a,
              "Id of its first parent; -1 for an initial individual (or one restored from a "
              "checkpoint without ids).")
      .def_ro("parent_b", &Individual::parent_b,
              "Id of its second parent (crossover only); -1 otherwise.")
      .def_ro("morphology_age", &Individual::morphology_age,
              "Generations since its lineage's morphology kind (fitness.morphology_kind) "
              "appeared: 0 for an\n"
              "initial individual and an offspring of a new kind, else its parent's + 1 (elites "
              "age by 1 per\n"
              "generation). Younger than evolution.protection_generations: protected.")
      // 6 entries: pickled before morphology_age.
      .def("__getstate__",
           [](const Individual& i) {
             return nb::make_tuple(i.genome, i.result, i.tries, i.id, i.parent_a, i.parent_b,
                                   i.morphology_age);
           })
      .def("__setstate__",
           [](Individual& i, const nb::tuple& t) {
             if (t.size() != 6 && t.size() != 7)
               throw nb::value_error("Individual state: expected 6 or 7 entries");
             new (&i)
                 Individual{nb::cast<Genome>(t[0]), nb::cast<Fitness>(t[1]), nb::cast<int>(t[2])};
             i.id = nb::cast<std::int64_t>(t[3]);
             i.parent_a = nb::cast<std::int64_t>(t[4]);
             i.parent_b = nb::cast<std::int64_t>(t[5]);
             if (t.size() == 7) i.morphology_age = nb::cast<int>(t[6]);
           })
      .def("__copy__", [](const Individual& i) { return i; })
      .def(
          "__deepcopy__", [](const Individual& i, nb::handle) { return i; }, "memo"_a)
      .def("__repr__", [](const Individual& i) {
        return fmt::format("<animat.Individual fitness={:.6g}{} cells={} ({} elements)>",
                           i.result.fitness, i.result.viable ? "" : " non-viable",
                           i.result.cell_count, i.genome.size());
      });

  nb::class_<Evolution>(
      m, "Evolution",
      "The GA engine behind animat.evolve, driven by ask()/tell() (animat.GA wraps it).")
      .def(
          "__init__",
          [](Evolution* e, const Config& c, nb::handle objective) {
            // The exploit guard, as animat.evolve has it: each new best re-evaluated at the
            // reference step with the run's objective (evaluation.reference_check "record" or
            // "select").
            FitnessFunction reference;
            if (c.evaluation.reference_check != "off")
              reference =
                  objective_fitness(reference_config(c), objective_from_python(objective, c));
            new (e) Evolution(c, {}, std::move(reference));
          },
          "config"_a, "objective"_a = nb::none(),
          "An engine for ask()/tell(). objective: None (the config's evaluation.objective), a "
          "built-in name or\n"
          "a Python objective: what the exploit guard re-evaluates each new best with (unless\n"
          "evaluation.reference_check = \"off\"), at physics.substeps x "
          "evaluation.reference_substeps.")
      .def(
          "ask",
          [](Evolution& e, int lookahead) {
            EngineLease lease(e, "ask");
            nb::gil_scoped_release release;  // "select" evaluates the elite candidates' references
            return e.ask(lookahead);
          },
          "lookahead"_a = 1, "The genomes that need a fitness next (see animat.GA.ask).")
      .def(
          "tell",
          [](Evolution& e, const std::vector<Fitness>& fitness) {
            EngineLease lease(e, "tell");
            nb::gil_scoped_release release;  // the exploit guard evaluates a new best's reference
            return e.tell(fitness);
          },
          "fitness"_a,
          "The Fitness of every genome of the last ask(), in order; True when a generation "
          "completed. Refuses\n"
          "(ValueError naming the value's index) what the engine's own evaluations refuse: a "
          "fitness that is\n"
          "not finite, a negative one under a distance objective, a negative cell_count.")
      .def_prop_ro(
          "asked",
          [](const Evolution& e) {
            EngineLease l(e, "asked");
            return e.asked();
          },
          "Whether an ask() awaits its tell().")
      .def_prop_ro(
          "generation",
          [](const Evolution& e) {
            EngineLease l(e, "generation");
            return e.generation();
          },
          "Last completed generation (-1 while drawing the initial population).")
      .def_prop_ro(
          "population",
          [](const Evolution& e) {
            EngineLease l(e, "population");
            return e.population();
          },
          "The population (list of Individual).")
      .def_prop_ro(
          "best",
          [](const Evolution& e) {
            EngineLease l(e, "best");
            return e.best();
          },
          "The best Individual (first of the fittest; under evaluation.reference_check = "
          "\"select\", "
          "of the best reference fitness).")
      .def_prop_ro(
          "history",
          [](const Evolution& e) {
            EngineLease l(e, "history");
            return e.history();
          },
          "GenerationStats of every generation.")
      .def_prop_ro(
          "evaluations",
          [](const Evolution& e) {
            EngineLease l(e, "evaluations");
            return e.evaluations();
          },
          "Fitness evaluations counted so far.")
      .def_prop_ro("generations_without_improvement",
                   [](const Evolution& e) {
                     EngineLease l(e, "generations_without_improvement");
                     return e.generations_without_improvement();
                   })
      .def(
          "stop_reason",
          [](const Evolution& e) {
            EngineLease l(e, "stop_reason");
            return e.stop_reason();
          },
          "Why the run should stop now ('' = keep going).")
      .def(
          "initial_tries",
          [](const Evolution& e) {
            EngineLease l(e, "initial_tries");
            return e.initial_tries();
          },
          "Random genomes drawn per initial individual.")
      .def(
          "checkpoint",
          [](const Evolution& e) {
            EngineLease l(e, "checkpoint");
            return e.checkpoint();
          },
          "The whole state as checkpoint JSON text (the run directory's format).")
      .def(
          "restore",
          [](Evolution& e, const std::string& text, const std::string& source) {
            EngineLease l(e, "restore");
            e.restore(text, source);
          },
          "text"_a, "source"_a = "checkpoint",
          "Restore a checkpoint (refused if corrupt or of another config).");

  nb::class_<RunSummary>(m, "EvolutionSummary",
                         "What animat._core.evolve returns (animat.evolve wraps it).")
      .def_ro("history", &RunSummary::history, "List of GenerationStats, generation 0 first.")
      .def_ro("best", &RunSummary::best, "The best Individual of the last generation.")
      .def_ro("population", &RunSummary::population, "The final population (list of Individual).")
      .def_prop_ro(
          "best_genome", [](const RunSummary& r) { return r.best.genome; },
          "The best genome of the last generation.")
      .def_prop_ro(
          "best_fitness", [](const RunSummary& r) { return r.best.result; }, "Its Fitness.")
      .def_ro("stop_reason", &RunSummary::stop_reason, "Why the run stopped.")
      .def("__repr__", [](const RunSummary& r) {
        return "<animat.EvolutionSummary " + std::to_string(r.history.size()) +
               " generations, best " + std::to_string(r.best.result.fitness) +
               ", stopped: " + r.stop_reason + ">";
      });

  m.def(
      "evolve",
      [](std::optional<Config> config, std::optional<std::filesystem::path> out, bool resume,
         std::optional<nb::callable> callback, bool quiet, nb::object stop, nb::handle objective,
         bool overwrite, std::string label) {
        const Config c = config.value_or(Config{});
        RunOptions opt;
        if (out) opt.out = *out;
        opt.resume = resume;
        opt.overwrite = overwrite;
        opt.quiet = quiet;
        opt.label = std::move(label);
        // A Python exception raised while the run is in progress (Ctrl-C's KeyboardInterrupt, an
        // error in or about the callback) stops the run like a signal does: the last complete
        // generation is checkpointed, and the exception is raised afterwards with the partial
        // result as `.result`. Touched with the GIL held only.
        std::optional<nb::python_error> pending;
        auto keep = [&pending] {
          if (!pending)
            pending.emplace();  // fetches the error indicator
          else
            PyErr_Clear();
        };
        if (callback) {
          nb::callable cb = *callback;
          opt.callback = [cb, &keep](const GenerationStats& s, const Evolution&) {
            nb::gil_scoped_acquire gil;
            try {
              nb::object r = cb(s);
              if (r.is_none()) return true;
              const std::string type = nb::type_name(r.type()).c_str();
              const bool numpy_bool =
                  nb::hasattr(r.type(), "__module__") &&
                  nb::str(r.type().attr("__module__")).equal(nb::str("numpy")) &&
                  (type == "bool" || type == "bool_" || type == "numpy.bool_" ||
                   type == "numpy.bool");
              if (PyBool_Check(r.ptr()) || numpy_bool) return PyObject_IsTrue(r.ptr()) == 1;
              const std::string shown = nb::repr(r).c_str();
              PyErr_SetString(
                  PyExc_TypeError,
                  ("evolve: the callback must return True, False or None (None = go on), got " +
                   type + " " + (shown.size() > 60 ? shown.substr(0, 57) + "..." : shown))
                      .c_str());
            } catch (nb::python_error& e) {
              e.restore();
            }
            keep();
            return false;
          };
        }
        // Polled between evaluations (about every 20 ms) on this thread: Ctrl-C, and the `stop`
        // event.
        opt.stop_poll = [&stop, &keep]() -> bool {
          nb::gil_scoped_acquire gil;
          if (PyErr_CheckSignals() != 0) {
            keep();
            return true;
          }
          if (stop.is_none()) return false;
          nb::object set = nb::steal(PyObject_CallMethod(stop.ptr(), "is_set", nullptr));
          if (!set.is_valid()) {
            keep();
            return true;
          }
          return PyObject_IsTrue(set.ptr()) == 1;
        };
        // The objective scores every swim; the exploit guard re-evaluates each new best with the
        // same objective at the reference step.
        const auto scored_by = objective_from_python(objective, c);
        FitnessFunction fitness = objective_fitness(c, scored_by);
        FitnessFunction reference;
        if (c.evaluation.reference_check != "off")
          reference = objective_fitness(reference_config(c), scored_by);
        opt.fitness_key = evaluation_key(c);
        RunSummary summary;
        {
          nb::gil_scoped_release release;
          summary = run_evolution(c, opt, std::move(fitness), std::move(reference));
        }
        // Ctrl-C while the Python objective ran: its KeyboardInterrupt (the run stopped as for a
        // signal).
        if (auto interrupt = take_interrupt(scored_by); interrupt && !pending)
          pending.emplace(std::move(*interrupt));
        // A Ctrl-C is an interruption wherever it landed (in the callback too), not the callback's
        // answer.
        if (pending && pending->matches(PyExc_KeyboardInterrupt))
          summary.stop_reason = "interrupted";
        if (pending) {
          nb::object result = nb::cast(std::move(summary));
          PyObject_SetAttrString(pending->value().ptr(), "result", result.ptr());
          pending->restore();
          throw nb::python_error();
        }
        return summary;
      },
      "config"_a = nb::none(), "out"_a = nb::none(), "resume"_a = false, "callback"_a = nb::none(),
      "quiet"_a = true, "stop"_a = nb::none(), "objective"_a = nb::none(), "overwrite"_a = false,
      "label"_a = "",
      "Run the paper's genetic algorithm (the engine behind animat_evolve); animat.evolve wraps "
      "it.\n\n"
      "config: animat.Config (default: the embedded paper setting; set evolution.generations!).\n"
      "out: run directory for config.toml, history.csv, best/ and checkpoint.json (None = write "
      "nothing).\n"
      "resume: continue the run in `out` (settings other than the caps, threads and checkpoint "
      "interval\n"
      "must equal the run's; a difference is a ValueError naming the keys, and nothing is "
      "written).\n"
      "callback: called with each generation's GenerationStats (generation 0 included); return "
      "False to stop\n"
      "(True or None: go on).\n"
      "stop: an object with is_set() (e.g. threading.Event), polled between evaluations; set = "
      "stop.\n"
      "objective: None (the config's evaluation.objective), a built-in name, or a Python "
      "objective.\n"
      "overwrite: start afresh in `out` even if it holds a run (its run files are removed, under "
      "the lock).\n"
      "label: prefix of every progress line, '[label] ' (several runs in one process).\n"
      "The run directory is locked (out/.lock) while it runs: a second writer gets BlockingIOError "
      "naming\n"
      "the holder's pid; a directory holding a run (with or without a checkpoint) gives "
      "FileExistsError.\n"
      "The GIL is released while it runs. Returns an EvolutionSummary (history, best, "
      "population);\n"
      "stop_reason is 'interrupted' when `stop` ended it. Ctrl-C (or an exception from the "
      "callback)\n"
      "stops it within one evaluation, leaves a checkpoint of the last complete generation in "
      "`out`\n"
      "(resume=True continues), and is raised with the partial EvolutionResult as its `.result`.");

  m.def(
      "evaluate_population",
      [](const std::vector<Genome>& genomes, std::optional<Config> config, int threads,
         nb::handle objective) {
        const Config c = config.value_or(Config{});
        const FitnessFunction f = objective_fitness(c, objective_from_python(objective, c));
        nb::gil_scoped_release release;
        return evaluate_all(genomes, f, threads);
      },
      "genomes"_a, "config"_a = nb::none(), "threads"_a = 0, "objective"_a = nb::none(),
      "Evaluate genomes in parallel (OpenMP, one Box2D world each); returns a list of Fitness in "
      "input order,\n"
      "identical for any thread count. objective: None (the config's), a built-in name or a Python "
      "objective.");

  m.def(
      "tournament_probability",
      [](int generation, std::optional<Config> config) {
        return tournament_probability(config.value_or(Config{}).evolution, generation);
      },
      "generation"_a, "config"_a = nb::none(),
      "Probability that the fitter of two wins a tournament at a generation (0.8 rising to 1 over "
      "1000).");

  m.def(
      "reference_disagrees",
      [](double fitness, double reference, std::optional<Config> config) {
        return reference_disagrees(fitness, reference, config.value_or(Config{}).evaluation);
      },
      "fitness"_a, "reference"_a, "config"_a = nb::none(),
      "The exploit guard's rule: whether a fitness and its reference-step fitness differ by more "
      "than both\n"
      "evaluation.reference_tolerance (relative to the reference) and "
      "evaluation.reference_abs_tolerance.");

  bind_search(m);

  m.def(
      "run_search",
      [](const Config& c, std::filesystem::path out, bool resume, bool overwrite, bool quiet,
         const std::vector<std::string>& supplied, nb::object evaluate, nb::object describe) {
        RunOptions opt;
        opt.supplied = supplied;
        return run_search_hooked(c, std::move(out), resume, overwrite, quiet, std::move(opt),
                                 std::move(evaluate), std::move(describe), nb::none(), nullptr);
      },
      "config"_a, "out"_a, "resume"_a = false, "overwrite"_a = false, "quiet"_a = true,
      "supplied"_a = std::vector<std::string>{}, "evaluate"_a = nb::none(),
      "describe"_a = nb::none(),
      "Run (or resume) the config's MAP-Elites or NSGA-II as animat_evolve does (search.hpp): the "
      "run\ndirectory out (config.toml, history.csv, checkpoint.json) is locked while it runs, its "
      "checkpoint is\nchecked on load, and a resume may change only the resumable keys. Returns "
      "a dict: algorithm,\ncolumns, history (rows of floats), stop_reason, generation. The GIL "
      "is released while it runs;\nCtrl-C stops it with a checkpoint of the last complete "
      "generation and raises KeyboardInterrupt.\nHooks (called with the GIL, once per "
      "generation): evaluate(genomes) -> list of Fitness replaces\nthe config's own evaluation; "
      "describe(genomes, fitness) -> one row per genome of the values of the\nsupplied "
      "descriptors (MAP-Elites) or criteria (NSGA-II), in supplied order. An exception raised in "
      "a\nhook stops the run and is raised here; the last checkpoint stays, and resume=True "
      "continues from it.");

  m.def(
      "reference_config", [](const Config& config) { return reference_config(config); }, "config"_a,
      "The config of the exploit guard's reference swim (the engine's): a copy of config with\n"
      "physics.substeps multiplied by evaluation.reference_substeps. The GA, MAP-Elites and "
      "NSGA-II\nswim their reference evaluations with it.");
}

}  // namespace animat::py
