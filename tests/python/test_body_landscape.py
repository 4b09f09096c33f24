"""studies/regime/body_landscape.py: a spring of the Gabriel graph flips under a vanishing move, a
best's development moves its body in proportion to the jitter's change, and the mutants' table
counts every mutant once."""

import csv
import sys
from pathlib import Path

import numpy as np
import pytest

import animat

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "studies" / "regime"))
import body_landscape as bl  # noqa: E402

CONFIG = animat.load_config(str(ROOT / "configs" / "regime_dn0.5.toml"))
CONTROLS = np.tile([0.1, 3.0, 0.0], (4, 1))


def test_a_square_gains_a_diagonal_when_one_corner_moves_in_by_a_millionth():
    # The closed diametral disc of either diagonal holds the other two corners: no diagonal. Moving
    # (1, 1) inward by 1e-6 leaves (1, 0) and (0, 1) outside the disc of the shorter diagonal.
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    before = bl.springs(square, CONTROLS, CONFIG)
    assert before == {(0, 1), (1, 2), (2, 3), (0, 3)}
    moved = square.copy()
    moved[2] -= 1e-6
    after = bl.springs(moved, CONTROLS, CONFIG)
    assert after == before | {(0, 2)}
    assert bl.springs_changed(before, after) == 1


def test_the_other_graph_rules_are_computed_on_request():
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    # the distance graph drops a grid square's cocircular diagonal too (docs/model.md, G2)
    assert bl.springs(square, CONTROLS, CONFIG, "distance") == {(0, 1), (1, 2), (2, 3), (0, 3)}


@pytest.fixture(scope="module")
def ladder():
    # re-tuning to the frequency the best has: the re-tuned change is the change itself
    tries, bl.RETUNE = bl.RETUNE, np.array([1.0])
    try:
        return bl.ladder((ROOT / "data" / "replication_regime" / "dn10" / "run_1", 424))
    finally:
        bl.RETUNE = tries


def test_a_best_is_moved_in_proportion_to_its_jitter_change(ladder):
    assert [r["eps"] for r in ladder] == list(bl.EPS)
    assert all(r["viable"] and r["same_cell_count"] for r in ladder)
    shape = np.array([r["shape_distance"] for r in ladder])
    assert np.all(np.diff(shape) > 0)
    # smooth for small changes: the shape distance per unit of eps is the same within a factor 3
    small = shape[:4] / np.array(bl.EPS[:4])
    assert small.max() < 3 * small.min()
    first = ladder[0]
    assert first["springs_changed"] == 0
    assert abs(first["change"]) < 1e-3
    for r in ladder:
        if r["eps"] >= bl.RETUNE_FROM:
            assert r["change_retuned"] == r["change"]
        else:
            assert np.isnan(r["change_retuned"])


def test_the_mutants_table_counts_every_mutant_once(tmp_path):
    path = tmp_path / "m.csv"
    keys = ["environment", "jitter_stream", "run", "springs", "count", "improve"]
    keys += ["shape_distance_median", "change_median"]
    rows = [
        ["dn0.5", "fixed", "run_0", "same", 2, 1, 0.01, 0.1],
        ["dn0.5", "fixed", "run_0", "other", 5, 0, 0.7, -0.9],
        ["dn0.5", "fixed", "run_1", "same", 0, 0, "nan", "nan"],
        ["dn0.5", "fixed", "run_1", "other", 3, 0, 0.9, -0.5],
    ]
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(keys)
        w.writerows(rows)
    table = bl.mutants_summary(path).splitlines()
    assert table[2] == "| dn0.5 | fixed | 2 | 10 | the same | 2 | 0.01 | 1 of 2 | +10.0 % |"
    assert table[3] == "| dn0.5 | fixed | 2 | 10 | other | 8 | 0.80 | 0 of 8 | -70.0 % |"


def test_a_square_s_diagonal_sits_on_the_gabriel_threshold_and_its_sides_45_degrees_from_it():
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    margins = dict(zip(map(tuple, animat.delaunay_edges(square)), bl.gabriel_margins(square)))
    assert margins.pop((1, 3)) == pytest.approx(0.0, abs=1e-9)
    assert list(margins.values()) == pytest.approx([45.0] * 4)
    # an equilateral triangle's edges are seen at 60 degrees by the third corner
    triangle = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, np.sqrt(3) / 2]])
    assert bl.gabriel_margins(triangle) == pytest.approx([30.0] * 3)
