#pragma once
// Each stage binds itself in its own file; module.cpp calls them in pipeline order.
#include <nanobind/nanobind.h>

#include <memory>
#include <optional>

namespace animat {
struct Config;
class Objective;
}  // namespace animat

namespace animat::py {
void bind_config(nanobind::module_& m);
void bind_genome(nanobind::module_& m);
void bind_development(nanobind::module_& m);
void bind_body(nanobind::module_& m);
void bind_physics(nanobind::module_& m);
void bind_evolution(nanobind::module_& m);
void bind_research(nanobind::module_& m);

/// The objective `objective` names: None = the config's (evaluation.objective), a str = that
/// built-in, otherwise a Python objective object (name, every, callable with an EvaluationRecord).
std::shared_ptr<const Objective> objective_from_python(nanobind::handle objective, const Config& config);

/// The KeyboardInterrupt that a Python objective raised while it scored a genome (Ctrl-C while it ran),
/// taken from it (later calls return nothing); nothing for a built-in objective. Called with the GIL held.
/// Such an objective throws animat::Interrupted, which stops a run like a signal does.
std::optional<nanobind::python_error> take_interrupt(const std::shared_ptr<const Objective>& objective);
}  // namespace animat::py
