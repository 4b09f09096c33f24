// Development (paper §2.2, Fig. 2): see include/animat/development.hpp for the step order and
// docs/notes/development.md for every [choose].
//
// Cells move as fixture-less dynamic Box2D bodies would (semi-implicit Euler with linear damping,
// no contacts): CellIntegrator performs b2World::Step's float arithmetic for them bit for bit
// (src/cell_integrator.hpp), so the only cost of the physics is our own pairwise force loop, which
// runs only when "repulsion" or "adhesion" is enabled. From 64 cells on (set_pair_grid_from), the
// contact pairs come from a uniform grid (src/neighbour_grid.hpp) in the all-pairs order, so the
// forces are bitwise those of the all-pairs loop; below it, every pair is checked (496 at the
// paper's 32 cells, cheaper than the grid). The morphogen field is a sum over every pair unless
// development.morphogen_cutoff is set; then it uses the grid as well and development is linear in
// cells.
#include "animat/development.hpp"

#include <box2d/box2d.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "animat/errors.hpp"
#include "animat/random.hpp"
#include "cell_integrator.hpp"
#include "neighbour_grid.hpp"

namespace animat {

namespace {
// last division of a cell that never divided
constexpr long long kNever = std::numeric_limits<int>::min();
}  // namespace

void validate(const DevelopmentParams& p) {
  auto fail = [](std::string_view key, const std::string& what) {
    throw ConfigError(fmt::format("development.{}: {}", key, what));
  };
  if (p.maternal_sources.size() != 6)
    fail("maternal_sources",
         fmt::format("expected 6 numbers x0,y0,x1,y1,x2,y2, got {}", p.maternal_sources.size()));
  for (double x : p.maternal_sources)
    if (!std::isfinite(x))
      fail("maternal_sources", fmt::format("coordinates must be finite, got {}", x));
  for (const auto& e : p.effects)
    if (std::find(std::begin(kDevelopmentEffectNames), std::end(kDevelopmentEffectNames), e) ==
        std::end(kDevelopmentEffectNames))
      fail("effects",
           fmt::format("unknown effect '{}' (known: repulsion, adhesion, morphogens)", e));
  if (std::find(std::begin(kDivisionAxisNames), std::end(kDivisionAxisNames), p.division_axis) ==
      std::end(kDivisionAxisNames))
    fail(
        "division_axis",
        fmt::format("unknown value '{}' (expected one of orientation, morphogen_gradient, outward)",
                    p.division_axis));
  if (std::find(std::begin(kJitterStreamNames), std::end(kJitterStreamNames), p.jitter_stream) ==
      std::end(kJitterStreamNames))
    fail("jitter_stream",
         fmt::format("unknown value '{}' (expected one of genome, fixed)", p.jitter_stream));
  if (p.division_max_contacts < 0)
    fail("division_max_contacts", fmt::format("must be >= 0, got {}", p.division_max_contacts));
  if (p.steps < 1) fail("steps", fmt::format("must be >= 1, got {}", p.steps));
  if (p.max_cells < 1) fail("max_cells", fmt::format("must be >= 1, got {}", p.max_cells));
  if (!(p.time_step > 0.0 && p.time_step <= 1.0))
    fail("time_step", fmt::format("must be in (0, 1], got {}", p.time_step));
  if (!(p.cell_mass > 0.0)) fail("cell_mass", fmt::format("must be > 0, got {}", p.cell_mass));
  if (!(p.cell_radius > 0.0))
    fail("cell_radius", fmt::format("must be > 0, got {}", p.cell_radius));
  if (!(p.damping >= 0.0)) fail("damping", fmt::format("must be >= 0, got {}", p.damping));
  if (!(p.morphogen_speed > 0.0))
    fail("morphogen_speed", fmt::format("must be > 0, got {}", p.morphogen_speed));
  if (!(p.morphogen_decay_length > 0.0))
    fail("morphogen_decay_length", fmt::format("must be > 0, got {}", p.morphogen_decay_length));
  if (!(p.maternal_decay_length > 0.0))
    fail("maternal_decay_length", fmt::format("must be > 0, got {}", p.maternal_decay_length));
  if (!(p.morphogen_cutoff >= 0.0))
    fail("morphogen_cutoff",
         fmt::format("must be >= 0 (0 = no cut-off), got {}", p.morphogen_cutoff));
  if (p.morphogen_max_delay < 0)
    fail("morphogen_max_delay", fmt::format("must be >= 0, got {}", p.morphogen_max_delay));
  if (!(p.max_force >= 0.0)) fail("max_force", fmt::format("must be >= 0, got {}", p.max_force));
  if (!(p.repulsion_stiffness >= 0.0) || !(p.adhesion_stiffness >= 0.0) ||
      !(p.adhesion_range >= 0.0))
    fail("repulsion_stiffness", "stiffnesses and adhesion_range must be >= 0");
}

// ---------------------------------------------------------------------------------------------
struct DevelopmentWorld::Impl {
  struct Cell {
    double radius = 0.0;
    Vec2 orientation{1.0, 0.0};
    /// motion's float position after the last physics step, widened (the step checks how far it
    /// moved)
    Vec2 position{0.0, 0.0};
    long long last_division = kNever;
  };
  std::uint64_t symmetry_seed = 0;

  Grn grn;
  GrnParams grn_params;
  DevelopmentParams params;
  bool repulsion = false, adhesion = false, morphogens = false;
  bool gradient_axis = false;  ///< division_axis == "morphogen_gradient"
  bool outward_axis = false;   ///< division_axis == "outward"
  std::array<Vec2, 3> sources{};

  CellIntegrator motion;  ///< the cells' Box2D state (position, velocity), index = cell
  std::vector<Cell> cells;
  std::vector<GrnState> states;
  std::vector<int> division_steps;

  // Morphogen history: per cell, a ring of `hist_len` samples of its `morph_count` product levels.
  int morph_count = 0;
  /// morphogen_max_delay + 1 when the morphogens effect is on and products exist; else 0
  int hist_len = 0;
  long long hist_time = 0;                      ///< time of the newest sample
  std::vector<double> history;                  ///< [cell][slot][k]
  std::vector<double> sensed;                   ///< [cell][k], written by sense()
  std::vector<std::array<double, 3>> maternal;  ///< per cell, written by sense()
  std::vector<Vec2> forces;                     ///< scratch of step_physics
  std::vector<double> fx, fy;                   ///< idem: the forces handed to the integrator
  std::vector<double> px, py;  ///< scratch of sense() and step_physics(): the positions, flat
  detail::NeighbourGrid grid;  ///< scratch of the pair loops from grid_from cells on
  /// below this many cells every pair is checked: at 32 cells the grid costs more than it saves
  /// (BM_DevelopStep/32/0: 14.5 µs against 15.3 with the grid from 16), at 64 and 128 a few percent
  /// less
  std::size_t grid_from = 64;

  /// Whether cells i and j touch: surfaces closer than adhesion_range (the adhesion's reach, a
  /// geometric definition whether or not adhesion is on).
  [[nodiscard]] bool touching(std::size_t i, std::size_t j) const {
    const double reach = cells[i].radius + cells[j].radius + params.adhesion_range;
    return (cells[j].position - cells[i].position).squaredNorm() < reach * reach;
  }
  /// How many other cells cell i touches (division_max_contacts). Only asked for cells about to
  /// divide, so a scan of every cell costs less than keeping a contact list.
  [[nodiscard]] int contact_count(std::size_t i) const {
    int count = 0;
    for (std::size_t j = 0; j < cells.size(); ++j)
      if (j != i && touching(i, j)) ++count;
    return count;
  }
  /// Σ of the unit vectors from cell i to the cells it touches (division_axis = "outward").
  [[nodiscard]] Vec2 contact_direction_sum(std::size_t i) const {
    Vec2 sum = Vec2::Zero();
    for (std::size_t j = 0; j < cells.size(); ++j) {
      if (j == i || !touching(i, j)) continue;
      const Vec2 d = cells[j].position - cells[i].position;
      const double norm = d.norm();
      if (norm > 1e-12) sum += d / norm;
    }
    return sum;
  }

  Impl(Grn g, const GrnParams& gp, const DevelopmentParams& p)
      : grn(std::move(g)), grn_params(gp), params(p) {
    validate(params);
    repulsion = has_effect(params.effects, "repulsion");
    adhesion = has_effect(params.effects, "adhesion");
    morphogens = has_effect(params.effects, "morphogens");
    gradient_axis = params.division_axis == "morphogen_gradient";
    outward_axis = params.division_axis == "outward";
    for (std::size_t k = 0; k < 3; ++k)
      sources[k] = Vec2(params.maternal_sources[2 * k], params.maternal_sources[2 * k + 1]);
    morph_count = static_cast<int>(grn.morphogen_units().size());
    hist_len = (morphogens && morph_count > 0) ? params.morphogen_max_delay + 1 : 0;

    motion.set_mass(params.cell_mass);
    motion.damping = static_cast<float>(params.damping);
    const auto reserve = static_cast<std::size_t>(std::min(params.max_cells, 64));
    motion.reserve(reserve);
    cells.reserve(reserve);
    // The per-step scratch buffers at their largest (max_cells <= 4096): a step allocates nothing
    // unless a cell is born (tests/cpp/test_physics.cpp, DevelopmentAllocatesOnlyWhenACellIsBorn).
    const auto most = static_cast<std::size_t>(params.max_cells);
    maternal.reserve(most);
    sensed.reserve(most * static_cast<std::size_t>(morph_count));
    forces.reserve(most);
    fx.reserve(most);
    fy.reserve(most);
    px.reserve(most);
    py.reserve(most);
    grid.reserve(most);
    states.reserve(reserve);
    history.reserve(reserve * static_cast<std::size_t>(hist_len) *
                    static_cast<std::size_t>(morph_count));
  }

  [[nodiscard]] std::size_t slot_of(long long time) const {
    const long long h = hist_len;
    return static_cast<std::size_t>(((time % h) + h) % h);
  }
  double* hist(std::size_t cell, std::size_t slot) {
    return history.data() + (cell * static_cast<std::size_t>(hist_len) + slot) *
                                static_cast<std::size_t>(morph_count);
  }
  [[nodiscard]] const double* hist(std::size_t cell, std::size_t slot) const {
    return history.data() + (cell * static_cast<std::size_t>(hist_len) + slot) *
                                static_cast<std::size_t>(morph_count);
  }

  /// Where to read a delay of `tau` steps: two slots and the weight of the older one.
  struct Tap {
    std::size_t newer, older;
    double frac;
  };
  [[nodiscard]] Tap tap(double tau) const { return tap_from(slot_of(hist_time), tau); }
  /// tap() with the current slot given: the slots k and k + 1 back from it, 0 <= k <= max_delay <
  /// hist_len, wrap with one addition (no integer division in sense()'s pair loop).
  [[nodiscard]] Tap tap_from(std::size_t now_slot, double tau) const {
    tau = std::min(tau, static_cast<double>(params.morphogen_max_delay));
    // tau is a distance over a speed, >= 0 and finite: truncation is floor(), without its bit
    // tricks.
    const auto k = static_cast<std::size_t>(tau);
    const double frac = tau - static_cast<double>(k);
    const auto h = static_cast<std::size_t>(hist_len);
    const std::size_t newer = now_slot >= k ? now_slot - k : now_slot + h - k;
    if (!(frac > 0.0)) return {newer, newer, frac};
    return {newer, newer >= 1 ? newer - 1 : h - 1, frac};
  }

  int append_cell(const Vec2& position, const Vec2& velocity, double radius,
                  const Vec2& orientation, GrnState state) {
    Cell c;
    const std::size_t k = motion.add(position.x(), position.y(), velocity.x(), velocity.y());
    c.position = Vec2(motion.px[k], motion.py[k]);
    c.radius = radius;
    c.orientation = orientation;
    cells.push_back(c);
    states.push_back(std::move(state));
    if (hist_len > 0)
      history.resize(cells.size() * static_cast<std::size_t>(hist_len) *
                     static_cast<std::size_t>(morph_count));
    return static_cast<int>(cells.size()) - 1;
  }

  void flatten_positions() {
    px.resize(cells.size());
    py.resize(cells.size());
    for (std::size_t i = 0; i < cells.size(); ++i) {
      px[i] = cells[i].position.x();
      py[i] = cells[i].position.y();
    }
  }

  double sample(std::size_t cell, std::size_t k, const Tap& t) const {
    const double a = hist(cell, t.newer)[k];
    if (t.frac == 0.0) return a;
    return a + t.frac * (hist(cell, t.older)[k] - a);
  }
};

// ---------------------------------------------------------------------------------------------
DevelopmentWorld::DevelopmentWorld(Grn grn, const GrnParams& grn_params,
                                   const DevelopmentParams& params)
    : impl_(std::make_unique<Impl>(std::move(grn), grn_params, params)) {}
DevelopmentWorld::~DevelopmentWorld() = default;
DevelopmentWorld::DevelopmentWorld(DevelopmentWorld&&) noexcept = default;
DevelopmentWorld& DevelopmentWorld::operator=(DevelopmentWorld&&) noexcept = default;

void DevelopmentWorld::set_symmetry_seed(std::uint64_t seed) { impl_->symmetry_seed = seed; }
void DevelopmentWorld::set_pair_grid_from(std::size_t cells) {
  impl_->grid_from = std::max<std::size_t>(cells, 2);
}

int DevelopmentWorld::add_cell(const Vec2& position, double radius, const Vec2& orientation,
                               const GrnState* state) {
  Impl& w = *impl_;
  if (!position.allFinite() || !(radius > 0.0) || !orientation.allFinite() ||
      orientation.norm() == 0.0)
    throw Error(fmt::format(
        "DevelopmentWorld::add_cell: invalid cell (position {},{}, radius {}, orientation {},{})",
        position.x(), position.y(), radius, orientation.x(), orientation.y()));
  GrnState s = state ? *state : w.grn.initial_state();
  if (s.levels.size() != static_cast<std::size_t>(w.grn.node_count()))
    throw Error(fmt::format("DevelopmentWorld::add_cell: state has {} levels, the GRN has {} nodes",
                            s.levels.size(), w.grn.node_count()));
  s.activation.resize(s.levels.size());
  const int i =
      w.append_cell(position, Vec2::Zero(), radius, orientation.normalized(), std::move(s));
  if (w.hist_len > 0) {  // a new cell's past: its current levels
    const auto& units = w.grn.morphogen_units();
    for (int slot = 0; slot < w.hist_len; ++slot) {
      double* h = w.hist(static_cast<std::size_t>(i), static_cast<std::size_t>(slot));
      for (int k = 0; k < w.morph_count; ++k)
        h[k] = w.states[static_cast<std::size_t>(i)]
                   .levels[static_cast<std::size_t>(units[static_cast<std::size_t>(k)])];
    }
  }
  return i;
}

int DevelopmentWorld::step() {
  advance_clock();
  sense();
  step_grn();
  record_history();
  const int divisions = divide_ready();
  step_physics();
  return divisions;
}

namespace {
// One pair's contribution to both cells' sensed levels; si and sj are different cells' rows, the
// history rows are read only.
inline void accumulate_pair(double* __restrict si, double* __restrict sj,
                            const double* __restrict i_new, const double* __restrict j_new,
                            double weight, std::size_t m) {
  for (std::size_t k = 0; k < m; ++k) {
    si[k] += weight * j_new[k];
    sj[k] += weight * i_new[k];
  }
}
inline void accumulate_pair(double* __restrict si, double* __restrict sj,
                            const double* __restrict i_new, const double* __restrict j_new,
                            const double* __restrict i_old, const double* __restrict j_old,
                            double weight, double frac, std::size_t m) {
  for (std::size_t k = 0; k < m; ++k) {
    si[k] += weight * (j_new[k] + frac * (j_old[k] - j_new[k]));
    sj[k] += weight * (i_new[k] + frac * (i_old[k] - i_new[k]));
  }
}
}  // namespace

void DevelopmentWorld::sense() {
  Impl& w = *impl_;
  const std::size_t n = w.cells.size();
  w.maternal.assign(n, {0.0, 0.0, 0.0});
  // the effect is off: maternal levels stay 0, products are sensed in-cell only
  if (!w.morphogens) return;
  const double lm = w.params.maternal_decay_length;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t k = 0; k < 3; ++k)
      w.maternal[i][k] = std::exp(-(w.cells[i].position - w.sources[k]).norm() / lm);

  const auto m = static_cast<std::size_t>(w.morph_count);
  if (m == 0) return;
  w.sensed.assign(n * m, 0.0);
  // Own level (distance 0, no delay), then every other emitter, pair by pair in index order.
  const std::size_t now_slot = w.slot_of(w.hist_time);
  const Impl::Tap now = w.tap_from(now_slot, 0.0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t k = 0; k < m; ++k) w.sensed[i * m + k] = w.sample(i, k, now);
  const double inv_lambda = 1.0 / w.params.morphogen_decay_length;
  const double inv_speed = 1.0 / w.params.morphogen_speed;
  // Same arithmetic as w.sample(), with the four history rows of a pair located once, over flat
  // copies of the positions, and rows that the compiler knows do not overlap (no alias checks).
  // Pairs in the all-pairs order (the grid keeps it): every cell adds its terms in the same order.
  w.flatten_positions();
  double* sensed = w.sensed.data();
  const double cutoff = w.params.morphogen_cutoff;
  auto pair = [&](std::size_t i, std::size_t j) {
    const double dx = w.px[j] - w.px[i], dy = w.py[j] - w.py[i];
    const double d = std::sqrt(dx * dx + dy * dy);  // Eigen's norm(), operation for operation
    if (cutoff > 0.0 && d > cutoff) return;
    const double weight = std::exp(-d * inv_lambda);
    const Impl::Tap t = w.tap_from(now_slot, d * inv_speed);
    if (t.frac == 0.0)
      accumulate_pair(sensed + i * m, sensed + j * m, w.hist(i, t.newer), w.hist(j, t.newer),
                      weight, m);
    else
      accumulate_pair(sensed + i * m, sensed + j * m, w.hist(i, t.newer), w.hist(j, t.newer),
                      w.hist(i, t.older), w.hist(j, t.older), weight, t.frac, m);
  };
  if (cutoff > 0.0 && n >= w.grid_from) {
    w.grid.build(w.px.data(), w.py.data(), n, cutoff);
    w.grid.for_each_pair(n, pair);
  } else {
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = i + 1; j < n; ++j) pair(i, j);
  }
  for (double& s : w.sensed) s = std::min(s, 1.0);
}

void DevelopmentWorld::step_grn() {
  Impl& w = *impl_;
  const std::size_t n = w.cells.size();
  if (w.maternal.size() != n) w.maternal.assign(n, {0.0, 0.0, 0.0});
  const auto m = static_cast<std::size_t>(w.morph_count);
  const bool use_sensed = w.morphogens && m > 0 && w.sensed.size() == n * m;
  for (std::size_t i = 0; i < n; ++i) {
    GrnInputs in;
    in.maternal = w.maternal[i];
    if (use_sensed) in.morphogens = std::span<const double>(w.sensed.data() + i * m, m);
    w.grn.step(w.states[i], in, w.grn_params);
  }
}

void DevelopmentWorld::record_history() {
  Impl& w = *impl_;
  if (w.hist_len == 0) return;
  ++w.hist_time;
  const std::size_t slot = w.slot_of(w.hist_time);
  const auto& units = w.grn.morphogen_units();
  for (std::size_t i = 0; i < w.cells.size(); ++i) {
    double* h = w.hist(i, slot);
    for (int k = 0; k < w.morph_count; ++k)
      h[k] = w.states[i].levels[static_cast<std::size_t>(units[static_cast<std::size_t>(k)])];
  }
}

int DevelopmentWorld::divide(int cell) {
  Impl& w = *impl_;
  const auto mi = static_cast<std::size_t>(cell);
  const Impl::Cell mother = w.cells.at(mi);
  const double angle = 2.0 * std::numbers::pi * output(cell, OutputChannel::rotate);
  const double grow = output(cell, OutputChannel::grow);
  const double c = std::cos(angle), s = std::sin(angle);
  Vec2 orientation(c * mother.orientation.x() - s * mother.orientation.y(),
                   s * mother.orientation.x() + c * mother.orientation.y());
  orientation.normalize();
  // The placement axis: the paper's is the mother's orientation. With "morphogen_gradient" it is
  // the gradient of maternal morphogen 0 at the mother, e^(−|p − s0|/λm), which points from the
  // mother to source 0 whatever λm, turned by the same 2π·rotate: an absolute, position-dependent
  // axis that the GRN can turn, instead of one carried down the lineage. At the source itself (no
  // gradient) the orientation is used.
  Vec2 direction = mother.orientation;
  if (w.outward_axis) {
    const Vec2 away = -w.contact_direction_sum(mi);
    const double norm = away.norm();
    if (norm > 1e-9) direction = away / norm;
  } else if (w.gradient_axis) {
    const Vec2 up = w.sources[0] - mother.position;
    const double norm = up.norm();
    if (norm > 0.0) {
      const Vec2 g = up / norm;
      direction = Vec2(c * g.x() - s * g.y(), s * g.x() + c * g.y());
    }
  }
  // A tiny deterministic deviation of the placement direction: without it, a genome that never
  // expresses `rotate` grows an exactly straight line that no force can ever bend.
  if (w.params.placement_jitter > 0.0) {
    Rng rng = Rng::derive(w.symmetry_seed, static_cast<std::uint64_t>(step_),
                          static_cast<std::uint64_t>(cell));
    const double delta = w.params.placement_jitter * rng.uniform(-1.0, 1.0);
    const double cj = std::cos(delta), sj = std::sin(delta);
    direction =
        Vec2(cj * direction.x() - sj * direction.y(), sj * direction.x() + cj * direction.y());
  }
  const Vec2 position = mother.position + w.params.division_offset * mother.radius * direction;
  const double radius = w.params.cell_radius * (1.0 + w.params.max_growth * grow);
  const Vec2 v(w.motion.vx[mi], w.motion.vy[mi]);
  GrnState state = w.states[mi];  // inherits every level
  const int d = w.append_cell(position, v, radius, orientation, std::move(state));
  if (w.hist_len > 0) {  // the daughter's past is its mother's
    const std::size_t block =
        static_cast<std::size_t>(w.hist_len) * static_cast<std::size_t>(w.morph_count);
    std::copy_n(
        w.history.begin() + static_cast<std::ptrdiff_t>(mi * block), block,
        w.history.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(d) * block));
  }
  w.cells[mi].last_division = step_;
  w.cells[static_cast<std::size_t>(d)].last_division = step_;
  return d;
}

int DevelopmentWorld::divide_ready() {
  Impl& w = *impl_;
  const int n0 = cell_count();
  int divisions = 0;
  for (int i = 0; i < n0; ++i) {
    if (cell_count() >= w.params.max_cells) break;
    if (output(i, OutputChannel::divide) < w.params.divide_threshold) continue;
    if (static_cast<long long>(step_) - w.cells[static_cast<std::size_t>(i)].last_division <=
        w.params.refractory_steps)
      continue;
    if (w.params.division_max_contacts > 0 &&
        w.contact_count(static_cast<std::size_t>(i)) > w.params.division_max_contacts)
      continue;
    divide(i);
    w.division_steps.push_back(step_);
    ++divisions;
  }
  return divisions;
}

void DevelopmentWorld::step_physics(std::span<const Vec2> external_forces) {
  Impl& w = *impl_;
  const std::size_t n = w.cells.size();
  if (!external_forces.empty() && external_forces.size() != n)
    throw Error(fmt::format("DevelopmentWorld::step_physics: {} external forces for {} cells",
                            external_forces.size(), n));
  w.forces.assign(n, Vec2::Zero());
  if (w.repulsion || w.adhesion) {
    const double krep = w.params.repulsion_stiffness, kadh = w.params.adhesion_stiffness;
    const double range = w.adhesion ? w.params.adhesion_range : 0.0;
    auto contact_pair = [&](std::size_t i, std::size_t j) {
      const Vec2 dx = w.cells[j].position - w.cells[i].position;
      const double contact = w.cells[i].radius + w.cells[j].radius;
      const double reach = contact + range;
      const double d2 = dx.squaredNorm();
      if (d2 >= reach * reach) return;
      const double d = std::sqrt(d2);
      // Unit vector i → j; coincident centres get a fixed direction (deterministic).
      const Vec2 u = d > 1e-12 ? Vec2(dx / d) : Vec2(1.0, 0.0);
      double f = 0.0;  // > 0 pushes apart
      if (d < contact) {
        if (w.repulsion) f = krep * (contact - d);
      } else if (w.adhesion) {
        const double gap = d - contact;
        // rises to kadh·range/2 at half range, then fades to 0
        f = -kadh * std::min(gap, range - gap);
      }
      w.forces[i] -= f * u;
      w.forces[j] += f * u;
    };
    if (n >= w.grid_from) {
      double largest = 0.0;
      for (const auto& c : w.cells) largest = std::max(largest, c.radius);
      w.flatten_positions();
      w.grid.build(w.px.data(), w.py.data(), n, 2.0 * largest + range);
      w.grid.for_each_pair(n, contact_pair);
    } else {
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i + 1; j < n; ++j) contact_pair(i, j);
    }
  }
  const double fmax = w.params.max_force;
  w.fx.resize(n);
  w.fy.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    Vec2 f = w.forces[i];
    if (fmax > 0.0) {
      const double norm = f.norm();
      if (norm > fmax) f *= fmax / norm;
    }
    if (!external_forces.empty()) f += external_forces[i];
    w.fx[i] = f.x();
    w.fy[i] = f.y();
  }
  w.motion.step(static_cast<float>(w.params.time_step), w.fx.data(), w.fy.data());
  constexpr double kMaxStep = 0.5 * static_cast<double>(b2_maxTranslation);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 now(w.motion.px[i], w.motion.py[i]);
    if (!now.allFinite())
      throw SimulationError(
          fmt::format("development step {}: cell {} has a non-finite position", step_, i));
    const double moved = (now - w.cells[i].position).norm();
    if (moved > kMaxStep)
      throw SimulationError(
          fmt::format("development step {}: cell {} moved {:.3g} in one step, beyond half of "
                      "Box2D's translation cap ({}); "
                      "lower development.time_step or the stiffnesses",
                      step_, i, moved, static_cast<double>(b2_maxTranslation)));
    w.cells[i].position = now;
  }
}

// ---------------------------------------------------------------------------------------------
int DevelopmentWorld::cell_count() const { return static_cast<int>(impl_->cells.size()); }
const Grn& DevelopmentWorld::grn() const { return impl_->grn; }
const DevelopmentParams& DevelopmentWorld::params() const { return impl_->params; }
DevelopmentWorld::Vec2 DevelopmentWorld::position(int cell) const {
  return impl_->cells.at(static_cast<std::size_t>(cell)).position;
}
DevelopmentWorld::Vec2 DevelopmentWorld::velocity(int cell) const {
  const auto i = static_cast<std::size_t>(cell);
  (void)impl_->cells.at(i);  // range check
  return {impl_->motion.vx[i], impl_->motion.vy[i]};
}
double DevelopmentWorld::radius(int cell) const {
  return impl_->cells.at(static_cast<std::size_t>(cell)).radius;
}
DevelopmentWorld::Vec2 DevelopmentWorld::orientation(int cell) const {
  return impl_->cells.at(static_cast<std::size_t>(cell)).orientation;
}
GrnState& DevelopmentWorld::state(int cell) {
  return impl_->states.at(static_cast<std::size_t>(cell));
}
const GrnState& DevelopmentWorld::state(int cell) const {
  return impl_->states.at(static_cast<std::size_t>(cell));
}
double DevelopmentWorld::output(int cell, OutputChannel c) const {
  return impl_->grn.output(state(cell), c);
}
const std::vector<int>& DevelopmentWorld::division_steps() const { return impl_->division_steps; }
bool DevelopmentWorld::has(std::string_view effect) const {
  return has_effect(impl_->params.effects, effect);
}

std::array<double, 3> DevelopmentWorld::maternal_at(const Vec2& p) const {
  std::array<double, 3> out{};
  for (std::size_t k = 0; k < 3; ++k)
    out[k] = std::exp(-(p - impl_->sources[k]).norm() / impl_->params.maternal_decay_length);
  return out;
}

double DevelopmentWorld::sensed_morphogen(int cell, int k) const {
  const Impl& w = *impl_;
  if (k < 0 || k >= w.morph_count)
    throw Error(fmt::format("sensed_morphogen: no morphogen product {}", k));
  const auto i = static_cast<std::size_t>(cell);
  const auto kk = static_cast<std::size_t>(k);
  if (w.hist_len == 0)  // effect off: only the cell's own level
    return w.states.at(i).levels[static_cast<std::size_t>(w.grn.morphogen_units()[kk])];
  double sum = w.sample(i, kk, w.tap(0.0));
  for (std::size_t j = 0; j < w.cells.size(); ++j) {
    if (j == i) continue;
    const double d = (w.cells[j].position - w.cells[i].position).norm();
    if (w.params.morphogen_cutoff > 0.0 && d > w.params.morphogen_cutoff) continue;
    sum += std::exp(-d / w.params.morphogen_decay_length) *
           w.sample(j, kk, w.tap(d / w.params.morphogen_speed));
  }
  return std::min(sum, 1.0);
}

std::span<const double> DevelopmentWorld::sensed_morphogens(int cell) const {
  const Impl& w = *impl_;
  const auto m = static_cast<std::size_t>(w.morph_count);
  const auto i = static_cast<std::size_t>(cell);
  if (!w.morphogens || m == 0 || w.sensed.size() < (i + 1) * m) return {};
  return {w.sensed.data() + i * m, m};
}

const std::array<double, 3>& DevelopmentWorld::sensed_maternal(int cell) const {
  return impl_->maternal.at(static_cast<std::size_t>(cell));
}

Points DevelopmentWorld::positions() const {
  Points p(cell_count(), 2);
  for (int i = 0; i < cell_count(); ++i)
    p.row(i) = impl_->cells[static_cast<std::size_t>(i)].position.transpose();
  return p;
}
Vector DevelopmentWorld::radii() const {
  Vector r(cell_count());
  for (int i = 0; i < cell_count(); ++i) r[i] = impl_->cells[static_cast<std::size_t>(i)].radius;
  return r;
}
Points DevelopmentWorld::orientations() const {
  Points o(cell_count(), 2);
  for (int i = 0; i < cell_count(); ++i)
    o.row(i) = impl_->cells[static_cast<std::size_t>(i)].orientation.transpose();
  return o;
}
OutputLevels DevelopmentWorld::outputs() const {
  // The paper's 6 columns, or all kOutputCount when the genome has an extension output.
  const int columns = impl_->grn.output_count();
  OutputLevels out(cell_count(), columns);
  for (int i = 0; i < cell_count(); ++i)
    for (int c = 0; c < columns; ++c) out(i, c) = output(i, static_cast<OutputChannel>(c));
  return out;
}

// ---------------------------------------------------------------------------------------------
namespace {

void snapshot(const DevelopmentWorld& w, DevelopmentTrace& t) {
  t.steps.push_back(w.current_step());
  t.positions.push_back(w.positions());
  t.radii.push_back(w.radii());
  t.orientations.push_back(w.orientations());
}

std::string missing_paths(const Grn& grn) {
  std::string names;
  for (OutputChannel c : {OutputChannel::divide, OutputChannel::amplitude, OutputChannel::frequency,
                          OutputChannel::phase}) {
    if (grn.reaches(c)) continue;
    if (!names.empty()) names += ", ";
    names += kOutputNames[static_cast<std::size_t>(c)];
  }
  return names;
}

}  // namespace

Embryo develop(const Genome& genome, const GenomeParams& genome_params, const GrnParams& grn_params,
               const DevelopmentParams& params) {
  validate(params);
  Grn grn(genome, genome_params);
  const bool paths = grn.has_required_paths();
  const bool divide_reachable = grn.reaches(OutputChannel::divide);
  DevelopmentWorld world(std::move(grn), grn_params, params);
  // jitter_stream = "fixed": any constant; this one is the first 64 bits of pi's fraction
  world.set_symmetry_seed(params.jitter_stream == "fixed" ? 0x243F6A8885A308D3ULL
                                                          : genome_hash(genome));
  world.add_cell(DevelopmentWorld::Vec2::Zero(), params.cell_radius,
                 DevelopmentWorld::Vec2(1.0, 0.0));

  Embryo e;
  const int steps = params.steps;
  const int last_allowed = steps - params.quiet_steps;  // a division after this step is too late
  const bool tracing = params.trace_every > 0;
  if (tracing) snapshot(world, e.trace);

  // Verdicts that are certain before any step.
  if (!paths)
    e.reasons.push_back(
        fmt::format("grn: no path from an input to the {} output(s)", missing_paths(world.grn())));
  if (!divide_reachable && params.min_cells > 1)
    e.reasons.push_back(
        fmt::format("cells: 1 cell, fewer than min_cells = {} (the divide output is unreachable)",
                    params.min_cells));
  if (params.max_cells < params.min_cells)
    e.reasons.push_back(fmt::format("cells: max_cells = {} is below min_cells = {}",
                                    params.max_cells, params.min_cells));
  auto too_few_cells_for_good = [&] {
    return world.current_step() >= last_allowed && world.cell_count() < params.min_cells;
  };
  if (e.reasons.empty() && too_few_cells_for_good())
    e.reasons.push_back(fmt::format(
        "cells: {} cell(s), fewer than min_cells = {}, and no division may come in time",
        world.cell_count(), params.min_cells));

  if (e.reasons.empty()) {
    while (world.current_step() < steps) {
      const int divisions = world.step();
      const int s = world.current_step();
      if (tracing && s % params.trace_every == 0) snapshot(world, e.trace);
      if (divisions > 0 && s > last_allowed) {
        e.reasons.push_back(
            fmt::format("late division: a division at step {} is fewer than quiet_steps = {} steps "
                        "before the end (step {})",
                        s, params.quiet_steps, steps));
        break;
      }
      if (too_few_cells_for_good()) {
        e.reasons.push_back(fmt::format("cells: {} cell(s) at step {}, fewer than min_cells = {}{}",
                                        world.cell_count(), s, params.min_cells,
                                        s < steps ? ", and no division may come in time" : ""));
        break;
      }
    }
  }
  e.steps_run = world.current_step();
  if (tracing && e.trace.steps.back() != e.steps_run) snapshot(world, e.trace);

  e.positions = world.positions();
  e.radii = world.radii();
  e.orientations = world.orientations();
  e.outputs = world.outputs();
  const int n = world.cell_count();
  e.amplitude = params.amplitude_max * e.outputs.col(static_cast<int>(OutputChannel::amplitude));
  e.frequency = (Vector::Constant(n, params.frequency_min).array() +
                 (params.frequency_max - params.frequency_min) *
                     e.outputs.col(static_cast<int>(OutputChannel::frequency)).array())
                    .matrix();
  e.phase = 2.0 * std::numbers::pi * e.outputs.col(static_cast<int>(OutputChannel::phase));
  // Evolvable stiffness (docs/model.md): only when the config enables the output; a genome
  // without a stiffness element has level 0 there (stiffness_min), as a missing amplitude element
  // gives 0.
  const auto enabled = enabled_output_channels(genome_params);
  if (std::find(enabled.begin(), enabled.end(), static_cast<int>(OutputChannel::stiffness)) !=
      enabled.end()) {
    e.stiffness.resize(n);
    const double ratio = params.stiffness_max / params.stiffness_min;
    for (int i = 0; i < n; ++i)
      e.stiffness(i) =
          params.stiffness_min * std::pow(ratio, world.output(i, OutputChannel::stiffness));
  }
  e.division_steps = world.division_steps();
  e.viable = e.reasons.empty();
  const int nodes = world.grn().node_count();
  const auto morph = static_cast<int>(world.grn().morphogen_units().size());
  e.grn_levels.resize(n, nodes);
  e.grn_maternal.resize(n, 3);
  e.grn_sensed.resize(n, world.has("morphogens") ? morph : 0);
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < nodes; ++k)
      e.grn_levels(i, k) = world.state(i).levels[static_cast<std::size_t>(k)];
    // A cell born after the last sense() has sensed nothing yet: 0, as sense() would start it.
    std::array<double, 3> maternal{};
    try {
      maternal = world.sensed_maternal(i);
    } catch (const std::out_of_range&) {
    }
    for (int k = 0; k < 3; ++k) e.grn_maternal(i, k) = maternal[static_cast<std::size_t>(k)];
    const auto sensed = world.sensed_morphogens(i);
    for (int k = 0; k < e.grn_sensed.cols(); ++k)
      e.grn_sensed(i, k) =
          static_cast<std::size_t>(k) < sensed.size() ? sensed[static_cast<std::size_t>(k)] : 0.0;
  }
  return e;
}

}  // namespace animat
