"""studies/regime/selection_step.py: the ranking error of a swim step, counted on known orders, and a
run's last population swum again reproduces the committed table."""

import csv
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "studies" / "regime"))
import selection_step  # noqa: E402

DATA = ROOT / "data" / "replication_regime"
TABLE = ROOT / "studies" / "regime" / "results" / "selection_step_regime.csv"


def test_discordant_pairs_count_reversed_orders_and_leave_ties_and_near_ties_out():
    ref = [10.0, 9.0, 8.95, 5.0]
    assert selection_step._discordant(ref, ref) == (0, 6)
    fit = [5.0, 8.95, 9.0, 10.0]  # every order reversed
    assert selection_step._discordant(fit, ref) == (6, 6)
    assert selection_step._discordant([10.0, 8.95, 9.0, 5.0], ref) == (1, 6)  # 9.0 and 8.95 swapped
    assert selection_step._discordant([10.0, 8.95, 9.0, 5.0], ref, apart=0.01) == (0, 5)  # the 0.6 % pair left out
    assert selection_step._discordant([1.0, 2.0], [3.0, 3.0]) == (0, 0)  # a tie at the reference: no order


def test_a_last_population_swims_to_the_committed_fitnesses():
    # a run the stall rule stopped, so growing the study does not move it; dt and dt/2 only
    run = DATA / "dn10" / "run_1"
    rows = selection_step.swim_ladder(run, top=2, substeps=(1, 2))
    with open(TABLE, newline="") as fh:
        table = [r for r in csv.DictReader(fh) if r["run"] == "dn10/run_1"]
    assert [r["id"] for r in rows] == [int(r["id"]) for r in table[:2]]
    for got, want in zip(rows, table):
        assert got["fitness_s1"] == pytest.approx(float(want["fitness_s1"]), rel=1e-5)  # the table keeps 6 digits
        assert got["fitness_s2"] == pytest.approx(float(want["fitness_s2"]), rel=1e-5)
    fits = [r["fitness_s1"] for r in rows]
    assert fits == sorted(fits, reverse=True)  # the fittest first, as the checkpoint ranks them


def test_summary_reads_the_committed_table():
    table = selection_step.summary(TABLE)
    lines = [line for line in table.splitlines() if line.startswith("| dn10 | dt/4 |")]
    assert len(lines) == 1 and "10 of 10" in lines[0]
    assert table.count("select (dt, elites by dt/16 among 4)") == 4
