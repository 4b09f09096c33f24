#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/function.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <atomic>

#include "animat/config.hpp"
#include "animat/evolution.hpp"
#include "bindings.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace animat::py {

void bind_evolution(nb::module_& m) {
  nb::class_<Fitness>(m, "Fitness", "What the GA knows about one evaluated genome.")
      .def_ro("fitness", &Fitness::fitness, "Distance travelled by the centre of mass (0 if not viable or unstable).")
      .def_ro("viable", &Fitness::viable, "Development verdict; non-viable genomes are never swum.")
      .def_ro("stable", &Fitness::stable, "False if the swim was flagged unstable.")
      .def_ro("cell_count", &Fitness::cell_count)
      .def_ro("valid", &Fitness::valid, "False if the swim broke an invariant (embedding, collisions); its fitness is 0.")
      .def("__repr__", [](const Fitness& f) {
        return "<animat.Fitness " + std::to_string(f.fitness) + (f.viable ? " viable" : " non-viable") +
               (f.stable ? "" : " UNSTABLE") + ", " + std::to_string(f.cell_count) + " cells>";
      });

  nb::class_<GenerationStats>(m, "GenerationStats", "Statistics of one generation (a row of history.csv).")
      .def_ro("generation", &GenerationStats::generation)
      .def_ro("best", &GenerationStats::best)
      .def_ro("mean", &GenerationStats::mean, "Mean fitness of the viable individuals.")
      .def_ro("median", &GenerationStats::median, "Median fitness of the viable individuals.")
      .def_ro("viable_fraction", &GenerationStats::viable_fraction)
      .def_ro("best_cells", &GenerationStats::best_cells)
      .def_ro("evaluations", &GenerationStats::evaluations, "Cumulative fitness evaluations.")
      .def_ro("wall_seconds", &GenerationStats::wall_seconds)
      .def_ro("evaluations_per_second", &GenerationStats::evaluations_per_second)
      .def_ro("best_changed", &GenerationStats::best_changed)
      .def_ro("crossovers", &GenerationStats::crossovers)
      .def_ro("best_reference", &GenerationStats::best_reference,
              "The best's fitness at the reference step (evaluation.reference_check); NaN when off.")
      .def_ro("invalid", &GenerationStats::invalid,
              "Viable individuals whose swim was unstable or broke an invariant (fitness 0).")
      .def("__repr__", [](const GenerationStats& s) {
        return "<animat.GenerationStats gen " + std::to_string(s.generation) + " best " + std::to_string(s.best) + ">";
      });

  nb::class_<RunSummary>(m, "EvolutionResult", "What animat.evolve returns.")
      .def_ro("history", &RunSummary::history, "List of GenerationStats, generation 0 first.")
      .def_prop_ro("best_genome", [](const RunSummary& r) { return r.best.genome; }, "The best genome of the last generation.")
      .def_prop_ro("best_fitness", [](const RunSummary& r) { return r.best.result; }, "Its Fitness.")
      .def_ro("stop_reason", &RunSummary::stop_reason)
      .def("__repr__", [](const RunSummary& r) {
        return "<animat.EvolutionResult " + std::to_string(r.history.size()) + " generations, best " +
               std::to_string(r.best.result.fitness) + ", stopped: " + r.stop_reason + ">";
      });

  m.def("evolve", [](std::optional<Config> config, std::optional<std::filesystem::path> out, bool resume,
                     std::optional<nb::callable> callback, bool quiet, nb::object stop) {
          const Config c = config.value_or(Config{});
          RunOptions opt;
          if (out) opt.out = *out;
          opt.resume = resume;
          opt.quiet = quiet;
          // A Python exception raised while the run is in progress (Ctrl-C's KeyboardInterrupt, an error
          // in or about the callback) stops the run like a signal does: the last complete generation is
          // checkpointed, and the exception is raised afterwards with the partial result as `.result`.
          // Touched with the GIL held only.
          std::optional<nb::python_error> pending;
          auto keep = [&pending] {
            if (!pending) pending.emplace();  // fetches the error indicator
            else PyErr_Clear();
          };
          if (callback) {
            nb::callable cb = *callback;
            opt.callback = [cb, &keep](const GenerationStats& s, const Evolution&) {
              nb::gil_scoped_acquire gil;
              try {
                nb::object r = cb(s);
                if (r.is_none()) return true;
                const std::string type = nb::type_name(r.type()).c_str();
                const bool numpy_bool = nb::hasattr(r.type(), "__module__") &&
                                        nb::str(r.type().attr("__module__")).equal(nb::str("numpy")) &&
                                        (type == "bool" || type == "bool_" || type == "numpy.bool_" || type == "numpy.bool");
                if (PyBool_Check(r.ptr()) || numpy_bool) return PyObject_IsTrue(r.ptr()) == 1;
                const std::string shown = nb::repr(r).c_str();
                PyErr_SetString(PyExc_TypeError,
                                ("evolve: the callback must return True, False or None (None = go on), got " + type + " " +
                                 (shown.size() > 60 ? shown.substr(0, 57) + "..." : shown)).c_str());
              } catch (nb::python_error& e) {
                e.restore();
              }
              keep();
              return false;
            };
          }
          // Polled between evaluations (about every 20 ms) on this thread: Ctrl-C, and the `stop` event.
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
          RunSummary summary;
          {
            nb::gil_scoped_release release;
            summary = run_evolution(c, opt);
          }
          if (pending) {
            nb::object result = nb::cast(std::move(summary));
            PyObject_SetAttrString(pending->value().ptr(), "result", result.ptr());
            pending->restore();
            throw nb::python_error();
          }
          return summary;
        }, "config"_a = nb::none(), "out"_a = nb::none(), "resume"_a = false, "callback"_a = nb::none(), "quiet"_a = true,
        "stop"_a = nb::none(),
        "Run the paper's genetic algorithm (the engine behind animat_evolve).\n\n"
        "config: animat.Config (default: the embedded paper setting; set evolution.generations!).\n"
        "out: run directory for config.toml, history.csv, best/ and checkpoint.json (None = write nothing).\n"
        "resume: continue the run in `out` (settings other than the caps, threads and checkpoint interval\n"
        "must equal the run's; a difference is a ValueError naming the keys, and nothing is written).\n"
        "callback: called with each generation's GenerationStats; return False to stop (True or None: go on).\n"
        "stop: an object with is_set() (e.g. threading.Event), polled between evaluations; set = stop.\n"
        "The GIL is released while it runs. Returns an EvolutionResult (history, best_genome, best_fitness);\n"
        "stop_reason is 'interrupted' when `stop` ended it. Ctrl-C (or an exception from the callback)\n"
        "stops it within one evaluation, leaves a checkpoint of the last complete generation in `out`\n"
        "(resume=True continues), and is raised with the partial EvolutionResult as its `.result`.");

  m.def("evaluate_population", [](const std::vector<Genome>& genomes, std::optional<Config> config, int threads) {
          const Config c = config.value_or(Config{});
          const FitnessFunction f = swim_fitness(c);
          nb::gil_scoped_release release;
          return evaluate_all(genomes, f, threads);
        }, "genomes"_a, "config"_a = nb::none(), "threads"_a = 0,
        "Evaluate genomes in parallel (OpenMP, one Box2D world each); returns a list of Fitness in input order,\n"
        "identical for any thread count.");

  m.def("tournament_probability", [](int generation, std::optional<Config> config) {
          return tournament_probability(config.value_or(Config{}).evolution, generation);
        }, "generation"_a, "config"_a = nb::none(),
        "Probability that the fitter of two wins a tournament at a generation (0.8 rising to 1 over 1000).");
}

}  // namespace animat::py
