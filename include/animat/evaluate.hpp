#pragma once
// Fitness evaluation (paper §5): genome -> development -> body -> swim -> distance of the centre of
// mass. Deterministic and thread-safe: each call owns its Box2D worlds; call warm_up_box2d() once
// before the first parallel region.
#include <Eigen/Core>
#include <string>
#include <type_traits>
#include <vector>

#include "animat/body.hpp"
#include "animat/config.hpp"
#include "animat/control.hpp"
#include "animat/energy.hpp"
#include "animat/genome.hpp"
#include "animat/locomotion.hpp"

namespace animat {

struct Body;
class Simulation;

/// Watches one evaluation (objectives that need the body or a trajectory); optional and passive:
/// an observed evaluation is bit-identical to an unobserved one.
struct EvaluationObserver {
  virtual ~EvaluationObserver() = default;
  /// Control steps between on_sample() calls (0 = none).
  [[nodiscard]] virtual long sample_every() const { return 0; }
  /// The body about to swim.
  virtual void on_body(const Body& body) { (void)body; }
  /// The simulation at step 0 and after every sample_every() control steps.
  virtual void on_sample(const Simulation& sim) { (void)sim; }
};

/// What a swim did.
struct SwimResult {
  double distance = 0.0;                   ///< |COM(end) − COM(start)| (0 when unstable)
  Eigen::Vector2d displacement{0.0, 0.0};  ///< COM(end) − COM(start), as simulated
  bool stable = true;                      ///< false if a step left the valid domain
  std::string failure;                     ///< the SimulationError message when !stable
  long steps = 0;                          ///< control steps completed
  double simulated_time = 0.0;
  double max_speed = 0.0;              ///< largest cell speed seen
  double max_step_displacement = 0.0;  ///< largest |v|·h of one Box2D step seen
  /// Largest spring length / max(L0, median L0 / 2), sampled every 16 steps and at the end (the
  /// floor keeps near-zero rest lengths of slivers and near-coincident cells meaningful).
  double max_stretch = 0.0;
  /// Smallest spring length / L0 over springs with L0 >= median L0 / 2 (same samples); 0 with no
  /// springs.
  double min_stretch = 0.0;
  double final_kinetic_energy = 0.0;
  double max_kinetic_energy = 0.0;           ///< largest kinetic energy (same samples)
  double max_kinetic_energy_per_cell = 0.0;  ///< max_kinetic_energy / cells
  // Invariants and counted deviations (every one is reported, never silent).
  bool valid = true;               ///< stable, embedding intact, every collision resolved
  bool embedding_checked = false;  ///< whether the embedding was checked after every step
  double min_area_ratio = 1.0;     ///< smallest S/S0 of any region seen (checked steps)
  long inverted_region_steps = 0;  ///< (region, step) pairs with S/S0 <= 0
  long skin_crossing_steps = 0;    ///< steps in which two skin edges intersected
  long first_invalid_step = -1;  ///< control step at whose end an invariant first broke (-1: never)
  long collisions = 0;           ///< cell-edge collisions resolved (SwimCounters)
  long collisions_inelastic = 0;
  long collisions_unresolved = 0;
  long drag_limited = 0;  ///< edge-component steps where drag_scheme "stable" scaled eq. 5 down
  // Crawl world and cost of actuation (docs/worlds.md).
  /// control steps settled (actuation off) before the fitness clock started
  long settle_steps = 0;
  /// (cell, Box2D step) contacts with the floor (effect ground; SwimCounters)
  long ground_contacts = 0;
  long ground_slips = 0;  ///< of those, sliding ones (kinetic friction)
  /// Box2D steps in which the floor pushed no cell (effect ground; SwimCounters)
  long airborne_steps = 0;
  /// net mechanical work of actuation on the springs (measured phase)
  double actuation_work = 0.0;
  /// positive work, per spring and Box2D step (what an actuator spends)
  double actuation_work_positive = 0.0;
  double actuation_work_absolute = 0.0;  ///< absolute work, per spring and Box2D step
  /// per cell: half the positive work of each spring it ends (n)
  Eigen::VectorXd cell_work_positive;
  /// per cell: half the absolute work of each spring it ends (n)
  Eigen::VectorXd cell_work_absolute;
  long grn_updates = 0;  ///< GRN updates while swimming (control.mode = "grn")
  Eigen::Vector2d displacement_at_push{0.0, 0.0};  ///< COM(push) − COM(start) (push_step >= 0)
  EnergyAccount energy;  ///< where the energy went (SwimOptions::account_energy)
};

/// The frames of a swim that the locomotion classifier reads (locomotion.hpp): node positions and
/// time at every control step from first_step on (step 0: the start), and the start positions.
/// swim() sizes the buffers before its step loop, so that recording allocates nothing there.
struct MotionRecording {
  long first_step = 0;
  MotionFrames frames;     ///< swim_start = 0: the window is the whole swim's
  Points start_positions;  ///< the cells where the swim started (the stroke rule's rest shape)
};

/// Options of swim() beyond the scene and physics.
struct SwimOptions {
  /// Control steps simulated before the fitness clock starts, with the scene minus actuation
  /// (evaluation.settle_steps): the swim then starts from the settled positions and velocities, at
  /// time 0. With effect "ground" the body is first moved vertically so that its lowest cell lies
  /// on the floor (whatever settle_steps).
  long settle_steps = 0;
  bool check_embedding = true;    ///< check the planar embedding after every Box2D step
  bool stop_when_invalid = true;  ///< stop at the first broken invariant (the fitness is 0 anyway)
  /// Keep the energy books of the measured swim (SwimResult::energy; settling is not included).
  bool account_energy = false;
  /// sees the simulation every observer->sample_every() steps
  EvaluationObserver* observer = nullptr;
  /// control.mode = "grn": where every cell's GRN starts (nullptr: open loop, the scene's own
  /// actuation). With it, "actuation" is dropped from the scene and a GrnControl effect drives
  /// eq. 2.
  const GrnControlStart* control_start = nullptr;
  /// the controller's params (required with control_start)
  const ControlParams* control = nullptr;
  /// A disruption (evaluation.push_step, push_impulse, push_cells): at the start of control step
  /// push_step (counted from the fitness clock's start; -1 = never) every pushed cell gets
  /// push_impulse (per cell; velocity change impulse/m). push_cells: "all", or "front" (the cells
  /// whose x is at least the centre of mass's x at that moment: a push that also turns the body;
  /// push_front_only = true).
  long push_step = -1;
  Eigen::Vector2d push_impulse{0.0, 0.0};
  bool push_front_only = false;
  /// A perturbed start (evaluation.repeats): n × 2 displacements added to the cells' start
  /// positions after the ground placement and settling (nullptr: none). The body's rest lengths
  /// and areas stay as given; the embedding is checked on the displaced start (step 0).
  const Points* start_offset = nullptr;
  /// Records the frames of the classifier's window into `motion` (nullptr: nothing recorded).
  MotionRecording* motion = nullptr;
};

/// Where a swim starts (the crawl world, docs/worlds.md): the body and its velocities.
struct StartState {
  Body body;          ///< the body at its starting positions (rest lengths and areas as given)
  Points velocities;  ///< n × 2 starting velocities (zeros unless settled)
  long settled = 0;   ///< control steps settled
};

/// The start of a swim: with effect "ground" in the scene, `body` moved vertically so that its
/// lowest cell centre lies on the floor; then, if settle_steps > 0, settle_steps control steps of
/// the scene without actuation from rest, whose end positions and velocities are the start. Without
/// ground and settling: the body unchanged, at rest. Throws SimulationError if settling leaves the
/// valid domain, ConfigError for settle_steps < 0. swim() and animat.replay start here.
[[nodiscard]] StartState start_state(const Body& body, const SceneParams& scene,
                                     const PhysicsParams& physics, long settle_steps);

/// Swims `body` for `steps` control steps with the scene and physics params. Never throws for a
/// simulation failure: it returns stable = false, distance 0 and the message. A swim that breaks
/// the planar embedding (a region inverted, the skin not simple) or leaves a collision unresolved
/// is invalid: valid = false, distance 0 and the reason in `failure`. Throws ConfigError for
/// invalid params.
[[nodiscard]] SwimResult swim(const Body& body, const SceneParams& scene,
                              const PhysicsParams& physics, long steps,
                              const SwimOptions& options = {});

struct EvaluationResult {
  double fitness = 0.0;  ///< straight-line distance of the centre of mass, start -> end
  /// evaluation.repeats = K > 1: standard deviation (K − 1 in the denominator) of the K repeats'
  /// objective values over |their mean| (the fitness); 0 for K = 1, or when the values are equal;
  /// +inf when they differ and their mean is 0.
  double fitness_spread = 0.0;
  bool viable = false;  ///< development verdict; non-viable genomes are never swum
  bool stable = true;   ///< false if the swim (or development) left the valid domain
  /// False if the swim broke an invariant: unstable, a region inverted, the skin not simple, or a
  /// collision left unresolved (fitness 0). True for non-viable genomes (never swum).
  bool valid = true;
  int cell_count = 0;
  /// The body plan's coarse class (morphology_kind() in body.hpp); 0 without a body (not viable).
  int morphology_kind = 0;
  // The body at rest (shape.hpp) and its oscillators; 0 without a body (not viable).
  double elongation = 0.0;
  int protrusions = 0;
  int symmetric_pair = 0;  ///< 1 when two protrusions mirror each other, else 0
  double concavity = 0.0;
  double frequency = 0.0;  ///< median oscillator frequency of the cells
  /// The locomotion mode of the swim (classify_body_motion(), the index of Locomotion: the order of
  /// animat.locomotion.MODES), classified during the evaluation's own swim when the config's
  /// search reads it (needs_locomotion()); -1 when not measured: no search reads it, not viable,
  /// or the swim stopped early or was too short (fewer than 8 frames).
  int locomotion = -1;
  std::vector<std::string> reasons;  ///< non-viability reasons or the instability description
  // Diagnostics.
  Eigen::Vector2d displacement{0.0, 0.0};  ///< COM(end) − COM(start)
  int spring_count = 0;
  int region_count = 0;
  int skin_edge_count = 0;
  int development_steps = 0;    ///< development steps actually run (early exits are shorter)
  long swim_steps = 0;          ///< control steps swum
  double simulated_time = 0.0;  ///< simulated swim time
  double max_speed = 0.0;
  double max_step_displacement = 0.0;
  double max_stretch = 0.0;
  double min_stretch = 0.0;
  double max_kinetic_energy = 0.0;
  double final_kinetic_energy = 0.0;
  double max_kinetic_energy_per_cell = 0.0;
  double min_area_ratio = 1.0;     ///< smallest S/S0 of any region over the swim
  long inverted_region_steps = 0;  ///< (region, step) pairs with S/S0 <= 0 (must be 0)
  long skin_crossing_steps = 0;    ///< steps with intersecting skin edges (must be 0)
  long first_invalid_step = -1;  ///< control step at whose end an invariant first broke (-1: never)
  long collisions = 0;           ///< cell-edge collisions resolved
  long collisions_inelastic = 0;   ///< of those, by the inelastic fallback
  long collisions_unresolved = 0;  ///< steps with a crossing no impulse could prevent (must be 0)
  long drag_limited = 0;           ///< drag limiter engagements (drag_scheme "stable" only)
  long settle_steps = 0;           ///< control steps settled before the fitness clock started
  long ground_contacts = 0;        ///< (cell, Box2D step) contacts with the floor (effect ground)
  long ground_slips = 0;           ///< of those, sliding ones
  long airborne_steps = 0;         ///< Box2D steps in which the floor pushed no cell
  double actuation_work = 0.0;     ///< net mechanical work of actuation (docs/worlds.md)
  double actuation_work_positive = 0.0;  ///< positive actuation work (per spring and Box2D step)
  double actuation_work_absolute = 0.0;  ///< absolute actuation work (per spring and Box2D step)
  Eigen::VectorXd cell_work_positive;  ///< per cell: half the positive work of each of its springs
  Eigen::VectorXd cell_work_absolute;  ///< per cell: half the absolute work of each of its springs
  /// Objective chemotaxis: the mean over evaluation.source_directions swims (the source at
  /// scene.chemical_source rotated to a random angle each, deterministic from
  /// evaluation.source_seed) of the progress toward the source, |x_s| − |x_s − displacement|
  /// (length units; 0 unless chemotaxis). The directions are evenly spaced, turned by a random
  /// offset (source_direction()).
  double source_progress = 0.0;
  long grn_updates = 0;  ///< GRN updates while swimming (control.mode = "grn"), first swim
  Eigen::Vector2d displacement_at_push{
      0.0, 0.0};  ///< COM(push) − COM(start) (evaluation.push_step >= 0)
  /// Where the actuation work went in the (first) swim, with evaluation.energy_accounting.
  EnergyAccount energy;
  double seconds_development = 0.0;  ///< wall time per stage (not deterministic; diagnostics only)
  double seconds_body = 0.0;
  double seconds_swim = 0.0;
};

/// What a swim measured, the same fields in SwimResult and EvaluationResult, with their
/// documentation: v(name, doc, field of each record...). One record: the descriptors below; two:
/// evaluate() copies a SwimResult into its EvaluationResult field by field.
template <class V, class... R>
void visit_swim_fields(V&& v, R&... r) {
  v("displacement", "COM(end) - COM(start) as a (2,) array.", r.displacement...);
  v("simulated_time", "Simulated swim time.", r.simulated_time...);
  v("max_speed", "Largest cell speed seen.", r.max_speed...);
  v("max_step_displacement", "Largest |v|*h of one Box2D step seen.", r.max_step_displacement...);
  v("max_stretch", "Largest spring length / L0 (sampled every 16 steps).", r.max_stretch...);
  v("min_stretch", "Smallest spring length / L0 (same samples).", r.min_stretch...);
  v("max_kinetic_energy", "Largest kinetic energy (same samples).", r.max_kinetic_energy...);
  v("final_kinetic_energy", "Kinetic energy at the end.", r.final_kinetic_energy...);
  v("max_kinetic_energy_per_cell", "Largest kinetic energy / cells.",
    r.max_kinetic_energy_per_cell...);
  v("valid",
    "False if the swim broke an invariant: unstable, a region inverted, the skin crossed itself, "
    "or a collision could not be resolved. An invalid swim has fitness/distance 0.",
    r.valid...);
  v("min_area_ratio", "Smallest S/S0 of any region over the swim (must stay > 0).",
    r.min_area_ratio...);
  v("inverted_region_steps", "(region, step) pairs with S/S0 <= 0 (must be 0).",
    r.inverted_region_steps...);
  v("skin_crossing_steps", "Steps in which two skin edges intersected (must be 0).",
    r.skin_crossing_steps...);
  v("first_invalid_step", "Step at whose end an invariant first broke (-1: never).",
    r.first_invalid_step...);
  v("collisions", "Cell-edge collisions resolved by an impulse.", r.collisions...);
  v("collisions_inelastic", "Collisions resolved by the inelastic fallback.",
    r.collisions_inelastic...);
  v("collisions_unresolved", "Steps with a crossing no impulse prevented (must be 0).",
    r.collisions_unresolved...);
  v("drag_limited", "Edge-component steps where drag_scheme 'stable' scaled eq. 5 down.",
    r.drag_limited...);
  v("settle_steps", "Control steps settled (actuation off) before the fitness clock started.",
    r.settle_steps...);
  v("ground_contacts", "(cell, Box2D step) contacts with the floor (effect ground).",
    r.ground_contacts...);
  v("ground_slips", "Of the floor contacts, those that slid (kinetic friction).",
    r.ground_slips...);
  v("airborne_steps",
    "Box2D steps in which the floor pushed no cell (effect ground); airborne share = "
    "airborne_steps / Box2D steps of the measured phase.",
    r.airborne_steps...);
  v("actuation_work", "Net mechanical work of actuation on the springs (docs/worlds.md).",
    r.actuation_work...);
  v("actuation_work_positive",
    "Positive actuation work, summed per spring and Box2D step (what the actuators spend).",
    r.actuation_work_positive...);
  v("actuation_work_absolute", "Absolute actuation work, summed per spring and Box2D step.",
    r.actuation_work_absolute...);
  v("cell_work_positive", "Per cell (n,): half the positive actuation work of each spring it ends.",
    r.cell_work_positive...);
  v("cell_work_absolute", "Per cell (n,): half the absolute actuation work of each spring it ends.",
    r.cell_work_absolute...);
  v("grn_updates", "GRN updates while swimming (control.mode = 'grn'; 0 in open loop).",
    r.grn_updates...);
  v("displacement_at_push",
    "COM(push) - COM(start), (2,), when evaluation.push_step >= 0 (docs/control.md).",
    r.displacement_at_push...);
  v("energy",
    "Where the energy went (an EnergyAccount; measured only with evaluation.energy_accounting).",
    r.energy...);
}

/// SwimResult's fields with their documentation, in one list from which the Python class's
/// properties follow (a new field: one line here, or in visit_swim_fields if both records have it).
template <class R, class V>
void visit_fields(R& r, V&& v)
  requires std::is_same_v<std::remove_const_t<R>, SwimResult>
{
  v("distance", "|COM(end) - COM(start)|; 0 when unstable.", r.distance);
  v("stable", "False if a step left the valid domain.", r.stable);
  v("failure", "The instability message ('' when stable).", r.failure);
  v("steps", "Control steps completed.", r.steps);
  v("embedding_checked", "Whether the planar embedding was checked after every step.",
    r.embedding_checked);
  visit_swim_fields(v, r);
}

/// EvaluationResult's fields with their documentation, in one list from which the Python class's
/// properties, its pickling and its dict follow (a new field: one line here).
template <class R, class V>
void visit_fields(R& r, V&& v)
  requires std::is_same_v<std::remove_const_t<R>, EvaluationResult>
{
  v("fitness",
    "The objective's value (default: the paper's straight-line distance of the centre of mass, "
    "start to end); 0 if not viable, unstable or invalid.",
    r.fitness);
  v("fitness_spread",
    "evaluation.repeats = K > 1: standard deviation (K - 1 in the denominator) of the K repeats' "
    "objective values over |their mean| (the fitness is the mean); 0 for K = 1 or equal values, "
    "inf when they differ around a mean of 0. The other diagnostics are repeat 0's.",
    r.fitness_spread);
  v("viable", "Development verdict; non-viable genomes are never swum.", r.viable);
  v("stable", "False if the development or the swim left the valid domain.", r.stable);
  v("cell_count", "Cells of the embryo.", r.cell_count);
  v("morphology_kind",
    "Coarse class of the body plan: cell_count * 16 + elongation band (floor(log_1.5 "
    "elongation), clamped to [0, 15]); 0 if not viable.",
    r.morphology_kind);
  v("elongation",
    "sqrt of the ratio of the principal second moments of the body at rest "
    "(animat.shape.body_shape(body).elongation); 0 if not viable.",
    r.elongation);
  v("protrusions",
    "Parts sticking out of the body's core (animat.shape.body_shape(body).protrusion_count); 0 if "
    "not viable.",
    r.protrusions);
  v("symmetric_pair",
    "1 when two protrusions mirror each other about a principal axis, else 0 "
    "(animat.shape.body_shape(body).symmetric_pair).",
    r.symmetric_pair);
  v("concavity",
    "1 - outline area / hull area of the body at rest (animat.shape.body_shape(body).concavity); 0 "
    "if not viable.",
    r.concavity);
  v("frequency", "Median oscillator frequency of the cells (rad per time unit); 0 if not viable.",
    r.frequency);
  v("locomotion",
    "Locomotion mode of the swim, the index in animat.locomotion.MODES (the default path of "
    "animat.classify_locomotion), classified during the swim when the config's search reads it; "
    "-1 when not measured (no search reads it, not viable, or the swim stopped early).",
    r.locomotion);
  v("reasons", "Non-viability reasons, or the instability description.", r.reasons);
  v("spring_count", "Springs of the body.", r.spring_count);
  v("region_count", "Regions of the body.", r.region_count);
  v("skin_edge_count", "Skin edges of the body.", r.skin_edge_count);
  v("development_steps", "Development steps actually run.", r.development_steps);
  v("swim_steps", "Control steps swum.", r.swim_steps);
  v("source_progress",
    "Objective chemotaxis: mean progress toward the chemical source over "
    "evaluation.source_directions swims (|x_s| - |x_s - displacement|; 0 otherwise).",
    r.source_progress);
  v("seconds_development", "Wall time of development (diagnostic).", r.seconds_development);
  v("seconds_body", "Wall time of body construction (diagnostic).", r.seconds_body);
  v("seconds_swim", "Wall time of the swim (diagnostic).", r.seconds_swim);
  visit_swim_fields(v, r);
}

/// The swim's counters (Simulation::counters) into the SwimResult fields of the same name and type:
/// both records list their fields (visit_fields), so a counter that SwimResult also reports needs
/// no line of its own.
void copy_counters(const SwimCounters& from, SwimResult& to);

/// Where control.mode = "grn" starts: the genome's GRN and every cell's state at the end of
/// `embryo`.
[[nodiscard]] GrnControlStart grn_control_start(const Genome& genome, const Embryo& embryo,
                                                const Config& config);
/// Objective chemotaxis: the source of trial `trial`, scene.chemical_source rotated by
/// offset + 2π·trial/source_directions, the offset uniform in [0, 2π) drawn from
/// evaluation.source_seed (the same for every genome): an evenly spaced fan at a random angle.
[[nodiscard]] std::vector<double> source_direction(const Config& config, int trial);

/// evaluation.repeats: where repeat `repeat` starts relative to the unperturbed start, `cells` × 2:
/// row i is `magnitude` times a unit vector drawn from Rng::derive(repeat, i) (uniform direction),
/// the same for every genome, thread and rank. Zeros for repeat 0.
[[nodiscard]] Points start_perturbation(int repeat, int cells, double magnitude);

/// Scores the repeats of one evaluation (evaluation.repeats, evaluate_repeats()).
class RepeatScorer {
 public:
  virtual ~RepeatScorer() = default;
  /// The observer of repeat `repeat` (nullptr: none): it sees the body (on_body) and the repeat's
  /// first swim.
  virtual EvaluationObserver* observer(int repeat) = 0;
  /// The value of repeat `repeat`, called in repeat order once its swims are done and only if they
  /// were stable and valid; `result` is that repeat's own (fitness = its paper's distance).
  virtual double value(int repeat, const EvaluationResult& result) = 0;
};

/// Whether the config's search reads the locomotion measure (search.algorithm "map_elites" with
/// "locomotion" among search.descriptors, or "nsga2" with a search.objectives entry naming it):
/// then evaluate() records the frames of the classifier's window during its swim and classifies
/// them (EvaluationResult::locomotion); otherwise it records nothing.
[[nodiscard]] bool needs_locomotion(const Config& config);

/// genome -> develop -> build_body -> swim(config.evaluation.steps). Deterministic (same genome and
/// config give a bit-identical fitness), thread-safe. A non-viable genome is never swum (fitness 0,
/// viable = false, reasons from development). A development or swim that leaves the valid domain
/// gives fitness 0, stable = false and the reason; nothing is clamped silently. A body the body
/// stage rejects (e.g. duplicate centres) is non-viable with the reason. Throws ConfigError for an
/// invalid config. With evaluation.repeats > 1 it is evaluate_repeats() scored by the distance (the
/// observer sees repeat 0).
[[nodiscard]] EvaluationResult evaluate(const Genome& genome, const Config& config,
                                        EvaluationObserver* observer = nullptr);

/// evaluation.repeats = K: develops the genome and builds its body once, then swims it K times
/// (each repeat swims every source direction of objective chemotaxis), repeat 0 from the
/// unperturbed start and repeat j >= 1 with start_offset = start_perturbation(j, n,
/// evaluation.repeat_perturbation). fitness = the mean of scorer.value() over the repeats (summed
/// in repeat order, then divided by K), or their minimum with evaluation.repeat_statistic = "min";
/// fitness_spread their relative spread about the mean; every other field
/// is repeat 0's, except seconds_swim (all repeats). If a repeat is unstable or invalid the
/// evaluation is (fitness 0, spread 0, the reason names the repeat) and no later repeat is swum.
/// For K = 1 it is evaluate() with the scorer's value, which evaluate() itself does not call.
[[nodiscard]] EvaluationResult evaluate_repeats(const Genome& genome, const Config& config,
                                                RepeatScorer& scorer);

}  // namespace animat
