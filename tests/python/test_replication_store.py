"""animat.replication_store (issue 19): packed runs unpack into run directories and pack back to the same bytes."""
import gzip
import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import animat
from animat import replication_store as R

ROOT = Path(__file__).resolve().parents[2]
# Frozen copies of two packed runs at generation 100 (data/replication itself grows across sessions).
FIXTURES = ROOT / "tests" / "data" / "replication"
PACKED = FIXTURES / "dn2_run_0"


def test_unpack_then_pack_gives_the_same_bytes(tmp_path):
    work = R.unpack_run(PACKED, tmp_path / "work" / "dn2" / "run_0")
    assert (work / "checkpoint.json").is_file() and (work / "history.csv").is_file()
    run = animat.Run(work)
    assert int(run.config["evolution.seed"]) == 1  # run 0 of the paper config (seed 1 + 0)
    assert int(run.history["generation"][-1]) == 100
    assert run.best_genomes[-1].fitness == pytest.approx(float(run.history["best"][-1]), rel=0, abs=0)
    again = R.pack_run(work, tmp_path / "packed" / "run_0")
    for name in R.PACKED_FILES:
        assert (again / name).read_bytes() == (PACKED / name).read_bytes(), name
    with pytest.raises(FileExistsError):
        R.unpack_run(PACKED, work)  # never overwrites a work directory that holds a run


def test_pack_tree_takes_stop_reasons_from_the_summary_and_derives_them_otherwise(tmp_path):
    data = tmp_path / "data"
    shutil.copytree(PACKED, data / "dn2" / "run_0")
    work = tmp_path / "work"
    assert [p.name for p in R.unpack_tree(data, work)] == ["run_0"]
    assert R.unpack_tree(data, work) == []  # already unpacked: kept
    (work / "dn2" / "summary.json").write_text(json.dumps({"runs": [{"index": 0, "stop_reason": "interrupted"}]}))
    R.pack_tree(work, data)
    assert json.loads((data / "dn2" / "run_0" / "status.json").read_text())["stop_reason"] == "interrupted"
    (work / "dn2" / "summary.json").unlink()
    (data / "dn2" / "run_0" / "status.json").write_text(json.dumps({"generation": 99, "stop_reason": "x"}))
    R.pack_tree(work, data)  # the run moved since: the reason is derived from its config and history
    status = json.loads((data / "dn2" / "run_0" / "status.json").read_text())
    assert status == {"generation": 100, "stop_reason": "generation cap evolution.generations = 100 reached"}
    assert gzip.decompress((data / "dn2" / "run_0" / "history.csv.gz").read_bytes()).startswith(b"generation,")


def _run(work: Path, env: str, i: int, bests: list, generations: int = 1000, stall: int = 500) -> None:
    """A run directory with a config and a history whose best is bests[g] at generation g."""
    run = work / env / f"run_{i}"
    run.mkdir(parents=True)
    (run / "config.toml").write_text(f"[evolution]\ngenerations = {generations}\nstall_generations = {stall}\n")
    rows = ["generation,best"] + [f"{g},{b}" for g, b in enumerate(bests)]
    (run / "history.csv").write_text("\n".join(rows) + "\n")


def test_next_round_cap_grows_the_least_advanced_open_run(tmp_path):
    work = tmp_path / "work"
    _run(work, "a", 0, [1.0 + g for g in range(301)])  # at 300, improving
    _run(work, "a", 1, [1.0 + g for g in range(151)])  # at 150: the least advanced
    _run(work, "b", 0, [5.0] * 700)                    # 699 generations without improvement: stalled
    _run(work, "b", 1, [1.0 + g for g in range(1001)])  # at the cap
    assert R.next_round_cap(work, ["a", "b"], 2, 1000, 150) == 300
    assert R.next_round_cap(work, ["a", "b"], 2, 1000, 1000) == 1000  # never past the cap
    assert R.next_round_cap(work, ["a", "b", "c"], 2, 1000, 150) == 150  # runs of "c" not started: generation 0
    assert R.next_round_cap(work, ["a", "b"], 3, 1000, 150) == 150  # nor is run 2 of each
    assert R.next_round_cap(work, ["b"], 2, 1000, 150) == -1  # stalled or at the cap: finished
    assert R.main(["next-cap", str(work), "--envs", "a", "b", "--runs", "2", "--generations", "1000", "--round", "150"]) == 0
    with pytest.raises(ValueError):
        R.next_round_cap(work, ["a"], 2, 1000, 0)


def _two_packed_runs_and_report_command(tmp_path):
    """Data with the two frozen packed runs (dn2 and dn10, 100 generations) and the report command over it."""
    data = tmp_path / "data"
    shutil.copytree(PACKED, data / "dn2" / "run_0")
    shutil.copytree(FIXTURES / "dn10_run_0", data / "dn10" / "run_0")
    doc = tmp_path / "docs" / "replication.md"
    cmd = [sys.executable, str(ROOT / "scripts" / "replication_report.py"), "--data", str(data), "--doc", str(doc),
           "--no-gif", "--no-calibration", "--target-runs", "3", "--discussion", str(tmp_path / "none.md")]
    return data, doc, cmd


def test_report_rebuilds_from_packed_data_alone(tmp_path):
    data, doc, cmd = _two_packed_runs_and_report_command(tmp_path)
    out = subprocess.run(cmd, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    text = doc.read_text()
    assert "**Scale, exactly:** 2 runs: 1 in `dn2`, 1 in `dn10` of the 3 per environment" in text
    assert "generations reached: 100 " in text
    assert "Runs not started yet: `dn2` run 1, run 2; `dn10` run 1, run 2." in text
    assert "Fisher's exact test (Freeman–Halton, r × c) over the three 32-cell environments" in text
    assert "| `dn2` | 0 | 21.665 | 21.670 | +0.02 % |" in text  # evolved and reference fitness of the best
    assert text.index("## Statistics") < text.index("## d_N = 2, 32 cells")
    assert not (data / "dn2" / "run_0" / "checkpoint.json").exists()  # the data is only read
    subprocess.run(cmd, capture_output=True, text=True, check=True)
    assert doc.read_text() == text  # deterministic


def test_report_states_the_guard_tolerances_per_environment_when_they_differ(tmp_path):
    data, doc, cmd = _two_packed_runs_and_report_command(tmp_path)
    subprocess.run(cmd, capture_output=True, text=True, check=True)
    same = ("Within the guard's tolerance (it warns where the two differ by more than both "
            "`evaluation.reference_tolerance` = 1 % and `evaluation.reference_abs_tolerance` = 0.05): 2 of 2 bests.")
    assert same in doc.read_text()
    config = data / "dn10" / "run_0" / "config.toml"
    text = config.read_text()
    assert "reference_tolerance = 0.01\n" in text
    config.write_text(text.replace("reference_tolerance = 0.01\n", "reference_tolerance = 0.02\n"))
    subprocess.run(cmd, capture_output=True, text=True, check=True)
    page = doc.read_text()
    assert same not in page
    assert ("`evaluation.reference_abs_tolerance`: `dn2` 1 % and 0.05, `dn10` 2 % and 0.05): 2 of 2 bests."
            in page)
