"""Independent evolutionary runs of one configuration: the replication workhorse (issue 10).

    python -m animat experiment configs/paper_dn2.toml --runs 3 --out runs/replication/dn2

Run ``i`` uses seed ``evolution.seed + i`` and lives in ``OUT/run_<i>``. Runs go one after another, or
``--parallel K`` at a time with the cores split between them (each run's ``evolution.threads`` is
``threads // K``; results do not depend on it). An interrupted experiment resumes: every run directory
that holds a checkpoint is continued, and a finished run stops at once. ``OUT/summary.json`` and
``OUT/summary.md`` hold the best fitness per run and the median with its spread.
"""
from __future__ import annotations

import json
import os
import statistics
import threading
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Dict, List, Optional, Sequence

from . import _core


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


def _run_one(config: "_core.Config", out: Path, index: int, quiet: bool) -> RunRecord:
    resume = (out / "checkpoint.json").exists()
    result = _core.evolve(config, out=str(out), resume=resume, quiet=quiet)
    last = result.history[-1]
    return RunRecord(index=index, seed=int(config["evolution.seed"]), path=str(out), best=last.best,
                     generations=last.generation, best_cells=last.best_cells, stop_reason=result.stop_reason,
                     wall_seconds=last.wall_seconds)


def summarize(records: Sequence[RunRecord]) -> Dict[str, float]:
    """Median, min, max and quartiles of the runs' best fitness."""
    bests = sorted(r.best for r in records)
    if not bests:
        return {}
    q = statistics.quantiles(bests, n=4) if len(bests) >= 2 else [bests[0]] * 3
    return {"runs": len(bests), "median": statistics.median(bests), "min": bests[0], "max": bests[-1],
            "q1": q[0], "q3": q[2]}


def run_experiment(config_path: str, runs: int, out: str, parallel: int = 1, threads: int = 0,
                   generations: Optional[int] = None, wall_seconds: Optional[float] = None,
                   overrides: Sequence[str] = (), quiet: bool = True) -> List[RunRecord]:
    """Run (or resume) ``runs`` independent seeds of a config; returns one record per run.

    config_path: TOML file. out: experiment directory. parallel: runs at once. threads: cores in all
    (0 = all). generations / wall_seconds: per-run cap and budget overriding the config.
    overrides: "section.key=value" strings applied to the config.
    """
    if runs < 1:
        raise ValueError(f"experiment: --runs must be >= 1, got {runs}")
    if parallel < 1:
        raise ValueError(f"experiment: --parallel must be >= 1, got {parallel}")
    base = _core.load_config(config_path)
    for o in overrides:
        base.apply_override(o)
    if generations is not None:
        base["evolution.generations"] = int(generations)
    if wall_seconds is not None:
        base["evolution.wall_seconds"] = float(wall_seconds)
    cores = threads if threads > 0 else (os.cpu_count() or 1)
    base["evolution.threads"] = max(1, cores // parallel)
    root = Path(out)
    root.mkdir(parents=True, exist_ok=True)

    records: List[Optional[RunRecord]] = [None] * runs
    errors: List[BaseException] = []
    lock = threading.Lock()
    pending = list(range(runs))

    def worker():
        while True:
            with lock:
                if not pending or errors:
                    return
                i = pending.pop(0)
            cfg = base.copy()
            cfg["evolution.seed"] = int(base["evolution.seed"]) + i
            try:
                record = records[i] = _run_one(cfg, root / f"run_{i}", i, quiet)
                if not quiet:
                    print(f"run {i}: best {record.best:.4f} after {record.generations} generations "
                          f"({record.stop_reason})", flush=True)
            except BaseException as e:  # noqa: BLE001 - reported after the other runs stop
                with lock:
                    errors.append(e)

    workers = [threading.Thread(target=worker) for _ in range(min(parallel, runs))]
    for w in workers:
        w.start()
    for w in workers:
        w.join()
    if errors:
        raise errors[0]
    done = [r for r in records if r is not None]
    write_summary(root, config_path, done)
    return done


def write_summary(root: Path, config_path: str, records: Sequence[RunRecord]) -> None:
    """Write OUT/summary.json and OUT/summary.md."""
    stats = summarize(records)
    (root / "summary.json").write_text(json.dumps(
        {"config": str(config_path), "runs": [asdict(r) for r in records], "best_fitness": stats}, indent=1) + "\n")
    lines = [f"# Experiment {root}", "", f"config: `{config_path}`", "",
             "| run | seed | best fitness | generations | cells of best | stop |", "| --- | --- | --- | --- | --- | --- |"]
    lines += [f"| {r.index} | {r.seed} | {r.best:.4f} | {r.generations} | {r.best_cells} | {r.stop_reason} |"
              for r in records]
    if stats:
        lines += ["", f"median best fitness {stats['median']:.4f} (min {stats['min']:.4f}, max {stats['max']:.4f}, "
                      f"quartiles {stats['q1']:.4f} to {stats['q3']:.4f}) over {stats['runs']} runs"]
    (root / "summary.md").write_text("\n".join(lines) + "\n")
