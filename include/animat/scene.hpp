#pragma once
// A scene: the list of effects a swim simulation needs, with their coefficients (paper §4).
// Effects that are not listed cost nothing: they are not in the step loop, and Box2D gets no
// fixtures or contacts unless an effect needs collisions (none of the built-in ones does: cell-edge
// collisions are resolved by our own swept test and impulses, src/effects/collisions.cpp).
//
// An effect is a small object with one job. Once per Box2D step the simulation fills a
// structure-of-arrays SwimState (positions, velocities, zeroed forces) and calls:
//   1. apply() of every enabled effect in stage order: modifiers first (actuation writes the spring
//      rest lengths), then force effects, which add their position-dependent forces (spring
//      elasticity, pressure, skin collision, gravity);
//   2. apply_velocity() of the velocity-dependent effects (spring damping, drag), which add forces
//      evaluated at the velocity s.ux, s.uy chosen by physics.velocity_forces: the velocity at the
//      start of the step, or (default) a prediction of the velocity at the middle of the step, for
//      which the stepper runs them twice (predictor, then corrector). An effect sees the forces of
//      the effects before it in s.fx, s.fy, so an implicit scheme (drag) can solve for the
//      velocity at the end of the step, v + h·F/m;
//   3. apply() of the constraint effects (collisions, then ground), which see every force and
//      change the end-of-step velocities by impulses (added to s.fx, s.fy as impulse/h). With both
//      in the scene, the floor contacts are events of the collisions' event loop (so no floor
//      impulse can undo a collision guarantee), and ground only adds the floor impulses collisions
//      computed.
// Effects loop over their own elements inside apply(): one virtual call per effect per pass, never
// one per element. New effects (like gravity and ground, docs/worlds.md) are new Effect
// subclasses (one file each in src/effects/) plus a name in make_effect(); the stepper does not
// change.
#include <memory>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "animat/params.hpp"

namespace animat {

struct Body;
struct PhysicsParams;

inline constexpr std::string_view kSceneEffectNames[] = {"springs", "actuation",  "pressure",
                                                         "drag",    "collisions", "skin_collision",
                                                         "gravity", "ground"};
inline constexpr std::string_view kCollisionEdgeNames[] = {"all", "skin"};
inline constexpr std::string_view kChemicalNames[] = {"none", "point", "plane"};
inline constexpr std::string_view kGroundContactNames[] = {"impulse", "compliant"};

/// Units (docs/notes/physics.md): length = the cell spacing at the end of development (cell
/// radius 0.5, so neighbouring centres are about 1 apart); mass = one cell; time = the unit of the
/// oscillator frequencies (rad per time unit). Forces are mass·length/time².
struct SceneParams {
  std::vector<std::string> effects = {"springs", "actuation", "pressure", "drag", "collisions"};
  /// equal mass m of every cell [paper: equal; value: choose, the mass unit]
  double cell_mass = 1.0;
  double spring_stiffness = 100.0;  ///< Hooke constant k of every spring [choose]
  /// damping coefficient c of every spring (force per unit stretching speed) [choose]
  double spring_damping = 4.0;
  /// c_p of eq. 3, force per unit edge length at S = 0 [choose: docs/model.md]
  double pressure = 300.0;
  /// eq. 3 divides by max(S0, floor·(longest rest edge)²): bounds sliver stiffness [choose]
  double pressure_area_floor = 0.3;
  double drag_normal = 2.0;       ///< d_N of eq. 5 [paper: 0.2, 0.5, 2, 10]
  double drag_tangential = -1.0;  ///< d_T of eq. 4; negative means d_N/200 [paper §6: d_N/200]
  /// Edges a cell may not cross (effect "collisions"): "all" springs (keeps the planar embedding:
  /// no region inverts, the skin stays simple) or only "skin" edges [choose].
  std::string collision_edges = "all";
  /// normal restitution of cell-edge collisions [paper: elastic, 1]
  double collision_restitution = 1.0;
  /// A cell that would come closer than this to an edge it is not an end of collides (a band that
  /// float rounding of Box2D's positions cannot jump) [choose]
  double collision_tolerance = 1e-3;
  /// penalty stiffness of the optional "skin_collision" effect [choose]
  double collision_stiffness = 500.0;
  /// distance from a skin edge at which that penalty starts [choose]
  double collision_radius = 0.25;
  // The crawl world (docs/worlds.md): effects "gravity" and "ground", off in the default scene.
  /// g of effect "gravity": force −m·g along y on every cell [choose]
  double gravity = 1.0;
  /// y of the floor of effect "ground" (cell centres stay at or above it) [choose]
  double ground_height = 0.0;
  double ground_friction_static = 0.8;  ///< Coulomb static coefficient μ_s of the floor [choose]
  /// Coulomb kinetic coefficient μ_k of the floor, <= μ_s [choose]
  double ground_friction_kinetic = 0.5;
  /// How the floor pushes: "impulse" (contact events: inelastic touchdown, Coulomb stick/slip;
  /// src/effects/ground.cpp) or "compliant" (a continuous force: a stiff Hunt–Crossley spring under
  /// each cell below the floor and regularised friction; src/effects/compliant_ground.cpp) [choose]
  std::string ground_contact = "impulse";
  double ground_stiffness = 1000.0;  ///< k_g of the compliant floor (force per length) [choose]
  /// λ of the compliant floor: F_n = k_g·d·(1 + λ·ḋ), d the penetration [choose]
  double ground_damping = 2.0;
  /// v_s of the compliant floor's friction μ_k·F_n·v/sqrt(v² + v_s²) [choose]
  double ground_slip_speed = 0.05;
  // A chemical field the cells sense under control.mode = "grn" (docs/control.md).
  /// "none", "point" (exp(−|x − x_s|/ℓ)) or "plane" (exp(−max(0, (x_s − x)·n)/ℓ), n from the body's
  /// start centre towards x_s) [beyond the paper]
  std::string chemical = "none";
  /// x_s relative to the body's centre at the start of the swim (length units) [choose]
  std::vector<double> chemical_source = {20.0, 0.0};
  double chemical_decay_length = 20.0;  ///< ℓ of the chemical field (length units) [choose]
};

template <class V>
void visit_fields(SceneParams& p, V&& v) {
  v(FieldInfo{"effects", "effects simulated while swimming", Bounds::any(), kSceneEffectNames},
    p.effects);
  v(FieldInfo{"cell_mass", "mass of every cell, the mass unit [paper: equal masses; value: choose]",
              Bounds::closed(kMinMass, kMaxMass)},
    p.cell_mass);
  v(FieldInfo{"spring_stiffness", "Hooke stiffness k of every spring [choose]",
              Bounds::upto(kMaxCoefficient)},
    p.spring_stiffness);
  v(FieldInfo{"spring_damping",
              "damping coefficient of every spring, force per unit stretching speed [choose]",
              Bounds::upto(kMaxCoefficient)},
    p.spring_damping);
  v(FieldInfo{"pressure", "region pressure coefficient c_p of eq. 3 [choose]",
              Bounds::upto(kMaxCoefficient)},
    p.pressure);
  v(FieldInfo{"pressure_area_floor",
              "eq. 3 uses max(S0, floor*(longest rest edge)^2) as its denominator, so sliver "
              "regions stay stable [choose]",
              Bounds::upto(kMaxLength)},
    p.pressure_area_floor);
  v(FieldInfo{"drag_normal", "normal drag coefficient d_N of eq. 5 [paper: 0.2, 0.5, 2, 10]",
              Bounds::upto(kMaxCoefficient)},
    p.drag_normal);
  v(
      FieldInfo{
          "drag_tangential",
          "tangential drag coefficient d_T of eq. 4; negative = drag_normal/200 [paper: d_N/200]",
          Bounds::closed(-1.0, kMaxCoefficient)},
      p.drag_tangential);
  v(FieldInfo{"collision_edges",
              "edges a cell may not cross (effect collisions): all springs, or skin edges only "
              "[choose]",
              Bounds::any(), kCollisionEdgeNames},
    p.collision_edges);
  v(FieldInfo{"collision_restitution",
              "normal restitution of cell-edge collisions: 1 = elastic [paper: elastic]",
              Bounds::unit()},
    p.collision_restitution);
  v(
      FieldInfo{
          "collision_tolerance",
          "a cell closer than this to an edge it is not an end of collides (length units) [choose]",
          Bounds{0.0, 0.1, true, false}},
      p.collision_tolerance);
  v(FieldInfo{"collision_stiffness",
              "penalty stiffness of the optional skin_collision effect (a soft force, lets cells "
              "through) [choose]",
              Bounds::upto(kMaxCoefficient)},
    p.collision_stiffness);
  v(FieldInfo{"collision_radius",
              "distance from a skin edge where the skin_collision penalty starts [choose]",
              Bounds::upto(kMaxLength)},
    p.collision_radius);
  v(FieldInfo{"gravity",
              "g of effect gravity: force -m*g along y on every cell, length/time^2 (crawl world, "
              "docs/worlds.md) [choose]",
              Bounds::upto(kMaxCoefficient),
              {},
              Identity::late},
    p.gravity);
  v(FieldInfo{"ground_height",
              "y of the floor of effect ground, length units; the body is placed with its lowest "
              "cell on it [choose]",
              Bounds::closed(-kMaxLength, kMaxLength),
              {},
              Identity::late},
    p.ground_height);
  v(FieldInfo{"ground_friction_static",
              "Coulomb static friction coefficient mu_s of the floor: a contact sticks while the "
              "tangential impulse needed is <= mu_s * normal impulse [choose]",
              Bounds::upto(100.0),
              {},
              Identity::late},
    p.ground_friction_static);
  v(FieldInfo{"ground_friction_kinetic",
              "Coulomb kinetic friction coefficient mu_k of the floor (sliding contacts), at most "
              "ground_friction_static [choose]",
              Bounds::upto(100.0),
              {},
              Identity::late},
    p.ground_friction_kinetic);
  v(
      FieldInfo{
          "ground_contact",
          "how the floor of effect ground pushes: impulse (contact events: inelastic touchdown, "
          "Coulomb stick/slip with mu_s and mu_k) or compliant (a continuous force: a stiff "
          "Hunt-Crossley spring ground_stiffness under every cell below the floor, damping "
          "ground_damping, friction mu_k*F_n*v/sqrt(v^2 + ground_slip_speed^2); mu_s unused) "
          "(docs/worlds.md) [choose]",
          Bounds::any(), kGroundContactNames, Identity::late},
      p.ground_contact);
  v(FieldInfo{"ground_stiffness",
              "k_g of the compliant floor: normal force per unit penetration, force/length "
              "(ground_contact = compliant) [choose]",
              Bounds::positive_upto(kMaxCoefficient),
              {},
              Identity::late},
    p.ground_stiffness);
  v(FieldInfo{"ground_damping",
              "lambda of the compliant floor, time/length: F_n = k_g*d*(1 + lambda*dd/dt), d the "
              "penetration (ground_contact = compliant) [choose]",
              Bounds::upto(kMaxCoefficient),
              {},
              Identity::late},
    p.ground_damping);
  v(FieldInfo{"ground_slip_speed",
              "v_s of the compliant floor's regularised friction, length/time: below it the floor "
              "grips viscously, above it the friction is mu_k*F_n (ground_contact = compliant) "
              "[choose]",
              Bounds::positive_upto(kMaxLength),
              {},
              Identity::late},
    p.ground_slip_speed);
  v(FieldInfo{"chemical",
              "chemical field sensed by the GRN's chemical input under control.mode = grn: none, "
              "point (exp(-|x - x_s|/l)) or plane (exp(-max(0, (x_s - x).n)/l), n from the start "
              "centre to x_s) (docs/control.md) [beyond the paper]",
              Bounds::any(), kChemicalNames, Identity::late},
    p.chemical);
  v(FieldInfo{"chemical_source",
              "source x_s [x, y] of the chemical field, relative to the body's centre at the start "
              "of the swim, length units [choose]",
              Bounds::closed(-kMaxLength, kMaxLength),
              {},
              Identity::late},
    p.chemical_source);
  v(FieldInfo{"chemical_decay_length",
              "decay length l of the chemical field, length units, > 0 [choose]",
              Bounds::positive_upto(kMaxLength),
              {},
              Identity::late},
    p.chemical_decay_length);
}

// has_effect(effects, name): params.hpp (development.effects uses it too).

/// d_T actually used: drag_tangential, or drag_normal/200 when drag_tangential is negative.
[[nodiscard]] inline double tangential_drag(const SceneParams& p) {
  return p.drag_tangential < 0.0 ? p.drag_normal / 200.0 : p.drag_tangential;
}

/// Checks what visit_fields bounds cannot say: known, non-duplicated effect names and finite
/// coefficients. Throws ConfigError naming the key.
void validate(const SceneParams& params);

/// What the effects count while a body swims (totals since the simulation started). Every deviation
/// from the equations as written is counted here, never silent.
struct SwimCounters {
  /// cell-edge collisions resolved by an impulse (effect collisions)
  long collisions = 0;
  long collisions_inelastic = 0;   ///< of those, resolved by the inelastic fallback (restitution 0)
  long collisions_unresolved = 0;  ///< Box2D steps after which a crossing could not be prevented
  long collision_max_passes = 0;   ///< most resolution passes one step needed
  /// edge-component steps where drag_scheme "stable" scaled eq. 5 down
  long drag_limited = 0;
  /// (cell, Box2D step) pairs in which the floor pushed a cell (effect ground)
  long ground_contacts = 0;
  long ground_slips = 0;  ///< of those, contacts that slid (kinetic friction)
  /// Box2D steps in which the floor pushed no cell (effect ground): airborne share = airborne_steps
  /// / Box2D steps
  long airborne_steps = 0;
  /// Mechanical work of actuation (effect springs, while actuation changes the rest lengths): per
  /// spring and Box2D step ΔW = k·(r_k − r_{k−1})·((r_k + r_{k−1})/2 − (ℓ_k + ℓ_{k−1})/2), the
  /// midpoint rule of ∫ k·(r − ℓ)·dr/dt dt (r rest length, ℓ length; docs/worlds.md).
  double actuation_work = 0.0;           ///< Σ ΔW (net)
  double actuation_work_positive = 0.0;  ///< Σ max(ΔW, 0) per spring and step
  double actuation_work_absolute = 0.0;  ///< Σ |ΔW| per spring and step
};

/// SwimCounters' fields with their documentation, in one list (Simulation.counters in Python).
template <class C, class V>
void visit_fields(C& c, V&& v)
  requires std::is_same_v<std::remove_const_t<C>, SwimCounters>
{
  v("collisions", "cell-edge collisions resolved by an impulse (effect collisions)", c.collisions);
  v("collisions_inelastic", "of those, resolved by the inelastic fallback (restitution 0)",
    c.collisions_inelastic);
  v("collisions_unresolved", "Box2D steps after which a crossing could not be prevented",
    c.collisions_unresolved);
  v("collision_max_passes", "most resolution passes one step needed", c.collision_max_passes);
  v("drag_limited", "edge-component steps where drag_scheme \"stable\" scaled eq. 5 down",
    c.drag_limited);
  v("ground_contacts", "(cell, Box2D step) pairs in which the floor pushed a cell (effect ground)",
    c.ground_contacts);
  v("ground_slips", "of those, contacts that slid (kinetic friction)", c.ground_slips);
  v("airborne_steps",
    "Box2D steps in which the floor pushed no cell (effect ground); airborne share = "
    "airborne_steps / Box2D steps",
    c.airborne_steps);
  v("actuation_work", "net mechanical work of actuation", c.actuation_work);
  v("actuation_work_positive", "positive work, per spring and Box2D step",
    c.actuation_work_positive);
  v("actuation_work_absolute", "absolute work, per spring and Box2D step",
    c.actuation_work_absolute);
}

/// The state every effect reads and writes during one Box2D step, structure-of-arrays, sized once
/// by the simulation (never resized in the step loop). Positions and velocities are Box2D's (float)
/// values widened to double; forces are zeroed before the first effect runs.
struct SwimState {
  int n = 0;          ///< cells
  long step = 0;      ///< Box2D steps done before this one
  double time = 0.0;  ///< simulated time at the start of this Box2D step
  double h = 0.0;     ///< length of this Box2D step (dt / substeps)
  double mass = 1.0;  ///< every cell's mass
  double inv_mass = 1.0;
  std::vector<double> x, y, vx, vy;  ///< n each: positions and velocities at the start of the step
  std::vector<double> ux, uy;        ///< n each: the velocity apply_velocity() evaluates forces at
  std::vector<double> fx, fy;        ///< n each: the force accumulator
  std::vector<double> rest;          ///< current rest length of every spring (actuation writes it)
  /// True during the predictor pass of the midpoint scheme: velocity effects then only estimate
  /// their forces (the stepper discards them after computing the midpoint velocity).
  bool predictor = false;
  /// Position corrections a constraint effect asks for, applied after Box2D's step (n each, read
  /// only when position_corrected): a collision at a fraction τ of the step turns the cell back at
  /// τ, not at the start of the step, so its end position differs from x + h·v by this much.
  std::vector<double> cx, cy;
  bool position_corrected = false;
  /// The floor's impulses (as forces J/h, n each) when effect collisions resolves the floor
  /// contacts inside its event loop (a scene with both collisions and ground): collisions writes
  /// them here, and effect ground, which runs after it, adds them to s.fx, s.fy (so the energy
  /// books keep the floor's work apart from the collisions').
  std::vector<double> ground_fx, ground_fy;
  /// Energy accounting only (null otherwise): drag adds the normal part of its forces here too, so
  /// that the books can split the fluid's dissipation into its normal and tangential parts (n
  /// each).
  double* normal_drag_fx = nullptr;
  double* normal_drag_fy = nullptr;
  SwimCounters counters;
};

/// One physical effect of a scene. apply() and apply_velocity() loop over the effect's own elements
/// (stored as structure-of-arrays at construction) and must not allocate.
class Effect {
 public:
  enum class Stage : int { modifier = 0, force = 1, constraint = 2 };

  virtual ~Effect() = default;
  [[nodiscard]] virtual std::string_view name() const = 0;
  [[nodiscard]] virtual Stage stage() const { return Stage::force; }
  /// Modifiers change per-step parameters; force effects add their position-dependent forces to
  /// s.fx, s.fy (and may cache geometry for apply_velocity); constraint effects run after every
  /// force is known and change the end-of-step velocities v + h·F/m by impulses. Called once per
  /// Box2D step.
  virtual void apply(SwimState& s) = 0;
  /// Whether apply_velocity() adds anything.
  [[nodiscard]] virtual bool velocity_dependent() const { return false; }
  /// Adds the forces that depend on velocity, evaluated at s.ux, s.uy (positions as in apply()).
  /// Called after every effect's apply(), once or twice per step (physics.velocity_forces).
  virtual void apply_velocity(SwimState& s) { (void)s; }
  /// Energy accounting (Simulation::account_energy): whether the forces apply() adds derive from a
  /// potential, potential_energy(), so that their work is stored energy, not dissipated.
  [[nodiscard]] virtual bool has_potential_energy() const { return false; }
  /// That potential at the state's positions and rest lengths (0 for effects without one).
  [[nodiscard]] virtual double potential_energy(const SwimState& s) const {
    (void)s;
    return 0.0;
  }
  /// Whether Box2D needs circle fixtures (and contacts) for this effect. None of the built-in
  /// effects does.
  [[nodiscard]] virtual bool needs_box2d_collisions() const { return false; }
  /// Number of apply() calls so far (lets tests prove that a disabled effect never runs).
  [[nodiscard]] long calls() const { return calls_; }

 protected:
  long calls_ = 0;
};

/// Actuation work per cell accumulated so far by effect `springs` (any other effect: false, outputs
/// untouched): each spring's positive and absolute work (SwimCounters) split evenly between its two
/// end cells. Resizes the outputs to the cell count.
bool actuation_work_per_cell(const Effect& springs, std::vector<double>& positive,
                             std::vector<double>& absolute);

/// The built-in effect `name` (one of kSceneEffectNames) for `body`; throws ConfigError for an
/// unknown name.
[[nodiscard]] std::unique_ptr<Effect> make_effect(std::string_view name, const Body& body,
                                                  const SceneParams& scene,
                                                  const PhysicsParams& physics);

/// The body as a swim simulation sees it: positions rounded to Box2D's float, and rest lengths and
/// areas that equal the geometry at construction (within 1e-6 of the coordinate scale) re-measured
/// from those float positions with the very formulas the effects use, so that a body at rest feels
/// exactly zero force. Rest values that differ from the geometry by more (a pre-stressed hand-made
/// body) are kept as given.
[[nodiscard]] Body swim_body(const Body& body);

// --- Pure pieces of the effects, exposed for analytic tests ------------------------------------

/// Time at which a cell with frequency f and phase phi starts its oscillation (paper §3): the
/// first t >= 0 at which sin(f·t + phi) passes through zero, i.e. 0 when phi is a multiple of π,
/// otherwise (π − (phi mod π)) / f, which is less than half a period. A cell with f <= 0 and
/// sin(phi) != 0 never starts (+infinity).
[[nodiscard]] double actuation_start_time(double frequency, double phase);
/// A cell's term of eq. 2 at time t: a·sin(f·t + phi) once t >= actuation_start_time(f, phi), else
/// 0. It is 0 at the start time and continuous in t.
[[nodiscard]] double actuation_term(double amplitude, double frequency, double phase, double t);

/// The fully implicit drag update of one velocity component: the backward-Euler solution u' of
/// u' = w − dt·c·u'·|u'| (c = d·L/M), i.e. 2w / (1 + sqrt(1 + 4·c·dt·|w|)). Same sign as w and
/// |u'| <= |w|: it never reverses the velocity, whatever c·dt·|w|.
[[nodiscard]] double implicit_quadratic_drag(double w, double c_dt);

}  // namespace animat
