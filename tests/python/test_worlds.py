"""The crawl world and the cost of actuation (docs/worlds.md) through the Python surface."""

import math
from pathlib import Path

import numpy as np
import pytest

import animat

CRAWL = Path(__file__).resolve().parents[2] / "configs" / "crawl.toml"


def wave_body(f=4.0, a=0.15, nx=5, ny=3):
    p = np.array([(i + (0.5 if j % 2 else 0.0), j * math.sqrt(3) / 2) for j in range(ny) for i in range(nx)])
    n = len(p)
    phase = (2 * np.pi * p[:, 0] / 4.0) % (2 * np.pi)
    return animat.build_body(p, np.full(n, a), np.full(n, f), phase)


def viable_genome(seed=5, tries=50000):
    cfg = animat.Config()
    for i in range(tries):
        g = animat.Genome.random(animat.Rng(seed * 1_000_003 + i))
        if animat.develop(g, cfg).viable:
            return g
    pytest.skip("no viable random genome found")


def test_crawl_preset_swims_on_the_floor_and_reports_work():
    cfg = animat.load_config(CRAWL)
    assert "gravity" in cfg.scene.effects and "ground" in cfg.scene.effects and "drag" not in cfg.scene.effects
    assert cfg.evaluation.settle_steps == 300 and cfg.evaluation.objective == "distance_x"
    body = wave_body()
    r = animat.swim(body, config=cfg, steps=600)
    assert r.valid, r.failure
    assert r.settle_steps == 300
    assert r.ground_contacts > 0 and 0 <= r.ground_slips <= r.ground_contacts
    assert r.actuation_work_positive > 0 and r.actuation_work_absolute >= r.actuation_work_positive
    assert r.cell_work_positive.shape == (body.positions.shape[0],)
    assert r.cell_work_positive.sum() == pytest.approx(r.actuation_work_positive, rel=1e-9)
    assert r.cell_work_absolute.sum() == pytest.approx(r.actuation_work_absolute, rel=1e-9)
    # settle_steps can be overridden per call
    assert animat.swim(body, config=cfg, steps=10, settle_steps=0).settle_steps == 0


def test_simulation_counters_include_floor_and_work():
    cfg = animat.load_config(CRAWL)
    body = wave_body()
    sim = animat.Simulation(body, config=cfg)
    sim.step(200)
    c = sim.counters
    for key in (
        "ground_contacts",
        "ground_slips",
        "airborne_steps",
        "actuation_work",
        "actuation_work_positive",
        "actuation_work_absolute",
    ):
        assert key in c
    assert c["actuation_work_absolute"] > 0


def test_bad_friction_is_a_clear_error():
    cfg = animat.load_config(CRAWL)
    with pytest.raises(ValueError, match="ground_friction_kinetic"):
        cfg.scene.ground_friction_kinetic = 2.0
        animat.Simulation(wave_body(), config=cfg)
    with pytest.raises(ValueError, match="gravity"):
        animat.Scene(gravity=-1.0)


def test_energy_objectives_from_the_same_swim():
    g = viable_genome()
    cfg = animat.Config()
    cfg.evaluation.steps = 400
    base = animat.evaluate(g, cfg)
    assert base.viable and base.valid, base.reasons
    assert base.actuation_work_positive > 0
    cfg.evaluation.objective = "distance_minus_energy"
    cfg.evaluation.energy_weight = 0.01
    r = animat.evaluate(g, cfg)
    assert r.fitness == pytest.approx(base.fitness - 0.01 * base.actuation_work_positive, rel=1e-12, abs=1e-12)
    cfg.evaluation.objective = "distance_per_energy"
    cfg.evaluation.energy_offset = 2.0
    r = animat.evaluate(g, cfg)
    assert r.fitness == pytest.approx(base.fitness / (base.actuation_work_positive + 2.0), rel=1e-12)
    cfg.evaluation.objective = "distance_x"
    r = animat.evaluate(g, cfg)
    assert r.fitness == pytest.approx(abs(base.displacement[0]), rel=1e-12)


@pytest.mark.parametrize("contact", ["impulse", "compliant"])
def test_replay_starts_where_evaluate_starts_in_the_crawl_world(contact):
    g = viable_genome()
    cfg = animat.load_config(CRAWL)
    cfg.scene.ground_contact = contact
    cfg.evaluation.steps = 300
    r = animat.evaluate(g, cfg)
    assert r.viable and r.valid, r.reasons
    traj = animat.replay(g, cfg, every=10)  # repeat 0 of the preset's repeats: the diagnostics' swim
    pos = np.asarray(traj.positions)
    # on the floor, settled: the impulse floor holds every centre on it; the compliant floor's springs
    # carry the body's weight, so no cell sinks deeper than all of it on one spring, N·m·g/k_g
    sink = 1e-6 if contact == "impulse" else r.cell_count * cfg.scene.gravity / cfg.scene.ground_stiffness
    assert pos[0, :, 1].min() >= -sink
    np.testing.assert_allclose(pos[-1].mean(axis=0) - pos[0].mean(axis=0), r.displacement, rtol=0, atol=1e-9)
    body, v, settled = animat._core.start_state(animat.build_body(animat.develop(g, cfg)), config=cfg)
    assert settled == 300 and np.asarray(v).shape == (body.positions.shape[0], 2)
