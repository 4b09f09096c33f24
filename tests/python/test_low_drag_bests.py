"""studies/regime/low_drag_bests.py: the drawn best is the run's final best, with the mode the committed
mode series gives it, and the figure has a row per run and four snapshots per environment."""

import csv
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "studies" / "regime"))
import low_drag_bests as ldb  # noqa: E402

DATA = ROOT / "data" / "replication_regime"
SERIES = ROOT / "studies" / "regime" / "results" / "mode_trajectory_regime.csv"


def _series_final(env: str, run: str) -> dict:
    rows = [r for r in csv.DictReader(open(SERIES)) if r["environment"] == env and r["run"] == run]
    return max(rows, key=lambda r: int(r["generation"]))


def test_the_drawn_best_is_the_final_best_with_its_committed_mode():
    with tempfile.TemporaryDirectory() as tmp:
        best = ldb.final_best("dn0.5", DATA / "dn0.5" / "run_9", Path(tmp) / "run_9")
    committed = _series_final("dn0.5", "run_9")
    assert best.generation == int(committed["best_generation"])
    assert best.mode == committed["mode"]
    assert abs(best.fitness - float(committed["fitness"])) <= 1e-5 * abs(best.fitness)

    fig = ldb.draw([best, best.__class__(**{**best.__dict__, "env": "other"})], ["dn0.5", "other"], frames=4)
    axes = fig.get_axes()
    assert len(axes) == 8  # one run, two environments, four snapshots each
    labels = [t.get_text() for ax in axes for t in ax.texts]
    assert labels == [
        f"dn0.5 run_9: gen {best.generation}, fitness {best.fitness:.1f}, {best.mode}",
        f"other run_9: gen {best.generation}, fitness {best.fitness:.1f}, {best.mode}",
    ]
    assert all(len(ax.collections) == 4 for ax in axes)  # fill, springs, skin, nodes
