"""studies/regime/invalid_swims.py: which generations a pass replays, and that the committed table
covers every invalid swim of the runs and generations its command names."""

import csv
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "studies" / "regime"))
import invalid_swims as iv  # noqa: E402

DATA = ROOT / "data" / "replication_regime"
TABLE = ROOT / "studies" / "regime" / "results" / "invalid_swims.csv"
#: the pass docs/regime.md's command makes: the 32-cell environments, generations 0-449
ENVS, THROUGH = ("dn0.5", "dn2", "dn10"), 449


def test_invalid_generations_stop_at_through():
    rows = [["generation", "best", "invalid"], ["0", "1.0", "0"], ["25", "2.0", "1"], ["512", "3.0", "2"]]
    assert iv.invalid_generations(rows) == {25, 512}
    assert iv.invalid_generations(rows, through=511) == {25}
    assert iv.invalid_generations(rows, through=25) == {25}
    assert iv.invalid_generations(rows, through=24) == set()


def test_the_committed_table_holds_every_invalid_swim_of_its_pass():
    expected = []
    for env in ENVS:
        for run in sorted((DATA / env).glob("run_*")):
            history = iv.stored_history(run)
            col, found = history[0].index("invalid"), iv.invalid_generations(history, THROUGH)
            counts = [int(r[col]) for r in history[1:] if int(r[0]) in found]
            assert set(counts) <= {1}, f"{run}: a generation with two invalid swims needs two rows"
            expected += [(env, run.name, g) for g in found]
    table = sorted((r["env"], r["run"], int(r["generation"])) for r in csv.DictReader(open(TABLE)))
    assert table == sorted(expected)
    assert len(table) == 8
