"""studies/regime/step_ladder.py: a packed study's best swum at finer steps, with its mode at each
step, reproduces the committed table."""

import csv
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "studies" / "regime"))
import step_ladder  # noqa: E402

DATA = ROOT / "data" / "replication_regime"
TABLE = ROOT / "studies" / "regime" / "results" / "step_ladder_replication_regime.csv"
SERIES = ROOT / "studies" / "regime" / "results" / "mode_trajectory_regime.csv"


def _row(path: Path, **match) -> dict:
    with open(path, newline="") as fh:
        rows = [r for r in csv.DictReader(fh) if all(r[k] == v for k, v in match.items())]
    assert rows, f"{path}: no row {match}"
    return rows[-1]


def test_ladder_reproduces_the_committed_row(monkeypatch):
    # a run the stall rule stopped, so growing the study does not move it; dt and dt/2 only: the
    # finer steps cost the same check many times over
    monkeypatch.setattr(step_ladder, "SUBSTEPS", (1, 2))
    fits, modes = step_ladder.ladder(DATA / "dn10" / "run_1", modes=True)
    row = _row(TABLE, run="dn10/run_1")
    assert fits == pytest.approx([float(row["fitness_s1"]), float(row["fitness_s2"])], rel=1e-8)
    assert modes == [row["mode_s1"], row["mode_s2"]]


def test_mode_at_dt_is_the_mode_the_trajectory_counts():
    # both classify a run's best at the run's own step; the trajectory's last counted generation may
    # precede the run's final best, so only the runs whose best it counts are compared
    with open(TABLE, newline="") as fh:
        table = list(csv.DictReader(fh))
    with open(SERIES, newline="") as fh:
        series = list(csv.DictReader(fh))
    assert len(table) == 40
    compared = 0
    for row in table:
        env, run = row["run"].split("/")
        last = [r for r in series if r["environment"] == env and r["run"] == run][-1]
        if int(last["best_generation"]) != step_ladder.final_best(DATA / env / run)["generation"]:
            continue
        assert row["mode_s1"] == last["mode"], row["run"]
        compared += 1
    assert compared >= 30


def test_main_writes_a_mode_column_per_step(monkeypatch, tmp_path, capsys):
    monkeypatch.setattr(step_ladder, "SUBSTEPS", (1, 2))
    run = tmp_path / "data" / "dn10" / "run_1"
    run.mkdir(parents=True)
    for name in ("config.toml", "best.tar.gz"):
        (run / name).write_bytes((DATA / "dn10" / "run_1" / name).read_bytes())
    out = tmp_path / "ladder.csv"
    assert step_ladder.main(["--data", str(tmp_path / "data"), "--out", str(out), "--modes"]) == 0
    with open(out, newline="") as fh:
        (row,) = list(csv.DictReader(fh))
    committed = _row(TABLE, run="dn10/run_1")
    assert row["run"] == "dn10/run_1"
    assert [row["mode_s1"], row["mode_s2"]] == [committed["mode_s1"], committed["mode_s2"]]
    assert float(row["error_s1"]) == pytest.approx(float(row["fitness_s1"]) / float(row["fitness_s2"]) - 1)
    printed = capsys.readouterr().out.splitlines()
    assert printed[0].endswith("| fitness at dt/32 | mode (dt ... dt/32) |")
    assert printed[2].startswith("| dn10/run_1 |") and printed[2].endswith(f"| {committed['mode_s1']} |")
