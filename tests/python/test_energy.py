"""Energy accounting from Python: evaluation.energy_accounting fills EvaluationResult.energy, the
books close on an evolved swimmer, the record pickles, and the figure draws what it says."""

import json
import pickle
from pathlib import Path

import numpy as np
import pytest

import animat

ROOT = Path(__file__).resolve().parents[2]


def evolved(name: str):
    """A committed evolved genome with the environment it evolved in."""
    data = json.loads((ROOT / "tests" / "data" / "evolved" / name).read_text())
    config = animat.Config()
    config["scene.drag_normal"] = data["drag_normal"]
    config["development.max_cells"] = data["max_cells"]
    config["development.frequency_max"] = data["frequency_max"]
    config["scene.pressure"] = data["pressure"]
    config["scene.pressure_area_floor"] = data["pressure_area_floor"]
    return animat.Genome.from_json(json.dumps(data["genome"])), config


def test_accounting_is_off_by_default_and_changes_no_result():
    genome, config = evolved("smooth_f6_dn0.5.json")
    plain = animat.evaluate(genome, config)
    assert not plain.energy.measured
    config["evaluation.energy_accounting"] = True
    booked = animat.evaluate(genome, config)
    assert booked.energy.measured
    assert booked.fitness == plain.fitness  # bit for bit
    assert booked.energy.actuation == booked.actuation_work


def test_books_close_and_the_shares_add_up():
    genome, config = evolved("smooth_f6_dn0.5.json")
    config["evaluation.energy_accounting"] = True
    e = animat.evaluate(genome, config).energy
    assert e.actuation > 0.0
    assert abs(e.residual) < 0.01 * e.actuation
    assert e.fluid == pytest.approx(e.drag_normal + e.drag_tangential, rel=1e-15)
    assert e.dissipated == pytest.approx(e.fluid + e.spring_damping + e.collisions + e.ground + e.other, rel=1e-15)
    assert 0.0 < e.fluid_share < 1.0
    d = e.as_dict()
    assert d["residual"] == e.residual and d["fluid_share"] == e.fluid_share
    assert d["actuation"] == pytest.approx(d["dissipated"] + d["stored_change"] + d["residual"], rel=1e-12)


def test_energy_pickles_with_its_result():
    genome, config = evolved("smooth_f6_dn0.5.json")
    config["evaluation.energy_accounting"] = True
    r = animat.evaluate(genome, config)
    back = pickle.loads(pickle.dumps(r))
    assert back.energy.as_dict() == r.energy.as_dict()
    assert pickle.loads(pickle.dumps(r.energy)).as_dict() == r.energy.as_dict()


def test_simulation_books_a_free_edge_in_the_fluid():
    # Two cells joined by one skin edge, moving normal to it at 1.5 through a fluid of d_N = 2: the
    # semi-implicit drag is exact for a free edge, u(t) = u0 / (1 + c u0 t), c = d_N L / (2 m).
    body = animat.build_body(np.array([[0.0, 0.0], [1.0, 0.0]]))
    sim = animat.Simulation(body, animat.Scene(effects=["drag"], drag_normal=2.0))
    sim.velocities = np.array([[0.0, 1.5], [0.0, 1.5]])
    sim.account_energy()
    sim.step(600)
    e = sim.energy
    u_end = 1.5 / (1.0 + 1.0 * 1.5 * sim.time)
    assert e.drag_normal == pytest.approx(1.5**2 - u_end**2, rel=1e-5)
    assert e.drag_tangential == 0.0


def test_energy_split_figure_names_every_sink():
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    genome, config = evolved("smooth_f6_dn0.5.json")
    config["evaluation.energy_accounting"] = True
    r = animat.evaluate(genome, config)
    fig = animat.plot.energy_split([r, r.energy], labels=["result", "account"])
    ax = fig.axes[0]
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert legend == [label for _, label, _ in animat.plot.ENERGY_SINKS]
    assert [t.get_text() for t in ax.get_yticklabels()] == ["result", "account"]
    fluid = 100.0 * r.energy.fluid / r.energy.actuation
    assert f"fluid {fluid:.0f} %" in [t.get_text() for t in ax.texts]
    with pytest.raises(ValueError, match="energy_accounting"):
        animat.plot.energy_split(animat.evaluate(genome, animat.Config()))
