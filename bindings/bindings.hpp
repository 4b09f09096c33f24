#pragma once
// Each stage binds itself in its own file; module.cpp calls them in pipeline order.
#include <nanobind/nanobind.h>

#include <memory>

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
}  // namespace animat::py
