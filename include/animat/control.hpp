#pragma once
// Active control beyond the paper (docs/control.md): the GRN keeps running while the
// animat swims. With control.mode = "grn" every cell's network (its state at the end of development
// carried over) is stepped every control.update_interval Box2D steps; its `actuation` output sets
// the cell's term u_i of eq. 2, its inputs read sensors (strain, pressure, the scene's chemical
// field) and the products of its neighbours, which diffuse along the springs (signalling).
// "open_loop" (default) is the paper: the oscillators of eq. 2 with the parameters development
// left.
#include <array>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "animat/grn.hpp"
#include "animat/params.hpp"
#include "animat/scene.hpp"

namespace animat {

struct Body;
struct PhysicsParams;

inline constexpr std::string_view kControlModeNames[] = {"open_loop", "grn"};
inline constexpr std::string_view kControlActuationNames[] = {"direct", "amplitude"};

/// [control]: what drives the actuation while swimming.
struct ControlParams {
  /// "open_loop" (paper: sinusoids with the GRN's final amplitude, frequency and phase) or "grn"
  /// (the GRN keeps running; its actuation output sets u_i).
  std::string mode = "open_loop";
  /// What the actuation output L sets in mode "grn": "direct": u_i = amplitude_max·(2L − 1);
  /// "amplitude": u_i = amplitude_max·L·sin(f_i·t + φ_i), the paper's oscillator (f_i, φ_i from
  /// development, the same phase-delayed start) with its amplitude under the GRN's control.
  std::string actuation = "direct";
  /// k: Box2D steps between two GRN updates (sensors, signalling and eq. 1 advance together)
  /// [choose: the bench of docs/control.md]
  int update_interval = 10;
  /// Time between two GRN updates, in time units; 0 = every update_interval Box2D steps. When set,
  /// the controller's schedule is the same at every physics step (k = update_period / h, which must
  /// be a whole number), so refining the step refines the physics only [choose]
  double update_period = 0.0;
  /// Rate of eq. 1 in swim time: one update advances eq. 1 by dt = grn_rate·k·h (h the Box2D step),
  /// so a level relaxes with time constant 1/grn_rate whatever k. k·h·grn_rate must be <= 1
  /// [choose]
  double grn_rate = 3.0;
  /// D: diffusion rate of cell products along the springs, per time unit (graph Laplacian) [choose]
  double signal_rate = 0.0;
  /// λ: rate at which a cell's sensed product relaxes towards its own product level (secretion and
  /// decay at one rate), per time unit [choose]
  double signal_decay = 1.0;
  /// The terms u_i are scaled by min(1, t/start_ramp) so that the rest lengths, equal to L0 when
  /// development ends, do not jump at t = 0 (open loop starts each sinusoid at 0 for the same
  /// reason); 0 = no ramp [choose]
  double start_ramp = 1.0;
};

template <class V>
void visit_fields(ControlParams& p, V&& v) {
  v(
      FieldInfo{
          "mode",
          "what drives actuation while swimming: open_loop (the paper's sinusoids) or grn (the GRN "
          "keeps running, its actuation output sets u_i; docs/control.md) [beyond the paper]",
          Bounds::any(), kControlModeNames, Identity::late},
      p.mode);
  v(FieldInfo{"actuation",
              "what the GRN's actuation output L sets in mode grn: direct (u_i = "
              "amplitude_max*(2L-1)) or amplitude (u_i = amplitude_max*L*sin(f_i t + phi_i), the "
              "developed oscillator with a GRN-controlled amplitude) [choose]",
              Bounds::any(), kControlActuationNames, Identity::late},
    p.actuation);
  v(FieldInfo{"update_interval",
              "k, Box2D steps between GRN updates in mode grn (sensors, signalling and eq. 1 "
              "advance together), 1 to 1000 [choose]",
              Bounds::closed(1, 1000),
              {},
              Identity::late},
    p.update_interval);
  v(
      FieldInfo{
          "update_period",
          "time between GRN updates in mode grn, time units; 0 = every update_interval Box2D "
          "steps. Set, the update schedule does not change with the physics step (update_period "
          "/ (physics.dt/substeps) must be a whole number) [choose]",
          Bounds::upto(1e6),
          {},
          Identity::late},
      p.update_period);
  v(FieldInfo{"grn_rate",
              "rate of eq. 1 while swimming, per time unit: an update advances eq. 1 by "
              "grn_rate*k*h (h = physics.dt/substeps, must be <= 1) [choose]",
              Bounds::positive_upto(1e6),
              {},
              Identity::late},
    p.grn_rate);
  v(FieldInfo{"signal_rate",
              "D, diffusion rate of cell products along the springs while swimming (graph "
              "Laplacian), per time unit, >= 0 [choose]",
              Bounds::upto(1e6),
              {},
              Identity::late},
    p.signal_rate);
  v(FieldInfo{"signal_decay",
              "lambda, rate at which a cell's sensed product relaxes to its own product level "
              "(secretion = decay), per time unit, >= 0 [choose]",
              Bounds::upto(1e6),
              {},
              Identity::late},
    p.signal_decay);
  v(FieldInfo{"start_ramp",
              "time units over which the GRN's actuation terms ramp in from 0 at the start of a "
              "swim (rest lengths do not jump), 0 = none [choose]",
              Bounds::upto(1e6),
              {},
              Identity::late},
    p.start_ramp);
}

/// Checks what bounds cannot: update_period a whole number of Box2D steps, and the eq. 1 step
/// grn_rate·k·h <= 1 (signalling stays stable by taking substeps, GrnControl::signal_substeps()).
/// Throws ConfigError naming the keys.
void validate(const ControlParams& control, const PhysicsParams& physics);

/// k, the Box2D steps between two GRN updates: update_period / h when update_period is set (h =
/// physics.dt / physics.substeps), else update_interval.
[[nodiscard]] int grn_update_steps(const ControlParams& control, const PhysicsParams& physics);

/// The scene's chemical field at a point (scene.chemical): "point": exp(−|x − x_s|/ℓ); "plane":
/// exp(−max(0, (x_s − x)·n)/ℓ), n the unit vector from the body's start centre towards x_s, so 1 on
/// and beyond the plane through x_s; "none": 0. `source` is absolute (start centre +
/// scene.chemical_source).
[[nodiscard]] double chemical_field(std::string_view kind, double source_x, double source_y,
                                    double normal_x, double normal_y, double decay_length, double x,
                                    double y);

/// The GRN of one genome with every cell's state at the end of development: what mode "grn" starts
/// from.
struct GrnControlStart {
  Grn grn;
  GrnParams grn_params;
  /// n × node_count levels, row-major (cell i's levels at [i·node_count, (i+1)·node_count)).
  std::vector<double> levels;
  std::vector<double> maternal;  ///< n × 3, held fixed while swimming
  /// n × morphogen units: the signalling field's start (empty: own levels)
  std::vector<double> sensed;
  double amplitude_max = 0.2;  ///< development.amplitude_max: |u_i| <= this
};

/// The controller effect (modifier stage, like actuation): see the file comment. Allocation-free
/// in apply().
class GrnControl final : public Effect {
 public:
  /// `body` must be the body the simulation swims (springs in order, rest lengths as swim_body()
  /// measures them); its cells are the GRN's cells.
  GrnControl(const Body& body, GrnControlStart start, const ControlParams& control,
             const SceneParams& scene, const PhysicsParams& physics);

  [[nodiscard]] std::string_view name() const override { return "grn_control"; }
  [[nodiscard]] Stage stage() const override { return Stage::modifier; }
  void apply(SwimState& s) override;

  [[nodiscard]] int cell_count() const { return n_; }
  /// The cells' terms u_i of eq. 2 (as of the last update).
  [[nodiscard]] const std::vector<double>& terms() const { return terms_; }
  /// Cell i's GRN state (levels: units, then outputs).
  [[nodiscard]] const GrnState& state(int cell) const {
    return states_[static_cast<std::size_t>(cell)];
  }
  /// The signalling field (n × morphogen units, row-major).
  [[nodiscard]] const std::vector<double>& signals() const { return field_; }
  /// Sensor values of the last update: strain, pressure, chemical (n × 3, row-major).
  [[nodiscard]] const std::vector<double>& sensors() const { return sensors_; }
  [[nodiscard]] long updates() const { return updates_; }
  /// Signalling substeps per update: the smallest count that keeps δ·(D·max degree + λ) <= 1.
  [[nodiscard]] int signal_substeps() const { return signal_substeps_; }
  [[nodiscard]] const Grn& grn() const { return start_.grn; }
  /// u = amplitude_max·(2L − 1) for an actuation level L ∈ [0, 1) (docs/model.md).
  [[nodiscard]] static double term_of_level(double level, double amplitude_max) {
    return amplitude_max * (2.0 * level - 1.0);
  }
  /// control.actuation = "amplitude": the cells' current amplitudes amplitude_max·L·ramp.
  [[nodiscard]] const std::vector<double>& amplitudes() const { return amplitude_; }
  /// Moves the chemical source (absolute coordinates) and the plane normal (normalised here).
  void set_chemical_source(double x, double y);

 private:
  void update(const SwimState& s);

  GrnControlStart start_;
  ControlParams control_;
  int n_ = 0, nodes_ = 0, morph_ = 0;
  int update_steps_ = 1;    ///< k, Box2D steps between updates (grn_update_steps)
  double update_dt_ = 0.0;  ///< simulated time between updates, k·h
  GrnParams step_params_;   ///< dt = grn_rate·k·h
  std::vector<int> a_, b_;
  std::vector<double> rest0_;
  std::vector<std::vector<int>> regions_;
  std::vector<double> area0_;
  // Cell -> incident springs and regions, CSR.
  std::vector<int> spring_begin_, spring_list_, region_begin_, region_list_;
  std::vector<double> field_, next_field_, sensors_, terms_, region_ratio_;
  std::vector<GrnState> states_;
  std::string chemical_;
  double source_x_ = 0, source_y_ = 0, normal_x_ = 1, normal_y_ = 0, decay_length_ = 1;
  int signal_substeps_ = 1;
  bool modulate_ = false;  ///< control.actuation = "amplitude"
  std::vector<double> amplitude_, frequency_, phase_, start_time_;
  long updates_ = 0;
  long last_update_step_ = -1;
};

}  // namespace animat
