"""One GA over MPI ranks, end to end with mpirun on localhost: bit-identical to one
process with one thread for 1-3 ranks x 1-2 threads; a killed rank stops the job with a message and
an intact checkpoint, and a resume on a different number of ranks finishes identically; islands are
deterministic on 1 and 3 ranks, and their migrants arrive at the scheduled generations.

Needs ANIMAT_EVOLVE_EXE and mpirun. scripts/test.sh sets ANIMAT_TEST_MPI=1: then a missing mpirun
or a build without MPI fails instead of skipping."""

import csv
import json
import os
import pathlib
import shutil
import signal
import subprocess
import sys
import time

import pytest

EXE = os.environ.get("ANIMAT_EVOLVE_EXE")
MPIRUN = shutil.which("mpirun")
REQUIRED = os.environ.get("ANIMAT_TEST_MPI") == "1"

if REQUIRED:
    assert EXE and os.path.exists(EXE), "ANIMAT_TEST_MPI=1 but ANIMAT_EVOLVE_EXE is not set"
    assert MPIRUN, "ANIMAT_TEST_MPI=1 but mpirun is not installed (scripts/setup.sh installs openmpi-bin)"
pytestmark = pytest.mark.skipif(
    not EXE or not os.path.exists(EXE) or not MPIRUN, reason="needs ANIMAT_EVOLVE_EXE and mpirun"
)

# mpirun refuses root without these (CI and containers run as root); localhost only.
ENV = dict(
    os.environ,
    OMPI_ALLOW_RUN_AS_ROOT="1",
    OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
    OMPI_MCA_btl="self,vader",
    OMPI_MCA_btl_vader_single_copy_mechanism="none",
)  # no CMA: containers may forbid ptrace
SMALL = ["--set", "evolution.population=10", "--set", "evaluation.steps=200", "--generations", "4", "--seed", "3"]


def evolve(out, *args, ranks=None, threads=1, timeout=120):
    cmd = [EXE, *args, "--threads", str(threads), "--out", str(out), "--quiet"]
    if ranks is not None:
        cmd = [MPIRUN, "--oversubscribe", "--bind-to", "none", "-np", str(ranks), *cmd]
    return subprocess.run(cmd, capture_output=True, text=True, env=ENV, timeout=timeout)


def history(run):
    """history.csv without the machine-dependent wall time (whatever the other columns are)."""
    with open(run / "history.csv", newline="") as f:
        return [{k: v for k, v in row.items() if k != "wall_seconds"} for row in csv.DictReader(f)]


def lineage(run):
    return {p.name: p.read_text() for p in sorted((run / "best").glob("*.json"))}


def population(run):
    payload = json.loads(json.loads((run / "checkpoint.json").read_text())["payload"])
    return payload["population"], payload["generation"]


def assert_same_run(a, b):
    assert history(a) == history(b)
    assert lineage(a) == lineage(b)
    assert population(a) == population(b)


def test_built_with_mpi(tmp_path):
    r = subprocess.run(
        [MPIRUN, "--oversubscribe", "-np", "2", EXE, "--print-config"],
        capture_output=True,
        text=True,
        env=ENV,
        timeout=60,
    )
    assert r.returncode == 0, r.stderr
    assert "built without MPI" not in r.stderr
    assert r.stdout.count("[evolution]") == 1  # rank 0 prints; rank 1 is released without a run


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    out = tmp_path_factory.mktemp("mpi") / "one_thread"
    r = evolve(out, *SMALL)
    assert r.returncode == 0, r.stderr
    return out


@pytest.mark.parametrize("ranks", [1, 2, 3])
@pytest.mark.parametrize("threads", [1, 2])
def test_any_ranks_and_threads_give_the_one_thread_run(tmp_path, reference, ranks, threads):
    out = tmp_path / "run"
    r = evolve(out, *SMALL, ranks=ranks, threads=threads)
    assert r.returncode == 0, r.stdout + r.stderr
    assert_same_run(reference, out)


def test_protected_ga_on_two_ranks_and_resumed_on_three_is_the_one_process_run(tmp_path):
    # Morphological innovation protection (evolution.protection_generations) decides tournaments on
    # rank 0 from each individual's morphology kind and age, which the ranks send back with the
    # fitness: the run must not depend on where the swims ran, nor on a resume on other ranks.
    protected = [*SMALL, "--set", "evolution.protection_generations=3"]
    one = tmp_path / "one"
    r = evolve(one, *protected)
    assert r.returncode == 0, r.stderr
    rows = history(one)
    assert rows[0]["protected"] == "10" and any(0 < int(row["protected"]) < 10 for row in rows[1:]), rows
    two = tmp_path / "two"
    r = evolve(two, *protected, ranks=2)
    assert r.returncode == 0, r.stdout + r.stderr
    assert_same_run(one, two)
    split = tmp_path / "split"
    first_half = list(protected)
    first_half[first_half.index("--generations") + 1] = "2"
    r = evolve(split, *first_half, ranks=2)
    assert r.returncode == 0, r.stdout + r.stderr
    cmd = [MPIRUN, "--oversubscribe", "--bind-to", "none", "-np", "3", EXE, "--resume", str(split)]
    cmd += ["--generations", "4", "--threads", "1", "--quiet"]
    r = subprocess.run(cmd, capture_output=True, text=True, env=ENV, timeout=120)
    assert r.returncode == 0, r.stdout + r.stderr
    assert_same_run(one, split)


def _rank_pids(mpirun_pid):
    """Children of mpirun by MPI rank (a local launch forks the ranks directly)."""
    ranks = {}
    for proc in pathlib.Path("/proc").iterdir():
        if not proc.name.isdigit():
            continue
        try:
            status = (proc / "status").read_text()
            ppid = int(next(l for l in status.splitlines() if l.startswith("PPid:")).split()[1])
            env = (proc / "environ").read_bytes().split(b"\0")
        except (OSError, StopIteration):
            continue
        if ppid != mpirun_pid:
            continue
        for item in env:
            if item.startswith(b"OMPI_COMM_WORLD_RANK="):
                ranks[int(item.split(b"=")[1])] = int(proc.name)
    return ranks


def test_killed_rank_stops_the_job_and_a_resume_on_other_ranks_finishes_identically(tmp_path):
    # Nothing here depends on the machine's speed or load. The job has no generation cap and no stall
    # limit (both may change on resume), so it cannot end before rank 1 is killed; rank 1 is killed
    # once checkpoint.json holds generation 3 (a condition, polled), wherever the job then is. The
    # uninterrupted run and the resume then go to the generation the checkpoint holds + 2. The time
    # limits only keep a broken build from hanging.
    args = ["--set", "evolution.population=16", "--set", "evaluation.steps=1000", "--seed", "5"]
    run = tmp_path / "killed"
    cmd = [
        MPIRUN,
        "--oversubscribe",
        "--bind-to",
        "none",
        "-np",
        "3",
        EXE,
        *args,
        "--generations",
        "0",
        "--set",
        "evolution.stall_generations=0",
        "--threads",
        "1",
        "--out",
        str(run),
        "--quiet",
    ]
    job = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=ENV)
    try:
        hang_guard = time.monotonic() + 900
        while not (run / "checkpoint.json").exists() or population(run)[1] < 3:  # written atomically
            assert job.poll() is None, f"the job ended before rank 1 was killed: {job.stdout.read()}"
            assert time.monotonic() < hang_guard, "hang guard: no checkpoint of generation 3 after 900 s"
            time.sleep(0.02)  # polling the condition
        ranks = _rank_pids(job.pid)
        assert 1 in ranks, f"rank 1 not found among mpirun's children: {ranks}"
        os.kill(ranks[1], signal.SIGKILL)
        output, _ = job.communicate(timeout=900)
    finally:
        if job.poll() is None:
            job.kill()
    assert job.returncode != 0
    assert "rank 1" in output, output  # mpirun names the rank that died
    done, generation = population(run)  # intact: parses, checksum verified by the resume below
    assert generation >= 3
    # Rank 0's own message (its output may already be cut off by mpirun): RUN_DIR/stopped.txt.
    stopped = run / "stopped.txt"
    if stopped.exists():  # Open MPI may abort rank 0 before it writes; the checkpoint is what counts
        text = stopped.read_text()
        assert "rank 1" in text and "stopped answering" in text, text
        assert f"is intact (generation {generation}" in text and "--resume" in text, text

    final = str(generation + 2)
    straight = tmp_path / "straight"
    r = evolve(straight, *args, "--generations", final, timeout=900)
    assert r.returncode == 0, r.stderr
    r = subprocess.run(
        [
            MPIRUN,
            "--oversubscribe",
            "--bind-to",
            "none",
            "-np",
            "2",
            EXE,
            "--resume",
            str(run),
            "--generations",
            final,
            "--threads",
            "2",
        ],
        capture_output=True,
        text=True,
        env=ENV,
        timeout=900,
    )
    assert r.returncode == 0, r.stdout + r.stderr
    assert not stopped.exists()
    assert_same_run(straight, run)


ISLANDS = [
    "--set",
    "evolution.population=12",
    "--set",
    "evolution.islands=3",
    "--set",
    "evolution.migration_interval=2",
    "--set",
    "evolution.migrants=1",
    "--set",
    "evolution.elites=1",
    "--set",
    "evaluation.steps=200",
    "--generations",
    "6",
    "--seed",
    "4",
]


def test_islands_are_deterministic_on_one_and_three_ranks_and_migrate_on_schedule(tmp_path):
    runs = {}
    for name, ranks, threads in [("local", None, 1), ("one_rank", 1, 2), ("three_ranks", 3, 1)]:
        runs[name] = tmp_path / name
        r = evolve(runs[name], *ISLANDS, ranks=ranks, threads=threads)
        assert r.returncode == 0, r.stdout + r.stderr
    for name in ("one_rank", "three_ranks"):
        assert_same_run(runs["local"], runs[name])
        assert (runs["local"] / "islands.csv").read_text() == (runs[name] / "islands.csv").read_text()
    with open(runs["local"] / "islands.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 7 * 3
    for row in rows:
        assert int(row["immigrants"]) == (1 if int(row["generation"]) in (2, 4, 6) else 0), row
    # At a migration generation the best of island k is in island k+1 too (a copy of it replaced the worst).
    pop, generation = population(runs["local"])
    assert generation == 6
    genomes = [json.dumps(ind["genome"], sort_keys=True) for ind in pop]
    islands = [range(0, 4), range(4, 8), range(8, 12)]

    def rank_key(i):
        return (not pop[i]["viable"], -pop[i]["fitness"], i)

    for k in range(3):
        best_of_k = min(islands[k], key=rank_key)
        # the best of k after migration is k's own best or the immigrant from k-1; either way it is in two islands
        holders = {j for j in range(12) if genomes[j] == genomes[best_of_k]}
        assert len({next(n for n, isl in enumerate(islands) if j in isl) for j in holders}) >= 2, (k, holders)


TINY = """
[evaluation]
steps = 200
[evolution]
population = 8
generations = 2
"""


def test_study_on_mpi_ranks_equals_the_same_study_run_task_by_task(tmp_path):
    cfg = tmp_path / "tiny.toml"
    cfg.write_text(TINY)
    py = [sys.executable, "-m", "animat", "experiment"]
    study = [f"a={cfg}", f"b={cfg}", "--runs", "2", "--set", "evolution.threads=1", "--quiet"]
    env = dict(ENV, PYTHONPATH=os.environ.get("PYTHONPATH", ""))
    r = subprocess.run(
        [MPIRUN, "--oversubscribe", "-np", "2", *py, *study, "--out", str(tmp_path / "mpi"), "--mpi"],
        capture_output=True,
        text=True,
        env=env,
        timeout=180,
    )
    assert r.returncode == 0, r.stdout + r.stderr
    assert (tmp_path / "mpi" / "a" / "summary.md").exists() and (tmp_path / "mpi" / "b" / "summary.json").exists()
    # The four runs as four array tasks, one process each: the same runs wherever they ran.
    for task in range(4):
        r = subprocess.run(
            [*py, *study, "--out", str(tmp_path / "array"), "--index", str(task)],
            capture_output=True,
            text=True,
            env=env,
            timeout=180,
        )
        assert r.returncode == 0, r.stderr
    assert not (tmp_path / "array" / "a" / "summary.md").exists()  # tasks write no summary
    for env_name in "ab":
        for i in range(2):
            assert_same_run(tmp_path / "mpi" / env_name / f"run_{i}", tmp_path / "array" / env_name / f"run_{i}")
    # Under mpirun without --mpi every rank would run everything: refused.
    r = subprocess.run(
        [MPIRUN, "--oversubscribe", "-np", "2", *py, *study, "--out", str(tmp_path / "x")],
        capture_output=True,
        text=True,
        env=env,
        timeout=180,
    )
    assert r.returncode != 0 and "without --mpi" in r.stderr + r.stdout


def test_errors_on_any_rank_reach_rank_0_and_release_the_others(tmp_path):
    # An evaluation error on another rank: the same message as with threads (the first by index).
    args = ["--set", "evolution.population=8", "--set", "evolution.max_init_tries=1", "--set", "evaluation.steps=100"]
    local = evolve(tmp_path / "local", *args)
    mpi = evolve(tmp_path / "mpi", *args, ranks=3)
    assert local.returncode == 2 and mpi.returncode != 0
    message = local.stderr.strip().splitlines()[-1]
    assert "no viable random genome in evolution.max_init_tries = 1 tries" in message
    assert message.split("error: ")[-1] in mpi.stderr, mpi.stderr
    # Rank 0 fails before the ranks got a run (no such directory), and after (a corrupt checkpoint):
    # both end at once with rank 0's message, no rank left waiting (the timeout would fail the test).
    r = subprocess.run(
        [MPIRUN, "--oversubscribe", "-np", "2", EXE, "--resume", str(tmp_path / "none")],
        capture_output=True,
        text=True,
        env=ENV,
        timeout=60,
    )
    assert r.returncode != 0 and "resume directory does not exist" in r.stderr
    ok = evolve(
        tmp_path / "run", "--set", "evolution.population=8", "--set", "evaluation.steps=100", "--generations", "1"
    )
    assert ok.returncode == 0, ok.stderr
    (tmp_path / "run" / "checkpoint.json").write_text("garbage")
    r = subprocess.run(
        [MPIRUN, "--oversubscribe", "-np", "2", EXE, "--resume", str(tmp_path / "run")],
        capture_output=True,
        text=True,
        env=ENV,
        timeout=60,
    )
    assert r.returncode != 0 and "corrupt checkpoint" in r.stderr


ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_paper_study_submits_an_array_and_a_report_and_a_task_runs_its_run(tmp_path):
    # A stand-in sbatch records what scripts/paper_study.sh --slurm submits.
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    log = tmp_path / "sbatch.log"
    (bin_dir / "sbatch").write_text(f'#!/bin/sh\necho "$@" >> {log}\necho 4242\n')
    (bin_dir / "sbatch").chmod(0o755)
    env = dict(
        ENV,
        PATH=f"{bin_dir}:{os.environ['PATH']}",
        ANIMAT_PYTHONPATH=os.environ.get("PYTHONPATH", ""),
        ANIMAT_PYTHON=sys.executable,
    )
    out = tmp_path / "study"
    r = subprocess.run(
        [
            str(ROOT / "scripts" / "paper_study.sh"),
            "--slurm",
            "--runs",
            "2",
            "--out",
            str(out),
            "--",
            "--generations",
            "1",
        ],
        capture_output=True,
        text=True,
        env=env,
        timeout=60,
    )
    assert r.returncode == 0, r.stderr
    array, report = log.read_text().splitlines()
    assert (
        "--array=0-7" in array
        and "scripts/cluster/paper_study.sbatch --runs 2" in array
        and "-- --generations 1" in array
    )
    assert "--dependency=afterok:4242" in report and "scripts/cluster/paper_report.sbatch" in report
    # Array task 5 is run 1 of the third environment (d_N = 10); it writes that run and no summary.
    r = subprocess.run(
        [
            str(ROOT / "scripts" / "paper_study.sh"),
            "--task",
            "5",
            "--runs",
            "2",
            "--out",
            str(out),
            "--",
            "--generations",
            "1",
            "--set",
            "evolution.population=8",
            "--set",
            "evaluation.steps=100",
            "--quiet",
        ],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr
    assert (out / "dn10" / "run_1" / "checkpoint.json").exists()
    assert [p.name for p in out.iterdir() if p.is_dir()] == ["dn10"]
    assert (
        json.loads(json.loads((out / "dn10" / "run_1" / "checkpoint.json").read_text())["payload"])["generation"] == 1
    )
