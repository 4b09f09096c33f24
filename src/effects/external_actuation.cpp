// ExternalActuation: eq. 2 with cell terms set from outside (external_actuation.hpp).
#include "animat/external_actuation.hpp"

#include <fmt/format.h>

#include <cmath>

#include "animat/body.hpp"
#include "animat/errors.hpp"
#include "animat/physics.hpp"
#include "oscillator.hpp"

namespace animat {
namespace {

void check_size(std::span<const double> v, std::size_t n, std::string_view what) {
  if (v.size() != n)
    throw GeometryError(fmt::format(
        "external actuation: {} has {} values, expected one per cell ({})", what, v.size(), n));
}

}  // namespace

ExternalActuation::ExternalActuation(const Body& body, Mode mode, bool delayed_start)
    : mode_(mode), delayed_start_(delayed_start) {
  if (delayed_start && mode != Mode::oscillator)
    throw ConfigError("external actuation: delayed_start needs the oscillator mode");
  const Body swum = swim_body(body);
  const auto n = static_cast<std::size_t>(swum.node_count());
  const int m = swum.spring_count();
  for (int s = 0; s < m; ++s) {
    a_.push_back(swum.springs(s, 0));
    b_.push_back(swum.springs(s, 1));
    rest0_.push_back(swum.rest_lengths(s));
  }
  terms_.assign(n, 0.0);
  amplitude_.assign(n, 0.0);
  phase_.assign(n, 0.0);
  frequency_.assign(n, 0.0);
  if (swum.frequency.size() == static_cast<Eigen::Index>(n))
    for (std::size_t i = 0; i < n; ++i)
      frequency_[i] = swum.frequency(static_cast<Eigen::Index>(i));
  cells_.resize(n);
  changed_.assign(n, 1);
  for (std::size_t i = 0; i < n; ++i) {
    cells_[i].frequency = frequency_[i];
    cells_[i].start_step = effects::CellOscillator::kNever;
  }
}

ExternalActuation::~ExternalActuation() = default;

void ExternalActuation::set_terms(std::span<const double> terms) {
  if (mode_ != Mode::rest_length)
    throw ConfigError("external actuation: set_terms needs the rest_length mode");
  check_size(terms, terms_.size(), "terms");
  for (std::size_t i = 0; i < terms.size(); ++i)
    if (!std::isfinite(terms[i]) || !(std::abs(terms[i]) < 0.5))
      throw GeometryError(
          fmt::format("external actuation: term {} of cell {} must be finite with |u| < 0.5 (rest "
                      "lengths (1 + u_i + u_j) L0 stay positive)",
                      terms[i], i));
  terms_.assign(terms.begin(), terms.end());
}

void ExternalActuation::set_oscillators(std::span<const double> amplitude,
                                        std::span<const double> phase) {
  if (mode_ != Mode::oscillator)
    throw ConfigError("external actuation: set_oscillators needs the oscillator mode");
  check_size(amplitude, amplitude_.size(), "amplitude");
  check_size(phase, phase_.size(), "phase");
  for (std::size_t i = 0; i < amplitude.size(); ++i) {
    if (!std::isfinite(amplitude[i]) || amplitude[i] < 0.0 || !(amplitude[i] < 0.5))
      throw GeometryError(fmt::format(
          "external actuation: amplitude {} of cell {} must be in [0, 0.5)", amplitude[i], i));
    if (!std::isfinite(phase[i]))
      throw GeometryError(
          fmt::format("external actuation: phase {} of cell {} must be finite", phase[i], i));
  }
  for (std::size_t i = 0; i < amplitude.size(); ++i) {
    if (phase[i] != phase_[i]) changed_[i] = 1;
    cells_[i].amplitude = amplitude[i];
    cells_[i].phase = phase[i];
  }
  amplitude_.assign(amplitude.begin(), amplitude.end());
  phase_.assign(phase.begin(), phase.end());
}

void ExternalActuation::set_frequency(std::span<const double> frequency) {
  check_size(frequency, frequency_.size(), "frequency");
  for (std::size_t i = 0; i < frequency.size(); ++i)
    if (!std::isfinite(frequency[i]))
      throw GeometryError(fmt::format("external actuation: frequency {} of cell {} must be finite",
                                      frequency[i], i));
  for (std::size_t i = 0; i < frequency.size(); ++i) {
    if (frequency[i] != frequency_[i]) changed_[i] = 1;
    cells_[i].frequency = frequency[i];
  }
  frequency_.assign(frequency.begin(), frequency.end());
}

std::vector<long> ExternalActuation::start_steps() const {
  std::vector<long> out(terms_.size(), -1);
  if (mode_ != Mode::oscillator) return out;
  for (std::size_t i = 0; i < out.size(); ++i)
    if (!changed_[i] && cells_[i].start_step != effects::CellOscillator::kNever)
      out[i] = cells_[i].start_step;
  return out;
}

void ExternalActuation::apply(SwimState& s) {
  ++calls_;
  if (mode_ == Mode::oscillator) {
    for (std::size_t i = 0; i < terms_.size(); ++i) {
      effects::CellOscillator& c = cells_[i];
      if (changed_[i]) {
        const bool started =
            c.start_step != effects::CellOscillator::kNever && c.last_step >= c.start_step;
        c.set_step(s.h);
        if (!started) c.start_step = delayed_start_ ? c.delayed_start(s.step, s.time, s.h) : s.step;
        c.last_step = -2;  // recompute sin/cos directly at this step
        changed_[i] = 0;
      }
      terms_[i] = c.term(s.step, s.time);
    }
  }
  const double* t = terms_.data();
  double* rest = s.rest.data();
  for (std::size_t e = 0; e < a_.size(); ++e) rest[e] = (1.0 + t[a_[e]] + t[b_[e]]) * rest0_[e];
}

}  // namespace animat
