// The swim simulation: a Box2D world of fixture-less cell bodies driven by the scene's effects.
// See physics.hpp for the step, docs/notes/physics.md for units and choices.
#include "animat/physics.hpp"

#include <box2d/box2d.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include "animat/body.hpp"
#include "animat/embedding.hpp"
#include "animat/energy.hpp"
#include "animat/errors.hpp"
#include "box2d_island.hpp"
#include "cell_integrator.hpp"

namespace animat {
namespace {

constexpr double kMaxTranslation = static_cast<double>(b2_maxTranslation);

void check_body(const Body& b) {
  const int n = b.node_count();
  auto fail = [](const std::string& what) { throw GeometryError("Simulation: " + what); };
  if (b.springs.rows() != b.rest_lengths.size())
    fail(fmt::format("{} springs but {} rest lengths", b.springs.rows(), b.rest_lengths.size()));
  if (static_cast<Eigen::Index>(b.regions.size()) != b.rest_areas.size())
    fail(fmt::format("{} regions but {} rest areas", b.regions.size(), b.rest_areas.size()));
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(b.positions(i, 0)) || !std::isfinite(b.positions(i, 1)))
      fail(fmt::format("node {} has a non-finite position", i));
  auto check_index = [&](int v, const char* what) {
    if (v < 0 || v >= n)
      fail(fmt::format("{} refers to node {}, but there are {} nodes", what, v, n));
  };
  for (int s = 0; s < b.spring_count(); ++s) {
    check_index(b.springs(s, 0), "a spring");
    check_index(b.springs(s, 1), "a spring");
    if (!(b.rest_lengths(s) >= 0.0) || !std::isfinite(b.rest_lengths(s)))
      fail(fmt::format("spring {} has rest length {}", s, b.rest_lengths(s)));
  }
  for (const auto& loop : b.regions)
    for (int v : loop) check_index(v, "a region");
  for (int r = 0; r < b.region_count(); ++r)
    if (!std::isfinite(b.rest_areas(r)))
      fail(fmt::format("region {} has rest area {}", r, b.rest_areas(r)));
  for (int e = 0; e < b.skin.rows(); ++e) {
    check_index(b.skin(e, 0), "a skin edge");
    check_index(b.skin(e, 1), "a skin edge");
  }
  if (b.stiffness.size() != 0 && b.stiffness.size() != n)
    fail(fmt::format("stiffness must have {} entries (or none), got {}", n, b.stiffness.size()));
  for (Eigen::Index i = 0; i < b.stiffness.size(); ++i)
    if (!(b.stiffness(i) > 0.0) || !std::isfinite(b.stiffness(i)))
      fail(fmt::format("node {} has stiffness factor {} (must be finite and > 0)", i,
                       b.stiffness(i)));
  for (const Vector* v : {&b.amplitude, &b.frequency, &b.phase}) {
    if (v->size() != 0 && v->size() != n)
      fail(fmt::format("oscillator vectors must have {} entries (or none), got {}", n, v->size()));
    for (Eigen::Index i = 0; i < v->size(); ++i)
      if (!std::isfinite((*v)(i)))
        fail(fmt::format("node {} has a non-finite oscillator parameter", i));
  }
}

}  // namespace

void link_bodies(b2World& world, b2Body* a, b2Body* b) {
  // Box2D solves each island separately, at ~700 instructions of fixed cost per island and step
  // (timers, solver setup, bookkeeping); unlinked cells are one island each. A friction joint with
  // zero maximum force and torque applies no impulse (it is clamped to zero before it reaches the
  // velocities) but puts both bodies in the same island.
  b2FrictionJointDef def;
  def.bodyA = a;
  def.bodyB = b;
  def.maxForce = 0.0f;
  def.maxTorque = 0.0f;
  def.collideConnected = true;  // no fixtures anyway: nothing to filter
  world.CreateJoint(&def);
}

void link_into_one_island(b2World& world, const std::vector<b2Body*>& bodies) {
  for (std::size_t i = 1; i < bodies.size(); ++i) link_bodies(world, bodies[i - 1], bodies[i]);
}

void warm_up_box2d() {
  static std::once_flag once;
  std::call_once(once, [] {
    b2World world(b2Vec2(0.0f, 0.0f));
    world.SetContinuousPhysics(false);
    b2CircleShape circle;
    circle.m_radius = 0.5f;
    for (int k = 0; k < 2; ++k) {
      b2BodyDef def;
      def.type = b2_dynamicBody;
      def.position.Set(0.6f * static_cast<float>(k), 0.0f);
      b2Body* body = world.CreateBody(&def);
      body->CreateFixture(&circle, 1.0f);
    }
    world.Step(1.0f / 60.0f, 1, 1);
  });
}

namespace {

/// The books of energy accounting (Simulation::account_energy): per effect pass a bucket of the
/// per-cell forces it added in the current Box2D step, and each bucket's work so far. Sized when
/// the books open, never in the step loop.
/// Energy accounting: where an effect pass's work is booked.
enum class Sink : int { none, drag, drag_normal, spring_damping, collisions, ground, other };

struct EnergyBooks {
  bool on = false;
  // per effect of each list; -1: not booked
  std::vector<int> force_bucket, velocity_bucket, constraint_bucket;
  std::vector<double> work;              // per bucket: the work of its forces so far
  std::vector<double> step_work;         // per bucket: in the current step
  std::vector<double> fx, fy;            // buckets × n: this step's forces per bucket
  std::vector<double> prev_fx, prev_fy;  // state.fx, fy before the current effect pass
  std::vector<double> ux, uy;            // per cell: the end velocity v' of the step
  std::vector<double> wx, wy;            // per cell: v' without the collisions' impulses
  double external = 0.0;                 // kinetic energy added by pushes
  double actuation_start = 0.0;
  double kinetic_start = 0.0, elastic_start = 0.0, pressure_start = 0.0, gravity_start = 0.0,
         other_start = 0.0;
  std::vector<Sink> sink;  // per bucket: where its work goes
};

}  // namespace

struct Simulation::Impl {
  SceneParams scene;
  PhysicsParams physics;
  std::unique_ptr<b2World> world;  // physics.integrator = "box2d" only
  std::vector<b2Body*> bodies;     // idem
  // the cells' float state (both integrators; "box2d" copies it from the world)
  CellIntegrator cells;
  std::vector<std::unique_ptr<Effect>> effects;  // in run order
  std::vector<Effect*> force_effects;            // modifier and force stages, in run order
  // those with velocity-dependent forces, in run order
  std::vector<Effect*> velocity_effects;
  std::vector<Effect*> constraint_effects;  // run after every force is known
  bool midpoint = true;
  std::vector<double> fx_pos, fy_pos;  // position-dependent forces (midpoint scheme)
  SwimState state;
  double h = 0.0;
  float hf = 0.0f;
  long box2d_steps = 0;
  long control_steps = 0;
  double max_disp = 0.0;
  double max_speed = 0.0;
  std::string failure;
  bool monitoring = false;
  EmbeddingMonitor monitor;
  long first_broken_step = -1;  // control step at the end of which the embedding first broke
  EnergyBooks books;            // energy accounting (account_energy()); off: never touched

  /// The sink of an effect's apply() (position or constraint forces) or apply_velocity() forces.
  static Sink sink_of(const Effect& e, bool velocity_pass) {
    if (velocity_pass) {
      if (e.name() == "drag") return Sink::drag;
      if (e.name() == "ground") return Sink::ground;  // the compliant floor
      if (e.name() == "springs") return Sink::spring_damping;
      return Sink::other;
    }
    if (e.has_potential_energy()) return Sink::none;  // work accounted by the potential
    if (e.name() == "collisions") return Sink::collisions;
    if (e.name() == "ground") return Sink::ground;
    if (e.name() == "actuation") return Sink::none;  // a modifier: it adds no force
    return Sink::other;
  }

  /// Assigns every effect pass a bucket of per-cell forces (once, and again when an effect is
  /// added while the books are kept).
  void layout_books() {
    EnergyBooks& b = books;
    const auto n = static_cast<std::size_t>(state.n);
    b.force_bucket.assign(force_effects.size(), -1);
    b.velocity_bucket.assign(velocity_effects.size(), -1);
    b.constraint_bucket.assign(constraint_effects.size(), -1);
    std::vector<Sink> sinks;
    auto bucket = [&](const Effect& e, bool velocity_pass) {
      const Sink k = sink_of(e, velocity_pass);
      if (k == Sink::none) return -1;
      sinks.push_back(k);
      return static_cast<int>(sinks.size()) - 1;
    };
    for (std::size_t k = 0; k < force_effects.size(); ++k)
      b.force_bucket[k] = bucket(*force_effects[k], false);
    for (std::size_t k = 0; k < velocity_effects.size(); ++k)
      b.velocity_bucket[k] = bucket(*velocity_effects[k], true);
    for (std::size_t k = 0; k < constraint_effects.size(); ++k)
      b.constraint_bucket[k] = bucket(*constraint_effects[k], false);
    // the last bucket: drag's normal part (state.normal_drag_fx)
    sinks.push_back(Sink::drag_normal);
    const std::size_t buckets = sinks.size();
    b.sink = std::move(sinks);
    b.work.resize(buckets, 0.0);  // keeps what was booked so far
    b.step_work.assign(buckets, 0.0);
    b.fx.assign(buckets * n, 0.0);
    b.fy.assign(buckets * n, 0.0);
    for (auto* v : {&b.prev_fx, &b.prev_fy, &b.ux, &b.uy, &b.wx, &b.wy}) v->assign(n, 0.0);
  }

  /// Books the forces the last effect pass added to state.fx, fy into bucket `k` (-1: none).
  void book(int k) {
    EnergyBooks& b = books;
    const auto n = static_cast<std::size_t>(state.n);
    if (k >= 0) {
      double* bx = b.fx.data() + static_cast<std::size_t>(k) * n;
      double* by = b.fy.data() + static_cast<std::size_t>(k) * n;
      for (std::size_t i = 0; i < n; ++i) {
        bx[i] = state.fx[i] - b.prev_fx[i];
        by[i] = state.fy[i] - b.prev_fy[i];
      }
    }
    std::copy(state.fx.begin(), state.fx.end(), b.prev_fx.begin());
    std::copy(state.fy.begin(), state.fy.end(), b.prev_fy.begin());
  }

  /// run_effects() that also books each effect pass's work (energy accounting): the works add up
  /// to the step's change of kinetic energy exactly (before Box2D rounds the velocities to float).
  void run_effects_booked() {
    EnergyBooks& b = books;
    const auto n = static_cast<std::size_t>(state.n);
    state.step = box2d_steps;
    state.time = static_cast<double>(box2d_steps) * h;
    state.position_corrected = false;
    std::fill(state.fx.begin(), state.fx.end(), 0.0);
    std::fill(state.fy.begin(), state.fy.end(), 0.0);
    std::fill(b.prev_fx.begin(), b.prev_fx.end(), 0.0);
    std::fill(b.prev_fy.begin(), b.prev_fy.end(), 0.0);
    std::fill(b.step_work.begin(), b.step_work.end(), 0.0);
    for (std::size_t k = 0; k < force_effects.size(); ++k) {
      force_effects[k]->apply(state);
      book(b.force_bucket[k]);
    }
    const std::size_t normal = b.sink.size() - 1;
    double* nx = b.fx.data() + normal * n;
    double* ny = b.fy.data() + normal * n;
    std::fill(nx, nx + n, 0.0);
    std::fill(ny, ny + n, 0.0);
    if (!velocity_effects.empty()) {
      evaluation_velocity();  // the predictor pass books nothing
      for (std::size_t k = 0; k < velocity_effects.size(); ++k) {
        const int bucket = b.velocity_bucket[k];
        if (bucket >= 0 && b.sink[static_cast<std::size_t>(bucket)] == Sink::drag) {
          state.normal_drag_fx = nx;
          state.normal_drag_fy = ny;
        }
        velocity_effects[k]->apply_velocity(state);
        state.normal_drag_fx = nullptr;
        state.normal_drag_fy = nullptr;
        book(bucket);
      }
    }
    for (std::size_t k = 0; k < constraint_effects.size(); ++k) {
      constraint_effects[k]->apply(state);
      book(b.constraint_bucket[k]);
    }
    // Every force and impulse is known. The collisions' impulses J_c act at an instant (a cell
    // turns back when it meets an edge); every other force, the floor's included, acts over the
    // step. So with v' = v + h·ΣF/m the end velocity and u = v' − J_c/m the end velocity without
    // the collisions, a force's work is h·F·(v + u)/2 and a collision impulse's J_c·(u + v')/2
    // (zero for an elastic one). Together they are ½m(v'² − v²) exactly.
    const double kv = h * state.inv_mass;
    for (std::size_t i = 0; i < n; ++i) {
      b.ux[i] = state.vx[i] + kv * state.fx[i];  // v'
      b.uy[i] = state.vy[i] + kv * state.fy[i];
    }
    std::copy(b.ux.begin(), b.ux.end(), b.wx.begin());  // u
    std::copy(b.uy.begin(), b.uy.end(), b.wy.begin());
    for (std::size_t k = 0; k < b.sink.size(); ++k) {
      if (b.sink[k] != Sink::collisions) continue;
      const double* bx = b.fx.data() + k * n;
      const double* by = b.fy.data() + k * n;
      for (std::size_t i = 0; i < n; ++i) {
        b.wx[i] -= kv * bx[i];
        b.wy[i] -= kv * by[i];
      }
    }
    for (std::size_t k = 0; k < b.sink.size(); ++k) {
      const double* bx = b.fx.data() + k * n;
      const double* by = b.fy.data() + k * n;
      const bool instant = b.sink[k] == Sink::collisions;
      double w = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        const double mx = instant ? b.wx[i] + b.ux[i] : state.vx[i] + b.wx[i];
        const double my = instant ? b.wy[i] + b.uy[i] : state.vy[i] + b.wy[i];
        w += bx[i] * mx + by[i] * my;
      }
      b.step_work[k] = 0.5 * h * w;
    }
  }

  /// After Box2D's step: the step's work goes into the books (a step that failed books nothing).
  void close_books_of_step() {
    EnergyBooks& b = books;
    for (std::size_t k = 0; k < b.sink.size(); ++k) b.work[k] += b.step_work[k];
  }

  /// Potentials of the conservative effects at the current state: elastic, pressure, gravity,
  /// other.
  void potentials(double& elastic, double& pressure, double& gravity, double& other) const {
    elastic = pressure = gravity = other = 0.0;
    for (const auto& e : effects) {
      if (!e->has_potential_energy()) continue;
      (e->name() == "springs"    ? elastic
       : e->name() == "pressure" ? pressure
       : e->name() == "gravity"  ? gravity
                                 : other) += e->potential_energy(state);
    }
  }

  double kinetic() const {
    double e = 0.0;
    for (std::size_t i = 0; i < cells.size(); ++i)
      e += static_cast<double>(cells.vx[i]) * cells.vx[i] +
           static_cast<double>(cells.vy[i]) * cells.vy[i];
    return 0.5 * state.mass * e;
  }

  void read_state() {
    for (std::size_t i = 0; i < bodies.size(); ++i) {  // a real world: its bodies are the truth
      const b2Vec2 p = bodies[i]->GetPosition();
      const b2Vec2 v = bodies[i]->GetLinearVelocity();
      cells.px[i] = p.x;
      cells.py[i] = p.y;
      cells.vx[i] = v.x;
      cells.vy[i] = v.y;
    }
    for (std::size_t i = 0; i < cells.size(); ++i) {
      state.x[i] = static_cast<double>(cells.px[i]);
      state.y[i] = static_cast<double>(cells.py[i]);
      state.vx[i] = static_cast<double>(cells.vx[i]);
      state.vy[i] = static_cast<double>(cells.vy[i]);
    }
  }

  void run_effects() {
    state.step = box2d_steps;
    state.time = static_cast<double>(box2d_steps) * h;
    state.position_corrected = false;
    std::fill(state.fx.begin(), state.fx.end(), 0.0);
    std::fill(state.fy.begin(), state.fy.end(), 0.0);
    for (Effect* e : force_effects) e->apply(state);
    velocity_forces();
    for (Effect* e : constraint_effects) e->apply(state);
  }

  /// The velocity s.ux, s.uy the velocity-dependent forces are evaluated at: u = v (start) or
  /// u = v + (h/2)·F(v)/m (midpoint: a predictor pass at v, whose forces are then discarded, so
  /// that the forces are recomputed at u on top of the position-dependent ones).
  void evaluation_velocity() {
    std::copy(state.vx.begin(), state.vx.end(), state.ux.begin());
    std::copy(state.vy.begin(), state.vy.end(), state.uy.begin());
    if (!midpoint) return;
    std::copy(state.fx.begin(), state.fx.end(), fx_pos.begin());
    std::copy(state.fy.begin(), state.fy.end(), fy_pos.begin());
    state.predictor = true;
    for (Effect* e : velocity_effects) e->apply_velocity(state);
    state.predictor = false;
    const double k = 0.5 * h * state.inv_mass;
    for (std::size_t i = 0; i < state.ux.size(); ++i) {
      state.ux[i] = state.vx[i] + k * state.fx[i];
      state.uy[i] = state.vy[i] + k * state.fy[i];
    }
    std::copy(fx_pos.begin(), fx_pos.end(), state.fx.begin());
    std::copy(fy_pos.begin(), fy_pos.end(), state.fy.begin());
  }

  void velocity_forces() {
    if (velocity_effects.empty()) return;
    evaluation_velocity();
    for (Effect* e : velocity_effects) e->apply_velocity(state);
  }

  [[noreturn]] void fail(std::string message) {
    failure = std::move(message);
    throw SimulationError(failure);
  }

  void check_forces() {
    // Predicted velocity after this step; Box2D moves a cell by |v|·h.
    double worst = 0.0;
    int worst_i = -1;
    const double k = h * state.inv_mass;
    for (int i = 0; i < state.n; ++i) {
      const auto u = static_cast<std::size_t>(i);
      const double wx = state.vx[u] + k * state.fx[u];
      const double wy = state.vy[u] + k * state.fy[u];
      const double w2 = wx * wx + wy * wy;
      if (!(w2 <= worst)) {  // also catches NaN
        worst = w2;
        worst_i = i;
        if (!std::isfinite(w2)) break;
      }
    }
    const double speed = std::sqrt(worst);
    if (!std::isfinite(speed)) {
      const auto u = static_cast<std::size_t>(worst_i);
      fail(fmt::format(
          "unstable swim: step {} (t = {:.6g}): cell {} has a non-finite state (position ({}, {}), "
          "velocity ({}, {}), force ({}, {}))",
          control_steps, state.time, worst_i, state.x[u], state.y[u], state.vx[u], state.vy[u],
          state.fx[u], state.fy[u]));
    }
    const double disp = speed * h;
    max_speed = std::max(max_speed, speed);
    max_disp = std::max(max_disp, disp);
    if (disp > physics.max_step_displacement) {
      fail(
          fmt::format("unstable swim: step {} (t = {:.6g}): cell {} would move {:.6g} length units "
                      "in one Box2D "
                      "step (speed {:.6g}), beyond physics.max_step_displacement = {} (Box2D "
                      "silently caps at {})",
                      control_steps, state.time, worst_i, disp, speed,
                      physics.max_step_displacement, kMaxTranslation));
    }
  }

  /// One Box2D step from the current state (read after the previous step).
  void box2d_step() {
    if (books.on)
      run_effects_booked();
    else
      run_effects();
    check_forces();
    if (world) {
      for (std::size_t i = 0; i < bodies.size(); ++i)
        bodies[i]->ApplyForceToCenter(
            b2Vec2(static_cast<float>(state.fx[i]), static_cast<float>(state.fy[i])), true);
      world->Step(hf, physics.velocity_iterations, physics.position_iterations);
    } else {
      cells.step(hf, state.fx.data(), state.fy.data());
    }
    ++box2d_steps;
    if (state.position_corrected) {
      for (std::size_t i = 0; i < cells.size(); ++i) {
        if (state.cx[i] == 0.0 && state.cy[i] == 0.0) continue;
        // SetTransform(p + c, 0): the body's position (and mass centre) becomes the float sum.
        const b2Vec2 p = world ? bodies[i]->GetPosition() : b2Vec2(cells.px[i], cells.py[i]);
        const b2Vec2 q(static_cast<float>(static_cast<double>(p.x) + state.cx[i]),
                       static_cast<float>(static_cast<double>(p.y) + state.cy[i]));
        if (world) {
          bodies[i]->SetTransform(q, 0.0f);
        } else {
          cells.px[i] = q.x;
          cells.py[i] = q.y;
        }
      }
    }
    read_state();
    if (books.on) close_books_of_step();
    if (monitoring && !monitor.observe(state.x, state.y) && first_broken_step < 0)
      first_broken_step = control_steps;
  }

  void insert(std::unique_ptr<Effect> e) {
    const auto stage = e->stage();
    auto pos = std::find_if(effects.begin(), effects.end(),
                            [&](const auto& x) { return x->stage() > stage; });
    effects.insert(pos, std::move(e));
    force_effects.clear();
    velocity_effects.clear();
    constraint_effects.clear();
    for (const auto& x : effects) {
      (x->stage() == Effect::Stage::constraint ? constraint_effects : force_effects)
          .push_back(x.get());
      if (x->velocity_dependent()) velocity_effects.push_back(x.get());
    }
    if (books.on) layout_books();
  }
};

Simulation::Simulation(const Body& body_in, const SceneParams& scene, const PhysicsParams& physics)
    : impl_(std::make_unique<Impl>()) {
  validate(scene);
  validate(physics);
  check_body(body_in);
  Impl& s = *impl_;
  s.scene = scene;
  s.physics = physics;
  s.h = physics.dt / physics.substeps;
  s.hf = static_cast<float>(s.h);
  const Body body = swim_body(body_in);
  const int n = body.node_count();

  s.cells.set_mass(scene.cell_mass);
  s.cells.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) s.cells.add(body.positions(i, 0), body.positions(i, 1), 0.0, 0.0);
  if (physics.integrator == "box2d") {
    s.world = std::make_unique<b2World>(b2Vec2(0.0f, 0.0f));
    s.world->SetAllowSleeping(false);
    s.world->SetContinuousPhysics(false);
    s.world->SetWarmStarting(false);
    s.bodies.reserve(static_cast<std::size_t>(n));
    b2MassData mass;
    mass.mass = static_cast<float>(scene.cell_mass);
    mass.center.SetZero();
    mass.I = 0.0f;
    for (int i = 0; i < n; ++i) {
      b2BodyDef def;
      def.type = b2_dynamicBody;
      def.position.Set(static_cast<float>(body.positions(i, 0)),
                       static_cast<float>(body.positions(i, 1)));
      def.allowSleep = false;
      def.awake = true;
      def.fixedRotation = true;
      def.bullet = false;
      def.linearDamping = 0.0f;
      def.angularDamping = 0.0f;
      b2Body* b = s.world->CreateBody(&def);
      b->SetMassData(&mass);
      s.bodies.push_back(b);
    }
    link_into_one_island(*s.world, s.bodies);
  }

  SwimState& st = s.state;
  st.n = n;
  st.h = s.h;
  st.mass = static_cast<double>(static_cast<float>(scene.cell_mass));  // what Box2D integrates with
  st.inv_mass = 1.0 / st.mass;
  for (auto* v : {&st.x, &st.y, &st.vx, &st.vy, &st.ux, &st.uy, &st.fx, &st.fy, &st.cx, &st.cy,
                  &st.ground_fx, &st.ground_fy, &s.fx_pos, &s.fy_pos})
    v->assign(static_cast<std::size_t>(n), 0.0);
  s.midpoint = physics.velocity_forces == "midpoint";
  st.rest.assign(body.rest_lengths.data(), body.rest_lengths.data() + body.rest_lengths.size());

  for (const auto& name : kSceneEffectNames) {  // canonical order within a stage
    if (!has_effect(scene.effects, name)) continue;
    s.insert(make_effect(name, body, scene, physics));
  }
  for (const auto& e : s.effects)
    if (e->needs_box2d_collisions())
      throw ConfigError(fmt::format(
          "effect '{}' needs Box2D collisions, which the swim world does not provide", e->name()));
  s.read_state();
}

Simulation::~Simulation() = default;
Simulation::Simulation(Simulation&&) noexcept = default;
Simulation& Simulation::operator=(Simulation&&) noexcept = default;

void Simulation::add_effect(std::unique_ptr<Effect> effect) {
  if (!effect) throw ConfigError("Simulation::add_effect: null effect");
  if (effect->needs_box2d_collisions())
    throw ConfigError(
        fmt::format("effect '{}' needs Box2D collisions, which the swim world does not provide",
                    effect->name()));
  impl_->insert(std::move(effect));
}

void Simulation::step(long n) {
  Impl& s = *impl_;
  if (!s.failure.empty()) throw SimulationError(s.failure);
  for (long k = 0; k < n; ++k) {
    for (int j = 0; j < s.physics.substeps; ++j) s.box2d_step();
    ++s.control_steps;
  }
}

void Simulation::compute_forces() {
  impl_->read_state();  // in case a caller moved bodies in world() directly
  impl_->run_effects();
}

void Simulation::monitor_embedding(const Body& body) {
  Impl& s = *impl_;
  if (body.node_count() != s.state.n)
    throw GeometryError(
        fmt::format("Simulation::monitor_embedding: the body has {} nodes, the simulation {}",
                    body.node_count(), s.state.n));
  s.monitor = EmbeddingMonitor(body);
  s.monitoring = true;
  s.first_broken_step = -1;
  if (!s.monitor.observe(s.state.x, s.state.y)) s.first_broken_step = s.control_steps;
}

const EmbeddingMonitor* Simulation::embedding_monitor() const {
  return impl_->monitoring ? &impl_->monitor : nullptr;
}
long Simulation::first_broken_step() const { return impl_->first_broken_step; }
const SwimCounters& Simulation::counters() const { return impl_->state.counters; }

void Simulation::set_velocities(const Points& v) {
  Impl& s = *impl_;
  if (v.rows() != s.state.n)
    throw GeometryError(
        fmt::format("Simulation::set_velocities: expected {} rows, got {}", s.state.n, v.rows()));
  if (!v.allFinite()) throw GeometryError("Simulation::set_velocities: non-finite velocity");
  for (int i = 0; i < s.state.n; ++i) {
    const auto u = static_cast<std::size_t>(i);
    s.cells.vx[u] = static_cast<float>(v(i, 0));
    s.cells.vy[u] = static_cast<float>(v(i, 1));
    if (s.world) s.bodies[u]->SetLinearVelocity(b2Vec2(s.cells.vx[u], s.cells.vy[u]));
  }
  s.read_state();
}

void Simulation::push(std::span<const int> cells, const Eigen::Vector2d& impulse) {
  Impl& s = *impl_;
  if (!impulse.allFinite()) throw GeometryError("Simulation::push: non-finite impulse");
  for (int c : cells)
    if (c < 0 || c >= s.state.n)
      throw GeometryError(
          fmt::format("Simulation::push: cell {} out of range [0, {})", c, s.state.n));
  const double inv_mass = s.state.inv_mass;
  const double kinetic_before = s.books.on ? s.kinetic() : 0.0;
  for (int c : cells) {
    const auto u = static_cast<std::size_t>(c);
    s.cells.vx[u] = static_cast<float>(static_cast<double>(s.cells.vx[u]) + impulse.x() * inv_mass);
    s.cells.vy[u] = static_cast<float>(static_cast<double>(s.cells.vy[u]) + impulse.y() * inv_mass);
    if (s.world) s.bodies[u]->SetLinearVelocity(b2Vec2(s.cells.vx[u], s.cells.vy[u]));
  }
  if (s.books.on) s.books.external += s.kinetic() - kinetic_before;
  s.read_state();
}

void Simulation::account_energy() {
  Impl& s = *impl_;
  EnergyBooks& b = s.books;
  b = EnergyBooks{};
  b.on = true;
  b.actuation_start = s.state.counters.actuation_work;
  b.kinetic_start = s.kinetic();
  s.potentials(b.elastic_start, b.pressure_start, b.gravity_start, b.other_start);
  s.layout_books();
}

EnergyAccount Simulation::energy_account() const {
  const Impl& s = *impl_;
  const EnergyBooks& b = s.books;
  EnergyAccount a;
  if (!b.on) return a;
  a.measured = true;
  a.actuation = s.state.counters.actuation_work - b.actuation_start;
  a.external = b.external;
  double drag = 0.0;
  for (std::size_t k = 0; k < b.sink.size(); ++k) {
    const double d = -b.work[k];  // dissipated = minus the work of the forces
    switch (b.sink[k]) {
      case Sink::drag: drag += d; break;
      case Sink::drag_normal: a.drag_normal += d; break;
      case Sink::spring_damping: a.spring_damping += d; break;
      case Sink::collisions: a.collisions += d; break;
      case Sink::ground: a.ground += d; break;
      case Sink::other: a.other += d; break;
      case Sink::none: break;
    }
  }
  a.drag_tangential = drag - a.drag_normal;
  a.kinetic_start = b.kinetic_start;
  a.kinetic_end = s.kinetic();
  a.elastic_start = b.elastic_start;
  a.pressure_start = b.pressure_start;
  a.gravity_start = b.gravity_start;
  a.other_potential_start = b.other_start;
  s.potentials(a.elastic_end, a.pressure_end, a.gravity_end, a.other_potential_end);
  return a;
}

int Simulation::node_count() const { return impl_->state.n; }
long Simulation::steps_done() const { return impl_->control_steps; }
long Simulation::substeps_done() const { return impl_->box2d_steps; }
double Simulation::time() const { return static_cast<double>(impl_->box2d_steps) * impl_->h; }

Points Simulation::positions() const {
  Points p(impl_->state.n, 2);
  const CellIntegrator& c = impl_->cells;
  for (int i = 0; i < impl_->state.n; ++i) {
    p(i, 0) = static_cast<double>(c.px[static_cast<std::size_t>(i)]);
    p(i, 1) = static_cast<double>(c.py[static_cast<std::size_t>(i)]);
  }
  return p;
}

Points Simulation::velocities() const {
  Points p(impl_->state.n, 2);
  const CellIntegrator& c = impl_->cells;
  for (int i = 0; i < impl_->state.n; ++i) {
    p(i, 0) = static_cast<double>(c.vx[static_cast<std::size_t>(i)]);
    p(i, 1) = static_cast<double>(c.vy[static_cast<std::size_t>(i)]);
  }
  return p;
}

Eigen::Vector2d Simulation::center_of_mass() const {
  Eigen::Vector2d c(0.0, 0.0);
  const int n = impl_->state.n;
  if (n == 0) return c;
  const CellIntegrator& cells = impl_->cells;
  for (std::size_t i = 0; i < cells.size(); ++i)
    c += Eigen::Vector2d(static_cast<double>(cells.px[i]), static_cast<double>(cells.py[i]));
  return c / n;
}

Eigen::Vector2d Simulation::momentum() const {
  Eigen::Vector2d c(0.0, 0.0);
  const CellIntegrator& cells = impl_->cells;
  for (std::size_t i = 0; i < cells.size(); ++i)
    c += Eigen::Vector2d(static_cast<double>(cells.vx[i]), static_cast<double>(cells.vy[i]));
  return c * impl_->state.mass;
}

double Simulation::kinetic_energy() const {
  double e = 0.0;
  const CellIntegrator& cells = impl_->cells;
  for (std::size_t i = 0; i < cells.size(); ++i)
    e += static_cast<double>(cells.vx[i]) * cells.vx[i] +
         static_cast<double>(cells.vy[i]) * cells.vy[i];
  return 0.5 * impl_->state.mass * e;
}

std::span<const double> Simulation::rest_lengths_now() const { return impl_->state.rest; }
std::span<const double> Simulation::forces_x() const { return impl_->state.fx; }
std::span<const double> Simulation::forces_y() const { return impl_->state.fy; }
const SwimState& Simulation::state() const { return impl_->state; }

std::vector<const Effect*> Simulation::effects() const {
  std::vector<const Effect*> out;
  for (const auto& e : impl_->effects) out.push_back(e.get());
  return out;
}

const Effect* Simulation::effect(std::string_view name) const {
  for (const auto& e : impl_->effects)
    if (e->name() == name) return e.get();
  return nullptr;
}

double Simulation::max_step_displacement_seen() const { return impl_->max_disp; }
double Simulation::max_speed_seen() const { return impl_->max_speed; }
bool Simulation::failed() const { return !impl_->failure.empty(); }
const std::string& Simulation::failure() const { return impl_->failure; }
const SceneParams& Simulation::scene() const { return impl_->scene; }
const PhysicsParams& Simulation::physics() const { return impl_->physics; }
namespace {
[[noreturn]] void no_world() {
  throw ConfigError(
      "Simulation::world(): physics.integrator = \"native\" moves the cells without a Box2D world; "
      "set physics.integrator = \"box2d\" to get one");
}
}  // namespace
b2World& Simulation::world() {
  if (!impl_->world) no_world();
  return *impl_->world;
}
const b2World& Simulation::world() const {
  if (!impl_->world) no_world();
  return *impl_->world;
}

}  // namespace animat
