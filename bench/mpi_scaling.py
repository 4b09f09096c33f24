#!/usr/bin/env python3
"""MPI scaling of animat_evolve: strong scaling (population 100 and 400 fixed) and weak
scaling (population 50 x ranks) over 1, 2, 4 ranks of one thread each on this machine, plus the GA
profile and the projection to many workers (build/bench_ga_profile). Writes bench/results/mpi_scaling.csv,
bench/results/ga_profile_<P>.jsonl and the Markdown tables printed at the end (docs/performance.md,
section "Scale-out with MPI").

    ANIMAT_BUILD_BENCH=ON scripts/build.sh
    .venv/bin/python bench/mpi_scaling.py [--generations 2] [--ranks 1 2 4] [--skip-profile]

Every configuration runs the embedded default config (the paper's d_N = 2, 32 cells, 4000 swim steps)
with seed 1; the times are the wall time of generation 0 (seeding the initial population) and the
mean wall time of the later generations, both from history.csv. Ranks beyond the machine's cores run
with --oversubscribe: their efficiency measures the machine, not the code.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import platform
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMPI_MCA_btl="self,vader")


def run(exe: Path, population: int, generations: int, ranks: int, threads: int, out: Path) -> dict:
    cmd = [
        str(exe),
        "--set",
        f"evolution.population={population}",
        "--generations",
        str(generations),
        "--seed",
        "1",
        "--threads",
        str(threads),
        "--out",
        str(out),
        "--quiet",
    ]
    if ranks > 0:
        cmd = ["mpirun", "--oversubscribe", "--bind-to", "none", "-np", str(ranks), *cmd]
    ru0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True, env=ENV)
    wall = time.perf_counter() - t0
    ru1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (ru1.ru_utime - ru0.ru_utime) + (ru1.ru_stime - ru0.ru_stime)  # every rank and mpirun
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed: {r.stderr[-2000:]}")
    with open(out / "history.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    t = [float(row["wall_seconds"]) for row in rows]
    later = (t[-1] - t[0]) / (len(t) - 1) if len(t) > 1 else float("nan")
    return {
        "population": population,
        "ranks": max(ranks, 1),
        "threads": threads,
        "mpirun": ranks > 0,
        "seeding_s": t[0],
        "generation_s": later,
        "process_wall_s": wall,
        "cpu_s": cpu,
        "best": rows[-1]["best"],
        "evaluations": rows[-1]["evaluations"],
    }


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", type=Path, default=ROOT / "build")
    ap.add_argument("--generations", type=int, default=2)
    ap.add_argument("--ranks", type=int, nargs="+", default=[1, 2, 4])
    ap.add_argument("--skip-profile", action="store_true")
    args = ap.parse_args()
    exe = args.build / "animat_evolve"
    results = ROOT / "bench" / "results"
    results.mkdir(parents=True, exist_ok=True)
    print(
        f"machine: {platform.node()} {os.cpu_count()} cores, load {os.getloadavg()}, "
        f"{subprocess.run(['mpirun', '--version'], capture_output=True, text=True).stdout.splitlines()[0]}",
        flush=True,
    )
    rows = []
    with tempfile.TemporaryDirectory() as tmp:

        def measure(kind, population, ranks, threads):
            out = Path(tmp) / f"{kind}_{population}_{ranks}_{threads}"
            load = os.getloadavg()[0]
            row = run(exe, population, args.generations, ranks, threads, out)
            row.update(kind=kind, load_before=load, load_after=os.getloadavg()[0])
            shutil.rmtree(out)
            rows.append(row)
            print(json.dumps(row), flush=True)
            return row

        for population in (100, 400):
            for ranks in args.ranks:
                measure("strong", population, ranks, 1)
            measure("threads", population, 0, 2)  # one process, two OpenMP threads, no mpirun
        for ranks in args.ranks:
            measure("weak", 50 * ranks, ranks, 1)
    with open(results / "mpi_scaling.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)

    md = [
        "| run | population | ranks x threads | generation 0 s | s per later generation | speedup (later) | "
        "efficiency | CPU s in all (every process) | CPU over 1 rank | load avg before/after |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    base = {}
    for r in rows:
        key = (r["kind"] if r["kind"] != "threads" else "strong", r["population"] if r["kind"] != "weak" else 0)
        if r["ranks"] == 1 and r["mpirun"] and key not in base:
            base[key] = r
    for r in rows:
        kind = r["kind"] if r["kind"] != "threads" else "strong"
        b = base.get((kind, r["population"] if kind != "weak" else 0))
        workers = r["ranks"] * r["threads"]
        if kind == "weak":
            speed = b["generation_s"] / r["generation_s"] * workers  # work grows with the ranks
        else:
            speed = b["generation_s"] / r["generation_s"]
        label = {"strong": "strong", "weak": "weak", "threads": "OpenMP only"}[r["kind"]]
        md.append(
            f"| {label} | {r['population']} | {r['ranks']} x {r['threads']}{'' if r['mpirun'] else ' (no mpirun)'} "
            f"| {r['seeding_s']:.2f} | {r['generation_s']:.2f} | {speed:.2f}x | {speed / workers:.0%} | "
            f"{r['cpu_s']:.1f} | {r['cpu_s'] / b['cpu_s'] / (1 if kind != 'weak' else workers):.3f} | "
            f"{r['load_before']:.1f} / {r['load_after']:.1f} |"
        )
    print("\n".join(md))

    if not args.skip_profile:
        prof = args.build / "bench_ga_profile"
        for population in (100, 400):
            text = subprocess.run([str(prof), str(population), "3"], capture_output=True, text=True, check=True).stdout
            (results / f"ga_profile_{population}.jsonl").write_text(text)
            print(text, flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
