#pragma once
// Context every animat benchmark prints (console and CSV/JSON output): the build and the settings.
// (Google Benchmark's own "Library was built as DEBUG" line is about Debian's libbenchmark, not
// animat.)
#include <benchmark/benchmark.h>

#include <fmt/format.h>

#include <string>

#include "animat/config.hpp"

namespace animat::bench {

inline void add_context() {
#ifdef NDEBUG
  benchmark::AddCustomContext("animat_build", "optimised, NDEBUG (CMAKE_BUILD_TYPE=Release)");
#else
  benchmark::AddCustomContext(
      "animat_build", "assertions on (not a Release build: timings are not representative)");
#endif
  benchmark::AddCustomContext("compiler", __VERSION__);
  const Config c;
  benchmark::AddCustomContext(
      "physics",
      fmt::format("dt={:.6g} substeps={} drag_scheme={} velocity_forces={}", c.physics.dt,
                  c.physics.substeps, c.physics.drag_scheme, c.physics.velocity_forces));
  benchmark::AddCustomContext("scene", fmt::format("effects={} d_N={} d_T={} (-1 = d_N/200)",
                                                   fmt::join(c.scene.effects, ","),
                                                   c.scene.drag_normal, c.scene.drag_tangential));
  benchmark::AddCustomContext(
      "evaluation", fmt::format("development steps={} max_cells={} swim steps={}",
                                c.development.steps, c.development.max_cells, c.evaluation.steps));
}

}  // namespace animat::bench
