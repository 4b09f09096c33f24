"""studies/regime/mode_trajectory.py: which best a run counts at each generation, and the table of
modes with Fisher's test."""

import json
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "studies" / "regime"))
import mode_trajectory as mt  # noqa: E402

STALLED = ROOT / "data" / "replication_regime" / "dn2" / "run_0"


def test_the_best_at_a_generation_is_the_last_found_by_then():
    lineage = [SimpleNamespace(generation=g) for g in (0, 5, 40)]
    assert mt.best_at(lineage, 0).generation == 0
    assert mt.best_at(lineage, 39).generation == 5
    assert mt.best_at(lineage, 1000).generation == 40
    assert mt.best_at(lineage[1:], 4) is None


def test_a_stalled_run_counts_its_final_best_after_it_stopped_and_a_growing_run_does_not(tmp_path):
    status = json.loads((STALLED / "status.json").read_text())
    assert "no improvement" in status["stop_reason"]
    last = status["generation"]
    rows = mt.run_rows("dn2", STALLED, tmp_path / "stalled", [last, 10**6])
    assert [r["generation"] for r in rows] == [last, 10**6]
    # the stall rule stopped it 500 generations after its last improvement: the same best at both
    assert rows[0]["best_generation"] == rows[1]["best_generation"] == last - 500
    assert rows[0]["mode"] == rows[1]["mode"] in mt.MODES
    growing = STALLED.parent / "run_1"
    assert "no improvement" not in json.loads((growing / "status.json").read_text())["stop_reason"]
    assert mt.run_rows("dn2", growing, tmp_path / "growing", [10**6]) == []


def test_the_table_counts_each_mode_and_tests_mode_against_drag():
    rows = [{"environment": "dn10", "generation": 150, "mode": "undulation"} for _ in range(3)]
    rows += [{"environment": "dn0.5", "generation": 150, "mode": "synchronous contraction"} for _ in range(3)]
    rows += [{"environment": "dn0.2_64cells", "generation": 150, "mode": "tail"}]
    header, _, line = mt.summary_lines(rows)
    # environments by drag, the 64-cell one last and not in the test
    assert header.index("dn0.5") < header.index("dn10") < header.index("dn0.2_64cells")
    cells = [c.strip() for c in line.strip("|").split("|")]
    assert cells[:4] == ["150", "0 / 3 / 0 / 0 (3)", "3 / 0 / 0 / 0 (3)", "0 / 0 / 0 / 1 (1)"]
    # 3 against 3, fully separated: the observed table and its mirror, 2 of the C(6, 3) = 20 tables
    assert float(cells[4]) == pytest.approx(0.1)
