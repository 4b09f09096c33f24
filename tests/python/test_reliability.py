"""Reliability (docs/reliability.md) through Python and the real binary.

- The bad-input catalogue (tests/bad_inputs/catalogue/): every case raises the Python exception and
  the exact message of its <case>.expected sidecar, and no case aborts the interpreter.
- Kill-and-resume of `animat_evolve` (path in ANIMAT_EVOLVE_EXE; skipped when unset): SIGKILL at
  random moments, resume each time; the result equals an uninterrupted run with the same seed and no
  checkpoint is ever corrupt. SIGINT and SIGTERM end cleanly with exit code 130 and a fresh checkpoint.
- Disk faults through the binary and `animat.evolve`: clear error, non-zero exit.

docs/reliability.md lists every guarantee with the test that checks it.
"""

from __future__ import annotations

import csv
import json
import os
import random
import resource
import shutil
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

import animat

ROOT = Path(__file__).resolve().parents[2]
CATALOGUE = ROOT / "tests" / "bad_inputs" / "catalogue"
EXE = os.environ.get("ANIMAT_EVOLVE_EXE")
needs_exe = pytest.mark.skipif(not EXE or not Path(EXE).exists(), reason="ANIMAT_EVOLVE_EXE is not set")
EXCEPTIONS = {"ValueError": ValueError, "OSError": OSError, "RuntimeError": RuntimeError}


# --------------------------------------------------------------------------------------------------
# The catalogue


def read_expected(path: Path) -> dict:
    """error/python/message (exact) or contains (substrings), as in the catalogue's README."""
    want = {"contains": []}
    for line in path.read_text().splitlines():
        if not line or line.startswith("#") or ": " not in line:
            continue
        key, value = line.split(": ", 1)
        if key == "contains":
            want["contains"].append(value)
        else:
            want[key] = value
    return want


def catalogue(*kinds: str) -> list:
    return sorted(
        p.name for p in CATALOGUE.iterdir() if p.suffix in (".toml", ".json", ".txt") and p.name.split("_")[0] in kinds
    )


def catalogue_config():
    """The config the catalogue's checkpoints are restored against (README.md)."""
    c = animat.Config()
    c["evolution.population"] = 2
    c["evolution.elites"] = 1
    c["evolution.seed"] = 11
    c["evolution.threads"] = 1
    return c


def check_message(message: str, want: dict, path: str):
    if "message" in want:
        assert message == want["message"].replace("{path}", path)
    for part in want["contains"]:
        assert part.replace("{path}", path) in message, f"expected {part!r} in {message!r}"


@pytest.mark.parametrize("case", catalogue("config", "genome", "checkpoint"))
def test_catalogue_case_raises_the_expected_python_exception(case, tmp_path):
    src = CATALOGUE / case
    want = read_expected(src.with_suffix(".expected"))
    kind = case.split("_")[0]
    if kind == "checkpoint":
        run = tmp_path / "run"
        run.mkdir()
        shutil.copy(src, run / "checkpoint.json")
        path = str(run / "checkpoint.json")
        load = lambda: animat.evolve(catalogue_config(), out=str(run), resume=True, quiet=True)  # noqa: E731
    elif kind == "config":
        path = str(src)
        load = lambda: animat.load_config(path)  # noqa: E731
    else:
        path = str(src)
        load = lambda: animat.Genome.load(path)  # noqa: E731
    with pytest.raises(Exception) as info:
        load()
    # isinstance, not type equality: a UnicodeDecodeError is a ValueError too, but then the message
    # check below fails, as it should (the C++ message was lost).
    assert isinstance(info.value, EXCEPTIONS[want["python"]]), f"{type(info.value).__name__}: {info.value}"
    check_message(str(info.value), want, path)


@needs_exe
@pytest.mark.parametrize("case", catalogue("override"))
def test_catalogue_override_is_a_clear_cli_error(case):
    text = (CATALOGUE / case).read_text().rstrip("\n")
    want = read_expected((CATALOGUE / case).with_suffix(".expected"))
    r = subprocess.run([EXE, "--print-config", "--set", text], capture_output=True, text=True, timeout=60)
    assert r.returncode == 2, r.stderr
    prefix = "animat_evolve: error: "
    assert r.stderr.startswith(prefix) and r.stderr.endswith("\n"), r.stderr
    check_message(r.stderr[len(prefix) : -1], want, "")


def run_isolated(code: str, timeout=300) -> subprocess.CompletedProcess:
    """Runs Python code in a fresh interpreter with the same animat on the path."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, timeout=timeout, env=env
    )


def test_no_catalogue_case_aborts_the_interpreter():
    # Every loader on every file in one fresh interpreter: a crash (abort, segfault) would kill it, so
    # its exit status and last line say which case did it. Exceptions other than ValueError and
    # OSError are listed as "wrong".
    r = run_isolated(f"""
        import shutil, tempfile
        from pathlib import Path
        import animat
        c = animat.Config(); c["evolution.population"] = 2; c["evolution.elites"] = 1
        def attempt(name, load):
            try:
                load()
            except (ValueError, OSError):
                pass
            except Exception as e:
                print("wrong", name, type(e).__name__, flush=True)
        for p in sorted(Path({str(CATALOGUE)!r}).iterdir()):
            if p.suffix not in (".toml", ".json", ".txt"):
                continue
            print("case", p.name, flush=True)
            attempt(p.name, lambda: animat.load_config(str(p)))
            attempt(p.name, lambda: animat.Genome.load(str(p)))
            with tempfile.TemporaryDirectory() as d:
                shutil.copy(p, Path(d) / "checkpoint.json")
                attempt(p.name, lambda: animat.evolve(c, out=d, resume=True, quiet=True))
        print("survived")
        """)
    lines = r.stdout.strip().splitlines() or ["(nothing)"]
    assert r.returncode == 0 and lines[-1] == "survived", f"exit {r.returncode} after {lines[-1]}: {r.stderr[-2000:]}"
    wrong = [line for line in lines if line.startswith("wrong")]
    assert not wrong, "exceptions other than ValueError/OSError: " + "; ".join(wrong)


def test_ten_million_element_genome_is_a_value_error():
    text = (
        '{"format": "animat.genome", "version": 1, "dimensions": 2, "elements": [' + ",".join(["0"] * 10_000_000) + "]}"
    )
    with pytest.raises(ValueError, match=r"^<string>: 10000000 elements exceed genome.max_elements = 1000000$"):
        animat.Genome.from_json(text)


def test_deeply_nested_genome_is_a_value_error_not_a_crash():
    # 100,000 nested arrays where a coordinate list is expected (found by review; see docs/reliability.md).
    r = run_isolated("""
        import animat
        deep = "[" * 100000 + "]" * 100000
        for doc in ('{"format": ' + deep + '}',
                    '{"format": "animat.genome", "version": 1, "dimensions": 2, "elements": '
                    '[{"type": "promoter", "sign": 1, "coords": ' + deep + '}]}'):
            try:
                animat.Genome.from_json(doc)
                print("accepted")
            except ValueError as e:
                print("ValueError", len(str(e)))
        print("survived")
        """)
    assert r.returncode == 0, f"the interpreter died (exit {r.returncode}): {r.stderr[-2000:]}"
    lines = r.stdout.splitlines()
    assert lines[-1] == "survived" and all(line.startswith("ValueError") for line in lines[:-1]), lines


# --------------------------------------------------------------------------------------------------
# Kill-and-resume of the real binary

FINAL_GENERATION = 20
RUN_ARGS = [
    "--quiet",
    "--threads",
    "2",
    "--seed",
    "5",
    "--set",
    "evolution.population=12",
    "--set",
    "evaluation.steps=300",
    "--generations",
    str(FINAL_GENERATION),
]
# The runs that are killed or signalled: the same run with no generation cap and no stall limit (both
# may change on resume and are not part of the run), so that it can never end before the kill or the
# signal, however fast or slow the machine; a resume with --generations FINAL_GENERATION finishes it.
UNCAPPED = [*RUN_ARGS[:-2], "--generations", "0", "--set", "evolution.stall_generations=0"]
HANG_GUARD_SECONDS = 900  # only keeps a broken build from hanging the suite; never a verdict on speed


def fnv1a(data: bytes) -> str:
    h = 0xCBF29CE484222325
    for b in data:
        h = ((h ^ b) * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return f"{h:016x}"


def read_checkpoint(run: Path) -> dict:
    """Parses checkpoint.json and checks its checksum; returns the payload."""
    outer = json.loads((run / "checkpoint.json").read_text())
    body = outer["payload"]
    assert outer["checksum"] == fnv1a(body.encode()), "checkpoint checksum mismatch"
    payload = json.loads(body)
    assert payload["format"] == "animat.checkpoint"
    assert payload["history"][-1]["generation"] == payload["generation"]
    assert len(payload["population"]) == 12
    return payload


def assert_restores(run: Path, tmp: Path):
    """The checkpoint restores in the engine itself: resume a copy for one generation."""
    copy = tmp / f"restore_{time.monotonic_ns()}"
    shutil.copytree(run, copy)
    config = animat.load_config(str(copy / "config.toml"))
    config["evolution.generations"] = read_checkpoint(run)["generation"] + 1  # the killed runs have no cap
    r = animat.evolve(config, out=str(copy), resume=True, quiet=True, callback=lambda s: False)
    assert r.history[-1].generation == read_checkpoint(run)["generation"] + 1
    shutil.rmtree(copy)


def history(run: Path) -> list:
    """history.csv without the wall_seconds column (the only machine-dependent one)."""
    with open(run / "history.csv") as f:
        return [row[:-1] for row in csv.reader(f)]


def lineage(run: Path) -> dict:
    return {p.name: json.loads(p.read_text()) for p in sorted((run / "best").glob("gen_*.json"))}


def start(args, **kw) -> subprocess.Popen:
    return subprocess.Popen([EXE, *args], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, **kw)


def checkpoint_generation(run: Path) -> int:
    """The generation checkpoint.json holds (-1 before the first); it is written atomically."""
    return read_checkpoint(run)["generation"] if (run / "checkpoint.json").exists() else -1


def wait_until(proc: subprocess.Popen, condition, what: str):
    """Polls `condition` (on the run's files) while `proc` runs. An uncapped run cannot end on its own,
    so an exit is a failure; the time limit is a hang guard only."""
    hang_guard = time.monotonic() + HANG_GUARD_SECONDS
    while not condition():
        assert proc.poll() is None, f"the run ended before {what}: exit {proc.returncode}: {proc.stderr.read()}"
        assert time.monotonic() < hang_guard, f"hang guard: no {what} after {HANG_GUARD_SECONDS} s"
        time.sleep(0.02)  # polling the condition


def finish_and_compare(run: Path, reference: dict):
    """Resumes an uncapped run and compares it with the uninterrupted run. The resume goes to
    FINAL_GENERATION, or one generation past the checkpoint when the last kill or signal landed after
    FINAL_GENERATION (a fast machine gets there within the kills' delays): the resume always evolves,
    so it also drops any row a SIGKILL between a history append and its checkpoint left behind (a
    resume already at its cap writes no file). The run's first FINAL_GENERATION + 1 generations must
    be the uninterrupted run's."""
    target = max(FINAL_GENERATION, read_checkpoint(run)["generation"] + 1)
    r = subprocess.run(
        [EXE, "--resume", str(run), "--generations", str(target), "--quiet"],
        capture_output=True,
        text=True,
        timeout=HANG_GUARD_SECONDS,
    )
    assert r.returncode == 0, r.stderr
    generation = read_checkpoint(run)["generation"]
    assert generation == target
    rows = history(run)
    assert len(rows) == len(reference["history"]) + generation - FINAL_GENERATION
    assert rows[: len(reference["history"])] == reference["history"]
    assert {
        name: genome
        for name, genome in lineage(run).items()
        if int(name[len("gen_") : -len(".json")]) <= FINAL_GENERATION
    } == reference["lineage"]


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """An uninterrupted run: its history and lineage."""
    if not EXE or not Path(EXE).exists():
        pytest.skip("ANIMAT_EVOLVE_EXE is not set")
    run = tmp_path_factory.mktemp("reference") / "run"
    r = subprocess.run([EXE, *RUN_ARGS, "--out", str(run)], capture_output=True, text=True, timeout=HANG_GUARD_SECONDS)
    assert r.returncode == 0, r.stderr
    return {"run": run, "history": history(run), "lineage": lineage(run)}


@needs_exe
def test_sigkill_at_random_moments_then_resume_equals_an_uninterrupted_run(reference, tmp_path):
    # Six SIGKILLs, each followed by a resume (or a fresh start while there is no checkpoint). Where a
    # kill lands is random: a seeded delay after its condition spreads the kills over initialization,
    # evaluations, checkpoint writes and history appends. That they land, and where they count, is
    # not: the run has no generation cap, so it is running at every kill, and kills 3 to 6 wait until
    # the checkpoint has moved 1 to 3 generations past the one they resumed from (a condition on the
    # files, polled), so they come after a checkpoint on any machine under any load.
    run = tmp_path / "run"
    rng = random.Random(20240901)
    mid_run, checked = [], 0
    for kill in range(6):
        resumed_from = checkpoint_generation(run)
        proc = start(
            ["--resume", str(run), "--threads", "2", "--quiet"] if resumed_from >= 0 else [*UNCAPPED, "--out", str(run)]
        )
        if kill < 2:
            delay = rng.uniform(0.0, 0.5)  # from the start: often during initialization
        else:
            target = resumed_from + rng.randint(1, 3)
            wait_until(proc, lambda: checkpoint_generation(run) >= target, f"checkpoint of generation {target}")  # noqa: B023
            delay = rng.uniform(0.0, 0.05)  # within the next generation or so
        try:
            proc.wait(timeout=delay)  # only where the kill lands; the run cannot end meanwhile
            pytest.fail(f"the uncapped run ended on its own: exit {proc.returncode}: {proc.stderr.read()}")
        except subprocess.TimeoutExpired:
            pass
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        assert proc.returncode == -signal.SIGKILL, proc.stderr.read()
        if (run / "checkpoint.json").exists():
            mid_run.append(read_checkpoint(run)["generation"])
            if checked < 2:  # a full restore costs one generation: do it for the first two
                assert_restores(run, tmp_path)
                checked += 1
    assert len(mid_run) >= 4, f"kills after the first checkpoint: generations {mid_run}"
    print(f"6 SIGKILLs; checkpoints found at generations {mid_run}")
    finish_and_compare(run, reference)


@needs_exe
def test_a_row_past_the_checkpoint_stays_until_a_resume_evolves(reference, tmp_path):
    # A SIGKILL between the history append of a generation and its checkpoint leaves history.csv one
    # row past the checkpoint. Built here without a kill: the uninterrupted run, resumed one
    # generation further, gets its earlier checkpoint back.
    run = tmp_path / "run"
    shutil.copytree(reference["run"], run)
    earlier = (run / "checkpoint.json").read_bytes()
    resume = [EXE, "--resume", str(run), "--quiet", "--generations"]
    r = subprocess.run([*resume, str(FINAL_GENERATION + 1)], capture_output=True, text=True, timeout=HANG_GUARD_SECONDS)
    assert r.returncode == 0, r.stderr
    one_more = history(run)
    assert len(one_more) == len(reference["history"]) + 1
    (run / "checkpoint.json").write_bytes(earlier)
    # A resume already at its cap has nothing to evolve: it writes no file, so the row stays.
    before = snapshot(run)
    r = subprocess.run([*resume, str(FINAL_GENERATION)], capture_output=True, text=True, timeout=HANG_GUARD_SECONDS)
    assert r.returncode == 0, r.stderr
    assert snapshot(run) == before
    # A resume that evolves rewrites history.csv from the checkpoint; the row comes back the same.
    r = subprocess.run([*resume, str(FINAL_GENERATION + 2)], capture_output=True, text=True, timeout=HANG_GUARD_SECONDS)
    assert r.returncode == 0, r.stderr
    assert read_checkpoint(run)["generation"] == FINAL_GENERATION + 2
    rows = history(run)
    assert len(rows) == len(one_more) + 1
    assert rows[: len(one_more)] == one_more


@needs_exe
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_sigint_and_sigterm_end_cleanly_with_a_fresh_checkpoint(sig, reference, tmp_path):
    # The signal is sent once generations 0 and 1 are in history.csv (a condition, polled); the run has
    # no generation cap, so it is still running then, on any machine under any load.
    run = tmp_path / "run"
    proc = start([*UNCAPPED, "--out", str(run)])
    wait_until(proc, lambda: (run / "history.csv").exists() and len(history(run)) >= 3, "generation 1")
    proc.send_signal(sig)
    proc.wait(timeout=HANG_GUARD_SECONDS)
    assert proc.returncode == 130, proc.stderr.read()
    rows = history(run)
    payload = read_checkpoint(run)
    assert payload["generation"] == int(rows[-1][0]), "the checkpoint is the last generation written"
    assert payload["generation"] >= 1
    # Resumed to the end, the run equals the uninterrupted one.
    finish_and_compare(run, reference)


# --------------------------------------------------------------------------------------------------
# Disk faults

SMALL = ["--quiet", "--threads", "1", "--seed", "3", "--set", "evolution.population=8", "--set", "evaluation.steps=50"]


@needs_exe
def test_cli_unwritable_output_directory(tmp_path):
    (tmp_path / "file").write_text("x")
    r = subprocess.run(
        [EXE, *SMALL, "--generations", "1", "--out", str(tmp_path / "file" / "run")],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert r.returncode == 2
    assert (
        r.stderr == f"animat_evolve: error: {tmp_path / 'file' / 'run'}: cannot create run directory: Not a directory\n"
    )


@needs_exe
def test_cli_missing_resume_directory(tmp_path):
    r = subprocess.run([EXE, "--resume", str(tmp_path / "nope")], capture_output=True, text=True, timeout=60)
    assert r.returncode == 2
    assert r.stderr == f"animat_evolve: error: {tmp_path / 'nope'}: resume directory does not exist\n"


@needs_exe
def test_cli_full_disk_via_file_size_limit(tmp_path):
    def limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (8192, 8192))

    r = subprocess.run(
        [EXE, *SMALL, "--generations", "3", "--out", str(tmp_path / "run")],
        capture_output=True,
        text=True,
        timeout=120,
        preexec_fn=limit,
    )
    assert r.returncode == 2, r.stderr
    assert r.stderr.startswith("animat_evolve: error: ") and "File too large" in r.stderr, r.stderr


def test_evolve_into_an_unwritable_directory_is_an_os_error(tmp_path):
    (tmp_path / "file").write_text("x")
    c = catalogue_config()
    c["evolution.generations"] = 1
    with pytest.raises(OSError, match="cannot create run directory: Not a directory"):
        animat.evolve(c, out=str(tmp_path / "file" / "run"))


# --------------------------------------------------------------------------------------------------
# The run directory: one writer (RUN/.lock), no run silently replaced, refusals that change nothing


def small_run_config(generations: int):
    c = animat.Config()
    c["evolution.population"] = 8
    c["evolution.elites"] = 1
    c["evolution.threads"] = 1
    c["evolution.seed"] = 3
    c["evaluation.steps"] = 50
    c["evolution.generations"] = generations
    return c


def snapshot(folder: Path) -> dict:
    """Every file and folder under `folder` with its bytes: equal snapshots = an unchanged directory."""
    return {str(p.relative_to(folder)): (None if p.is_dir() else p.read_bytes()) for p in sorted(folder.rglob("*"))}


def test_evolve_refuses_a_second_writer_naming_the_holder(tmp_path):
    # While evolve(out=run) is paused in its callback it holds run/.lock: another evolve() in this
    # process and animat_evolve in another are refused, naming this pid, and change no byte.
    out = tmp_path / "run"
    c = small_run_config(4)
    seen = {}

    def second_writers(stats):
        if stats.generation != 1:
            return None
        before = snapshot(out)
        with pytest.raises(BlockingIOError, match=f"in use by another animat process \\(pid {os.getpid()} on host "):
            animat.evolve(small_run_config(6), out=str(out), resume=True, quiet=True)
        with pytest.raises(BlockingIOError, match=f"pid {os.getpid()}"):
            animat.evolve(small_run_config(6), out=str(out), overwrite=True, quiet=True)
        if EXE and Path(EXE).exists():
            r = subprocess.run(
                [EXE, "--quiet", "--resume", str(out), "--generations", "6"],
                capture_output=True,
                text=True,
                timeout=300,
            )
            seen["cli"] = (r.returncode, r.stderr)
        seen["same"] = snapshot(out) == before
        return None

    r = animat.evolve(c, out=str(out), quiet=True, callback=second_writers)
    assert seen["same"], "a refused writer changed the run directory"
    if "cli" in seen:
        rc, err = seen["cli"]
        assert rc == 2 and f"pid {os.getpid()} on host " in err, err
    assert [int(row[0]) for row in history(out)[1:]] == [0, 1, 2, 3, 4]
    assert r.history[-1].generation == 4
    assert not (out / ".lock").exists(), "the lock file goes with the run"
    assert not list(out.rglob("*.tmp"))


def test_evolve_never_replaces_run_files_without_a_checkpoint(tmp_path):
    out = tmp_path / "run"
    animat.evolve(small_run_config(3), out=str(out), quiet=True)
    (out / "checkpoint.json").unlink()
    before = snapshot(out)
    with pytest.raises(FileExistsError, match=r"no checkpoint.json.*history.csv \(4 generations\).*overwrite=True"):
        animat.evolve(small_run_config(1), out=str(out), quiet=True)
    assert snapshot(out) == before
    r = animat.evolve(small_run_config(1), out=str(out), quiet=True, overwrite=True)
    assert [int(row[0]) for row in history(out)[1:]] == [0, 1] == [int(g) for g in r.history["generation"]]
    assert sorted(p.name for p in (out / "best").iterdir()) == sorted(
        f"gen_{e.generation:06d}.json" for e in animat.Run(out).best_genomes
    )


@needs_exe
def test_cli_refused_resume_keeps_stopped_txt(tmp_path):
    run = tmp_path / "run"
    r = subprocess.run(
        [EXE, *SMALL, "--generations", "2", "--out", str(run)], capture_output=True, text=True, timeout=300
    )
    assert r.returncode == 0, r.stderr
    (run / "stopped.txt").write_text("animat_evolve: error: MPI job stopped: rank 1 lost\n")
    empty = tmp_path / "empty"
    shutil.copytree(run, empty)
    (empty / "checkpoint.json").unlink()
    for folder, args in [
        (run, ["--resume", str(run), "--set", "evolution.population=9"]),
        (run, ["--resume", str(run), "--threads", "-2"]),
        (empty, ["--resume", str(empty)]),
    ]:
        before = snapshot(folder)
        r = subprocess.run([EXE, "--quiet", *args], capture_output=True, text=True, timeout=300)
        assert r.returncode != 0, args
        assert snapshot(folder) == before, f"{args} changed {folder}"
