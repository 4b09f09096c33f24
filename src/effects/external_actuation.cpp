// ExternalActuation: eq. 2 with cell terms set from outside (external_actuation.hpp).
#include "animat/external_actuation.hpp"

#include <fmt/format.h>

#include <cmath>

#include "animat/body.hpp"
#include "animat/errors.hpp"
#include "animat/physics.hpp"

namespace animat {
namespace {

void check_size(std::span<const double> v, std::size_t n, std::string_view what) {
  if (v.size() != n)
    throw GeometryError(fmt::format(
        "external actuation: {} has {} values, expected one per cell ({})", what, v.size(), n));
}

}  // namespace

ExternalActuation::ExternalActuation(const Body& body, Mode mode) : mode_(mode) {
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
}

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
  amplitude_.assign(amplitude.begin(), amplitude.end());
  phase_.assign(phase.begin(), phase.end());
}

void ExternalActuation::set_frequency(std::span<const double> frequency) {
  check_size(frequency, frequency_.size(), "frequency");
  for (std::size_t i = 0; i < frequency.size(); ++i)
    if (!std::isfinite(frequency[i]))
      throw GeometryError(fmt::format("external actuation: frequency {} of cell {} must be finite",
                                      frequency[i], i));
  frequency_.assign(frequency.begin(), frequency.end());
}

void ExternalActuation::apply(SwimState& s) {
  ++calls_;
  if (mode_ == Mode::oscillator)
    for (std::size_t i = 0; i < terms_.size(); ++i)
      terms_[i] = amplitude_[i] * std::sin(frequency_[i] * s.time + phase_[i]);
  const double* t = terms_.data();
  double* rest = s.rest.data();
  for (std::size_t e = 0; e < a_.size(); ++e) rest[e] = (1.0 + t[a_[e]] + t[b_[e]]) * rest0_[e];
}

}  // namespace animat
