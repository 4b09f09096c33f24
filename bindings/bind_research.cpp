// Python research API pieces that span stages: pickling of every value type (through stable
// serialised forms), the evaluation record and Python objectives, externally driven actuation,
// viable random genomes, and `animat evolve` (the animat_evolve command line in-process).
#include <nanobind/eigen/dense.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/string_view.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <fmt/format.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "animat/body.hpp"
#include "animat/config.hpp"
#include "animat/control.hpp"
#include "animat/development.hpp"
#include "animat/errors.hpp"
#include "animat/evaluate.hpp"
#include "animat/evaluator.hpp"
#include "animat/evolution.hpp"
#include "animat/external_actuation.hpp"
#include "animat/objective.hpp"
#include "animat/objective_table.hpp"
#include "animat/physics.hpp"
#include "bindings.hpp"

int animat_evolve_main(int argc, char** argv);  // src/cli/animat_evolve.cpp

namespace nb = nanobind;
using namespace nb::literals;

namespace animat::py {
namespace {

nb::ndarray<nb::numpy, double> owned(std::vector<double> v,
                                     std::initializer_list<std::size_t> shape) {
  auto* heap = new std::vector<double>(std::move(v));
  nb::capsule owner(heap, [](void* p) noexcept { delete static_cast<std::vector<double>*>(p); });
  return nb::ndarray<nb::numpy, double>(heap->data(), shape.size(), shape.begin(), owner);
}

nb::ndarray<nb::numpy, std::int64_t> owned_int(std::vector<std::int64_t> v,
                                               std::initializer_list<std::size_t> shape) {
  auto* heap = new std::vector<std::int64_t>(std::move(v));
  nb::capsule owner(heap,
                    [](void* p) noexcept { delete static_cast<std::vector<std::int64_t>*>(p); });
  return nb::ndarray<nb::numpy, std::int64_t>(heap->data(), shape.size(), shape.begin(), owner);
}

/// Adds a method to a class bound in another file (so each stage's file stays as it is).
template <class F, class... Extra>
void add_method(nb::handle type, const char* name, F&& f, const Extra&... extra) {
  nb::setattr(type, name,
              nb::cpp_function(std::forward<F>(f), nb::scope(type), nb::name(name), nb::is_method(),
                               extra...));
}

/// Pickle and copy support from a serialised form: state = (format name, version, payload).
template <class T, class Save, class Load>
void add_pickle(nb::handle type, const char* format, Save save, Load load) {
  const std::string fmt_name = format;
  add_method(type, "__getstate__", [fmt_name, save](const T& value) {
    return std::make_tuple(fmt_name, 1, save(value));
  });
  add_method(type, "__setstate__",
             [fmt_name, load](T& self, const std::tuple<std::string, int, nb::object>& state) {
               if (std::get<0>(state) != fmt_name || std::get<1>(state) != 1)
                 throw Error(
                     fmt::format("cannot unpickle {} version {} as {} (this build reads version 1)",
                                 std::get<0>(state), std::get<1>(state), fmt_name));
               new (&self) T(load(std::get<2>(state)));
             });
  if (!nb::hasattr(type, "__copy__")) {
    add_method(type, "__copy__", [](const T& v) { return T(v); });
    add_method(type, "__deepcopy__", [](const T& v, nb::handle) { return T(v); }, "memo"_a);
  }
}

// --- EvaluationResult pickling, from its descriptor (visit_fields in animat/evaluate.hpp) -------
nb::dict result_state(const EvaluationResult& r) {
  nb::dict d;
  EvaluationResult copy = r;
  visit_fields(copy, [&](const char* name, const char*, auto& value) {
    d[name] = nb::cast(value, nb::rv_policy::copy);
  });
  return d;
}

EvaluationResult result_from_state(nb::handle state) {
  const nb::dict d = nb::cast<nb::dict>(state);
  EvaluationResult r;
  visit_fields(r, [&](const char* name, const char*, auto& value) {
    using T = std::decay_t<decltype(value)>;
    if (d.contains(name)) value = nb::cast<T>(d[name]);
  });
  return r;
}

nb::tuple body_state(const Body& b) {
  return nb::make_tuple(b.positions, b.springs, b.rest_lengths, b.regions, b.rest_areas, b.skin,
                        b.skin_loops, b.amplitude, b.frequency, b.phase, b.stiffness);
}

Body body_from_state(nb::handle state) {
  const nb::tuple t = nb::cast<nb::tuple>(state);
  Body b;
  b.positions = nb::cast<Points>(t[0]);
  b.springs = nb::cast<IndexPairs>(t[1]);
  b.rest_lengths = nb::cast<Vector>(t[2]);
  b.regions = nb::cast<std::vector<std::vector<int>>>(t[3]);
  b.rest_areas = nb::cast<Vector>(t[4]);
  b.skin = nb::cast<IndexPairs>(t[5]);
  b.skin_loops = nb::cast<std::vector<std::vector<int>>>(t[6]);
  b.amplitude = nb::cast<Vector>(t[7]);
  b.frequency = nb::cast<Vector>(t[8]);
  b.phase = nb::cast<Vector>(t[9]);
  if (t.size() > 10)
    b.stiffness = nb::cast<Vector>(t[10]);  // absent in states pickled before evolvable stiffness
  return b;
}

nb::tuple trace_state(const DevelopmentTrace& t) {
  return nb::make_tuple(t.steps, t.positions, t.radii, t.orientations);
}

DevelopmentTrace trace_from_state(nb::handle state) {
  const nb::tuple s = nb::cast<nb::tuple>(state);
  DevelopmentTrace t;
  t.steps = nb::cast<std::vector<int>>(s[0]);
  t.positions = nb::cast<std::vector<Points>>(s[1]);
  t.radii = nb::cast<std::vector<Vector>>(s[2]);
  t.orientations = nb::cast<std::vector<Points>>(s[3]);
  return t;
}

nb::tuple embryo_state(const Embryo& e) {
  return nb::make_tuple(e.positions, e.radii, e.orientations, e.outputs, e.amplitude, e.frequency,
                        e.phase, e.division_steps, e.steps_run, e.viable, e.reasons,
                        trace_state(e.trace), e.stiffness);
}

Embryo embryo_from_state(nb::handle state) {
  const nb::tuple t = nb::cast<nb::tuple>(state);
  Embryo e;
  e.positions = nb::cast<Points>(t[0]);
  e.radii = nb::cast<Vector>(t[1]);
  e.orientations = nb::cast<Points>(t[2]);
  e.outputs = nb::cast<OutputLevels>(t[3]);
  e.amplitude = nb::cast<Vector>(t[4]);
  e.frequency = nb::cast<Vector>(t[5]);
  e.phase = nb::cast<Vector>(t[6]);
  e.division_steps = nb::cast<std::vector<int>>(t[7]);
  e.steps_run = nb::cast<int>(t[8]);
  e.viable = nb::cast<bool>(t[9]);
  e.reasons = nb::cast<std::vector<std::string>>(t[10]);
  e.trace = trace_from_state(t[11]);
  if (t.size() > 12)
    e.stiffness = nb::cast<Vector>(t[12]);  // absent in states pickled before evolvable stiffness
  return e;
}

/// A Python objective: any object with `name` (str), `every` (int, trajectory sampling; 0 = none)
/// that is callable with an EvaluationRecord and returns a float. Called under the GIL from the
/// evaluating threads; everything else runs without it.
class PythonObjective final : public Objective {
 public:
  explicit PythonObjective(nb::object obj) : obj_(std::move(obj)) {
    name_ = nb::cast<std::string>(obj_.attr("name"));
    every_ = nb::cast<long>(obj_.attr("every"));
    if (every_ < 0)
      throw ConfigError(fmt::format("objective {}: every must be >= 0, got {}", name_, every_));
  }
  ~PythonObjective() override {
    nb::gil_scoped_acquire gil;
    interrupt_.reset();
    obj_.reset();
  }
  std::string name() const override { return name_; }
  bool needs_body() const override { return true; }
  long sample_every() const override { return every_; }
  double value(const EvaluationRecord& record) const override {
    nb::gil_scoped_acquire gil;
    try {
      nb::object out = obj_(nb::cast(record, nb::rv_policy::copy));
      if (!nb::isinstance<nb::float_>(out) && !nb::isinstance<nb::int_>(out) &&
          !nb::hasattr(out, "__float__"))
        throw Error(fmt::format("objective {} returned a {}, expected a float", name_,
                                nb::cast<std::string>(nb::str(out.type().attr("__name__")))));
      return nb::cast<double>(out.attr("__float__")());
    } catch (nb::python_error& e) {
      // Ctrl-C while the objective ran: kept (under the GIL) for the caller to raise again, and the
      // evaluation stops like a signal stops it (Interrupted; animat.evolve raises the
      // KeyboardInterrupt with the partial result, stop reason "interrupted").
      if (e.matches(PyExc_KeyboardInterrupt)) {
        if (!interrupt_) interrupt_.emplace(std::move(e));
        throw Interrupted(fmt::format("objective {} interrupted (KeyboardInterrupt)", name_));
      }
      // Re-raised as a C++ error: a Python exception must not cross the evaluation threads.
      throw Error(fmt::format("objective {} raised {}", name_, e.what()));
    }
  }
  /// The KeyboardInterrupt it raised, if any (with the GIL held).
  std::optional<nb::python_error> take_interrupt() const {
    std::optional<nb::python_error> out = std::move(interrupt_);
    interrupt_.reset();
    return out;
  }

 private:
  nb::object obj_;
  std::string name_;
  long every_ = 0;
  mutable std::optional<nb::python_error> interrupt_;  ///< touched with the GIL held only
};

ExternalActuation::Mode actuation_mode(const std::string& mode) {
  if (mode == "rest_length") return ExternalActuation::Mode::rest_length;
  if (mode == "oscillator") return ExternalActuation::Mode::oscillator;
  throw ConfigError(fmt::format(
      "external actuation: unknown mode '{}' (expected rest_length or oscillator)", mode));
}

/// An objective that scores as `inner` does and keeps a copy of the body it was shown: the body
/// the evaluation developed and swam (an observed evaluation is bit-identical to an unobserved
/// one). value() runs only for a viable, stable and valid swim; with evaluation.repeats > 1 every
/// repeat shows the same body, the first is kept. One per evaluation (value() writes the copy).
class BodyKeeper final : public Objective {
 public:
  explicit BodyKeeper(const Objective& inner) : inner_(inner) {}
  std::string name() const override { return inner_.name(); }
  bool needs_body() const override { return true; }
  long sample_every() const override { return inner_.sample_every(); }
  double value(const EvaluationRecord& record) const override {
    if (!body_) body_ = record.body;
    return inner_.value(record);
  }
  std::optional<Body>& body() { return body_; }

 private:
  const Objective& inner_;
  mutable std::optional<Body> body_;
};

std::vector<double> to_doubles(nb::handle obj) {
  const nb::module_ np = nb::module_::import_("numpy");
  nb::object a = np.attr("ascontiguousarray")(obj, "dtype"_a = np.attr("float64")).attr("ravel")();
  return nb::cast<std::vector<double>>(a.attr("tolist")());
}

}  // namespace

std::shared_ptr<const Objective> objective_from_python(nb::handle objective, const Config& config) {
  if (objective.is_none()) return make_objective(config.evaluation);
  if (nb::isinstance<nb::str>(objective)) {
    EvaluationParams p = config.evaluation;
    p.objective = nb::cast<std::string>(objective);
    validate(p);
    return make_objective(p);
  }
  return std::make_shared<PythonObjective>(nb::borrow(objective));
}

std::optional<nb::python_error> take_interrupt(const std::shared_ptr<const Objective>& objective) {
  if (const auto* python = dynamic_cast<const PythonObjective*>(objective.get()))
    return python->take_interrupt();
  return std::nullopt;
}

void bind_research(nb::module_& m) {
  // --- pickling of the classes bound elsewhere ---------------------------------------------------
  add_pickle<Config>(
      nb::type<Config>(), "animat.Config", [](const Config& c) { return nb::cast(to_toml(c)); },
      [](nb::handle s) { return config_from_toml(nb::cast<std::string>(s), "<pickle>"); });
  add_pickle<Genome>(
      nb::type<Genome>(), "animat.Genome", [](const Genome& g) { return nb::cast(to_json(g)); },
      [](nb::handle s) {
        return genome_from_json(nb::cast<std::string>(s), GenomeParams{.max_elements = 1000000},
                                "<pickle>");
      });
  add_pickle<SceneParams>(
      nb::type<SceneParams>(), "animat.Scene",
      [](const SceneParams& p) {
        Config c;
        c.scene = p;
        return nb::cast(to_toml(c));
      },
      [](nb::handle s) { return config_from_toml(nb::cast<std::string>(s), "<pickle>").scene; });
  add_pickle<Body>(
      nb::type<Body>(), "animat.Body", [](const Body& b) { return nb::object(body_state(b)); },
      body_from_state);
  add_pickle<Embryo>(
      nb::type<Embryo>(), "animat.Embryo",
      [](const Embryo& e) { return nb::object(embryo_state(e)); }, embryo_from_state);
  add_pickle<DevelopmentTrace>(
      nb::type<DevelopmentTrace>(), "animat.DevelopmentTrace",
      [](const DevelopmentTrace& t) { return nb::object(trace_state(t)); }, trace_from_state);
  add_pickle<EvaluationResult>(
      nb::type<EvaluationResult>(), "animat.EvaluationResult",
      [](const EvaluationResult& r) { return nb::object(result_state(r)); }, result_from_state);
  add_pickle<SwimResult>(
      nb::type<SwimResult>(), "animat.SwimResult",
      [](const SwimResult& r) {
        return nb::object(nb::make_tuple(r.distance, r.displacement, r.stable, r.failure, r.steps,
                                         r.simulated_time, r.max_speed, r.max_step_displacement,
                                         r.max_stretch, r.min_stretch, r.final_kinetic_energy,
                                         r.max_kinetic_energy));
      },
      [](nb::handle s) {
        const nb::tuple t = nb::cast<nb::tuple>(s);
        SwimResult r;
        r.distance = nb::cast<double>(t[0]);
        r.displacement = nb::cast<Eigen::Vector2d>(t[1]);
        r.stable = nb::cast<bool>(t[2]);
        r.failure = nb::cast<std::string>(t[3]);
        r.steps = nb::cast<long>(t[4]);
        r.simulated_time = nb::cast<double>(t[5]);
        r.max_speed = nb::cast<double>(t[6]);
        r.max_step_displacement = nb::cast<double>(t[7]);
        r.max_stretch = nb::cast<double>(t[8]);
        r.min_stretch = nb::cast<double>(t[9]);
        r.final_kinetic_energy = nb::cast<double>(t[10]);
        r.max_kinetic_energy = nb::cast<double>(t[11]);
        return r;
      });
  add_pickle<Rng>(
      nb::type<Rng>(), "animat.Rng", [](const Rng& r) { return nb::cast(r.state()); },
      [](nb::handle s) {
        Rng r;
        r.set_state(nb::cast<Rng::State>(s));
        return r;
      });
  add_method(nb::type<EvaluationResult>(), "to_dict",
             [](const EvaluationResult& r) { return result_state(r); });

  // --- the evaluation record ---------------------------------------------------------------------
  nb::class_<EvaluationRecord>(
      m, "EvaluationRecord",
      "What an objective sees of one evaluation: the EvaluationResult (its fields are also\n"
      "attributes of the record: ``record.displacement``, ``record.cell_count``, every\n"
      "diagnostic), the Body that swam and its trajectory sampled every ``every`` control\n"
      "steps (frame 0 is the start). ``result.fitness`` is the paper's distance.")
      .def_prop_ro(
          "result", [](const EvaluationRecord& r) { return r.result; },
          "The EvaluationResult (a copy).")
      .def_prop_ro(
          "body",
          [](const EvaluationRecord& r) -> std::optional<Body> {
            if (r.body.node_count() == 0) return std::nullopt;
            return r.body;
          },
          "The Body that swam, or None if the genome was not viable.")
      .def_ro("every", &EvaluationRecord::every, "Control steps between frames (0: no trajectory).")
      .def_prop_ro(
          "steps",
          [](const EvaluationRecord& r) {
            return owned_int(std::vector<std::int64_t>(r.steps.begin(), r.steps.end()),
                             {r.steps.size()});
          },
          nb::rv_policy::move, "(F,) int64 control step of every frame.")
      .def_prop_ro(
          "times", [](const EvaluationRecord& r) { return owned(r.times, {r.times.size()}); },
          nb::rv_policy::move, "(F,) float64 simulated time of every frame.")
      .def_prop_ro(
          "positions",
          [](const EvaluationRecord& r) {
            const std::size_t f = r.frame_count(), n = f ? r.positions.size() / (2 * f) : 0;
            return owned(r.positions, {f, n, 2});
          },
          nb::rv_policy::move, "(F, n, 2) float64 cell positions of every frame.")
      .def_prop_ro(
          "velocities",
          [](const EvaluationRecord& r) {
            const std::size_t f = r.frame_count(), n = f ? r.velocities.size() / (2 * f) : 0;
            return owned(r.velocities, {f, n, 2});
          },
          nb::rv_policy::move, "(F, n, 2) float64 cell velocities of every frame.")
      .def_prop_ro(
          "com",
          [](const EvaluationRecord& r) {
            const std::size_t f = r.frame_count(), n = f ? r.positions.size() / (2 * f) : 0;
            std::vector<double> c(2 * f, 0.0);
            for (std::size_t k = 0; k < f; ++k)
              for (std::size_t i = 0; i < n; ++i)
                for (std::size_t d = 0; d < 2; ++d)
                  c[2 * k + d] += r.positions[(k * n + i) * 2 + d] / static_cast<double>(n);
            return owned(std::move(c), {f, 2});
          },
          nb::rv_policy::move, "(F, 2) float64 centre of mass of every frame.")
      .def(
          "__getattr__",
          [](const EvaluationRecord& r, const std::string& name) {
            nb::object result = nb::cast(r.result);
            if (!nb::hasattr(result, name.c_str()))
              throw nb::attribute_error(
                  ("EvaluationRecord has no attribute '" + name + "'").c_str());
            return nb::object(result.attr(name.c_str()));  // resolved now, while `result` lives
          },
          "name"_a)
      .def("__getstate__",
           [](const EvaluationRecord& r) {
             return nb::make_tuple(std::string("animat.EvaluationRecord"), 1,
                                   result_state(r.result), body_state(r.body), r.every, r.steps,
                                   r.times, r.positions, r.velocities);
           })
      .def("__setstate__",
           [](EvaluationRecord& self, const nb::tuple& t) {
             if (nb::len(t) != 9 || nb::cast<std::string>(t[0]) != "animat.EvaluationRecord" ||
                 nb::cast<int>(t[1]) != 1)
               throw Error("cannot unpickle this state as animat.EvaluationRecord version 1");
             EvaluationRecord r;
             r.result = result_from_state(t[2]);
             r.body = body_from_state(t[3]);
             r.every = nb::cast<long>(t[4]);
             r.steps = nb::cast<std::vector<long>>(t[5]);
             r.times = nb::cast<std::vector<double>>(t[6]);
             r.positions = nb::cast<std::vector<double>>(t[7]);
             r.velocities = nb::cast<std::vector<double>>(t[8]);
             new (&self) EvaluationRecord(std::move(r));
           })
      .def("__copy__", [](const EvaluationRecord& r) { return r; })
      .def(
          "__deepcopy__", [](const EvaluationRecord& r, nb::handle) { return r; }, "memo"_a)
      .def("__repr__", [](const EvaluationRecord& r) {
        return fmt::format("<animat.EvaluationRecord fitness={:.6g} viable={} cells={} frames={}>",
                           r.result.fitness, r.result.viable ? "True" : "False",
                           r.result.cell_count, r.frame_count());
      });

  m.def(
      "record_evaluation",
      [](const Genome& genome, std::optional<Config> config, long every) {
        const Config c = config.value_or(Config{});
        nb::gil_scoped_release release;
        return record_evaluation(genome, c, true, every);
      },
      "genome"_a, "config"_a = nb::none(), "every"_a = 20,
      "Evaluate a genome as animat.evaluate does and return the EvaluationRecord an objective "
      "sees:\n"
      "the result, the body and the trajectory every `every` control steps (0 = no trajectory).");
  m.def(
      "fitness_of", [](const EvaluationResult& r) { return fitness_of(r); }, "result"_a,
      "The Fitness the searches know of an evaluation (evolution.hpp fitness_of): every Fitness "
      "field\ncopied from the EvaluationResult, as animat_evolve's evaluations give them.");
  m.def(
      "_evaluate_population_bodies",
      [](const std::vector<Genome>& genomes, std::optional<Config> config, int threads,
         nb::handle objective) {
        const Config c = config.value_or(Config{});
        validate(c);
        const std::shared_ptr<const Objective> scored_by = objective_from_python(objective, c);
        std::vector<std::optional<Body>> bodies(genomes.size());
        // objective_fitness()'s function, keeping the body: the evaluator hands each genome of
        // `genomes` by reference, so its index is its offset in the vector.
        const FitnessFunction keep = [&](const Genome& genome) {
          BodyKeeper keeper(*scored_by);
          const EvaluationResult r = evaluate(genome, c, keeper);
          const Fitness f = fitness_of(r);
          bodies[static_cast<std::size_t>(&genome - genomes.data())] = std::move(keeper.body());
          return f;
        };
        std::vector<Fitness> fits;
        {
          nb::gil_scoped_release release;
          fits = evaluate_all(genomes, keep, threads);
        }
        return std::make_tuple(std::move(fits), std::move(bodies));
      },
      "genomes"_a, "config"_a = nb::none(), "threads"_a = 0, "objective"_a = nb::none(),
      "evaluate_population (the same Fitness, bit for bit) and the Body each evaluation developed "
      "and swam\n"
      "(None where the swim was not viable, stable and valid): (fitnesses, bodies). MAP-Elites "
      "describes\n"
      "its candidates from these bodies (animat.qd).");
  m.def(
      "source_direction",
      [](const Config& config, int trial) {
        const int count = std::max(1, config.evaluation.source_directions);
        if (trial < 0 || trial >= count)
          throw ConfigError(fmt::format(
              "source_direction: trial {} is not one of the {} evaluation.source_directions", trial,
              count));
        return source_direction(config, trial);
      },
      "config"_a, "trial"_a,
      "Objective chemotaxis: the chemical source of swim `trial` of an evaluation, relative to the "
      "body's\n"
      "start centre: scene.chemical_source turned by the run's offset + 2*pi*trial/T (T =\n"
      "evaluation.source_directions), as the evaluation places it.");
  m.def("body_length", &body_length, "body"_a,
        "Length of a body along its longest axis: the largest distance between two cell centres at "
        "rest plus\n"
        "one cell diameter (1 length unit). The `distance_per_size` objective divides by it.");
  nb::class_<ObjectiveSpec>(
      m, "ObjectiveSpec",
      "A built-in objective (a row of the C++ table kObjectives): its name, what it measures, its\n"
      "sign rule and what it reads. animat.objectives() lists them.")
      .def_prop_ro(
          "name", [](const ObjectiveSpec& s) { return std::string(s.name); },
          "Its value of evaluation.objective.")
      .def_prop_ro(
          "meaning", [](const ObjectiveSpec& s) { return std::string(s.meaning); },
          "What it measures.")
      .def_ro("nonnegative", &ObjectiveSpec::nonnegative,
              "Every value is >= 0 by construction (a negative fitness is refused under it).")
      .def_ro("needs_body", &ObjectiveSpec::needs_body, "It reads the body's length.")
      .def_ro(
          "one_swim", &ObjectiveSpec::one_swim,
          "One swim decides it (SwimEnv can reward it); otherwise one swim per source direction.")
      .def("__repr__", [](const ObjectiveSpec& s) {
        return fmt::format("ObjectiveSpec('{}': {})", s.name, s.meaning);
      });
  m.def(
      "objectives",
      [] { return std::vector<ObjectiveSpec>(std::begin(kObjectives), std::end(kObjectives)); },
      "The built-in objectives, in the order of the C++ table.");
  m.attr("OBJECTIVES") = [] {
    std::vector<std::string> out;
    for (const auto& spec : kObjectives) out.emplace_back(spec.name);
    return out;
  }();
  m.def(
      "objective_value",
      [](std::string_view name, double distance, double dx, double dy, double duration,
         double body_length, double actuation_work_positive, double source_progress,
         std::optional<Config> config) {
        const ObjectiveSpec* spec = find_objective(name);
        if (!spec) {
          std::vector<std::string_view> names;
          for (const auto& row : kObjectives) names.push_back(row.name);
          throw ConfigError(
              fmt::format("objective_value: \"{}\" is not a built-in objective (one of {})", name,
                          fmt::join(names, ", ")));
        }
        const Config c = config.value_or(Config{});
        validate(c.evaluation);
        SwimOutcome o;
        o.distance = distance;
        o.dx = dx;
        o.dy = dy;
        o.duration = duration;
        o.body_length = body_length;
        o.actuation_work_positive = actuation_work_positive;
        o.source_progress = source_progress;
        return spec->value(o, c.evaluation);
      },
      "name"_a, "distance"_a, "dx"_a, "dy"_a, "duration"_a, "body_length"_a = 0.0,
      "actuation_work_positive"_a = 0.0, "source_progress"_a = 0.0, "config"_a = nb::none(),
      "A built-in objective's value of a swim's outcome, exactly as the engine scores it (the C++ "
      "table's\n"
      "function; SwimEnv rewards with it). config supplies evaluation.direction, energy_weight and "
      "energy_offset.");

  // --- externally driven actuation
  // ------------------------------------------------------------------
  nb::class_<ExternalActuation>(
      m, "ExternalActuation",
      "Actuation set from outside the simulation (see ``Simulation.add_external_actuation``):\n"
      "rest length of spring (i, j) = (1 + u_i + u_j) L0, with the cell terms u_i set directly\n"
      "(mode 'rest_length') or u_i = a_i sin(f_i t + phase_i) with amplitudes and phases set\n"
      "(mode 'oscillator'; f_i: the body's frequencies unless set). |u_i| < 0.5. The oscillators\n"
      "step exactly as the body's own (effect 'actuation'); with ``delayed_start`` each cell "
      "starts at\n"
      "a zero of its sine as the paper's cells do, so the body's amplitudes, frequencies and "
      "phases\n"
      "swim the body as an evaluation does, bit for bit.")
      .def_prop_ro(
          "mode",
          [](const ExternalActuation& a) {
            return std::string(a.mode() == ExternalActuation::Mode::rest_length ? "rest_length"
                                                                                : "oscillator");
          },
          "'rest_length' or 'oscillator'.")
      .def_prop_ro("delayed_start", &ExternalActuation::delayed_start,
                   "Mode 'oscillator': each cell starts at the first zero of its sine (the paper's "
                   "delayed start).")
      .def_prop_ro(
          "start_steps",
          [](const ExternalActuation& a) {
            const std::vector<long> v = a.start_steps();
            return owned_int(std::vector<std::int64_t>(v.begin(), v.end()), {v.size()});
          },
          nb::rv_policy::move,
          "(n,) int64: each cell's start step as of the last step (mode 'oscillator'; -1 = not yet "
          "decided or never).")
      .def_prop_ro("node_count", &ExternalActuation::node_count, "Cells.")
      .def(
          "set_terms", [](ExternalActuation& a, nb::handle u) { a.set_terms(to_doubles(u)); },
          "terms"_a,
          "Mode 'rest_length': set every cell's term u_i, an (n,) array with |u_i| < 0.5.")
      .def(
          "set_oscillators",
          [](ExternalActuation& a, nb::handle amplitude, nb::handle phase) {
            a.set_oscillators(to_doubles(amplitude), to_doubles(phase));
          },
          "amplitude"_a, "phase"_a,
          "Mode 'oscillator': set every cell's amplitude (n,) in [0, 0.5) and phase (n,) "
          "(radians).")
      .def_prop_rw(
          "frequency",
          [](const ExternalActuation& a) { return owned(a.frequency(), {a.frequency().size()}); },
          [](ExternalActuation& a, nb::handle f) { a.set_frequency(to_doubles(f)); },
          nb::rv_policy::move,
          "(n,) oscillator frequencies (mode 'oscillator'; default: the body's).")
      .def_prop_ro(
          "terms", [](const ExternalActuation& a) { return owned(a.terms(), {a.terms().size()}); },
          nb::rv_policy::move, "(n,) cell terms u_i of the last step.");
  add_method(
      nb::type<Simulation>(), "add_external_actuation",
      [](Simulation& sim, const Body& body, const std::string& mode, bool delayed_start) {
        for (const Effect* e : sim.effects())
          if (e->name() == "actuation" || e->name() == "external_actuation")
            throw ConfigError(fmt::format(
                "Simulation.add_external_actuation: the scene already has '{}' (both would write "
                "the rest lengths); remove it from the scene's effects",
                e->name()));
        if (body.node_count() != sim.node_count())
          throw GeometryError(fmt::format(
              "Simulation.add_external_actuation: the body has {} cells, the simulation {}",
              body.node_count(), sim.node_count()));
        auto effect =
            std::make_unique<ExternalActuation>(body, actuation_mode(mode), delayed_start);
        ExternalActuation* raw = effect.get();
        sim.add_effect(std::move(effect));
        return raw;
      },
      "body"_a, "mode"_a = "rest_length", "delayed_start"_a = false,
      nb::rv_policy::reference_internal,
      "Drive the rest lengths from outside (returns the ExternalActuation to set): `body` is the "
      "body this\n"
      "simulation swims; mode 'rest_length' (set u_i) or 'oscillator' (set amplitudes and phases;\n"
      "`delayed_start`: each cell starts at a zero of its sine, as the body's own actuation starts "
      "it). The\n"
      "scene must not list 'actuation'.");

  // --- GRN control added to a Python-built simulation (docs/control.md) ------------------------
  nb::class_<GrnControl>(
      m, "GrnControl",
      "The GRN running while the body swims (control.mode = 'grn'; see "
      "``Simulation.add_grn_control``):\n"
      "every control.update_interval Box2D steps it reads the sensors, diffuses the cells' "
      "products\n"
      "along the springs, steps eq. 1 and sets the cells' actuation. Read-only views of its state.")
      .def_prop_ro("cell_count", &GrnControl::cell_count, "Cells.")
      .def_prop_ro(
          "terms", [](const GrnControl& g) { return owned(g.terms(), {g.terms().size()}); },
          nb::rv_policy::move, "(n,) the cells' terms u_i of eq. 2 as of the last update.")
      .def_prop_ro(
          "sensors",
          [](const GrnControl& g) {
            return owned(g.sensors(), {static_cast<std::size_t>(g.cell_count()), 3});
          },
          nb::rv_policy::move,
          "(n, 3) sensor values of the last update: strain, pressure S/S0, chemical.")
      .def_prop_ro(
          "actuation_levels",
          [](const GrnControl& g) {
            std::vector<double> v;
            for (int i = 0; i < g.cell_count(); ++i)
              v.push_back(g.grn().output(g.state(i), OutputChannel::actuation));
            return owned(std::move(v), {static_cast<std::size_t>(g.cell_count())});
          },
          nb::rv_policy::move,
          "(n,) the cells' actuation output levels L (u_i = amplitude_max (2L - 1), ramped in).")
      .def_prop_ro("updates", &GrnControl::updates, "GRN updates done so far.")
      .def("set_chemical_source", &GrnControl::set_chemical_source, "x"_a, "y"_a,
           "Move the chemical source (absolute coordinates) while swimming.");
  add_method(
      nb::type<Simulation>(), "add_grn_control",
      [](Simulation& sim, const Body& body, const Genome& genome, std::optional<Config> config) {
        const Config c = config ? *config : Config{};
        for (const Effect* e : sim.effects())
          if (e->name() == "actuation" || e->name() == "external_actuation" ||
              e->name() == "grn_control")
            throw ConfigError(fmt::format(
                "Simulation.add_grn_control: the scene already has '{}' (both would write "
                "the rest lengths); remove it from the scene's effects",
                e->name()));
        if (body.node_count() != sim.node_count())
          throw GeometryError(
              fmt::format("Simulation.add_grn_control: the body has {} cells, the simulation {}",
                          body.node_count(), sim.node_count()));
        const Embryo embryo = develop(genome, c.genome, c.grn, c.development);
        if (!embryo.viable)
          throw ConfigError("Simulation.add_grn_control: the genome is not viable");
        if (embryo.cell_count() != body.node_count())
          throw GeometryError(fmt::format(
              "Simulation.add_grn_control: the genome develops {} cells, the body has {}",
              embryo.cell_count(), body.node_count()));
        auto effect = std::make_unique<GrnControl>(body, grn_control_start(genome, embryo, c),
                                                   c.control, c.scene, c.physics);
        GrnControl* raw = effect.get();
        sim.add_effect(std::move(effect));
        return raw;
      },
      "body"_a, "genome"_a, "config"_a = nb::none(), nb::rv_policy::reference_internal,
      "Run `genome`'s GRN while this simulation swims (docs/control.md): `body` is the body it "
      "swims (developed\n"
      "from `genome` with `config`), whose cells start from their end-of-development GRN states; "
      "the\n"
      "control keys (control.*, scene.chemical*) come from `config`. The scene must not list "
      "'actuation'.\n"
      "Returns the GrnControl, whose terms, sensors and actuation levels can be read while "
      "stepping.");

  // --- animat evolve
  // ------------------------------------------------------------------------------
  m.def(
      "evolve_cli",
      [](std::vector<std::string> args) {
        std::vector<std::string> argv_store = {"animat evolve"};
        argv_store.insert(argv_store.end(), args.begin(), args.end());
        std::vector<char*> argv;
        for (auto& a : argv_store) argv.push_back(a.data());
        argv.push_back(nullptr);
        // animat_evolve installs SIGINT/SIGTERM handlers (finish the generation, checkpoint, exit);
        // Python's own handlers come back afterwards.
        auto old_int = std::signal(SIGINT, SIG_DFL);
        auto old_term = std::signal(SIGTERM, SIG_DFL);
        std::fflush(stdout);
        int rc = 0;
        {
          nb::gil_scoped_release release;
          rc = animat_evolve_main(static_cast<int>(argv_store.size()), argv.data());
          std::fflush(stdout);
          std::fflush(stderr);
        }
        std::signal(SIGINT, old_int);
        std::signal(SIGTERM, old_term);
        return rc;
      },
      "args"_a,
      "Run the animat_evolve command line in this process (the `animat evolve` console script): "
      "the same\n"
      "engine, flags and output. Returns the exit status.");
}

}  // namespace animat::py
