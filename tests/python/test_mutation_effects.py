"""studies/regime/mutation_effects.py: a mutant is sorted by what development makes of it, the shape
distance ignores cell order and position, and one best's neighbourhood accounts for every mutant."""

import math
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import animat

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "studies" / "regime"))
import mutation_effects as me  # noqa: E402

CONFIG = animat.load_config(str(ROOT / "configs" / "regime_dn0.5.toml"))
RADIUS = CONFIG["development.cell_radius"]


def embryo(positions, amplitude, frequency, phase, viable=True):
    return SimpleNamespace(
        positions=np.asarray(positions, dtype=float),
        amplitude=np.asarray(amplitude, dtype=float),
        frequency=np.asarray(frequency, dtype=float),
        phase=np.asarray(phase, dtype=float),
        viable=viable,
    )


PARENT = embryo([[0, 0], [2, 0], [1, 1.7]], [0.1, 0.2, 0.3], [6, 6, 6], [0.0, 1.0, 6.2])


def test_the_same_embryo_is_silent_and_a_nonviable_one_is_nonviable():
    assert me.classify(PARENT, PARENT, CONFIG) == ("silent", 0.0, 0.0)
    assert me.classify(PARENT, None, CONFIG)[0] == "nonviable"
    assert me.classify(PARENT, embryo(PARENT.positions, *controls_of(PARENT), viable=False), CONFIG)[0] == "nonviable"


def controls_of(e):
    return e.amplitude, e.frequency, e.phase


def test_a_changed_controller_on_the_same_body_counts_its_cells_and_step():
    # one cell's phase moves by a tenth of a turn, across the wrap at 2 pi
    phase = PARENT.phase.copy()
    phase[2] = (phase[2] + 0.1 * math.tau) % math.tau
    kind, cells, rms = me.classify(PARENT, embryo(PARENT.positions, PARENT.amplitude, PARENT.frequency, phase), CONFIG)
    assert kind == "controller"
    assert cells == pytest.approx(1 / 3)
    assert rms == pytest.approx(0.1 / math.sqrt(9))  # one of 3 cells x 3 controls moved by 0.1 turn


def test_the_shape_distance_ignores_cell_order_and_translation():
    p = PARENT.positions
    moved = p[::-1] + np.array([5.0, -3.0])
    assert me.shape_distance(p, moved) == pytest.approx(0.0, abs=1e-12)
    one_out = p.copy()
    one_out[0] += [0.0, -0.3]  # the centroid moves by 0.1 as well
    assert 0.0 < me.shape_distance(p, one_out) < 0.3


def test_a_moved_or_added_cell_is_another_body():
    moved = PARENT.positions.copy()
    moved[1, 0] += 1e-6
    kind, other, shift = me.classify(PARENT, embryo(moved, *controls_of(PARENT)), CONFIG)
    assert (kind, other) == ("body", 0.0)
    assert shift == pytest.approx(me.shape_distance(PARENT.positions, moved) / RADIUS)
    grown = np.vstack([PARENT.positions, [[3, 1.7]]])
    kind, other, _ = me.classify(PARENT, embryo(grown, [0.1] * 4, [6] * 4, [0] * 4), CONFIG)
    assert (kind, other) == ("body", 1.0)


def test_one_best_neighbourhood_accounts_for_every_mutant():
    run = ROOT / "data" / "replication_regime" / "dn0.5" / "run_0"
    rows = me.neighbourhood((run, 424, 6, 1, []))
    assert [r["class"] for r in rows] == list(me.CLASSES)
    assert sum(r["count"] for r in rows if r["class"] in me.GA_CLASSES) == 6
    assert all(r["count"] == 6 for r in rows if r["class"].startswith("random_"))
    assert len({r["parent_distance"] for r in rows}) == 1 and rows[0]["generation"] <= 424
    for r in rows:
        assert 0 <= r["improve"] <= r["count"]


def test_the_jitter_stream_table_is_read_from_the_packed_runs():
    import csv

    import jitter_stream as js

    with open(ROOT / "studies" / "regime" / "results" / "jitter_stream.csv") as fh:
        rows = {
            (r["stream"], int(r["protection_generations"]), r["environment"], r["run"]): r for r in csv.DictReader(fh)
        }
    assert len(rows) == (len(js.STREAMS) * len(js.ENVS) + len(js.PROTECTED_ENVS)) * js.RUNS
    got = js.row_of(js.DATA["fixed"] / "dn0.5" / "run_0")
    want = rows[("fixed", 0, "dn0.5", "run_0")]
    assert got["generation"] == int(want["generation"]) == js.CAP
    assert got["last_rise"] == int(want["last_rise"])
    for g in js.CHECKPOINTS:
        assert got[f"best_reference_{g}"] == pytest.approx(float(want[f"best_reference_{g}"]), rel=1e-5)
    assert got["mode"] == want["mode"]
    # the genome's stream is read from the regime replication, cut at the same generation
    assert js.row_of(js.DATA["genome"] / "dn10" / "run_3")["generation"] == js.CAP
    protected = js.row_of(js.PROTECTED / "dn0.5" / "run_1")
    assert protected["protection_generations"] == js.PROTECTION
    assert protected["mode"] == rows[("fixed", js.PROTECTION, "dn0.5", "run_1")]["mode"]
