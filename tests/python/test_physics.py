"""Swimming physics through the Python surface: animat.Scene, animat.Simulation,
animat.swim and animat.evaluate."""

import math

import numpy as np
import pytest

import animat

EFFECTS = ["springs", "actuation", "pressure", "drag", "collisions"]  # the default scene


def lattice(nx=8, ny=4, jitter=0.0, seed=0):
    rng = np.random.default_rng(seed)
    p = np.array([(i + (0.5 if j % 2 else 0.0), j * math.sqrt(3) / 2) for j in range(ny) for i in range(nx)])
    return p + rng.uniform(-jitter, jitter, p.shape)


def wave_body(f=4.0, a=0.2, nx=8, ny=4):
    p = lattice(nx, ny)
    n = len(p)
    phase = (2 * np.pi * p[:, 0] / 4.0) % (2 * np.pi)
    return animat.build_body(p, np.full(n, a), np.full(n, f), phase)


def viable_genomes(count, seed=5, tries=50000):
    out = []
    cfg = animat.Config()
    for i in range(tries):
        g = animat.Genome.random(animat.Rng(seed * 1_000_003 + i))
        if animat.develop(g, cfg).viable:
            out.append(g)
            if len(out) == count:
                break
    return out


# --- Scene -------------------------------------------------------------------------------------


def test_default_scene_has_every_effect_and_paper_drag():
    s = animat.Scene()
    assert list(s.effects) == EFFECTS
    assert s.drag_normal == 2.0
    assert s.drag_tangential < 0  # means d_N / 200
    assert s == animat.Scene.from_config(animat.Config())
    assert "drag_normal=2" in repr(s)


def test_scene_from_keywords_and_dict():
    s = animat.Scene(effects=["springs", "actuation", "pressure", "drag"], drag_normal=10)
    assert list(s.effects) == ["springs", "actuation", "pressure", "drag"]
    assert s.drag_normal == 10.0
    d = animat.Scene.from_dict({"drag_normal": 0.5, "effects": ["springs", "drag"]})
    assert d.drag_normal == 0.5 and list(d.effects) == ["springs", "drag"]
    assert animat.Scene.from_dict(d.to_dict()) == d
    assert d.replace(drag_normal=2.0).drag_normal == 2.0
    d.pressure = 7.5
    assert d.pressure == 7.5


def test_scene_rejects_unknown_keywords_effects_and_ranges():
    with pytest.raises(ValueError, match="drag_nromal"):
        animat.Scene(drag_nromal=2.0)
    with pytest.raises(ValueError, match="buoyancy"):
        animat.Scene(effects=["springs", "buoyancy"])
    with pytest.raises(ValueError, match="drag_normal"):
        animat.Scene(drag_normal=-1.0)
    with pytest.raises(ValueError, match="twice"):
        animat.Scene(effects=["drag", "drag"])
    with pytest.raises(AttributeError):
        animat.Scene().no_such_field


def test_config_scene_section_drives_the_simulation():
    cfg = animat.Config()
    cfg.scene.drag_normal = 10.0
    cfg.scene.effects = ["springs", "drag"]
    sim = animat.Simulation(wave_body(), config=cfg)
    assert sim.effects == ["springs", "drag"]
    assert sim.scene.drag_normal == 10.0
    # An explicit scene wins over the config's.
    sim = animat.Simulation(wave_body(), animat.Scene(), config=cfg)
    assert sim.effects == ["actuation", "springs", "pressure", "drag", "collisions"]


# --- Simulation ----------------------------------------------------------------------------------


def test_simulation_surface_shapes_and_time():
    b = wave_body()
    sim = animat.Simulation(b)
    n = len(b.positions)
    assert len(sim) == n and sim.node_count == n
    assert sim.positions.shape == (n, 2) and sim.positions.dtype == np.float64
    assert sim.velocities.shape == (n, 2)
    np.testing.assert_allclose(sim.positions, b.positions, atol=1e-6)  # float32 inside Box2D
    np.testing.assert_allclose(sim.rest_lengths_now, b.rest_lengths, rtol=1e-6)
    assert sim.time == 0.0 and sim.steps_done == 0
    sim.step(60)
    assert sim.steps_done == 60
    assert sim.time == pytest.approx(60 * animat.Config().physics.dt)
    assert sim.center_of_mass().shape == (2,)
    assert sim.rest_lengths_now.shape == b.rest_lengths.shape
    assert not np.allclose(sim.rest_lengths_now, b.rest_lengths)  # actuation changed them
    assert sim.kinetic_energy() > 0
    assert sim.compute_forces().shape == (n, 2)


def test_record_returns_frames():
    sim = animat.Simulation(wave_body())
    frames = sim.record(100, every=10)
    assert frames.shape == (11, 32, 2)
    assert sim.steps_done == 100
    np.testing.assert_array_equal(frames[-1], sim.positions)
    assert animat.Simulation(wave_body()).record(5).shape == (6, 32, 2)
    with pytest.raises(ValueError):
        sim.record(10, every=0)


def test_body_at_rest_stays_at_rest():
    p = lattice(6, 4, 0.1, 3)
    sim = animat.Simulation(animat.build_body(p))
    start = sim.positions
    sim.step(500)
    np.testing.assert_array_equal(sim.positions, start)


def test_centre_of_mass_fixed_without_drag_and_moves_with_it():
    b = wave_body(f=4.0)
    still = animat.Simulation(b, animat.Scene(effects=["springs", "actuation", "pressure", "collisions"]))
    c0 = still.center_of_mass()
    still.step(4000)
    assert np.linalg.norm(still.center_of_mass() - c0) < 1e-3  # float round-off, see test_physics.cpp
    swimmer = animat.Simulation(b)
    c0 = swimmer.center_of_mass()
    swimmer.step(4000)
    assert np.linalg.norm(swimmer.center_of_mass() - c0) > 1.0  # a swimmer at d_N = 2 moves visibly


def test_effects_off_means_absent():
    sim = animat.Simulation(wave_body(), animat.Scene(effects=["springs", "pressure"]))
    assert sim.effects == ["springs", "pressure"]
    sim.step(100)
    np.testing.assert_allclose(sim.rest_lengths_now, wave_body().rest_lengths, rtol=1e-6)


def test_explicit_drag_blows_up_where_stable_does_not():
    b = animat.build_body(np.array([[0.0, 0.0], [1.0, 0.0]]))
    for scheme, ok in [("stable", True), ("implicit", True), ("explicit", False)]:
        cfg = animat.Config()
        cfg.physics.drag_scheme = scheme
        sim = animat.Simulation(b, animat.Scene(effects=["drag"], drag_normal=50.0), config=cfg)
        sim.velocities = np.array([[0.0, 10.0], [0.0, 10.0]])
        if ok:
            sim.step(200)
            v = sim.velocities[:, 1]
            assert np.all(v > 0) and np.all(v < 10.0)
        else:
            sim.step()
            v1 = sim.velocities[0, 1]
            assert v1 < 0 or v1 > 10.0  # reversed or amplified: the explicit overshoot
            with pytest.raises(RuntimeError, match="max_step_displacement"):
                sim.step(20)
            assert sim.failed


def test_swim_flags_instability_instead_of_raising():
    r = animat.swim(wave_body(f=12.0), animat.Scene(), steps=200)
    assert r.stable and r.steps == 200 and r.distance > 0
    # Springs far too stiff for dt: the swim leaves the valid domain, and says so.
    bad = animat.swim(wave_body(f=12.0), animat.Scene(spring_stiffness=1e6), steps=200)
    assert not bad.stable and bad.distance == 0.0 and bad.steps < 200
    assert "unstable swim" in bad.failure
    with pytest.raises(RuntimeError, match="unstable swim"):
        animat.Simulation(wave_body(f=12.0), animat.Scene(spring_stiffness=1e6)).step(200)


def test_phase_delay_rule():
    for phi in [0.0, 0.5, 2.0, math.pi, 4.0, 2 * math.pi]:
        t0 = animat.actuation_start_time(6.0, phi)
        assert 0.0 <= t0 < math.pi / 6.0 + 1e-12
        if t0 > 0:
            assert animat.actuation_term(0.2, 6.0, phi, 0.5 * t0) == 0.0
        assert abs(animat.actuation_term(0.2, 6.0, phi, t0)) < 1e-12


# --- evaluate --------------------------------------------------------------------------------------


def test_evaluate_is_deterministic_and_reports_diagnostics():
    genomes = viable_genomes(2)
    assert genomes, "no viable random genome found"
    for g in genomes:
        r = animat.evaluate(g)
        assert r.viable and r.stable, r.reasons
        assert r.fitness == animat.evaluate(g, animat.Config()).fitness
        assert r.fitness == pytest.approx(np.linalg.norm(r.displacement))
        assert r.cell_count >= 3 and r.swim_steps == 4000
        assert r.spring_count > 0 and r.skin_edge_count > 0
        assert r.max_stretch > 0 and r.seconds_swim >= 0
        assert "fitness=" in repr(r)


def test_evaluate_non_viable_genome_is_not_swum():
    g = animat.Genome.random(animat.Rng(0))
    cfg = animat.Config()
    if animat.develop(g, cfg).viable:
        pytest.skip("seed 0 happens to be viable")
    r = animat.evaluate(g, cfg)
    assert not r.viable and r.fitness == 0.0 and r.swim_steps == 0 and r.reasons


def test_evaluate_steps_from_config():
    genomes = viable_genomes(1)
    cfg = animat.Config()
    cfg.evaluation.steps = 500
    r = animat.evaluate(genomes[0], cfg)
    assert r.swim_steps == 500
    assert r.simulated_time == pytest.approx(500 * cfg.physics.dt)
