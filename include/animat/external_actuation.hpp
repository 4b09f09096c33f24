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

/// Eq. 2 with externally set cell terms: rest = (1 + u_i + u_j)·L0 for spring (i, j). The terms
/// come either directly (Mode::rest_length: u_i as set) or from oscillators whose amplitude and
/// phase are set from outside (Mode::oscillator: u_i = a_i·sin(f_i·t + φ_i), f_i the body's own
/// frequency unless set). Every |u_i| must stay below 0.5, so that rest lengths stay positive.
class ExternalActuation final : public Effect {
 public:
  enum class Mode { rest_length, oscillator };

  /// `body` must be the body the simulation swims (the same springs, in order; rest lengths as
  /// swim_body() measures them). All terms start at 0 (amplitudes 0).
  ExternalActuation(const Body& body, Mode mode);

  [[nodiscard]] std::string_view name() const override { return "external_actuation"; }
  [[nodiscard]] Stage stage() const override { return Stage::modifier; }
  void apply(SwimState& s) override;

  [[nodiscard]] Mode mode() const { return mode_; }
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

 private:
  Mode mode_;
  std::vector<int> a_, b_;
  std::vector<double> rest0_;
  std::vector<double> terms_, amplitude_, phase_, frequency_;
};

}  // namespace animat
