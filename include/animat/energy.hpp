#pragma once
// Where the energy of a swim goes: the books of one simulation (Simulation::account_energy()).
//
// Energy enters through actuation (the work the changing rest lengths do on the springs,
// SwimCounters::actuation_work) and pushes (the kinetic energy they add). It leaves through the
// velocity-dependent forces (fluid drag, split into its normal and tangential parts, and spring
// damping) and the constraints (collision and ground impulses), and what stays is stored as kinetic
// energy and as the potentials of the conservative effects (spring elasticity, pressure, gravity).
//
// Each force's work over a Box2D step of length h is h·F·(v + v')/2, with v and v' the cell's
// velocities at the start and end of the step: with symplectic Euler (v' = v + h·F/m) the works of
// all forces add up to the change of kinetic energy exactly, so the split between the effects is
// exact. The potentials are evaluated at the positions, which move by h·v' rather than
// h·(v + v')/2: that O(h²) difference per step (bounded, not a drift, for a symplectic step),
// Box2D's float rounding, and the position corrections of the collisions are what the residual
// holds. The books close when the residual is small against the energy that flowed.
#include <type_traits>

namespace animat {

struct EnergyAccount {
  bool measured = false;  ///< whether the simulation kept the books (off by default: it costs time)
  // In.
  /// net work of actuation on the springs (= SwimCounters::actuation_work)
  double actuation = 0.0;
  double external = 0.0;  ///< kinetic energy added by pushes (Simulation::push)
  // Dissipated (energy removed from the body: minus the work of the forces, >= 0 for drag and
  // damping).
  double drag_normal = 0.0;      ///< by the normal part of eq. 5 (effect drag)
  double drag_tangential = 0.0;  ///< by the tangential part of eq. 4 (effect drag)
  double spring_damping = 0.0;   ///< by the springs' dampers (effect springs)
  /// by cell-edge collision impulses (0 for elastic ones, up to rounding)
  double collisions = 0.0;
  double ground = 0.0;  ///< by the floor's normal and friction impulses (effect ground)
  /// by every other force that no potential accounts for (custom effects, the skin_collision
  /// penalty, GRN-driven external actuation forces)
  double other = 0.0;
  // Stored, at the start and at the end of the measured swim.
  double kinetic_start = 0.0, kinetic_end = 0.0;    ///< Σ ½·m·v²
  double elastic_start = 0.0, elastic_end = 0.0;    ///< springs: Σ ½·k·(ℓ − r)²
  double pressure_start = 0.0, pressure_end = 0.0;  ///< pressure: Σ c_p·(S − S0)²/(2A)
  double gravity_start = 0.0, gravity_end = 0.0;    ///< gravity: Σ m·g·y
  /// custom effects with a potential
  double other_potential_start = 0.0, other_potential_end = 0.0;

  bool operator==(const EnergyAccount&) const = default;

  [[nodiscard]] double fluid() const { return drag_normal + drag_tangential; }
  [[nodiscard]] double dissipated() const {
    return drag_normal + drag_tangential + spring_damping + collisions + ground + other;
  }
  [[nodiscard]] double stored_change() const {
    return (kinetic_end - kinetic_start) + (elastic_end - elastic_start) +
           (pressure_end - pressure_start) + (gravity_end - gravity_start) +
           (other_potential_end - other_potential_start);
  }
  /// What the books leave unexplained: in − dissipated − stored change.
  [[nodiscard]] double residual() const {
    return actuation + external - dissipated() - stored_change();
  }
  /// The fluid's share of the dissipated energy (0 when nothing was dissipated).
  [[nodiscard]] double fluid_share() const {
    const double d = dissipated();
    return d > 0.0 ? fluid() / d : 0.0;
  }
};

/// The account's fields with their documentation, one list from which the bindings, pickling and
/// dictionaries follow (a new field: one line here).
template <class A, class V>
void visit_fields(A& a, V&& v)
  requires std::is_same_v<std::remove_const_t<A>, EnergyAccount>
{
  v("measured", "whether the simulation kept the books", a.measured);
  v("actuation", "net work of actuation on the springs (in)", a.actuation);
  v("external", "kinetic energy added by pushes (in)", a.external);
  v("drag_normal", "dissipated by the normal part of the fluid drag, eq. 5", a.drag_normal);
  v("drag_tangential", "dissipated by the tangential part of the fluid drag, eq. 4",
    a.drag_tangential);
  v("spring_damping", "dissipated by the springs' dampers", a.spring_damping);
  v("collisions", "dissipated by cell-edge collision impulses (0 for elastic ones, up to rounding)",
    a.collisions);
  v("ground", "dissipated by the floor's impulses", a.ground);
  v("other", "dissipated by forces no potential accounts for (custom effects, skin_collision)",
    a.other);
  v("kinetic_start", "kinetic energy at the start", a.kinetic_start);
  v("kinetic_end", "kinetic energy at the end", a.kinetic_end);
  v("elastic_start", "spring elastic energy at the start", a.elastic_start);
  v("elastic_end", "spring elastic energy at the end", a.elastic_end);
  v("pressure_start", "pressure potential at the start", a.pressure_start);
  v("pressure_end", "pressure potential at the end", a.pressure_end);
  v("gravity_start", "gravitational potential at the start", a.gravity_start);
  v("gravity_end", "gravitational potential at the end", a.gravity_end);
  v("other_potential_start", "potential of custom conservative effects at the start",
    a.other_potential_start);
  v("other_potential_end", "potential of custom conservative effects at the end",
    a.other_potential_end);
}

}  // namespace animat
