"""Independent evolutionary runs of one configuration: the replication workhorse
(docs/replication.md).

    python -m animat experiment configs/paper_dn2.toml --runs 3 --out runs/replication/dn2

Run ``i`` uses seed ``evolution.seed + i`` and lives in ``OUT/run_<i>``. Runs go one after another, or
``--parallel K`` at a time with the cores split between them (each run's ``evolution.threads`` is
``threads // K``; results do not depend on it). An interrupted experiment resumes: every run directory
that holds a checkpoint is continued, and a finished run stops at once; a run whose checkpoint is already
at or past the generation cap is left untouched (no file of it is rewritten), so a study grown in rounds
of rising caps (``studies/replication/replication.sh``) keeps the config and status of its runs that are
ahead. ``OUT/summary.json`` and
``OUT/summary.md`` hold the best fitness per run and the median with its spread.

A study is several environments at once, ``NAME=CONFIG`` each, in ``OUT/NAME/run_<i>``, and
can be spread over many machines (docs/cluster.md): ``--mpi`` places the runs on the ranks of an MPI
job (``mpirun -np R python -m animat experiment ... --mpi``, needs mpi4py), ``--index I`` runs only
run I of the study (one task of a Slurm array). Every run depends only on its config and seed, never
on where it ran.
"""

from __future__ import annotations

import json
import os
import statistics
import threading
import warnings
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Dict, List, Optional, Sequence, Tuple

from . import _core
from .pipeline import load_config


@dataclass
class RunRecord:
    """One run of an experiment, as written to summary.json."""

    index: int
    seed: int
    path: str
    best: float
    generations: int
    best_cells: int
    stop_reason: str
    wall_seconds: float


def _checkpoint_generation(out: Path) -> int:
    """The generation a run's checkpoint.json holds (its payload's ``generation``)."""
    wrapper = json.loads((out / "checkpoint.json").read_text(encoding="utf-8"))
    return int(json.loads(wrapper["payload"])["generation"])


def _record_at_cap(config: _core.Config, out: Path, index: int) -> Optional[RunRecord]:
    """The record of a run whose checkpoint is at or past the config's generation cap, read from its
    files; None when it has no cap, no checkpoint or is below the cap (then it is resumed). Resuming it
    would change no file, but would give this round's cap as the reason the run stopped."""
    cap = int(config["evolution.generations"])
    if cap <= 0 or not (out / "checkpoint.json").exists():
        return None
    try:
        if _checkpoint_generation(out) < cap:
            return None
    except (ValueError, KeyError, TypeError):  # unreadable: the resume reports it, naming the file
        return None
    from .run import read_history

    last = read_history(out / "history.csv")[-1]
    status = json.loads((out / "status.json").read_text(encoding="utf-8")) if (out / "status.json").exists() else {}
    return RunRecord(
        index=index,
        seed=int(config["evolution.seed"]),
        path=str(out),
        best=float(last["best"]),
        generations=int(last["generation"]),
        best_cells=int(last["best_cells"]),
        stop_reason=str(
            status.get("stop_reason", f"already at generation {int(last['generation'])}, past the cap {cap}")
        ),
        wall_seconds=float(last["wall_seconds"]),
    )


def _run_one(
    config: _core.Config,
    out: Path,
    index: int,
    quiet: bool,
    stop: Optional[threading.Event] = None,
    label: str = "",
) -> Optional[RunRecord]:
    ahead = _record_at_cap(config, out, index)
    if ahead is not None:
        return ahead
    resume = (out / "checkpoint.json").exists()
    result = _core.evolve(config, out=str(out), resume=resume, quiet=quiet, stop=stop, label=label)
    if not result.history:  # stopped before its initial population was complete: nothing to record
        return None
    last = result.history[-1]
    return RunRecord(
        index=index,
        seed=int(config["evolution.seed"]),
        path=str(out),
        best=last.best,
        generations=last.generation,
        best_cells=last.best_cells,
        stop_reason=result.stop_reason,
        wall_seconds=last.wall_seconds,
    )


def summarize(records: Sequence[RunRecord]) -> Dict[str, float]:
    """Median, min, max and quartiles of the runs' best fitness."""
    bests = sorted(r.best for r in records)
    if not bests:
        return {}
    q = statistics.quantiles(bests, n=4) if len(bests) >= 2 else [bests[0]] * 3
    return {
        "runs": len(bests),
        "median": statistics.median(bests),
        "min": bests[0],
        "max": bests[-1],
        "q1": q[0],
        "q3": q[2],
    }


def run_experiment(
    config_path: str,
    runs: int,
    out: str,
    parallel: int = 1,
    threads: int = 0,
    generations: Optional[int] = None,
    wall_seconds: Optional[float] = None,
    overrides: Sequence[str] = (),
    quiet: bool = True,
) -> List[RunRecord]:
    """Run (or resume) ``runs`` independent seeds of a config; returns one record per run.

    config_path: TOML file. out: experiment directory (OUT/run_<i>, summary.json, summary.md).
    parallel: runs at once. threads: cores in all (0 = all). generations / wall_seconds: per-run cap
    and budget overriding the config. overrides: "section.key=value" strings applied to the config.
    One environment of :func:`run_study`.
    """
    by_env = run_study(
        [config_path],
        runs,
        out,
        parallel=parallel,
        threads=threads,
        generations=generations,
        wall_seconds=wall_seconds,
        overrides=overrides,
        quiet=quiet,
    )
    return next(iter(by_env.values()))


def write_summary(root: Path, config_path: str, records: Sequence[RunRecord]) -> None:
    """Write OUT/summary.json and OUT/summary.md."""
    stats = summarize(records)
    (root / "summary.json").write_text(
        json.dumps({"config": str(config_path), "runs": [asdict(r) for r in records], "best_fitness": stats}, indent=1)
        + "\n"
    )
    lines = [
        f"# Experiment {root}",
        "",
        f"config: `{config_path}`",
        "",
        "| run | seed | best fitness | generations | cells of best | stop |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    lines += [
        f"| {r.index} | {r.seed} | {r.best:.4f} | {r.generations} | {r.best_cells} | {r.stop_reason} |" for r in records
    ]
    if stats:
        lines += [
            "",
            f"median best fitness {stats['median']:.4f} (min {stats['min']:.4f}, max {stats['max']:.4f}, "
            f"quartiles {stats['q1']:.4f} to {stats['q3']:.4f}) over {stats['runs']} runs",
        ]
    (root / "summary.md").write_text("\n".join(lines) + "\n")


# --- Studies: several environments, on MPI ranks or as array tasks ---------------------------------


@dataclass
class _Task:
    env: str
    config_path: str
    index: int  # run index within the environment
    out: Path


def _environments(configs: Sequence[str]) -> List[Tuple[str, str]]:
    """``NAME=PATH`` or ``PATH`` -> [(name, path)], names unique. A PATH is named by its file name less
    ``.toml``: ``configs/paper_dn0.5.toml`` and the packaged ``paper_dn0.5`` are both ``paper_dn0.5``
    (not the stem, which cuts at the dot)."""
    envs = []
    for c in configs:
        name, sep, path = c.partition("=")
        if not sep:
            name, path = Path(c).name.removesuffix(".toml"), c
        if not name or not path:
            raise ValueError(f"experiment: expected CONFIG or NAME=CONFIG, got {c!r}")
        envs.append((name, path))
    names = [n for n, _ in envs]
    if len(set(names)) != len(names):
        raise ValueError(f"experiment: environment names must differ, got {names}")
    return envs


def _mpi_world():
    """mpi4py's COMM_WORLD, or a clear error saying how to get it."""
    try:
        from mpi4py import MPI  # noqa: PLC0415 - optional dependency
    except ImportError as e:
        raise RuntimeError(
            "--mpi needs mpi4py: .venv/bin/pip install mpi4py (and an MPI: apt-get install "
            "libopenmpi-dev openmpi-bin, as scripts/setup.sh does)"
        ) from e
    return MPI.COMM_WORLD


def launched_ranks() -> int:
    """Ranks of the MPI job this process was started in by mpirun/srun (1 when none)."""
    for var in ("OMPI_COMM_WORLD_SIZE", "PMI_SIZE"):
        if os.environ.get(var, "").isdigit():
            return int(os.environ[var])
    return 1


def run_study(
    configs: Sequence[str],
    runs: int,
    out: str,
    *,
    mpi: bool = False,
    index: Optional[Sequence[int]] = None,
    parallel: int = 1,
    threads: int = 0,
    generations: Optional[int] = None,
    wall_seconds: Optional[float] = None,
    overrides: Sequence[str] = (),
    quiet: bool = True,
    log=print,
) -> Dict[str, List[RunRecord]]:
    """Run (or resume) ``runs`` seeds of every environment; returns the records by environment name.

    configs: ``PATH`` or ``NAME=PATH``; one plain PATH keeps the single-experiment layout OUT/run_<i>,
    otherwise runs go to OUT/NAME/run_<i>. Runs are numbered env-major over the study (run i of the
    e-th environment is task e * runs + i); ``index`` runs only those tasks and writes no summary;
    ``mpi`` deals the tasks round-robin over the ranks of COMM_WORLD (rank 0 writes the summaries).
    threads: cores per machine in all (0 = all), shared by the ranks on it and their ``parallel`` runs.
    """
    if runs < 1:
        raise ValueError(f"experiment: --runs must be >= 1, got {runs}")
    if parallel < 1:
        raise ValueError(f"experiment: --parallel must be >= 1, got {parallel}")
    envs = _environments(configs)
    nested = len(envs) > 1 or "=" in configs[0]
    root = Path(out)
    tasks = [
        _Task(name, path, i, (root / name if nested else root) / f"run_{i}") for name, path in envs for i in range(runs)
    ]
    if index is not None:
        for t in index:
            if not 0 <= t < len(tasks):
                raise ValueError(
                    f"experiment: --index {t} is outside the study's {len(tasks)} runs "
                    f"(0 to {len(tasks) - 1}: {len(envs)} environment(s) x {runs} runs)"
                )
    ranks = launched_ranks()
    if ranks > 1 and not mpi:
        raise RuntimeError(
            f"experiment: started as one of {ranks} MPI ranks without --mpi: every rank would run "
            "every run; add --mpi to place the runs on the ranks"
        )
    comm = _mpi_world() if mpi else None
    rank, size = (comm.Get_rank(), comm.Get_size()) if comm is not None else (0, 1)
    local = 1
    if comm is not None:
        from mpi4py import MPI  # noqa: PLC0415

        local = comm.Split_type(MPI.COMM_TYPE_SHARED).Get_size()
    cores = (
        threads
        if threads > 0
        else len(os.sched_getaffinity(0))
        if hasattr(os, "sched_getaffinity")
        else (os.cpu_count() or 1)
    )
    per_run = max(1, cores // max(1, local) // parallel)

    bases = {}
    for name, path in envs:
        base = load_config(path)  # a file, or a packaged config by name
        base.apply_overrides(list(overrides))  # checked together: their order does not matter
        if generations is not None:
            base["evolution.generations"] = int(generations)
        if wall_seconds is not None:
            base["evolution.wall_seconds"] = float(wall_seconds)
        base["evolution.threads"] = per_run
        bases[name] = base
        if rank == 0 and int(base["evolution.generations"]) == 0 and float(base["evolution.wall_seconds"]) == 0:
            warnings.warn(
                f"experiment: {name}: no generation cap (--generations) and no wall-clock budget (--wall-seconds): "
                f"each run stops only after {int(base['evolution.stall_generations'])} generations without "
                "improvement (hours)",
                UserWarning,
                stacklevel=2,
            )
    chosen = list(index) if index is not None else list(range(len(tasks)))
    mine = chosen[rank::size]

    results: List[Tuple[int, Optional[RunRecord], Optional[str]]] = []
    lock = threading.Lock()
    pending = list(mine)
    # The runs live in worker threads, where Ctrl-C is not delivered: the main thread catches it and
    # sets `stop`, which every running evolve polls between evaluations (each writes its checkpoint),
    # and no new run starts.
    stop = threading.Event()
    # Thread.join() interrupted by Ctrl-C can mark a running thread as stopped (CPython issue 90882), so
    # the main thread waits on this event instead, set by the last worker to finish.
    active = [0]
    all_done = threading.Event()

    def work():
        while True:
            with lock:
                if not pending or stop.is_set():
                    return
                t = pending.pop(0)
            task = tasks[t]
            cfg = bases[task.env].copy()
            cfg["evolution.seed"] = int(bases[task.env]["evolution.seed"]) + task.index
            task.out.parent.mkdir(parents=True, exist_ok=True)
            try:
                # Runs share the process's output: every line names its run.
                rec = _run_one(cfg, task.out, task.index, quiet, stop, label=f"{task.env} run {task.index}")
                if rec is None:
                    if stop.is_set():  # stopped while drawing its initial population: nothing to record
                        return
                    raise RuntimeError(f"{task.out}: the run ended before its initial population was complete")
                if not quiet:
                    log(
                        f"{task.env} run {task.index} (rank {rank}): best {rec.best:.4f} after {rec.generations} "
                        f"generations ({rec.stop_reason})"
                    )
                with lock:
                    results.append((t, rec, None))
            except Exception as e:  # noqa: BLE001 - reported with the others by rank 0
                with lock:
                    results.append((t, None, f"{task.env} run {task.index}: {e}"))

    def worker():
        try:
            work()
        finally:
            with lock:
                active[0] -= 1
                if active[0] == 0:
                    all_done.set()

    workers = [
        threading.Thread(target=worker, name=f"animat-study-{k}") for k in range(min(parallel, max(1, len(mine))))
    ]
    active[0] = len(workers)
    for w in workers:
        w.start()
    interrupted = False
    try:
        while not all_done.wait(0.1):
            pass
    except KeyboardInterrupt:
        interrupted = True
        stop.set()
        while not all_done.wait(0.1):
            pass
    for w in workers:
        w.join()
    if interrupted:
        if index is None and comm is None:  # the finished runs are summarised; the others resume
            for name, path in envs:
                done = [
                    rec for t, rec, _ in sorted(results, key=lambda r: r[0]) if rec is not None and tasks[t].env == name
                ]
                if done:
                    write_summary(root / name if nested else root, path, done)
        raise KeyboardInterrupt(
            f"experiment {root}: interrupted; every run stopped with a checkpoint of its last "
            f"complete generation; run the same command again to resume"
        )
    if comm is not None:
        gathered = comm.gather(results, root=0)
        if rank != 0 or gathered is None:  # only rank 0 receives the gathered list
            return {}
        results = [r for part in gathered for r in part]
    errors = [e for _, _, e in sorted(results, key=lambda r: r[0]) if e]
    by_env: Dict[str, List[RunRecord]] = {name: [] for name, _ in envs}
    for t, rec, _ in sorted(results, key=lambda r: r[0]):
        if rec is not None:
            by_env[tasks[t].env].append(rec)
    if index is None:
        for name, path in envs:
            write_summary(root / name if nested else root, path, by_env[name])
    if errors:
        raise RuntimeError("; ".join(errors))
    return by_env
