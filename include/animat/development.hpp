#pragma once
// Development (paper §2.2, Fig. 2): one cell grows into an embryo of up to `max_cells` cells in a
// 2-D fluid-like Box2D world, driven by the GRN that every cell runs.
//
// One development step (DevelopmentWorld::step), for every cell in index order:
//   1. sense: maternal morphogens (three fixed sources) and the diffusible products of all cells,
//      through the grid-less, history-based model (level = Σ_j L_j(t − d/v)·e^(−d/λ), capped at 1);
//   2. one GRN step (eq. 1, Δt = GrnParams::dt) with what was sensed;
//   3. record the new morphogen-product levels in each cell's history ring buffer;
//   4. divisions: a cell whose divide output is ≥ divide_threshold and that has not divided in the
//      last `refractory_steps` steps divides (cell index order, never beyond max_cells);
//   5. physics: pairwise soft repulsion + adhesion forces, then one Box2D step (linear damping).
#include <array>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "animat/genome.hpp"
#include "animat/grn.hpp"
#include "animat/params.hpp"
#include "animat/types.hpp"

namespace animat {

inline constexpr std::string_view kDevelopmentEffectNames[] = {"repulsion", "adhesion",
                                                               "morphogens"};
/// Where a daughter is placed (DevelopmentParams::division_axis): "orientation" (the paper's: along
/// the mother's orientation vector), "morphogen_gradient" (along the gradient of maternal
/// morphogen 0 at the mother's position, turned by 2π × the mother's rotate output) or "outward"
/// (away from the cells the mother touches).
inline constexpr std::string_view kDivisionAxisNames[] = {"orientation", "morphogen_gradient",
                                                          "outward"};
/// What seeds the placement jitter (DevelopmentParams::jitter_stream): "genome" (the genome's hash)
/// or "fixed" (one stream for every genome).
inline constexpr std::string_view kJitterStreamNames[] = {"genome", "fixed"};

struct DevelopmentParams {
  int steps = 400;                ///< development steps [paper: 400]
  int max_cells = 32;             ///< hard cap on cells [paper: 32, one series 64]
  double divide_threshold = 0.9;  ///< divide output level that triggers division [paper: 0.9]
  /// a cell (mother and daughter) cannot divide again for this many steps [choose]
  int refractory_steps = 20;
  int min_cells = 3;  ///< viability: at least this many cells [paper: 3]
  /// viability: last division at least this many steps before the end [paper: 100]
  int quiet_steps = 100;
  double cell_radius = 0.5;  ///< radius r0 of the first cell [choose]
  /// a daughter's radius is r0·(1 + max_growth·grow) [paper: up to +50%]
  double max_growth = 0.5;
  /// daughter placement direction deviates by up to ± this angle (rad), seeded by jitter_stream
  /// [choose]
  double placement_jitter = 0.05;
  /// What seeds the jitter's draws: "genome" (the genome's hash, so that any mutation redraws every
  /// daughter's deviation) or "fixed" (one stream for every genome: a deviation depends only on the
  /// step and the cell, and a mutation changes development only through what the GRN does) [choose]
  std::string jitter_stream = "genome";
  /// daughter centre = mother centre + division_offset·r_mother·orientation [choose]
  double division_offset = 0.2;
  /// Placement direction of a daughter: "orientation" (the mother's orientation vector) [paper] or
  /// "morphogen_gradient" (the unit gradient of maternal morphogen 0 at the mother's position, i.e.
  /// toward source 0, rotated by 2π·rotate of the mother) or "outward" (opposite to the sum of the
  /// unit vectors to the cells the mother touches; the orientation when it touches none) [choose];
  /// the jitter applies to every axis.
  std::string division_axis = "orientation";
  /// A cell divides only while it touches at most this many cells (surfaces closer than
  /// adhesion_range): 1 grows from the ends of a line only, 2 also lets branches start from a line;
  /// 0 = any cell may divide [paper]. With division_axis = "outward" it grows from the tips.
  int division_max_contacts = 0;
  double frequency_min = 0.5;  ///< oscillator frequency at output 0, rad per unit time [choose]
  double frequency_max = 6.0;  ///< oscillator frequency at output 1 [choose: docs/model.md]
  double amplitude_max = 0.2;  ///< amplitude scale [paper: 0.2]
  /// Stiffness factor at stiffness output 0 and 1 (evolvable stiffness; only when
  /// genome.extra_outputs enables `stiffness`):
  /// f = stiffness_min·(stiffness_max/stiffness_min)^level, geometric [choose]
  double stiffness_min = 0.25;
  double stiffness_max = 4.0;
  // Physics of the development world [choose].
  double time_step = 0.1;            ///< Box2D time step of one development step
  double cell_mass = 1.0;            ///< mass of every cell body (equal masses)
  double damping = 10.0;             ///< Box2D linear damping (fluid-like, overdamped)
  double repulsion_stiffness = 5.0;  ///< force per unit overlap of two cells
  double adhesion_stiffness = 2.0;   ///< force per unit gap between two close-by cells
  /// gap beyond which adhesion vanishes (force peaks at half of it)
  double adhesion_range = 0.25;
  /// cap on the net contact force on one cell (crowded births); 0 = none
  double max_force = 25.0;
  // Morphogens [choose].
  /// x0,y0,x1,y1,x2,y2
  std::vector<double> maternal_sources = {0.0, 5.0, -4.330127018922193, -2.5, 4.330127018922193,
                                          -2.5};
  double maternal_decay_length = 5.0;   ///< maternal level at distance d is e^(−d/λm)
  double morphogen_speed = 0.25;        ///< v: length units per development step
  double morphogen_decay_length = 2.0;  ///< λ of e^(−d/λ) for cell-made morphogens
  /// longest delay d/v kept in the history (steps); longer delays read the oldest sample
  int morphogen_max_delay = 64;
  /// Cells farther apart than this do not sense each other's morphogens; 0 = no cut-off, every pair
  /// (the paper's field). A cut-off makes development linear in cells [choose]
  double morphogen_cutoff = 0.0;
  std::vector<std::string> effects = {"repulsion", "adhesion", "morphogens"};
  int trace_every = 0;  ///< record a trace snapshot every k steps; 0 = off
};

template <class V>
void visit_fields(DevelopmentParams& p, V&& v) {
  v(FieldInfo{"steps", "development steps [paper: 400]", Bounds::closed(1, 100000)}, p.steps);
  v(FieldInfo{"max_cells", "hard cap on the number of cells [paper: 32; 64 in one series]",
              Bounds::closed(1, 4096)},
    p.max_cells);
  v(FieldInfo{"divide_threshold", "divide output level that triggers division [paper: 0.9]",
              Bounds::closed(0, 1)},
    p.divide_threshold);
  v(FieldInfo{"refractory_steps",
              "steps after a division before the mother or daughter may divide again [choose]",
              Bounds::closed(0, 100000)},
    p.refractory_steps);
  v(FieldInfo{"min_cells", "viability: at least this many cells [paper: 3]",
              Bounds::closed(0, 4096)},
    p.min_cells);
  v(FieldInfo{"quiet_steps",
              "viability: last division at least this many steps before the end [paper: 100]",
              Bounds::closed(0, 100000)},
    p.quiet_steps);
  v(FieldInfo{"cell_radius", "radius r0 of a cell that does not grow [choose]",
              Bounds::closed(1e-6, kMaxLength)},
    p.cell_radius);
  v(FieldInfo{"max_growth", "daughter radius is r0*(1 + max_growth*grow) [paper: 0.5]",
              Bounds::closed(0, 10)},
    p.max_growth);
  v(FieldInfo{"placement_jitter",
              "daughter placement direction deviates by up to +-this angle (rad), seeded by "
              "jitter_stream; breaks exact symmetry [choose]",
              Bounds::closed(0, 3.2)},
    p.placement_jitter);
  v(FieldInfo{"jitter_stream",
              "what seeds the placement jitter: genome (the genome's hash: any mutation redraws "
              "every daughter's deviation) or fixed (one stream for every genome: a mutation "
              "changes development only through the GRN) [choose]",
              Bounds::any(), kJitterStreamNames, Identity::late},
    p.jitter_stream);
  v(FieldInfo{"division_offset",
              "daughter placed at division_offset*r_mother from the mother along its orientation "
              "[choose]",
              Bounds::closed(0, 10)},
    p.division_offset);
  v(FieldInfo{"division_axis",
              "direction in which a daughter is placed: orientation (the mother's orientation "
              "vector) [paper] or morphogen_gradient (gradient of maternal morphogen 0 at the "
              "mother, i.e. toward source 0, rotated by 2*pi*rotate of the mother) or outward "
              "(away from the cells the mother touches) [choose]",
              Bounds::any(), kDivisionAxisNames, Identity::late},
    p.division_axis);
  v(FieldInfo{"division_max_contacts",
              "a cell divides only while it touches at most this many cells (surfaces closer "
              "than adhesion_range); 0 = any cell [paper]; with division_axis = outward the "
              "body grows from its tips [choose]",
              Bounds::closed(0, 4096),
              {},
              Identity::late},
    p.division_max_contacts);
  v(FieldInfo{"frequency_min",
              "oscillator frequency (rad per time unit) at frequency output 0 [choose]",
              Bounds::upto(kMaxCoefficient)},
    p.frequency_min);
  v(FieldInfo{"frequency_max",
              "oscillator frequency (rad per time unit) at frequency output 1 [choose]",
              Bounds::upto(kMaxCoefficient)},
    p.frequency_max);
  v(FieldInfo{"amplitude_max", "oscillator amplitude at amplitude output 1 [paper: 0.2]",
              Bounds::closed(0, 0.45)},
    p.amplitude_max);
  v(FieldInfo{"stiffness_min",
              "spring stiffness factor of a cell at stiffness output 0 (used only when "
              "genome.extra_outputs has stiffness), dimensionless multiple of "
              "scene.spring_stiffness, [1e-6, 1e6] [choose]",
              Bounds::closed(1e-6, 1e6),
              {},
              Identity::late},
    p.stiffness_min);
  v(FieldInfo{"stiffness_max",
              "stiffness factor at stiffness output 1; the factor is "
              "stiffness_min*(stiffness_max/stiffness_min)^output (geometric), [1e-6, 1e6], >= "
              "stiffness_min [choose]",
              Bounds::closed(1e-6, 1e6),
              {},
              Identity::late},
    p.stiffness_max);
  v(FieldInfo{"time_step", "Box2D time step of one development step [choose]",
              Bounds::closed(kMinTimeStep, 1.0)},
    p.time_step);
  v(FieldInfo{"cell_mass", "mass of every cell body during development [choose]",
              Bounds::closed(kMinMass, kMaxMass)},
    p.cell_mass);
  v(FieldInfo{"damping", "Box2D linear damping of cells, fluid-like [choose]",
              Bounds::upto(kMaxCoefficient)},
    p.damping);
  v(FieldInfo{"repulsion_stiffness", "repulsive force per unit overlap of two cells [choose]",
              Bounds::upto(kMaxCoefficient)},
    p.repulsion_stiffness);
  v(FieldInfo{"adhesion_stiffness",
              "adhesive force per unit gap between two close-by cells [choose]",
              Bounds::upto(kMaxCoefficient)},
    p.adhesion_stiffness);
  v(FieldInfo{"adhesion_range", "gap between cell surfaces beyond which adhesion vanishes [choose]",
              Bounds::upto(kMaxLength)},
    p.adhesion_range);
  v(FieldInfo{"max_force",
              "cap on the net repulsion+adhesion force on one cell, keeps crowded births far below "
              "Box2D's speed cap; 0 = no cap [choose]",
              Bounds::upto(kMaxCoefficient)},
    p.max_force);
  v(FieldInfo{"maternal_sources",
              "positions x0,y0,x1,y1,x2,y2 of the three maternal morphogen sources [choose]",
              Bounds::closed(-kMaxLength, kMaxLength)},
    p.maternal_sources);
  v(FieldInfo{"maternal_decay_length",
              "maternal level at distance d from its source is exp(-d/length) [choose]",
              Bounds::positive_upto(kMaxLength)},
    p.maternal_decay_length);
  v(FieldInfo{"morphogen_speed",
              "speed v of cell-made morphogens, length units per step: delay = d/v [choose]",
              Bounds::positive_upto(kMaxLength)},
    p.morphogen_speed);
  v(FieldInfo{"morphogen_decay_length",
              "cell-made morphogen level falls as exp(-d/length) [choose]",
              Bounds::positive_upto(kMaxLength)},
    p.morphogen_decay_length);
  v(FieldInfo{"morphogen_cutoff",
              "distance beyond which cells do not sense each other's morphogens; 0 = no cut-off, "
              "every pair (the paper's field); a cut-off makes development linear in cells "
              "[choose]",
              Bounds::upto(kMaxLength),
              {},
              Identity::late},
    p.morphogen_cutoff);
  v(FieldInfo{"morphogen_max_delay",
              "longest morphogen delay kept in the per-cell history, in steps [choose]",
              Bounds::closed(0, 100000)},
    p.morphogen_max_delay);
  v(FieldInfo{"effects", "effects of the development world", Bounds::any(),
              kDevelopmentEffectNames},
    p.effects);
  v(FieldInfo{"trace_every", "record positions every k steps for plotting; 0 = off",
              Bounds::closed(0, 100000)},
    p.trace_every);
}

/// Checks what visit_fields bounds cannot say (maternal_sources has 6 finite numbers, known effect
/// names); throws ConfigError naming the key.
void validate(const DevelopmentParams& params);

/// Snapshots of a development, for paper Fig. 2.
struct DevelopmentTrace {
  std::vector<int> steps;
  std::vector<Points> positions;
  std::vector<Vector> radii;
  std::vector<Points> orientations;  ///< unit vectors

  [[nodiscard]] bool empty() const { return steps.empty(); }
};

/// n × (Grn::output_count()) output levels: the paper's 6 columns, or kOutputCount (8) when the
/// genome has an extension output element.
using OutputLevels = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// The grown embryo.
struct Embryo {
  Points positions;     ///< cell centres, n × 2
  Vector radii;         ///< n
  Points orientations;  ///< unit orientation vectors, n × 2
  /// n × 6 output levels (divide, rotate, grow, amplitude, frequency, phase; + stiffness, actuation
  /// when the genome has extension outputs)
  OutputLevels outputs;
  Vector amplitude, frequency, phase;  ///< oscillator parameters derived from the outputs
  /// Stiffness factor per cell from the `stiffness` output (evolvable stiffness); empty unless the
  /// config enables that output channel (genome.extra_outputs has `stiffness`).
  Vector stiffness;
  std::vector<int> division_steps;  ///< step (1-based) of every division, in order
  int steps_run = 0;                ///< < params.steps when stopped early (verdict certain)
  bool viable = false;
  std::vector<std::string> reasons;  ///< why not viable; empty when viable
  DevelopmentTrace trace;            ///< filled when params.trace_every > 0
  /// Every cell's GRN at the end of development, where control.mode = "grn" starts the swim
  /// (docs/control.md): levels n × node_count (units, then outputs), the maternal levels sensed
  /// last (n × 3) and the cell-made products sensed last (n × morphogen units; 0 columns when the
  /// morphogens effect is off). Empty for a genome that was not simulated.
  OutputLevels grn_levels, grn_maternal, grn_sensed;

  [[nodiscard]] int cell_count() const { return static_cast<int>(positions.rows()); }
};

/// Grows an embryo from one cell. Deterministic: depends only on the genome and the params.
/// A genome without the GRN paths of viability criterion 1 is not simulated at all (steps_run = 0);
/// any other genome stops as soon as its non-viability is certain (a division within the last
/// quiet_steps steps, or fewer than min_cells cells when no more division may happen in time).
/// Throws SimulationError if a cell would move at a speed near Box2D's translation cap.
[[nodiscard]] Embryo develop(const Genome& genome, const GenomeParams& genome_params,
                             const GrnParams& grn_params, const DevelopmentParams& params);

/// The lower-level development world: cells as fixture-less Box2D bodies plus their GRN states and
/// morphogen histories. develop() drives one; tests use it to check the pieces of a step.
class DevelopmentWorld {
 public:
  using Vec2 = Eigen::Vector2d;

  /// An empty world (no cells). Throws ConfigError for invalid params.
  DevelopmentWorld(Grn grn, const GrnParams& grn_params, const DevelopmentParams& params);
  ~DevelopmentWorld();
  DevelopmentWorld(DevelopmentWorld&&) noexcept;
  DevelopmentWorld& operator=(DevelopmentWorld&&) noexcept;
  DevelopmentWorld(const DevelopmentWorld&) = delete;
  DevelopmentWorld& operator=(const DevelopmentWorld&) = delete;

  /// Adds a cell at rest. Its state defaults to grn.initial_state(); its morphogen history is
  /// filled with its current levels (as if they had always been so). Ignores max_cells. Returns its
  /// index.
  int add_cell(const Vec2& position, double radius, const Vec2& orientation,
               const GrnState* state = nullptr);

  /// One full development step (see the file comment). Returns the number of divisions in it.
  int step();
  /// Seeds the placement jitter (develop() uses genome_hash), so results depend only on genome +
  /// params.
  void set_symmetry_seed(std::uint64_t seed);
  /// From how many cells on the pair loops (contact forces; the morphogen field with a cut-off)
  /// take their pairs from a neighbour grid instead of checking every pair; default 64. Results do
  /// not depend on it, bit for bit (the grid keeps the all-pairs order); tests and benchmarks set
  /// it.
  void set_pair_grid_from(std::size_t cells);

  // --- The pieces of a step, in order -------------------------------------------------------
  /// Computes what every cell senses (maternal levels and cell-made morphogens) now.
  void sense();
  /// Advances every cell's GRN by one step with what sense() computed.
  void step_grn();
  /// Appends every cell's current morphogen-product levels to its history and advances the
  /// history clock by one step.
  void record_history();
  /// Divides every eligible cell (divide output ≥ threshold, refractory period over), in index
  /// order, while below max_cells; records the current step. Returns the number of divisions.
  int divide_ready();
  /// Divides `cell` now, whatever its outputs (daughter placement, inheritance, rotation and size
  /// as in a normal division); ignores max_cells and the refractory period. Returns the daughter.
  int divide(int cell);
  /// Applies repulsion/adhesion (those enabled) plus optional external forces (one per cell, or
  /// empty), then advances Box2D by time_step. Throws SimulationError on non-finite positions or a
  /// displacement of more than half of Box2D's translation cap in one step.
  void step_physics(std::span<const Vec2> external_forces = {});
  /// Increments the step counter (step() does it first; division steps are recorded with it).
  void advance_clock() { ++step_; }

  // --- Observation -------------------------------------------------------------------------
  [[nodiscard]] int cell_count() const;
  [[nodiscard]] int current_step() const { return step_; }
  [[nodiscard]] const Grn& grn() const;
  [[nodiscard]] const DevelopmentParams& params() const;
  [[nodiscard]] Vec2 position(int cell) const;
  [[nodiscard]] Vec2 velocity(int cell) const;
  [[nodiscard]] double radius(int cell) const;
  [[nodiscard]] Vec2 orientation(int cell) const;
  [[nodiscard]] GrnState& state(int cell);
  [[nodiscard]] const GrnState& state(int cell) const;
  [[nodiscard]] double output(int cell, OutputChannel c) const;
  /// Maternal morphogen levels at a point: e^(−|p − source_k| / maternal_decay_length).
  [[nodiscard]] std::array<double, 3> maternal_at(const Vec2& p) const;
  /// Level of the k-th morphogen product (grn.morphogen_units()[k]) sensed by `cell` right now,
  /// computed from the histories (includes the cell's own current level at distance 0).
  [[nodiscard]] double sensed_morphogen(int cell, int k) const;
  /// What sense() last computed for `cell` (empty if the morphogens effect is off).
  [[nodiscard]] std::span<const double> sensed_morphogens(int cell) const;
  [[nodiscard]] const std::array<double, 3>& sensed_maternal(int cell) const;
  [[nodiscard]] const std::vector<int>& division_steps() const;
  [[nodiscard]] bool has(std::string_view effect) const;

  [[nodiscard]] Points positions() const;
  [[nodiscard]] Vector radii() const;
  [[nodiscard]] Points orientations() const;
  [[nodiscard]] OutputLevels outputs() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int step_ = 0;
};

}  // namespace animat
