"""replication_store (studies/replication): packed runs unpack into run directories and pack back to the
same bytes; pack refuses runs that would not restore or are behind, unpack verifies every checksum and size."""

import gzip
import hashlib
import json
import resource
import shutil
import signal
import subprocess
import sys
import tracemalloc
from pathlib import Path

import pytest

import animat

import replication_store as R  # studies/replication (conftest.py)

ROOT = Path(__file__).resolve().parents[2]
STUDY = ROOT / "studies" / "replication"
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
    manifest = (again / R.MANIFEST).read_bytes()
    assert json.loads(manifest)["unpacked"]["checkpoint.json"] == {
        "sha256": hashlib.sha256((work / "checkpoint.json").read_bytes()).hexdigest(),
        "size": (work / "checkpoint.json").stat().st_size,
    }
    R.pack_run(work, again)
    assert (again / R.MANIFEST).read_bytes() == manifest  # the manifest is deterministic too
    with pytest.raises(FileExistsError):
        R.unpack_run(PACKED, work)  # never overwrites a work directory that holds a run


def test_pack_tree_takes_stop_reasons_from_a_current_summary_and_derives_them_otherwise(tmp_path):
    data = tmp_path / "data"
    shutil.copytree(PACKED, data / "dn2" / "run_0")
    work = tmp_path / "work"
    assert [p.name for p in R.unpack_tree(data, work)] == ["run_0"]
    assert R.unpack_tree(data, work) == []  # already unpacked: kept
    summary = {"runs": [{"index": 0, "generations": 100, "stop_reason": "interrupted"}]}
    (work / "dn2" / "summary.json").write_text(json.dumps(summary))
    R.pack_tree(work, data)
    assert json.loads((data / "dn2" / "run_0" / "status.json").read_text())["stop_reason"] == "interrupted"
    # A summary of an earlier session (one stopped before writing its own keeps it) is not this run's reason.
    summary["runs"][0].update(generations=90, stop_reason="generation cap evolution.generations = 90 reached")
    (work / "dn2" / "summary.json").write_text(json.dumps(summary))
    (data / "dn2" / "run_0" / "status.json").write_text(json.dumps({"generation": 99, "stop_reason": "x"}))
    R.pack_tree(work, data)
    status = json.loads((data / "dn2" / "run_0" / "status.json").read_text())
    assert status == {"generation": 100, "stop_reason": "generation cap evolution.generations = 100 reached"}
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
    _run(work, "b", 0, [5.0] * 700)  # 699 generations without improvement: stalled
    _run(work, "b", 1, [1.0 + g for g in range(1001)])  # at the cap
    assert R.next_round_cap(work, ["a", "b"], 2, 1000, 150) == 300
    assert R.next_round_cap(work, ["a", "b"], 2, 1000, 1000) == 1000  # never past the cap
    assert R.next_round_cap(work, ["a", "b", "c"], 2, 1000, 150) == 150  # runs of "c" not started: generation 0
    assert R.next_round_cap(work, ["a", "b"], 3, 1000, 150) == 150  # nor is run 2 of each
    assert R.next_round_cap(work, ["b"], 2, 1000, 150) == -1  # stalled or at the cap: finished
    assert (
        R.main(["next-cap", str(work), "--envs", "a", "b", "--runs", "2", "--generations", "1000", "--round", "150"])
        == 0
    )
    with pytest.raises(ValueError):
        R.next_round_cap(work, ["a"], 2, 1000, 0)


def test_status_says_how_far_each_environment_has_grown(tmp_path, capsys):
    data = tmp_path / "data"
    for i in range(3):
        shutil.copytree(PACKED, data / "dn2" / f"run_{i}")
    shutil.copytree(FIXTURES / "dn10_run_0", data / "dn10" / "run_0")
    (data / "dn2" / "run_1" / "status.json").write_text(
        json.dumps(
            {"generation": 57, "stop_reason": "no improvement for evolution.stall_generations = 500 generations"}
        )
    )
    (data / "dn2" / "run_2" / "status.json").write_text(json.dumps({"generation": 80, "stop_reason": "interrupted"}))
    assert R.growth(data)["dn2"][1] == ("run_1", 57, "no improvement for evolution.stall_generations = 500 generations")
    assert R.main(["status", str(data)]) == 0
    assert capsys.readouterr().out.splitlines() == [
        "dn10: 1 run; 1 at generation 100",
        "dn2: 3 runs; 2 at generation 80-100; 1 stopped by the stall rule: run_1 at 57",
    ]
    assert R.main(["status", str(tmp_path / "missing")]) == 1


def _timed_run(data: Path, env: str, i: int, seconds: list, stop_reason: str = "interrupted") -> None:
    """A packed run (as far as pace reads one) whose generation g took seconds[g - 1] of wall time."""
    run = data / env / f"run_{i}"
    run.mkdir(parents=True)
    (run / "config.toml").write_text("")
    (run / "checkpoint.json.gz").write_bytes(gzip.compress(b"{}"))
    wall = [0.0]
    for s in seconds:
        wall.append(wall[-1] + s)
    rows = ["generation,best,wall_seconds"] + [f"{g},1,{w}" for g, w in enumerate(wall)]
    (run / "history.csv.gz").write_bytes(gzip.compress(("\n".join(rows) + "\n").encode()))
    (run / "status.json").write_text(json.dumps({"generation": len(seconds), "stop_reason": stop_reason}))


def test_pace_prices_the_generations_left_at_each_runs_median_generation(tmp_path, capsys):
    data = tmp_path / "data"
    # Run 0: 2 s a generation, one generation slowed to 500 s by other work (the median ignores it).
    _timed_run(data, "a", 0, [2.0] * 5 + [500.0] + [2.0] * 4)
    _timed_run(data, "a", 1, [4.0] * 10)
    _timed_run(data, "b", 0, [7.0] * 8, stop_reason="no improvement for evolution.stall_generations = 500 generations")
    _timed_run(data, "b", 1, [1.0] * 8 + [3.0] * 2)
    lines = R.pace(data, last=4, target=1810)
    assert lines == [
        # (1810 - 10) generations at 2 s and at 4 s: 10,800 s
        "a: 2 runs, median 3.0 s a generation (runs 2.0-4.0) over the 4 generations up to 10; "
        "3600 generations left to 1810: 3.0 core-hours",
        # the stalled run has nothing left; run 1's last 4 generations: 1, 1, 3, 3 s, median 2
        "b: 2 runs, median 4.5 s a generation (runs 2.0-7.0) over the 4 generations up to 8-10; "
        "1800 generations left to 1810: 1.0 core-hours",
        "all: 4.0 core-hours to generation 1810",
    ]
    # The window can end earlier: run b/1 up to generation 8 took 1 s a generation.
    assert R.pace(data, last=4, until=8, target=1000)[1].startswith(
        "b: 2 runs, median 4.0 s a generation (runs 1.0-7.0)"
    )
    assert R.main(["pace", str(data), "--last", "4", "--target", "3610"]) == 0
    assert capsys.readouterr().out.splitlines()[-1] == "all: 8.0 core-hours to generation 3610"
    assert R.main(["pace", str(tmp_path / "missing")]) == 1
    assert R.main(["pace", str(data), "--until", "0"]) == 1
    assert "fewer than two generations up to 0" in capsys.readouterr().err


def _two_packed_runs_and_report_command(tmp_path):
    """Data with the two frozen packed runs (dn2 and dn10, 100 generations) and the report command over it."""
    data = tmp_path / "data"
    shutil.copytree(PACKED, data / "dn2" / "run_0")
    shutil.copytree(FIXTURES / "dn10_run_0", data / "dn10" / "run_0")
    doc = tmp_path / "docs" / "replication.md"
    cmd = [
        sys.executable,
        str(STUDY / "replication_report.py"),
        "--data",
        str(data),
        "--doc",
        str(doc),
        "--no-gif",
        "--no-calibration",
        "--target-runs",
        "3",
        "--discussion",
        str(tmp_path / "none.md"),
    ]
    return data, doc, cmd


def test_report_rebuilds_from_packed_data_alone(tmp_path):
    data, doc, cmd = _two_packed_runs_and_report_command(tmp_path)
    out = subprocess.run(cmd, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    text = doc.read_text()
    assert "**Scale, exactly:** 2 runs: 1 in `dn2`, 1 in `dn10` of the 3 per environment" in text
    assert "generations reached: 100 " in text
    assert "Runs not started yet: `dn2` run 1, run 2; `dn10` run 1, run 2." in text
    assert (
        "Fisher's exact test (Freeman–Halton, r × c) over the two 32-cell environments (d_N = 2, 10: does the mode"
        in text
    )
    assert "| `dn2` | 0 | 21.665 | 21.670 | +0.02 % |" in text  # evolved and reference fitness of the best
    # the last new best and the new bests of the last 100 generations (all 100 here)
    assert "| `dn2` | 43 | 8 | 1 of 1 | 100 |" in text
    assert "| `dn10` | 95 | 13 | 1 of 1 | 100 |" in text
    assert "the stall rule stops a run 500 generations after its last" in text
    assert text.index("## Statistics") < text.index("## d_N = 2, 32 cells")
    assert not (data / "dn2" / "run_0" / "checkpoint.json").exists()  # the data is only read
    subprocess.run(cmd, capture_output=True, text=True, check=True)
    assert doc.read_text() == text  # deterministic


def test_new_bests_are_the_generations_that_beat_every_earlier_one():
    import numpy as np
    import replication_report as RR  # studies/replication (conftest.py)

    # by best, the column the stall rule counts: equal is not new, a drop is not, the reference is not read
    rows = [(0, 1.0, 1.5), (1, 2.0, 1.4), (2, 2.0, 1.6), (3, 3.0, 1.6), (4, 2.5, 1.7), (5, 3.5, 1.2)]
    h = np.array(rows, dtype=[("generation", int), ("best", float), ("best_reference", float)])
    assert RR.new_best_generations(h) == [1, 3, 5]
    assert RR.new_best_generations(h[["generation", "best"]]) == [1, 3, 5]
    assert RR.new_best_generations(h[:1]) == []
    assert RR.new_best_generations(h[:0]) == []


def test_report_states_the_guard_tolerances_per_environment_when_they_differ(tmp_path):
    data, doc, cmd = _two_packed_runs_and_report_command(tmp_path)
    subprocess.run(cmd, capture_output=True, text=True, check=True)
    same = (
        "Within the guard's tolerance (it warns where the two differ by more than both "
        "`evaluation.reference_tolerance` = 1 % and `evaluation.reference_abs_tolerance` = 0.05): 2 of 2 bests."
    )
    assert same in doc.read_text()
    config = data / "dn10" / "run_0" / "config.toml"
    text = config.read_text()
    assert "reference_tolerance = 0.01\n" in text
    config.write_text(text.replace("reference_tolerance = 0.01\n", "reference_tolerance = 0.02\n"))
    subprocess.run(cmd, capture_output=True, text=True, check=True)
    page = doc.read_text()
    assert same not in page
    assert "`evaluation.reference_abs_tolerance`: `dn2` 1 % and 0.05, `dn10` 2 % and 0.05): 2 of 2 bests." in page


def _tree(root: Path) -> dict:
    """Every file under root with its bytes."""
    return {str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def _fnv1a(data: bytes) -> str:
    h = 0xCBF29CE484222325
    for c in data:
        h = ((h ^ c) * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return f"{h:016x}"


def _checkpoint_at(text: bytes, generation: int) -> bytes:
    """The checkpoint ``text`` with its history cut (or extended by copies of its last row) to end at
    ``generation``, with a valid checksum."""
    payload = json.loads(json.loads(text)["payload"])
    hist = [h for h in payload["history"] if h["generation"] <= generation]
    while hist[-1]["generation"] < generation:
        hist.append(dict(hist[-1], generation=hist[-1]["generation"] + 1))
    payload.update(history=hist, generation=generation)
    body = json.dumps(payload, separators=(",", ":"), sort_keys=True)
    return json.dumps({"checksum": _fnv1a(body.encode()), "payload": body}, separators=(",", ":")).encode()


def _packed_with_manifest(tmp_path: Path):
    """data/dn2/run_0: the frozen dn2 run packed by today's pack (with its manifest)."""
    work = R.unpack_run(PACKED, tmp_path / "scratch" / "dn2" / "run_0")
    data = tmp_path / "data"
    R.pack_run(work, data / "dn2" / "run_0")
    shutil.rmtree(tmp_path / "scratch")
    return data, data / "dn2" / "run_0"


def _cut(path: Path, keep: int) -> None:
    path.write_bytes(path.read_bytes()[:keep])


def _edit_payload(ckpt: Path) -> None:
    """Valid JSON whose checksum no longer matches: one number of the payload changed."""
    outer = json.loads(ckpt.read_text())
    outer["payload"] = outer["payload"].replace('"evaluations":', '"evaluations":1', 1)
    ckpt.write_text(json.dumps(outer))


DAMAGES = {  # what is damaged, and the file and the words the refusal names
    "truncated checkpoint": (
        lambda run: _cut(run / "checkpoint.json", (run / "checkpoint.json").stat().st_size // 2),
        "checkpoint.json: not valid JSON",
    ),
    "edited checkpoint": (lambda run: _edit_payload(run / "checkpoint.json"), "checkpoint.json: checksum"),
    "best file not JSON": (
        lambda run: _cut(run / "best" / "gen_000000.json", 100),
        "best/gen_000000.json: not a JSON genome record",
    ),
    "history missing": (lambda run: (run / "history.csv").unlink(), "history.csv: missing"),
    "history cut mid-row": (
        lambda run: _cut(run / "history.csv", (run / "history.csv").stat().st_size - 5),
        "history.csv: the last line is incomplete",
    ),
    "config not TOML": (
        lambda run: (run / "config.toml").write_text((run / "config.toml").read_text() + "[[[\n"),
        "config.toml: not a TOML config",
    ),
}


@pytest.mark.parametrize("damage", sorted(DAMAGES))
def test_pack_refuses_a_run_that_would_not_restore_naming_it_and_changes_no_file(tmp_path, capsys, damage):
    data = tmp_path / "data"
    shutil.copytree(PACKED, data / "dn2" / "run_0")
    shutil.copytree(FIXTURES / "dn10_run_0", data / "dn10" / "run_0")
    work = tmp_path / "work"
    R.unpack_tree(data, work)
    run = work / "dn10" / "run_0"
    damage_run, message = DAMAGES[damage]
    damage_run(run)
    before = _tree(data)
    assert R.main(["pack", str(work), str(data)]) == 1
    err = capsys.readouterr().err
    assert f"{run}/{message}" in err, err
    assert _tree(data) == before  # not even the good dn2 run got its manifest


def test_pack_never_replaces_a_packed_run_with_one_behind_it(tmp_path, capsys):
    data, packed = _packed_with_manifest(tmp_path)
    work = tmp_path / "work"
    run = R.unpack_run(packed, work / "dn2" / "run_0")
    (run / "checkpoint.json").write_bytes(_checkpoint_at((run / "checkpoint.json").read_bytes(), 50))
    (run / "history.csv").write_text("".join((run / "history.csv").read_text().splitlines(keepends=True)[:52]))
    for f in (run / "best").glob("gen_*.json"):
        if int(f.stem[4:]) > 50:
            f.unlink()
    before = _tree(data)
    assert R.main(["pack", str(work), str(data)]) == 1
    err = capsys.readouterr().err
    assert (
        f"{run}: at generation 50 (checkpoint.json), behind the run packed in {packed} at generation 100 "
        f"(checkpoint.json.gz); refusing to replace it"
    ) in err
    assert _tree(data) == before
    with pytest.raises(R.StoreError):
        R.pack_run(run, packed)
    assert _tree(data) == before


def test_unpack_repairs_what_an_unpack_cut_short_left(tmp_path):
    data = tmp_path / "data"
    shutil.copytree(PACKED, data / "dn2" / "run_0")
    work = tmp_path / "work"
    ckpt = work / "dn2" / "run_0" / "checkpoint.json"
    want = gzip.decompress((PACKED / "checkpoint.json.gz").read_bytes())
    R.unpack_tree(data, work)
    _cut(ckpt, len(want) // 3)  # what a write stopped by a full disk leaves
    stale = work / "dn2" / ".run_0.unpack-killed"  # the staging directory of a killed unpack
    stale.mkdir()
    (stale / "checkpoint.json").write_bytes(want[:10])
    assert R.main(["unpack", str(data), str(work)]) == 0
    assert ckpt.read_bytes() == want
    assert not stale.exists()
    assert R.unpack_tree(data, work) == []  # now equal to the packed run: nothing to do
    (work / "dn2" / "run_0" / "best" / "gen_000000.json").unlink()
    assert R.unpack_tree(data, work) == [work / "dn2" / "run_0"]
    assert _tree(work / "dn2" / "run_0") == _tree(R.unpack_run(PACKED, tmp_path / "fresh"))


def test_unpack_on_a_full_disk_writes_nothing_and_a_retry_completes_it(tmp_path):
    data = tmp_path / "data"
    shutil.copytree(PACKED, data / "dn2" / "run_0")
    work = tmp_path / "work"
    cmd = [sys.executable, str(STUDY / "replication_store.py"), "unpack", str(data), str(work)]

    def file_size_limit():  # every other file fits; the checkpoint (440 KB) does not
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (100_000, 100_000))

    full = subprocess.run(cmd, capture_output=True, text=True, preexec_fn=file_size_limit)
    assert full.returncode == 1, full.stderr
    assert f"unpacking {data / 'dn2' / 'run_0'} into {work / 'dn2' / 'run_0'}: File too large" in full.stderr
    assert not work.exists() or _tree(work) == {}
    retry = subprocess.run(cmd, capture_output=True, text=True)
    assert retry.returncode == 0, retry.stderr
    assert _tree(work / "dn2" / "run_0") == _tree(R.unpack_run(PACKED, tmp_path / "fresh"))


def test_unpack_keeps_a_work_run_further_on_and_refuses_one_behind(tmp_path):
    data = tmp_path / "data"
    shutil.copytree(PACKED, data / "dn2" / "run_0")
    work = tmp_path / "work"
    (target,) = R.unpack_tree(data, work)
    ckpt = target / "checkpoint.json"
    good = ckpt.read_bytes()
    ckpt.write_bytes(_checkpoint_at(good, 101))
    newer = _tree(target)
    assert R.unpack_tree(data, work) == [] and _tree(target) == newer
    ckpt.write_bytes(_checkpoint_at(good, 50))
    with pytest.raises(R.StoreError) as e:
        R.unpack_tree(data, work)
    assert f"{ckpt}: at generation 50, behind the packed run {data / 'dn2' / 'run_0'} at generation 100" in str(e.value)
    ckpt.write_bytes(b'{"checksum": "x", ' + good[:50])  # damaged, and not a part of the packed one
    with pytest.raises(R.StoreError) as e:
        R.unpack_tree(data, work)
    assert f"{ckpt}: not valid JSON" in str(e.value) and f"move {target} away" in str(e.value)


@pytest.mark.parametrize(
    "name", ["checkpoint.json.gz", "best.tar.gz", "history.csv.gz", "config.toml", "status.json", "manifest.json"]
)
def test_one_flipped_bit_in_a_packed_file_is_an_error_naming_it_and_writes_nothing(tmp_path, name):
    data, packed = _packed_with_manifest(tmp_path)
    f = packed / name
    b = bytearray(f.read_bytes())
    b[len(b) // 2] ^= 0x10
    f.write_bytes(bytes(b))
    work = tmp_path / "work"
    with pytest.raises(R.StoreError) as e:
        R.unpack_tree(data, work)
    assert f"{packed / name}:" in str(e.value)
    assert not (work / "dn2" / "run_0").exists()
    with pytest.raises(R.StoreError):
        R.unpack_run(packed, tmp_path / "single")
    assert not (tmp_path / "single").exists()


def test_a_packed_run_without_manifest_is_checked_by_its_gzip_crc(tmp_path):
    """A best.tar.gz whose deflate data decodes to other numbers than its CRC-32 describes (what one flipped bit
    can do): the tar reads fine, only the CRC at the end of the stream tells."""
    data = tmp_path / "data"
    packed = data / "dn2" / "run_0"
    shutil.copytree(PACKED, packed)
    original = (packed / "best.tar.gz").read_bytes()
    tar = gzip.decompress(original)
    i = tar.index(b'"fitness": 4.9') + len(b'"fitness": 4.9')
    altered = gzip.compress(tar[:i] + b"8" + tar[i + 1 :], compresslevel=9, mtime=0)
    (packed / "best.tar.gz").write_bytes(altered[:-8] + original[-8:])  # the original CRC-32 and length
    with pytest.raises(R.StoreError) as e:
        R.unpack_tree(data, tmp_path / "work")
    assert f"{packed / 'best.tar.gz'}: corrupt gzip stream" in str(e.value)
    assert "incorrect data check" in str(e.value)
    assert not (tmp_path / "work" / "dn2" / "run_0").exists()


def test_a_gzip_bomb_is_refused_at_the_size_limit_in_bounded_memory(tmp_path, monkeypatch):
    bomb = gzip.compress(b"0" * (64 << 20), compresslevel=9, mtime=0)  # 64 MiB from about 64 KiB
    data, packed = _packed_with_manifest(tmp_path)
    (packed / "history.csv.gz").write_bytes(bomb)
    manifest = json.loads((packed / R.MANIFEST).read_text())  # made to agree with the bomb's packed bytes
    manifest["packed"]["history.csv.gz"].update(sha256=hashlib.sha256(bomb).hexdigest(), size=len(bomb))
    (packed / R.MANIFEST).write_text(json.dumps(manifest))
    limit = manifest["packed"]["history.csv.gz"]["gunzipped"]["size"]

    def unpack_peak() -> tuple:
        tracemalloc.start()
        try:
            with pytest.raises(R.StoreError) as e:
                R.unpack_tree(data, tmp_path / "work")
            return str(e.value), tracemalloc.get_traced_memory()[1]
        finally:
            tracemalloc.stop()

    message, peak = unpack_peak()  # capped at the manifest's size
    assert f"{packed / 'history.csv.gz'}: expands past {limit} bytes" in message
    assert peak < 8 << 20
    (packed / R.MANIFEST).unlink()  # no manifest: capped at MAX_UNPACKED_BYTES, here lowered to 1 MiB
    monkeypatch.setattr(R, "MAX_UNPACKED_BYTES", 1 << 20)
    message, peak = unpack_peak()
    assert f"{packed / 'history.csv.gz'}: expands past {1 << 20} bytes" in message
    assert peak < 8 << 20
    assert not (tmp_path / "work" / "dn2" / "run_0").exists()


@pytest.mark.parametrize(
    "study,count",
    [
        ("replication", 40),
        ("replication_regime", 40),
        ("replication_regime_fixed", 40),
        ("replication_long", 30),
        ("regime_protection", 4),
    ],
)
def test_every_committed_packed_run_has_a_manifest_and_unpacks_verified(tmp_path, study, count):
    runs = [p for group in R.packed_runs(ROOT / "data" / study).values() for p in group]
    assert len(runs) >= count
    assert [p for p in runs if not (p / R.MANIFEST).is_file()] == []
    done = R.unpack_tree(ROOT / "data" / study, tmp_path)
    assert len(done) == len(runs)
    for p in runs:
        target = tmp_path / p.parent.name / p.name
        assert (target / "checkpoint.json").read_bytes() == gzip.decompress((p / "checkpoint.json.gz").read_bytes())
