#pragma once
// Swimming physics (paper §4): a Box2D world with one fixture-less body per cell, plus our own force
// effects (springs, actuation, pressure, drag, skin collision) applied before every Step.
#include <string>
#include <string_view>

#include "animat/params.hpp"

namespace animat {

inline constexpr std::string_view kDragSchemeNames[] = {"explicit", "stable"};

/// The accuracy knobs: what trades accuracy for speed.
struct PhysicsParams {
  double dt = 1.0 / 60.0;          ///< control step, simulated time units [choose]
  int substeps = 1;                ///< Box2D steps per control step (forces recomputed each) [choose]
  int velocity_iterations = 1;     ///< Box2D solver iterations (no joints or contacts: 1 suffices)
  int position_iterations = 1;
  std::string drag_scheme = "stable";  ///< "explicit" or "stable" (never reverses a velocity in a step)
};

template <class V>
void visit_fields(PhysicsParams& p, V&& v) {
  v(FieldInfo{"dt", "control time step in simulated time units [choose]", Bounds{0.0, 1.0, true, false}}, p.dt);
  v(FieldInfo{"substeps", "Box2D steps per control step, forces recomputed each [choose]", Bounds::closed(1, 1000)}, p.substeps);
  v(FieldInfo{"velocity_iterations", "Box2D velocity iterations", Bounds::closed(1, 100)}, p.velocity_iterations);
  v(FieldInfo{"position_iterations", "Box2D position iterations", Bounds::closed(1, 100)}, p.position_iterations);
  v(FieldInfo{"drag_scheme", "drag integration: explicit, or stable (never reverses a velocity)", Bounds::any(), kDragSchemeNames}, p.drag_scheme);
}

}  // namespace animat
