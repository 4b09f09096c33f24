// Python bindings of the swim stage: Scene (effects + coefficients), Simulation, swim() and
// evaluate().
#include <nanobind/eigen/dense.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/string_view.h>
#include <nanobind/stl/variant.h>
#include <nanobind/stl/vector.h>
#include <array>

#include <fmt/format.h>

#include <cstddef>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <unordered_set>
#include <vector>

#include "animat/body.hpp"
#include "animat/config.hpp"
#include "animat/control.hpp"
#include "animat/development.hpp"
#include "animat/embedding.hpp"
#include "animat/energy.hpp"
#include "animat/errors.hpp"
#include "animat/evaluate.hpp"
#include "animat/objective.hpp"
#include "animat/physics.hpp"
#include "animat/scene.hpp"
#include "bindings.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace animat::py {
namespace {

// A Simulation owns one Box2D world and is not thread-safe. step() and record() run without the
// GIL, so two Python threads could drive one world at once (Box2D aborts on its stack allocator).
// Every method holds a lease on its Simulation; a second thread gets a RuntimeError instead.
class Lease : public ThreadLease<Simulation> {
 public:
  Lease(const Simulation& s, const char* method)
      : ThreadLease(s, "Simulation", method,
                    "this Simulation is in use by another thread; a Simulation (one Box2D world) "
                    "is not thread-safe: "
                    "give each thread its own Simulation") {}
};

std::vector<std::string> scene_keys() {
  SceneParams p;
  std::vector<std::string> out;
  visit_fields(p, [&](const FieldInfo& info, auto&) { out.emplace_back(info.name); });
  return out;
}

/// Sets scene fields from a {name: value} mapping through the config machinery (types and ranges
/// checked there); an unknown name is a ValueError naming it.
SceneParams scene_with(SceneParams base, const nb::handle& mapping, const char* who) {
  const auto keys = scene_keys();
  Config c;
  c.scene = std::move(base);
  for (auto item : nb::cast<nb::dict>(mapping)) {
    const std::string key = nb::cast<std::string>(item.first);
    if (std::find(keys.begin(), keys.end(), key) == keys.end())
      throw ConfigError(fmt::format("{}: unknown keyword '{}' (expected any of {})", who, key,
                                    fmt::join(keys, ", ")));
    ConfigValue v;
    if (nb::isinstance<nb::tuple>(item.second) || nb::isinstance<nb::list>(item.second)) {
      // A list of numbers (scene.chemical_source) or of words (scene.effects).
      bool numbers = nb::len(item.second) > 0;
      for (auto w : item.second)
        numbers = numbers && (nb::isinstance<nb::float_>(w) || nb::isinstance<nb::int_>(w));
      if (numbers) {
        std::vector<double> xs;
        for (auto w : item.second) xs.push_back(nb::cast<double>(w));
        v = std::move(xs);
      } else {
        std::vector<std::string> words;
        for (auto w : item.second) words.push_back(nb::cast<std::string>(w));
        v = std::move(words);
      }
    } else {
      v = nb::cast<ConfigValue>(item.second);
    }
    set_value(c, "scene." + key, v);
  }
  validate(c.scene);
  return c.scene;
}

nb::dict scene_to_dict(const SceneParams& p) {
  Config c;
  c.scene = p;
  nb::dict d;
  for (const auto& k : scene_keys()) d[k.c_str()] = nb::cast(get_value(c, "scene." + k));
  return d;
}

std::string scene_repr(const SceneParams& p) {
  std::string out = "animat.Scene(";
  Config c;
  c.scene = p;
  bool first = true;
  for (const auto& k : scene_keys()) {
    const ConfigValue v = get_value(c, "scene." + k);
    std::string s;
    std::visit(
        [&](const auto& x) {
          using X = std::decay_t<decltype(x)>;
          if constexpr (std::is_same_v<X, std::vector<std::string>>) {
            s = "[";
            for (std::size_t i = 0; i < x.size(); ++i) s += (i ? ", '" : "'") + x[i] + "'";
            s += "]";
          } else if constexpr (std::is_same_v<X, std::vector<double>>) {
            s = fmt::format("{}", fmt::join(x, ", "));
          } else if constexpr (std::is_same_v<X, std::string>) {
            s = "'" + x + "'";
          } else if constexpr (std::is_same_v<X, bool>) {
            s = x ? "True" : "False";
          } else {
            s = fmt::format("{}", x);
          }
        },
        v);
    out += (first ? "" : ", ") + k + "=" + s;
    first = false;
  }
  return out + ")";
}

nb::ndarray<nb::numpy, double> owned_array(std::vector<double> v,
                                           std::initializer_list<std::size_t> shape) {
  auto* heap = new std::vector<double>(std::move(v));
  nb::capsule owner(heap, [](void* p) noexcept { delete static_cast<std::vector<double>*>(p); });
  return nb::ndarray<nb::numpy, double>(heap->data(), shape.size(), shape.begin(), owner);
}

/// A numpy copy of an Eigen vector (owned by the array: safe whatever the lifetime of the source).
nb::ndarray<nb::numpy, double> owned_vector(const Eigen::VectorXd& v) {
  return owned_array(std::vector<double>(v.data(), v.data() + v.size()),
                     {static_cast<std::size_t>(v.size())});
}

const char* kSceneDoc =
    "The effects a swim simulates, with their coefficients (paper §4; docs/model.md §4).\n\n"
    "``Scene()`` is the default swim scene (all five effects, d_N = 2). Keywords set fields by "
    "their\n"
    "config names, e.g. ``Scene(effects=['springs', 'actuation', 'pressure', 'drag'], "
    "drag_normal=10)``;\n"
    "an unknown keyword or an out-of-range value raises ValueError naming it. Effect names (same "
    "in\n"
    "TOML): springs, actuation, pressure, drag, skin_collision. Fields are readable and writable "
    "as\n"
    "attributes; ``drag_tangential < 0`` means drag_normal/200 (paper §6).";

const char* kSimulationDoc =
    "A swim simulation of one Body: a Box2D world with one fixture-less body per cell, driven by "
    "the\n"
    "scene's effects (see ``animat.Scene``).\n\n"
    "``Simulation(body, scene=None, config=None)``: ``scene`` (an animat.Scene) defaults to\n"
    "``config.scene``, or the default scene; the physics (dt, substeps, drag scheme) come from\n"
    "``config.physics`` (default config if None). One ``step()`` is one control step of dt =\n"
    "``config.physics.dt`` (``substeps`` Box2D steps). A step that would leave the valid domain\n"
    "(non-finite state, or a displacement per Box2D step above physics.max_step_displacement)\n"
    "raises RuntimeError and leaves the state as it was before that Box2D step.";

}  // namespace

void bind_physics(nb::module_& m) {
  auto scene = nb::class_<SceneParams>(m, "Scene", kSceneDoc);
  scene
      .def(
          "__init__",
          [](SceneParams* p, const nb::kwargs& kw) {
            new (p) SceneParams(scene_with(SceneParams{}, kw, "Scene"));
          },
          "Build a scene from keywords (config names of the [scene] section); no keyword = default "
          "scene.")
      .def_static(
          "from_dict",
          [](const nb::dict& d) { return scene_with(SceneParams{}, d, "Scene.from_dict"); },
          "values"_a, "Build a scene from a {field: value} dict (the [scene] section of a config).")
      .def_static(
          "from_config", [](const Config& c) { return SceneParams(c.scene); }, "config"_a,
          "The scene of an animat.Config (its [scene] section).")
      .def("to_dict", &scene_to_dict, "The scene as a {field: value} dict.")
      .def(
          "replace",
          [](const SceneParams& p, const nb::kwargs& kw) {
            return scene_with(p, kw, "Scene.replace");
          },
          "A copy with some fields changed by keyword.")
      .def_prop_ro(
          "effect_names",
          [](const SceneParams&) {
            std::vector<std::string> out;
            for (auto n : kSceneEffectNames) out.emplace_back(n);
            return out;
          },
          "Every effect name a scene may list.")
      .def(
          "__getattr__",
          [](const SceneParams& p, const std::string& k) -> ConfigValue {
            const auto keys = scene_keys();
            if (std::find(keys.begin(), keys.end(), k) == keys.end())
              throw nb::attribute_error(("Scene has no field '" + k + "'").c_str());
            Config c;
            c.scene = p;
            return get_value(c, "scene." + k);
          },
          "name"_a)
      .def(
          "__setattr__",
          [](SceneParams& p, const std::string& k, nb::object v) {
            nb::dict d;
            d[k.c_str()] = v;
            p = scene_with(p, d, "Scene");
          },
          "name"_a, "value"_a)
      .def("__dir__", [](const SceneParams&) { return scene_keys(); })
      .def("__eq__",
           [](const SceneParams& a, const SceneParams& b) {
             Config ca, cb;
             ca.scene = a;
             cb.scene = b;
             return ca == cb;
           })
      .def("__copy__", [](const SceneParams& p) { return SceneParams(p); })
      .def(
          "__deepcopy__", [](const SceneParams& p, nb::handle) { return SceneParams(p); }, "memo"_a)
      .def("__repr__", &scene_repr);

  // EnergyAccount: every field from its one descriptor (visit_fields in animat/energy.hpp).
  nb::class_<EnergyAccount> energy(
      m, "EnergyAccount",
      "Where the energy of a swim went (evaluation.energy_accounting; include/animat/energy.hpp):\n"
      "actuation (and pushes) in; drag (normal, tangential), spring damping, collisions, ground\n"
      "and other forces out; kinetic and potential energies stored. `residual` is what the books\n"
      "leave unexplained (integration error), small against the energy that flowed.");
  energy.def(nb::init<>());
  {
    const EnergyAccount probe;
    visit_fields(probe, [&](const char* name, const char* doc, const auto& field) {
      def_field_property(energy, probe, field, name, doc);
    });
  }
  energy
      .def_prop_ro("fluid", &EnergyAccount::fluid,
                   "Dissipated by the fluid: drag_normal + drag_tangential.")
      .def_prop_ro("dissipated", &EnergyAccount::dissipated, "Everything dissipated.")
      .def_prop_ro("stored_change", &EnergyAccount::stored_change,
                   "Change of kinetic plus potential energy.")
      .def_prop_ro("residual", &EnergyAccount::residual,
                   "actuation + external - dissipated - stored_change.")
      .def_prop_ro("fluid_share", &EnergyAccount::fluid_share,
                   "fluid / dissipated (0 when nothing was dissipated).")
      .def(
          "as_dict",
          [](const EnergyAccount& a) {
            nb::dict d;
            EnergyAccount c = a;
            visit_fields(c, [&](const char* name, const char*, auto& field) { d[name] = field; });
            for (const auto& [k, v] :
                 {std::pair{"fluid", a.fluid()}, std::pair{"dissipated", a.dissipated()},
                  std::pair{"stored_change", a.stored_change()},
                  std::pair{"residual", a.residual()}, std::pair{"fluid_share", a.fluid_share()}})
              d[k] = v;
            return d;
          },
          "Every field and the derived totals as a dict.")
      .def("__getstate__",
           [](const EnergyAccount& a) {
             nb::dict d;
             EnergyAccount c = a;
             visit_fields(c, [&](const char* name, const char*, auto& field) { d[name] = field; });
             return d;
           })
      .def("__setstate__",
           [](EnergyAccount& self, const nb::dict& d) {
             new (&self) EnergyAccount();
             visit_fields(self, [&](const char* name, const char*, auto& field) {
               if (d.contains(name)) field = nb::cast<std::decay_t<decltype(field)>>(d[name]);
             });
           })
      .def("__eq__", [](const EnergyAccount& a, const EnergyAccount& b) { return a == b; })
      .def("__repr__", [](const EnergyAccount& a) {
        if (!a.measured) return std::string("EnergyAccount(measured=False)");
        return fmt::format(
            "EnergyAccount(actuation={:.6g}, fluid={:.6g} (normal {:.6g}, tangential {:.6g}), "
            "spring_damping={:.6g}, collisions={:.6g}, ground={:.6g}, other={:.6g}, "
            "stored_change={:.6g}, residual={:.3g})",
            a.actuation, a.fluid(), a.drag_normal, a.drag_tangential, a.spring_damping,
            a.collisions, a.ground, a.other, a.stored_change(), a.residual());
      });

  nb::class_<SwimResult> swim_result(m, "SwimResult", "What one swim did (see ``animat.swim``).");
  nb::class_<EvaluationResult> evaluation_result(
      m, "EvaluationResult", "Fitness and diagnostics of one genome (see ``animat.evaluate``).");
  // SwimResult and EvaluationResult: every field from its one descriptor (animat/evaluate.hpp).
  auto def_properties = [](auto& cls, const auto& probe) {
    using Record = std::decay_t<decltype(probe)>;
    visit_fields(probe, [&](const char* name, const char* doc, const auto& field) {
      using T = std::decay_t<decltype(field)>;
      if constexpr (std::is_same_v<T, Eigen::VectorXd>) {  // a numpy array that owns its copy
        const std::ptrdiff_t offset =
            reinterpret_cast<const char*>(&field) - reinterpret_cast<const char*>(&probe);
        cls.def_prop_ro(
            name,
            [offset](const Record& r) {
              return owned_vector(
                  *reinterpret_cast<const T*>(reinterpret_cast<const char*>(&r) + offset));
            },
            nb::rv_policy::move, doc);
      } else {
        def_field_property(cls, probe, field, name, doc);
      }
    });
  };
  const SwimResult swim_probe;
  def_properties(swim_result, swim_probe);
  const EvaluationResult evaluation_probe;
  def_properties(evaluation_result, evaluation_probe);
  swim_result.def("__repr__", [](const SwimResult& r) {
    return fmt::format("<animat.SwimResult distance={:.6g} stable={} valid={} steps={}>",
                       r.distance, r.stable ? "True" : "False", r.valid ? "True" : "False",
                       r.steps);
  });

  evaluation_result.def("__repr__", [](const EvaluationResult& r) {
    return fmt::format(
        "<animat.EvaluationResult fitness={:.6g} viable={} stable={} valid={} cells={}>", r.fitness,
        r.viable ? "True" : "False", r.stable ? "True" : "False", r.valid ? "True" : "False",
        r.cell_count);
  });

  nb::class_<Simulation>(m, "Simulation", kSimulationDoc)
      .def(
          "__init__",
          [](Simulation* s, const Body& body, std::optional<SceneParams> scene,
             std::optional<Config> config) {
            const Config c = config ? *config : Config{};
            if (body.node_count() < 2)
              PyErr_WarnEx(PyExc_RuntimeWarning,
                           fmt::format("Simulation: the body has {} cell(s) and no springs: it "
                                       "cannot swim (a non-viable "
                                       "embryo? see Genome.random_viable)",
                                       body.node_count())
                               .c_str(),
                           1);
            new (s) Simulation(body, scene ? *scene : c.scene, c.physics);
          },
          "body"_a, "scene"_a = nb::none(), "config"_a = nb::none())
      .def(
          "step",
          [](Simulation& s, long n) {
            if (n < 0) throw ConfigError(fmt::format("Simulation.step: n must be >= 0, got {}", n));
            Lease lease(s, "step");
            nb::gil_scoped_release release;
            s.step(n);
          },
          "n"_a = 1,
          "Advance n control steps; raises RuntimeError if a step leaves the valid domain.")
      .def(
          "record",
          [](Simulation& s, long steps, long every) {
            if (steps < 0)
              throw ConfigError(
                  fmt::format("Simulation.record: steps must be >= 0, got {}", steps));
            if (every < 1)
              throw ConfigError(
                  fmt::format("Simulation.record: every must be >= 1, got {}", every));
            Lease lease(s, "record");
            const auto n = static_cast<std::size_t>(s.node_count());
            const auto frames = static_cast<std::size_t>(steps / every + 1);
            std::vector<double> out;
            out.reserve(frames * n * 2);
            auto grab = [&] {
              const SwimState& st = s.state();
              for (std::size_t i = 0; i < n; ++i) {
                out.push_back(st.x[i]);
                out.push_back(st.y[i]);
              }
            };
            {
              nb::gil_scoped_release release;
              grab();
              for (std::size_t f = 1; f < frames; ++f) {
                s.step(every);
                grab();
              }
            }
            return owned_array(std::move(out), {frames, n, 2});
          },
          "steps"_a, "every"_a = 1,
          "Advance `steps` control steps and return the positions as a (frames, n, 2) array: the "
          "current\n"
          "state, then every `every` steps (frames = steps // every + 1; trailing steps that do "
          "not fill\n"
          "a frame are not run).")
      .def(
          "compute_forces",
          [](Simulation& s) {
            Lease lease(s, "compute_forces");
            s.compute_forces();
            const auto n = static_cast<std::size_t>(s.node_count());
            std::vector<double> f(2 * n);
            for (std::size_t i = 0; i < n; ++i) {
              f[2 * i] = s.forces_x()[i];
              f[2 * i + 1] = s.forces_y()[i];
            }
            return owned_array(std::move(f), {n, 2});
          },
          "The (n, 2) forces the enabled effects produce in the current state (nothing is "
          "integrated).")
      .def_prop_ro(
          "positions",
          [](const Simulation& s) -> Points {
            Lease l(s, "positions");
            return s.positions();
          },
          "(n, 2) cell positions.")
      .def_prop_rw(
          "velocities",
          [](const Simulation& s) -> Points {
            Lease l(s, "velocities");
            return s.velocities();
          },
          [](Simulation& s, const Points& v) {
            Lease l(s, "velocities");
            s.set_velocities(v);
          },
          "(n, 2) cell velocities; assign an (n, 2) array to set them (e.g. to launch a body).")
      .def(
          "push",
          [](Simulation& s, const std::vector<int>& cells, std::array<double, 2> impulse) {
            Lease l(s, "push");
            s.push(cells, Eigen::Vector2d(impulse[0], impulse[1]));
          },
          "cells"_a, "impulse"_a,
          "A disruption (docs/control.md): add impulse / cell_mass to the velocity of every listed "
          "cell now\n"
          "(impulse = [Jx, Jy] per cell). ValueError for a cell out of range or a non-finite "
          "impulse.")
      .def(
          "center_of_mass",
          [](const Simulation& s) -> Eigen::Vector2d {
            Lease l(s, "center_of_mass");
            return s.center_of_mass();
          },
          "The centre of mass (equal masses: the mean position) as a (2,) array.")
      .def(
          "momentum",
          [](const Simulation& s) -> Eigen::Vector2d {
            Lease l(s, "momentum");
            return s.momentum();
          },
          "Total momentum, (2,).")
      .def(
          "kinetic_energy",
          [](const Simulation& s) {
            Lease l(s, "kinetic_energy");
            return s.kinetic_energy();
          },
          "Total kinetic energy.")
      .def_prop_ro(
          "time",
          [](const Simulation& s) {
            Lease l(s, "time");
            return s.time();
          },
          "Simulated time.")
      .def_prop_ro(
          "steps_done",
          [](const Simulation& s) {
            Lease l(s, "steps_done");
            return s.steps_done();
          },
          "Control steps done.")
      .def_prop_ro("node_count", &Simulation::node_count, "Cells.")
      .def_prop_ro(
          "rest_lengths_now",
          [](const Simulation& s) {
            Lease l(s, "rest_lengths_now");
            const auto r = s.rest_lengths_now();
            return owned_array(std::vector<double>(r.begin(), r.end()), {r.size()});
          },
          nb::rv_policy::move, "(m,) current rest length of every spring (eq. 2 at the last step).")
      .def_prop_ro(
          "effects",
          [](const Simulation& s) {
            std::vector<std::string> out;
            for (const Effect* e : s.effects()) out.emplace_back(e->name());
            return out;
          },
          "Enabled effects, in the order they run each step.")
      .def_prop_ro(
          "scene", [](const Simulation& s) { return s.scene(); },
          "The simulation's Scene (a copy).")
      .def_prop_ro(
          "failed",
          [](const Simulation& s) {
            Lease l(s, "failed");
            return s.failed();
          },
          "True after a step raised.")
      .def_prop_ro(
          "max_speed_seen",
          [](const Simulation& s) {
            Lease l(s, "max_speed_seen");
            return s.max_speed_seen();
          },
          "Largest cell speed seen so far.")
      .def_prop_ro(
          "max_step_displacement_seen",
          [](const Simulation& s) {
            Lease l(s, "max_step_displacement_seen");
            return s.max_step_displacement_seen();
          },
          "Largest |v|*h a cell was about to move in one Box2D step so far.")
      .def_prop_ro(
          "counters",
          [](const Simulation& s) {
            nb::dict d;
            visit_fields(s.counters(), [&](const char* name, const char*, const auto& value) {
              d[name] = value;
            });
            return d;
          },
          "What the effects counted so far: collisions (resolved, inelastic, unresolved, most "
          "passes in a\n"
          "step), drag limiter engagements, floor contacts and slips, and the actuation work "
          "(net,\n"
          "positive, absolute), as a dict.")
      .def(
          "account_energy",
          [](Simulation& s) {
            Lease l(s, "account_energy");
            s.account_energy();
          },
          "Open the energy books now: from here on every step books each effect's work (see "
          "`energy`).")
      .def_prop_ro(
          "energy",
          [](const Simulation& s) {
            Lease l(s, "energy");
            return s.energy_account();
          },
          "The EnergyAccount since account_energy() (measured False before).")
      .def("monitor_embedding", &Simulation::monitor_embedding, "body"_a,
           "Check the planar embedding of `body` (the body this simulation swims) now and after "
           "every step:\n"
           "region signs and skin simplicity; see `embedding`.")
      .def_prop_ro(
          "embedding",
          [](const Simulation& s) -> nb::object {
            const EmbeddingMonitor* m = s.embedding_monitor();
            if (!m) return nb::none();
            nb::dict d;
            d["steps_checked"] = m->frames();
            d["min_area_ratio"] = m->min_area_ratio();
            d["inverted_region_steps"] = m->inverted_region_frames();
            d["skin_crossing_steps"] = m->skin_crossing_frames();
            d["first_broken_step"] = s.first_broken_step();
            d["intact"] = m->intact();
            return d;
          },
          "The embedding checks so far (a dict), or None before monitor_embedding().")
      .def("__len__", &Simulation::node_count)
      .def("__repr__", [](const Simulation& s) {
        Lease l(s, "__repr__");
        return fmt::format("<animat.Simulation cells={} t={:.6g} steps={}>", s.node_count(),
                           s.time(), s.steps_done());
      });

  m.def(
      "swim",
      [](const Body& body, std::optional<SceneParams> scene, std::optional<Config> config,
         std::optional<long> steps, std::optional<bool> check_embedding, bool stop_when_invalid,
         std::optional<long> settle_steps, std::optional<bool> account_energy) {
        const Config c = config ? *config : Config{};
        const long n = steps ? *steps : c.evaluation.steps;
        if (n < 0) throw ConfigError(fmt::format("swim: steps must be >= 0, got {}", n));
        SwimOptions options;
        options.check_embedding = check_embedding ? *check_embedding : c.evaluation.check_embedding;
        options.stop_when_invalid = stop_when_invalid;
        options.settle_steps = settle_steps ? *settle_steps : c.evaluation.settle_steps;
        options.account_energy = account_energy ? *account_energy : c.evaluation.energy_accounting;
        warm_up_box2d();  // Box2D's lazily filled globals, before other threads may run worlds too
        nb::gil_scoped_release release;
        return swim(body, scene ? *scene : c.scene, c.physics, n, options);
      },
      "body"_a, "scene"_a = nb::none(), "config"_a = nb::none(), "steps"_a = nb::none(),
      "check_embedding"_a = nb::none(), "stop_when_invalid"_a = true, "settle_steps"_a = nb::none(),
      "account_energy"_a = nb::none(),
      "Swim a body for `steps` control steps (default config.evaluation.steps) and return a "
      "SwimResult.\n"
      "Never raises for an unstable or invalid swim: it returns stable/valid=False and distance "
      "0.\n"
      "check_embedding (default config.evaluation.check_embedding) checks region signs and skin\n"
      "simplicity after every step; stop_when_invalid=False swims on after a broken invariant so "
      "that\n"
      "the counts cover the whole horizon. settle_steps (default config.evaluation.settle_steps) "
      "control\n"
      "steps are simulated first with actuation off (crawl world: with effect 'ground' the body "
      "is\n"
      "placed with its lowest cell on the floor first); the distance is measured from there.\n"
      "account_energy (default config.evaluation.energy_accounting) keeps the energy books of the "
      "swim\n"
      "(SwimResult.energy, an EnergyAccount).");
  m.def(
      "start_state",
      [](const Body& body, std::optional<SceneParams> scene, std::optional<Config> config,
         std::optional<long> settle_steps) {
        const Config c = config ? *config : Config{};
        const long n = settle_steps ? *settle_steps : c.evaluation.settle_steps;
        StartState s;
        warm_up_box2d();
        {
          nb::gil_scoped_release release;
          s = start_state(body, scene ? *scene : c.scene, c.physics, n);
        }
        return nb::make_tuple(s.body, s.velocities, s.settled);
      },
      "body"_a, "scene"_a = nb::none(), "config"_a = nb::none(), "settle_steps"_a = nb::none(),
      "Where a swim starts (crawl world, docs/worlds.md): returns (body, velocities, settled). "
      "With effect\n"
      "'ground' the body is moved vertically so that its lowest cell lies on the floor; then "
      "settle_steps\n"
      "(default config.evaluation.settle_steps) control steps without actuation are simulated from "
      "rest.\n"
      "Without ground and settling: the body unchanged, zero velocities, settled 0.");
  m.def(
      "evaluate",
      [](const Genome& genome, std::optional<Config> config, nb::handle objective) {
        const Config c = config ? *config : Config{};
        const auto scored_by = objective_from_python(objective, c);
        warm_up_box2d();
        nb::gil_scoped_release release;
        return evaluate(genome, c, *scored_by);
      },
      "genome"_a, "config"_a = nb::none(), "objective"_a = nb::none(),
      "genome -> development -> body -> swim; returns an EvaluationResult whose fitness is the "
      "objective\n"
      "(default: config.evaluation.objective, the paper's distance of the centre of mass). "
      "Deterministic.\n"
      "Non-viable genomes are not swum; unstable swims give fitness 0 and stable=False.");
  m.def(
      "grn_swim",
      [](const Genome& genome, std::optional<Config> config, long steps, long every,
         std::optional<std::vector<double>> source) {
        Config c = config ? *config : Config{};
        c.control.mode = "grn";
        validate(c);
        if (steps < 0 || every < 1)
          throw ConfigError("grn_swim: steps must be >= 0 and every >= 1");
        if (source) {
          if (source->size() != 2) throw ConfigError("grn_swim: source must be [x, y]");
          c.scene.chemical_source = *source;
        }
        warm_up_box2d();
        std::vector<double> times, terms, levels, sensors, com, positions;
        int n = 0;
        {
          nb::gil_scoped_release release;
          const Embryo e = develop(genome, c.genome, c.grn, c.development);
          if (!e.viable) throw ConfigError("grn_swim: the genome is not viable");
          const StartState st =
              start_state(build_body(e, c.body), c.scene, c.physics, c.evaluation.settle_steps);
          SceneParams scene = c.scene;
          std::erase(scene.effects, std::string("actuation"));
          Simulation sim(st.body, scene, c.physics);
          if (st.settled > 0) sim.set_velocities(st.velocities);
          auto effect = std::make_unique<GrnControl>(st.body, grn_control_start(genome, e, c),
                                                     c.control, c.scene, c.physics);
          const GrnControl* ctl = effect.get();
          sim.add_effect(std::move(effect));
          n = sim.node_count();
          auto sample = [&] {
            times.push_back(sim.time());
            terms.insert(terms.end(), ctl->terms().begin(), ctl->terms().end());
            for (int i = 0; i < n; ++i)
              levels.push_back(ctl->grn().output(ctl->state(i), OutputChannel::actuation));
            sensors.insert(sensors.end(), ctl->sensors().begin(), ctl->sensors().end());
            const Eigen::Vector2d p = sim.center_of_mass();
            com.push_back(p.x());
            com.push_back(p.y());
            const Points x = sim.positions();
            for (int i = 0; i < n; ++i) {
              positions.push_back(x(i, 0));
              positions.push_back(x(i, 1));
            }
          };
          sample();
          for (long done = 0; done + every <= steps; done += every) {
            sim.step(every);
            sample();
          }
        }
        const std::size_t f = times.size(), cells = static_cast<std::size_t>(n);
        nb::dict d;
        d["times"] = owned_array(std::move(times), {f});
        d["terms"] = owned_array(std::move(terms), {f, cells});
        d["actuation"] = owned_array(std::move(levels), {f, cells});
        d["sensors"] = owned_array(std::move(sensors), {f, cells, 3});
        d["com"] = owned_array(std::move(com), {f, 2});
        d["positions"] = owned_array(std::move(positions), {f, cells, 2});
        return d;
      },
      "genome"_a, "config"_a = nb::none(), "steps"_a = 4000, "every"_a = 10,
      "source"_a = nb::none(),
      "Swim `genome` under control.mode = 'grn' (forced) and record, every `every` control steps: "
      "'times'\n"
      "(F,), the cells' actuation terms u_i 'terms' (F, n), their actuation output levels "
      "'actuation' (F, n),\n"
      "the sensors 'sensors' (F, n, 3: strain, pressure, chemical), the centre of mass 'com' (F, "
      "2) and the\n"
      "cell positions 'positions' (F, n, 2).\n"
      "`source` overrides scene.chemical_source (relative to the start centre). docs/control.md.");
  m.def("warm_up_box2d", &warm_up_box2d,
        "Initialise Box2D's lazily filled globals; call once before using worlds from several "
        "threads.");
  m.def("actuation_start_time", &actuation_start_time, "frequency"_a, "phase"_a,
        "When a cell's oscillation starts (paper §3): the first t >= 0 where sin(f*t + phase) "
        "crosses 0.");
  m.def("actuation_term", &actuation_term, "amplitude"_a, "frequency"_a, "phase"_a, "t"_a,
        "A cell's term of eq. 2 at time t: a*sin(f*t + phase) once started, else 0.");
}

}  // namespace animat::py
