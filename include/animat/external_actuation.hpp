#pragma once
// Actuation driven from outside the simulation (a controller, e.g. animat.SwimEnv): a modifier
// effect that replaces the genome's oscillators of eq. 2. Add it with Simulation::add_effect to a
// scene without "actuation" (both would write the rest lengths).
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "animat/scene.hpp"

namespace animat {

struct Body;
namespace effects {
struct CellOscillator;
}

/// Eq. 2 with externally set cell terms: rest = (1 + u_i + u_j)·L0 for spring (i, j). The terms
/// come either directly (Mode::rest_length: u_i as set) or from oscillators whose amplitude and
/// phase are set from outside (Mode::oscillator: u_i = a_i·sin(f_i·t + φ_i), f_i the body's own
/// frequency unless set). Every |u_i| must stay below 0.5, so that rest lengths stay positive.
///
/// Mode::oscillator steps each cell exactly as the effect "actuation" steps the body's own
/// oscillators (sin/cos advanced by an exact-angle rotation, recomputed directly every 1024 steps
/// after the cell's start and at the first step after its phase or frequency is set to a new value;
/// setting the same values again changes nothing), so with the body's amplitudes, frequencies and
/// phases and `delayed_start` it writes the rest lengths an evaluation writes, bit for bit.
/// Without `delayed_start` every cell oscillates from the first step on (u_i(0) = a_i·sin φ_i);
/// with it a cell starts as the paper's cells do [§3]: at the first step at or after its
/// oscillation reaches a zero of its sine (actuation_start_time), counted from the step after its
/// phase or frequency was first set (from t = 0 when set before the first step) and recounted when
/// they change before it has started; once started, a cell keeps oscillating.
class ExternalActuation final : public Effect {
 public:
  enum class Mode { rest_length, oscillator };

  /// `body` must be the body the simulation swims (the same springs, in order; rest lengths as
  /// swim_body() measures them). All terms start at 0 (amplitudes 0). `delayed_start` needs
  /// Mode::oscillator (ConfigError otherwise).
  ExternalActuation(const Body& body, Mode mode, bool delayed_start = false);
  ~ExternalActuation() override;
  ExternalActuation(const ExternalActuation&) = delete;
  ExternalActuation& operator=(const ExternalActuation&) = delete;

  [[nodiscard]] std::string_view name() const override { return "external_actuation"; }
  [[nodiscard]] Stage stage() const override { return Stage::modifier; }
  void apply(SwimState& s) override;

  [[nodiscard]] Mode mode() const { return mode_; }
  [[nodiscard]] bool delayed_start() const { return delayed_start_; }
  [[nodiscard]] int node_count() const { return static_cast<int>(terms_.size()); }
  /// Mode::rest_length: the cell terms u_i (n values, each finite with |u| < 0.5); GeometryError
  /// otherwise.
  void set_terms(std::span<const double> terms);
  /// Mode::oscillator: amplitudes a_i (n values in [0, 0.5)) and phases φ_i (n finite values).
  void set_oscillators(std::span<const double> amplitude, std::span<const double> phase);
  /// Mode::oscillator: the frequencies f_i (n finite values; default: the body's).
  void set_frequency(std::span<const double> frequency);
  /// The cell terms of the last step (rest_length mode: as set).
  [[nodiscard]] const std::vector<double>& terms() const { return terms_; }
  [[nodiscard]] const std::vector<double>& amplitude() const { return amplitude_; }
  [[nodiscard]] const std::vector<double>& phase() const { return phase_; }
  [[nodiscard]] const std::vector<double>& frequency() const { return frequency_; }
  /// Mode::oscillator: each cell's start step as of the last step (the Box2D step from which it
  /// oscillates; -1 = not yet decided, no step taken since its phase was set, or never: a
  /// non-positive frequency under `delayed_start`). Mode::rest_length: all -1.
  [[nodiscard]] std::vector<long> start_steps() const;

 private:
  Mode mode_;
  bool delayed_start_;
  std::vector<int> a_, b_;
  std::vector<double> rest0_;
  std::vector<double> terms_, amplitude_, phase_, frequency_;
  // Mode::oscillator: the cells' oscillators (src/effects/oscillator.hpp), and whether a cell's
  // phase or frequency was set to a new value since the last step.
  std::vector<effects::CellOscillator> cells_;
  std::vector<char> changed_;
};

}  // namespace animat
