#pragma once
// Each stage binds itself in its own file; module.cpp calls them in pipeline order.
#include <nanobind/nanobind.h>

namespace animat::py {
void bind_config(nanobind::module_& m);
void bind_genome(nanobind::module_& m);
void bind_development(nanobind::module_& m);
void bind_body(nanobind::module_& m);
void bind_physics(nanobind::module_& m);
void bind_evolution(nanobind::module_& m);
}  // namespace animat::py
