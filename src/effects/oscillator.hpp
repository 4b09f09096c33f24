#pragma once
// Internal: one cell's oscillator of eq. 2 as the swim steps it, shared by the effects "actuation"
// (the body's own oscillators) and "external_actuation" (amplitudes and phases set from outside),
// so that both produce the same terms bit for bit. Not a public header.
#include <cmath>
#include <limits>

#include "animat/scene.hpp"

namespace animat::effects {

/// sin(f·t + φ) of one cell, advanced by an exact-angle rotation each Box2D step and recomputed
/// directly every kResync steps after the start and at any step that does not follow the last one.
/// The cell contributes from its start step on (term() is 0 before it).
struct CellOscillator {
  static constexpr long kResync = 1024;
  static constexpr long kNever = std::numeric_limits<long>::max();

  double amplitude = 0, frequency = 0, phase = 0;
  long start_step = 0;
  long last_step = -2;
  double cos_step = 1, sin_step = 0;
  double sin = 0, cos = 1;

  /// The rotation of one step of length h (call after setting the frequency).
  void set_step(double h) {
    cos_step = std::cos(frequency * h);
    sin_step = std::sin(frequency * h);
  }

  /// The paper's delayed start [§3]: the first step at or after `step` (whose time is `time`, step
  /// length h) at which f·t + φ has reached a multiple of π (actuation_start_time), so that the
  /// oscillation starts at a zero of its sine; never for a non-positive frequency. At step 0 (time
  /// 0) this is ceil(actuation_start_time(f, φ) / h), what the actuation effect uses.
  [[nodiscard]] long delayed_start(long step, double time, double h) const {
    // At step 0 the phase itself (f·0 + φ is φ for finite f; this keeps it so for any f).
    const double angle = step == 0 ? phase : frequency * time + phase;
    const double wait = actuation_start_time(frequency, angle);
    const double k0 = std::ceil(wait / h);
    return (std::isfinite(k0) && k0 < 1e15) ? step + static_cast<long>(k0) : kNever;
  }

  /// The cell's term of eq. 2 at Box2D step k (time t = k·h): amplitude·sin(f·t + φ) from the start
  /// step on, else 0. Calling it again for the same step keeps sin/cos.
  double term(long k, double time) {
    if (k < start_step) return 0.0;
    if (k == last_step) {
      // same step again (compute_forces): keep sin/cos
    } else if (k == last_step + 1 && (k - start_step) % kResync != 0) {
      const double sn = sin * cos_step + cos * sin_step;
      const double cs = cos * cos_step - sin * sin_step;
      sin = sn;
      cos = cs;
    } else {
      const double angle = frequency * time + phase;
      sin = std::sin(angle);
      cos = std::cos(angle);
    }
    last_step = k;
    return amplitude * sin;
  }
};

}  // namespace animat::effects
