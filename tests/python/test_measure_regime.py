"""studies/regime/measure_regime.py: the elastic modes of a body at rest against the analytic
two-cell spring, and an evolved best's energy books, which close at the reference step."""

import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import animat

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "studies" / "regime"))
sys.path.insert(0, str(ROOT / "studies" / "replication"))
import measure_regime as mr  # noqa: E402
from replication_store import unpack_run  # noqa: E402


def test_two_cells_on_one_spring_have_the_analytic_mode_and_damping_ratio():
    k, c, m = 100.0, 0.25, 2.0
    body = SimpleNamespace(positions=[[0.0, 0.0], [1.0, 0.0]], springs=[[0, 1]], regions=[], rest_areas=[])
    config = {
        "scene.spring_stiffness": k,
        "scene.spring_damping": c,
        "scene.pressure": 300.0,
        "scene.pressure_area_floor": 0.1,
        "scene.cell_mass": m,
    }
    w, zeta = mr.elastic_modes(body, config)
    # the rigid translations and the rotation are dropped; the stretch has the reduced mass m/2
    assert w == pytest.approx([np.sqrt(2 * k / m)], rel=1e-12)
    assert zeta == pytest.approx([c / (m * w[0])], rel=1e-12)


@pytest.fixture(scope="module")
def best(tmp_path_factory):
    work = tmp_path_factory.mktemp("run") / "run_1"
    unpack_run(ROOT / "data" / "replication_regime" / "dn10" / "run_1", work)
    run = animat.Run(work)
    return run.best().genome, run.config


def test_an_evolved_best_books_close_at_the_reference_step(best):
    genome, config = best
    at_dt = mr.measure(genome, config.copy())
    at_reference = mr.measure(genome, animat.reference_config(config))
    for row in (at_dt, at_reference):
        # in the fluid world the fluid, the dampers and the collisions take all that is dissipated
        assert row["fluid_share"] + row["damping_share"] + row["collision_share"] == pytest.approx(1, abs=1e-9)
        assert row["fluid_share"] == pytest.approx(row["drag_normal_share"] + row["drag_tangential_share"])
    # the residual is the integration error: it shrinks with the step, and at dt/16 it is under 0.1 %
    assert abs(at_reference["residual_share"]) < 1e-3
    assert abs(at_reference["residual_share"]) < abs(at_dt["residual_share"])
