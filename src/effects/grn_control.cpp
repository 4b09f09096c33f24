// Effect "grn_control" (control.mode = "grn"): the GRN keeps running while the animat
// swims and its actuation output drives eq. 2 (control.hpp, docs/control.md).
//
// Every k = control.update_interval Box2D steps (or k = control.update_period / h; at steps 0, k,
// 2k, ...) one update:
//   1. sensors from the positions at the start of that step: strain (mean of ℓ/L0 − 1 over the
//      cell's springs), pressure (mean S/S0 over the cell's regions; 1 for a cell in no region, the
//      value at rest) and the scene's chemical field at the cell;
//   2. signalling, one explicit step of length Δ = k·h for every diffusible product m:
//        f_i ← f_i + Δ·(λ·(p_i − f_i) + D·Σ_{j ~ i} (f_j − f_i))
//      (p_i the product level of cell i, j over the cell's spring neighbours): with λ = 0, the
//      explicit heat equation of the graph Laplacian;
//   3. one step of eq. 1 for every cell, with dt = grn_rate·Δ, inputs: the maternal levels of the
//      end of development (fixed), the field f_i as the sensed products, and the three sensors;
//   4. u_i = amplitude_max·(2·L_actuation − 1)·ramp(t).
// Between updates u_i stays; the rest lengths (1 + u_i + u_j)·L0 are written every Box2D step.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "animat/body.hpp"
#include "animat/control.hpp"
#include "animat/errors.hpp"
#include "animat/physics.hpp"
#include "effect_support.hpp"

namespace animat {

int grn_update_steps(const ControlParams& c, const PhysicsParams& physics) {
  if (!(c.update_period > 0.0)) return c.update_interval;
  const double h = physics.dt / physics.substeps;
  return static_cast<int>(std::lround(c.update_period / h));
}

void validate(const ControlParams& c, const PhysicsParams& physics) {
  if (c.mode != "grn") return;
  const double h = physics.dt / physics.substeps;
  if (c.update_period > 0.0) {
    const double k = c.update_period / h;
    if (!(k >= 0.5) || std::abs(k - std::round(k)) > 1e-9 * std::max(1.0, k))
      throw ConfigError(fmt::format(
          "control.update_period = {} is not a whole number of Box2D steps h = physics.dt / "
          "physics.substeps = {} (it is {} steps); choose a multiple of h",
          c.update_period, h, k));
  }
  const int k = grn_update_steps(c, physics);
  const double step = c.grn_rate * k * h;
  if (!(step <= 1.0))
    throw ConfigError(fmt::format(
        "control.grn_rate = {} x {} x h = {} (physics.dt / physics.substeps) is {}: one GRN update "
        "would advance eq. 1 by more than 1 (levels would overshoot); lower grn_rate or the update "
        "interval",
        c.grn_rate,
        c.update_period > 0.0 ? fmt::format("control.update_period / h = {} steps", k)
                              : fmt::format("control.update_interval = {}", c.update_interval),
        h, step));
}

double chemical_field(std::string_view kind, double sx, double sy, double nx, double ny,
                      double decay_length, double x, double y) {
  if (kind == "point") return std::exp(-std::hypot(x - sx, y - sy) / decay_length);
  if (kind == "plane")
    return std::exp(-std::max(0.0, (sx - x) * nx + (sy - y) * ny) / decay_length);
  return 0.0;
}

namespace {

void csr(int n, const std::vector<std::vector<int>>& lists, std::vector<int>& begin,
         std::vector<int>& flat) {
  begin.assign(static_cast<std::size_t>(n) + 1, 0);
  for (int i = 0; i < n; ++i)
    begin[static_cast<std::size_t>(i) + 1] =
        begin[static_cast<std::size_t>(i)] +
        static_cast<int>(lists[static_cast<std::size_t>(i)].size());
  flat.clear();
  for (const auto& l : lists) flat.insert(flat.end(), l.begin(), l.end());
}

}  // namespace

GrnControl::GrnControl(const Body& body_in, GrnControlStart start, const ControlParams& control,
                       const SceneParams& scene, const PhysicsParams& physics)
    : start_(std::move(start)), control_(control) {
  validate(control_, physics);
  const Body body = swim_body(body_in);
  n_ = body.node_count();
  nodes_ = start_.grn.node_count();
  morph_ = static_cast<int>(start_.grn.morphogen_units().size());
  const double h = physics.dt / physics.substeps;
  update_steps_ = grn_update_steps(control_, physics);
  update_dt_ = update_steps_ * h;
  step_params_ = start_.grn_params;
  step_params_.dt = control_.grn_rate * update_dt_;
  const auto n = static_cast<std::size_t>(n_);
  if (start_.levels.size() != n * static_cast<std::size_t>(nodes_))
    throw ConfigError(fmt::format("grn control: {} start levels for {} cells of {} nodes",
                                  start_.levels.size(), n_, nodes_));
  if (start_.maternal.size() != n * 3) start_.maternal.assign(n * 3, 0.0);

  std::vector<std::vector<int>> cell_springs(n), cell_regions(n);
  for (int s = 0; s < body.spring_count(); ++s) {
    a_.push_back(body.springs(s, 0));
    b_.push_back(body.springs(s, 1));
    rest0_.push_back(body.rest_lengths(s));
    cell_springs[static_cast<std::size_t>(a_.back())].push_back(s);
    cell_springs[static_cast<std::size_t>(b_.back())].push_back(s);
  }
  for (int r = 0; r < body.region_count(); ++r) {
    regions_.push_back(body.regions[static_cast<std::size_t>(r)]);
    area0_.push_back(body.rest_areas(r));
    std::vector<int> seen;
    for (int c : regions_.back())
      if (std::find(seen.begin(), seen.end(), c) == seen.end()) {
        seen.push_back(c);
        cell_regions[static_cast<std::size_t>(c)].push_back(r);
      }
  }
  csr(n_, cell_springs, spring_begin_, spring_list_);
  csr(n_, cell_regions, region_begin_, region_list_);
  // Explicit signalling is stable and keeps the field in [0, 1) when δ·(D·deg + λ) <= 1 everywhere:
  // an update takes as many equal signalling substeps δ = Δ/substeps as this body needs (1 unless
  // a cell has many springs or D is large).
  if (morph_ > 0) {
    std::size_t most = 0;
    for (const auto& l : cell_springs) most = std::max(most, l.size());
    const double worst =
        update_dt_ * (control_.signal_rate * static_cast<double>(most) + control_.signal_decay);
    if (!std::isfinite(worst))
      throw ConfigError("control.signal_rate / signal_decay: non-finite signalling step");
    signal_substeps_ = std::max(1, static_cast<int>(std::ceil(worst)));
  }

  states_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    states_[i] = start_.grn.initial_state();
    std::copy_n(
        start_.levels.begin() + static_cast<std::ptrdiff_t>(i * static_cast<std::size_t>(nodes_)),
        nodes_, states_[i].levels.begin());
  }
  const auto m = static_cast<std::size_t>(morph_);
  field_.assign(n * m, 0.0);
  if (start_.sensed.size() == n * m) {
    field_ = start_.sensed;
  } else {
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t k = 0; k < m; ++k)
        field_[i * m + k] =
            states_[i].levels[static_cast<std::size_t>(start_.grn.morphogen_units()[k])];
  }
  next_field_.assign(n * m, 0.0);
  sensors_.assign(n * 3, 0.0);
  terms_.assign(n, 0.0);
  region_ratio_.assign(regions_.size(), 1.0);
  modulate_ = control_.actuation == "amplitude";
  amplitude_.assign(n, 0.0);
  frequency_.assign(n, 0.0);
  phase_.assign(n, 0.0);
  start_time_.assign(n, 0.0);
  for (int i = 0; i < n_; ++i) {
    const auto u = static_cast<std::size_t>(i);
    if (body.frequency.size() == n_) frequency_[u] = body.frequency(i);
    if (body.phase.size() == n_) phase_[u] = body.phase(i);
    start_time_[u] = actuation_start_time(frequency_[u], phase_[u]);
  }

  chemical_ = scene.chemical;
  decay_length_ = scene.chemical_decay_length;
  double cx = 0.0, cy = 0.0;
  for (int i = 0; i < n_; ++i) {
    cx += body.positions(i, 0);
    cy += body.positions(i, 1);
  }
  if (n_ > 0) {
    cx /= n_;
    cy /= n_;
  }
  set_chemical_source(cx + scene.chemical_source[0], cy + scene.chemical_source[1]);
  // The plane's normal points from the start centre to the source.
  const double norm = std::hypot(scene.chemical_source[0], scene.chemical_source[1]);
  normal_x_ = norm > 0.0 ? scene.chemical_source[0] / norm : 1.0;
  normal_y_ = norm > 0.0 ? scene.chemical_source[1] / norm : 0.0;
}

void GrnControl::set_chemical_source(double x, double y) {
  source_x_ = x;
  source_y_ = y;
}

void GrnControl::update(const SwimState& s) {
  const auto n = static_cast<std::size_t>(n_);
  const double* x = s.x.data();
  const double* y = s.y.data();
  // 1. Sensors.
  for (std::size_t r = 0; r < regions_.size(); ++r) {
    const double twice =
        effects::twice_area([x](int i) { return x[i]; }, [y](int i) { return y[i]; }, regions_[r]);
    region_ratio_[r] = 0.5 * twice / area0_[r];
  }
  for (std::size_t i = 0; i < n; ++i) {
    double strain = 0.0;
    const int sb = spring_begin_[i], se = spring_begin_[i + 1];
    for (int q = sb; q < se; ++q) {
      const auto e = static_cast<std::size_t>(spring_list_[static_cast<std::size_t>(q)]);
      const auto a = static_cast<std::size_t>(a_[e]), b = static_cast<std::size_t>(b_[e]);
      strain += std::hypot(x[b] - x[a], y[b] - y[a]) / rest0_[e] - 1.0;
    }
    double pressure = 1.0;
    const int rb = region_begin_[i], re = region_begin_[i + 1];
    if (re > rb) {
      pressure = 0.0;
      for (int q = rb; q < re; ++q)
        pressure +=
            region_ratio_[static_cast<std::size_t>(region_list_[static_cast<std::size_t>(q)])];
      pressure /= (re - rb);
    }
    sensors_[3 * i] = se > sb ? strain / (se - sb) : 0.0;
    sensors_[3 * i + 1] = pressure;
    sensors_[3 * i + 2] = chemical_field(chemical_, source_x_, source_y_, normal_x_, normal_y_,
                                         decay_length_, x[i], y[i]);
  }
  // 2. Signalling: relaxation towards the own product, then the Laplacian spring by spring.
  const auto m = static_cast<std::size_t>(morph_);
  if (m > 0) {
    const double relax = update_dt_ / signal_substeps_ * control_.signal_decay;
    const double flow = update_dt_ / signal_substeps_ * control_.signal_rate;
    const auto& units = start_.grn.morphogen_units();
    for (int sub = 0; sub < signal_substeps_; ++sub) {
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t k = 0; k < m; ++k) {
          const double f = field_[i * m + k];
          next_field_[i * m + k] =
              f + relax * (states_[i].levels[static_cast<std::size_t>(units[k])] - f);
        }
      if (flow != 0.0)
        for (std::size_t e = 0; e < a_.size(); ++e) {
          const auto a = static_cast<std::size_t>(a_[e]) * m,
                     b = static_cast<std::size_t>(b_[e]) * m;
          for (std::size_t k = 0; k < m; ++k) {
            const double q = flow * (field_[b + k] - field_[a + k]);
            next_field_[a + k] += q;
            next_field_[b + k] -= q;
          }
        }
      field_.swap(next_field_);
    }
  }
  // 3. Eq. 1 in every cell; 4. the terms.
  const double ramp = control_.start_ramp > 0.0 ? std::min(1.0, s.time / control_.start_ramp) : 1.0;
  const double amax = start_.amplitude_max;
  for (std::size_t i = 0; i < n; ++i) {
    GrnInputs in;
    in.maternal = {start_.maternal[3 * i], start_.maternal[3 * i + 1], start_.maternal[3 * i + 2]};
    if (m > 0) in.morphogens = std::span<const double>(field_.data() + i * m, m);
    in.sensors = {sensors_[3 * i], sensors_[3 * i + 1], sensors_[3 * i + 2]};
    start_.grn.step(states_[i], in, step_params_);
    const double level = start_.grn.output(states_[i], OutputChannel::actuation);
    if (modulate_)
      amplitude_[i] = ramp * amax * level;
    else
      terms_[i] = ramp * term_of_level(level, amax);
  }
  ++updates_;
}

void GrnControl::apply(SwimState& s) {
  ++calls_;
  if (s.step != last_update_step_ && s.step % update_steps_ == 0) {
    update(s);
    last_update_step_ = s.step;
  }
  if (modulate_)  // eq. 2's oscillator with the GRN's amplitude, from the cell's start time on
    for (std::size_t i = 0; i < terms_.size(); ++i)
      terms_[i] = s.time >= start_time_[i]
                      ? amplitude_[i] * std::sin(frequency_[i] * s.time + phase_[i])
                      : 0.0;
  const double* t = terms_.data();
  double* rest = s.rest.data();
  for (std::size_t e = 0; e < a_.size(); ++e) rest[e] = (1.0 + t[a_[e]] + t[b_[e]]) * rest0_[e];
}

}  // namespace animat
