"""studies/regime/stroke_modes.py: the stroke path's label of stored evolved bests is a valid label, the
same on every call, and the one the committed results/stroke_modes.csv records."""

import csv
import sys
from pathlib import Path

import pytest

from animat import locomotion as L

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "studies" / "regime"))
import stroke_modes  # noqa: E402

#: Two replication bests at d_N = 0.5 that the stroke path labels with protrusions (alone, and mixed into
#: undulation): the labels the stroke path adds to the default classifier's.
RUNS = ("dn0.5/run_2", "dn0.5/run_3")


def _recorded() -> dict:
    path = stroke_modes.OUT_CSV
    if not path.is_file():
        return {}
    with open(path) as fh:
        return {(r["source"], r["run"]): r for r in csv.DictReader(fh)}


@pytest.mark.parametrize("run", RUNS)
def test_stroke_label_of_a_stored_best_is_valid_and_stable(run):
    best = stroke_modes.replication_best(stroke_modes.REPLICATION / run)
    assert best.environment == "dn0.5" and best.growth == "paper" and best.fitness > 0
    row = stroke_modes.classify_best(best)
    for key in ("default_label", "stroke_label"):
        modes = row[key].split(" + ")
        assert all(m in L.MODES for m in modes) and len(set(modes)) == len(modes), row[key]
    assert stroke_modes.main_mode(row["stroke_label"]) == row["stroke_mode"]
    assert stroke_modes.has_mode(row["stroke_label"], "protrusions")
    assert row["strokes"] == 1 and row["pair_score"] >= 0.4 and row["pair_area"] >= 0.1
    again = stroke_modes.classify_best(stroke_modes.replication_best(stroke_modes.REPLICATION / run))
    assert (again["default_label"], again["stroke_label"], again["pair_score"]) == (
        row["default_label"],
        row["stroke_label"],
        row["pair_score"],
    )
    recorded = _recorded().get(("replication", run))
    if recorded is not None:
        assert (recorded["default_label"], recorded["stroke_label"]) == (row["default_label"], row["stroke_label"])


def test_mixed_labels_count_under_their_main_mode():
    assert stroke_modes.main_mode("undulation + protrusions") == "undulation"
    assert stroke_modes.has_mode("undulation + protrusions", "protrusions")
    assert not stroke_modes.has_mode("synchronous contraction", "protrusions")
