#pragma once
// A scene: the list of effects a swim simulation needs, with their coefficients (paper §4).
// Effects that are not listed cost nothing: they are not in the step loop, and Box2D gets no
// fixtures or contacts unless an effect needs collisions.
#include <string>
#include <string_view>
#include <vector>

#include "animat/params.hpp"

namespace animat {

inline constexpr std::string_view kSceneEffectNames[] = {"springs", "actuation", "pressure", "drag", "skin_collision"};

struct SceneParams {
  std::vector<std::string> effects = {"springs", "actuation", "pressure", "drag", "skin_collision"};
  double cell_mass = 1.0;             ///< equal mass of every cell [paper: equal; value: choose]
  double spring_stiffness = 30.0;     ///< Hooke constant k of every spring [choose]
  double spring_damping = 1.0;        ///< damping coefficient c of every spring [choose]
  double pressure = 20.0;             ///< c_p of eq. 3 [choose]
  double drag_normal = 2.0;           ///< d_N of eq. 5 [paper: 0.2, 0.5, 2, 10]
  double drag_tangential = 0.01;      ///< d_T of eq. 4 [paper: d_N / 200]
  double collision_stiffness = 200.0; ///< penalty stiffness of skin collisions [choose]
  double collision_radius = 0.1;      ///< distance from a skin edge at which the penalty starts [choose]
};

template <class V>
void visit_fields(SceneParams& p, V&& v) {
  v(FieldInfo{"effects", "effects simulated while swimming", Bounds::any(), kSceneEffectNames}, p.effects);
  v(FieldInfo{"cell_mass", "mass of every cell [paper: equal masses]", Bounds::positive()}, p.cell_mass);
  v(FieldInfo{"spring_stiffness", "Hooke stiffness of every spring [choose]", Bounds::non_negative()}, p.spring_stiffness);
  v(FieldInfo{"spring_damping", "damping coefficient of every spring [choose]", Bounds::non_negative()}, p.spring_damping);
  v(FieldInfo{"pressure", "region pressure coefficient c_p of eq. 3 [choose]", Bounds::non_negative()}, p.pressure);
  v(FieldInfo{"drag_normal", "normal drag coefficient d_N of eq. 5 [paper: 0.2 to 10]", Bounds::non_negative()}, p.drag_normal);
  v(FieldInfo{"drag_tangential", "tangential drag coefficient d_T of eq. 4 [paper: d_N/200]", Bounds::non_negative()}, p.drag_tangential);
  v(FieldInfo{"collision_stiffness", "penalty stiffness keeping cells out of skin edges [choose]", Bounds::non_negative()}, p.collision_stiffness);
  v(FieldInfo{"collision_radius", "distance from a skin edge where the collision penalty starts [choose]", Bounds::non_negative()}, p.collision_radius);
}

[[nodiscard]] inline bool has_effect(const std::vector<std::string>& effects, std::string_view name) {
  for (const auto& e : effects)
    if (e == name) return true;
  return false;
}

}  // namespace animat
