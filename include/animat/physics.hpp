#pragma once
// Swimming physics (paper §4): a Box2D world with one fixture-less body per cell, plus our own
// force effects (springs, actuation, pressure, drag, skin collision; see scene.hpp) applied before
// every Step. Units and every coefficient choice: docs/notes/physics.md.
#include <Eigen/Core>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "animat/energy.hpp"
#include "animat/params.hpp"
#include "animat/scene.hpp"
#include "animat/types.hpp"

class b2World;
class b2Body;

namespace animat {

struct Body;
class EmbeddingMonitor;

inline constexpr std::string_view kDragSchemeNames[] = {"semi_implicit", "explicit", "stable",
                                                        "implicit"};
inline constexpr std::string_view kVelocityForceNames[] = {"midpoint", "start"};
inline constexpr std::string_view kIntegratorNames[] = {"native", "box2d"};

/// The accuracy knobs: what trades accuracy for speed (docs/accuracy.md measures them).
struct PhysicsParams {
  double dt = 1.0 / 60.0;  ///< control step, simulated time units [choose]
  /// Box2D steps per control step (forces recomputed each) [choose]
  int substeps = 1;
  int velocity_iterations = 1;  ///< Box2D solver iterations (no joints or contacts: 1 suffices)
  int position_iterations = 1;
  /// "semi_implicit" (eq. 5 as F = −d·L·|u_start|·u_end, solved for the end-of-step velocity:
  /// second order, exact for a free edge and at terminal velocity, never reverses a velocity),
  /// "explicit", "stable" (explicit scaled down where it would overshoot; every scaled step is
  /// counted) or "implicit" (backward Euler of the quadratic law); see src/effects/drag.cpp.
  std::string drag_scheme = "semi_implicit";
  /// The velocity that spring damping and drag are evaluated at: "midpoint" (a predictor step
  /// estimates the velocity at the middle of the step; second order, two evaluations) or "start"
  /// (the velocity at the start of the step; first order, one evaluation).
  std::string velocity_forces = "midpoint";
  /// A Box2D step that would move a cell farther than this is reported as unstable
  /// (SimulationError) before Box2D's own cap of b2_maxTranslation = 2 silently clamps it [choose].
  double max_step_displacement = 1.0;
  /// Who moves the cells: "native" performs Box2D 2.4's integration step for fixture-less bodies
  /// (the same float operations in the same order, bitwise the same positions and velocities) on
  /// flat arrays, without Box2D's per-step overhead; "box2d" steps a real b2World (the reference,
  /// and what world() needs). Results do not depend on it (src/cell_integrator.hpp).
  std::string integrator = "native";
};

template <class V>
void visit_fields(PhysicsParams& p, V&& v) {
  v(FieldInfo{"dt", "control time step in simulated time units [choose]",
              Bounds::closed(kMinTimeStep, 1.0)},
    p.dt);
  v(FieldInfo{"substeps", "Box2D steps per control step, forces recomputed each [choose]",
              Bounds::closed(1, 1000)},
    p.substeps);
  v(FieldInfo{"velocity_iterations", "Box2D velocity iterations (no contacts or joints: no effect)",
              Bounds::closed(1, 100)},
    p.velocity_iterations);
  v(FieldInfo{"position_iterations", "Box2D position iterations (no contacts or joints: no effect)",
              Bounds::closed(1, 100)},
    p.position_iterations);
  v(FieldInfo{"drag_scheme",
              "drag integration: semi_implicit (F = -d L |u_start| u_end, second order, never "
              "reverses an edge velocity); explicit; stable (explicit, scaled down where it would "
              "overshoot, counted); implicit (backward Euler)",
              Bounds::any(), kDragSchemeNames},
    p.drag_scheme);
  v(FieldInfo{"velocity_forces",
              "velocity that damping and drag use: midpoint (predicted, second order) or start "
              "(first order) [choose]",
              Bounds::any(), kVelocityForceNames},
    p.velocity_forces);
  v(FieldInfo{"max_step_displacement",
              "a Box2D step moving a cell farther than this is an instability error; Box2D itself "
              "clamps at 2 [choose]",
              Bounds{0.0, 2.0, true, false}},
    p.max_step_displacement);
  v(FieldInfo{"integrator",
              "who moves the cells: native (Box2D's float step for fixture-less bodies, bit for "
              "bit, without its overhead) or box2d (a real b2World); same results",
              Bounds::any(), kIntegratorNames, Identity::resumable},
    p.integrator);
}

/// Checks what visit_fields bounds cannot say (finite dt, known drag scheme); throws ConfigError.
void validate(const PhysicsParams& params);

/// Fills Box2D 2.4's lazily initialised process-wide globals (the contact registry) by stepping a
/// tiny world with two touching circles. Call once on the main thread before any parallel region
/// that creates worlds; later calls do nothing. Thread-safe.
void warm_up_box2d();

/// The swim of one body: a heap-allocated b2World with one dynamic, fixture-less body per cell
/// (equal masses set with SetMassData, fixed rotation, sleeping off, continuous physics off, zero
/// gravity), driven by the scene's effects.
///
/// One control step = `substeps` Box2D steps of h = dt/substeps. Each Box2D step:
///   1. reads positions and velocities into the SoA state and zeroes the force buffer;
///   2. runs apply() of the enabled effects in stage order (modifiers, then position-dependent
///      forces), then the velocity-dependent forces (spring damping, drag) at the velocity chosen
///      by physics.velocity_forces: "start" = v; "midpoint" = v + (h/2)·F(v)/m, which needs a
///      predictor pass at v first (second order: v lives at half steps in symplectic Euler), then
///      the constraint effects (collisions), which change the end-of-step velocities by impulses;
///   3. checks the predicted velocity v + h·F/m of every cell: a non-finite value, or a
///      displacement |v|·h above max_step_displacement, throws SimulationError (the world is left
///      as it was before the step; Box2D never clamps anything silently);
///   4. applies the forces (ApplyForceToCenter(f, true)), calls b2World::Step and reads the new
///      state (and checks the planar embedding when monitor_embedding() was called).
/// Nothing is allocated in the loop. Not thread-safe itself; use one Simulation per thread.
class Simulation {
 public:
  Simulation(const Body& body, const SceneParams& scene = {}, const PhysicsParams& physics = {});
  ~Simulation();
  Simulation(Simulation&&) noexcept;
  Simulation& operator=(Simulation&&) noexcept;
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  /// Adds an effect (custom or future: gravity, ground...). It runs with the effects of its stage,
  /// after those already there.
  void add_effect(std::unique_ptr<Effect> effect);

  /// Advances n control steps. Throws SimulationError when a step leaves the valid domain; after
  /// that, every further step() throws the same error.
  void step(long n = 1);
  /// Computes the forces of the current state (effects run, nothing integrated) into forces().
  /// Modifier effects advance as if a step had started; meant for tests and inspection.
  void compute_forces();
  /// Sets every cell's velocity (n × 2), e.g. to launch a body; throws GeometryError for a wrong
  /// shape or non-finite values.
  void set_velocities(const Points& velocities);
  /// A disruption (docs/control.md): adds impulse/m (impulse = [Jx, Jy], per cell) to the
  /// velocity of every listed cell, now. Throws GeometryError for a cell index out of range or a
  /// non-finite impulse. Momentum grows by |cells|·impulse.
  void push(std::span<const int> cells, const Eigen::Vector2d& impulse);

  [[nodiscard]] int node_count() const;
  [[nodiscard]] long steps_done() const;     ///< control steps done
  [[nodiscard]] long substeps_done() const;  ///< Box2D steps done
  [[nodiscard]] double time() const;         ///< simulated time
  [[nodiscard]] Points positions() const;
  [[nodiscard]] Points velocities() const;
  [[nodiscard]] Eigen::Vector2d center_of_mass() const;
  [[nodiscard]] Eigen::Vector2d momentum() const;
  [[nodiscard]] double kinetic_energy() const;
  /// Current rest length of every spring (actuation's eq. 2 at the last step; L0 before any step).
  [[nodiscard]] std::span<const double> rest_lengths_now() const;
  /// Forces of the last step (or compute_forces()), n each.
  [[nodiscard]] std::span<const double> forces_x() const;
  [[nodiscard]] std::span<const double> forces_y() const;
  /// The SoA state: positions and velocities as of the end of the last step (no allocation).
  [[nodiscard]] const SwimState& state() const;
  /// Enabled effects, in the order they run.
  [[nodiscard]] std::vector<const Effect*> effects() const;
  [[nodiscard]] const Effect* effect(std::string_view name) const;
  /// Largest |v|·h a cell was about to move in one Box2D step so far (the quantity checked against
  /// max_step_displacement), and the largest cell speed.
  [[nodiscard]] double max_step_displacement_seen() const;
  [[nodiscard]] double max_speed_seen() const;
  /// What the effects counted so far (collisions, drag limiter engagements...).
  [[nodiscard]] const SwimCounters& counters() const;
  /// Checks the planar embedding of `body` (the body this simulation was built from) now and after
  /// every Box2D step from now on: region signs and skin simplicity (EmbeddingMonitor).
  void monitor_embedding(const Body& body);
  /// The monitor, or nullptr if monitor_embedding() was not called.
  [[nodiscard]] const EmbeddingMonitor* embedding_monitor() const;
  /// Opens the books of energy accounting now (EnergyAccount, include/animat/energy.hpp): from now
  /// on every Box2D step also books the work of each effect's forces. Off until called, and then
  /// the step loop is exactly the one without books (results do not depend on it).
  void account_energy();
  /// The books since account_energy() (measured = false if it was never called).
  [[nodiscard]] EnergyAccount energy_account() const;
  /// Control step at the end of which the embedding was first seen broken (-1: never, or no
  /// monitor).
  [[nodiscard]] long first_broken_step() const;
  [[nodiscard]] bool failed() const;
  [[nodiscard]] const std::string& failure() const;  ///< empty unless failed()

  [[nodiscard]] const SceneParams& scene() const;
  [[nodiscard]] const PhysicsParams& physics() const;
  /// The Box2D world (tests inspect it: bodies, fixtures, contacts). Only with physics.integrator
  /// = "box2d"; throws ConfigError with "native", which has none.
  [[nodiscard]] b2World& world();
  [[nodiscard]] const b2World& world() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace animat
