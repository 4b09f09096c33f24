"""Active control (docs/control.md) through the Python surface: the extension channels,
the [control] keys, GRN-mode evaluations, objective chemotaxis and Simulation.push."""

import math

import numpy as np
import pytest

import animat


def square_body():
    return animat.build_body(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]))


def test_extension_channels_have_fixed_numbers():
    assert int(animat.InputChannel.strain) == 4
    assert int(animat.InputChannel.pressure) == 5
    assert int(animat.InputChannel.chemical) == 6
    assert int(animat.OutputChannel.stiffness) == 6
    assert int(animat.OutputChannel.actuation) == 7


def test_control_keys_default_to_the_paper_and_validate():
    cfg = animat.Config()
    assert cfg["control.mode"] == "open_loop"
    assert cfg["genome.extra_inputs"] == "" and cfg["genome.extra_outputs"] == ""
    assert cfg["scene.chemical"] == "none"
    assert cfg["evaluation.push_step"] == -1
    cfg["control.mode"] = "grn"
    with pytest.raises(ValueError, match="control.mode"):
        cfg["control.mode"] = "closed_loop"
    cfg["genome.extra_outputs"] = "actuation,wings"
    with pytest.raises(ValueError, match='genome.extra_outputs = "actuation,wings": unknown channel "wings"'):
        cfg.validate()


def test_push_changes_the_listed_velocities_by_impulse_over_mass():
    sim = animat.Simulation(square_body(), animat.Scene(effects=["springs"], cell_mass=2.0))
    sim.push([1, 3], [4.0, -2.0])
    v = sim.velocities
    np.testing.assert_allclose(v[[1, 3]], [[2.0, -1.0], [2.0, -1.0]])
    np.testing.assert_array_equal(v[[0, 2]], 0.0)
    np.testing.assert_allclose(sim.momentum(), [8.0, -4.0])
    with pytest.raises(ValueError, match="out of range"):
        sim.push([4], [1.0, 0.0])


def test_grn_mode_evaluation_updates_the_grn_and_chemotaxis_scores_progress():
    cfg = animat.Config()
    cfg["evaluation.steps"] = 200
    cfg["genome.extra_inputs"] = "chemical"
    cfg["genome.extra_outputs"] = "actuation"
    genome, _ = animat.Genome.random_viable(3, cfg)
    cfg["control.mode"] = "grn"
    cfg["scene.chemical"] = "point"
    r = animat.evaluate(genome, cfg)
    assert r.viable and r.grn_updates == math.ceil(200 / cfg["control.update_interval"])
    cfg["evaluation.objective"] = "chemotaxis"
    cfg["evaluation.source_directions"] = 2
    c = animat.evaluate(genome, cfg)
    assert c.fitness == c.source_progress
    assert math.isfinite(c.source_progress) and abs(c.source_progress) < 20.0


def test_grn_swim_records_terms_levels_sensors_and_the_centre():
    cfg = animat.Config()
    cfg["genome.extra_inputs"] = "chemical"
    cfg["genome.extra_outputs"] = "actuation"
    cfg["scene.chemical"] = "point"
    genome, _ = animat.Genome.random_viable(3, cfg)
    t = animat.grn_swim(genome, cfg, steps=100, every=10)
    n = t["terms"].shape[1]
    assert t["times"].shape == (11,) and t["actuation"].shape == (11, n) and t["sensors"].shape == (11, n, 3)
    assert t["com"].shape == (11, 2) and t["positions"].shape == (11, n, 2)
    np.testing.assert_allclose(t["positions"].mean(axis=1), t["com"], rtol=0, atol=1e-12)  # equal masses
    a = cfg["development.amplitude_max"]
    assert cfg["control.update_interval"] == 10 and cfg["physics.substeps"] == 1
    # Frame j (j >= 1) follows the update at Box2D step 10 (j - 1), time t_j - 10 h:
    # u = a_max (2 L - 1) min(1, t / start_ramp).
    h = cfg["physics.dt"]
    ramp = np.minimum(1.0, (t["times"][1:] - 10 * h) / cfg["control.start_ramp"])[:, None]
    np.testing.assert_allclose(t["terms"][1:], a * (2 * t["actuation"][1:] - 1) * ramp, rtol=0, atol=1e-15)
    assert np.all(np.abs(t["terms"]) <= a + 1e-15)
    assert np.all((t["sensors"][1:, :, 2] > 0) & (t["sensors"][1:, :, 2] <= 1))  # exp(-r/l)


def test_a_grn_control_added_in_python_drives_the_swim_as_grn_swim_does():
    cfg = animat.Config()
    cfg["genome.extra_inputs"] = "chemical,strain"
    cfg["genome.extra_outputs"] = "actuation"
    cfg["scene.chemical"] = "point"
    cfg["control.mode"] = "grn"
    genome, _ = animat.Genome.random_viable(3, cfg)
    body = animat.build_body(animat.develop(genome, cfg), config=cfg)
    scene = animat.Scene.from_config(cfg).replace(effects=[e for e in cfg["scene.effects"] if e != "actuation"])
    sim = animat.Simulation(body, scene, cfg)
    ctl = sim.add_grn_control(body, genome, cfg)
    assert ctl.cell_count == body.node_count
    reference = animat.grn_swim(genome, cfg, steps=100, every=10)
    for j in range(1, 11):
        sim.step(10)
        np.testing.assert_array_equal(ctl.terms, reference["terms"][j])
        np.testing.assert_array_equal(ctl.sensors, reference["sensors"][j])
        np.testing.assert_array_equal(ctl.actuation_levels, reference["actuation"][j])
        np.testing.assert_array_equal(sim.positions, reference["positions"][j])
    assert ctl.updates == 10
    with pytest.raises(ValueError, match="already has 'grn_control'"):
        sim.add_grn_control(body, genome, cfg)
    with_actuation = animat.Simulation(body, animat.Scene.from_config(cfg), cfg)
    with pytest.raises(ValueError, match="already has 'actuation'"):
        with_actuation.add_grn_control(body, genome, cfg)
