#!/usr/bin/env python3
"""Does an evolved fitness survive refinement? (docs/accuracy.md "Evolved swimmers")

Takes the best genome of each run directory given (the last entry of its lineage, developed and
swum with the run's own config.toml) and swims it over the evaluation horizon (4000 steps of the
default dt = 1/60, 66.7 time units) at the steps

    h = 1/30 (dt 1/30), 1/60 (the default), 1/120, 1/240 and the reference 1/960 (dt/16)

recording, per genome and step: fitness (|COM displacement|), validity, collisions resolved, the
smallest S/S0, and the CPU time of the swim. It also measures how chaotic each swim is: the spread
of the fitness at the default step when the initial cell positions are perturbed by 1e-6 (four
draws). A discretisation error below that spread is noise that no step size removes.

    PYTHONPATH=build/python .venv/bin/python bench/accuracy_evolved.py runs/study/*/run_* \\
        --csv bench/results/accuracy_evolved.csv --plot docs/images/accuracy_evolved.png

prints the Markdown tables that docs/accuracy.md quotes.
"""

from __future__ import annotations

import argparse
import concurrent.futures as cf
import csv
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

import animat

HORIZON_STEPS = 4000
DEFAULT_DT = 1.0 / 60.0
# (label, dt, substeps): h = dt / substeps; the reference is the default dt in 16 substeps.
SETTINGS = [("1/30", 1 / 30, 1), ("1/60", 1 / 60, 1), ("1/120", 1 / 60, 2), ("1/240", 1 / 60, 4), ("1/960", 1 / 60, 16)]
REFERENCE = "1/960"
DEFAULT = "1/60"
PERTURBATION = 1e-6
DRAWS = 4


def best_of(run: Path):
    lineage = sorted((run / "best").glob("gen_*.json"))
    if not lineage:
        raise SystemExit(f"{run}: no best/gen_*.json")
    data = json.loads(lineage[-1].read_text())
    return int(data["generation"]), animat.Genome.from_json(json.dumps(data["genome"]))


def config_for(run: Path, dt: float, substeps: int) -> animat.Config:
    c = animat.load_config(str(run / "config.toml"))
    horizon = c["evaluation.steps"] * c["physics.dt"]
    c["physics.dt"] = dt
    c["physics.substeps"] = substeps
    c["evaluation.steps"] = int(round(horizon / dt))
    return c


def measure(run_path: str) -> list[dict]:
    """Every setting for the best of one run (one worker process)."""
    run = Path(run_path)
    generation, genome = best_of(run)
    base = animat.load_config(str(run / "config.toml"))
    env = f"d_N = {base['scene.drag_normal']:g}, {base['development.max_cells']} cells"
    rows = []
    for label, dt, sub in SETTINGS:
        c = config_for(run, dt, sub)
        embryo = animat.develop(genome, c)
        body = animat.build_body(embryo, config=c)
        t0 = time.process_time()
        r = animat.swim(body, config=c)
        cpu = time.process_time() - t0
        rows.append(
            dict(
                run=str(run),
                environment=env,
                drag_normal=base["scene.drag_normal"],
                generation=generation,
                cells=embryo.cell_count,
                step=label,
                h=dt / sub,
                fitness=r.distance,
                valid=r.valid,
                collisions=r.collisions,
                min_area_ratio=r.min_area_ratio,
                drag_limited=r.drag_limited,
                cpu_seconds=cpu,
                median_frequency=float(np.median(embryo.frequency)),
            )
        )
    # Chaos: perturbed starts at the default step.
    c = config_for(run, DEFAULT_DT, 1)
    embryo = animat.develop(genome, c)
    body = animat.build_body(embryo, config=c)
    rng = np.random.default_rng(2026)
    spread = []
    for _ in range(DRAWS):
        p = np.asarray(body.positions) + PERTURBATION * rng.standard_normal(np.asarray(body.positions).shape)
        b = animat.build_body(p, embryo.amplitude, embryo.frequency, embryo.phase, config=c)
        spread.append(animat.swim(b, config=c).distance)
    for row in rows:
        row["chaos_min"] = min(spread)
        row["chaos_max"] = max(spread)
    return rows


def percent(a: float, ref: float) -> float:
    return 100.0 * abs(a - ref) / max(abs(ref), 1e-12)


def summarize(rows: list[dict]) -> str:
    by_run: dict[str, dict[str, dict]] = {}
    for r in rows:
        by_run.setdefault(r["run"], {})[r["step"]] = r
    out = []
    out.append(
        "| environment | run | gen. | cells | median f | collisions | min S/S0 | "
        + " | ".join(f"h = {s[0]}" for s in SETTINGS)
        + " | error at 1/60 | chaos spread (1e-6) |"
    )
    out.append("|" + "---|" * (8 + len(SETTINGS)))
    for run, steps in sorted(by_run.items(), key=lambda kv: (kv[1][DEFAULT]["drag_normal"], kv[0])):
        d = steps[DEFAULT]
        ref = steps[REFERENCE]["fitness"]
        chaos = 100.0 * (d["chaos_max"] - d["chaos_min"]) / max(ref, 1e-12)
        fits = " | ".join(
            f"{steps[s[0]]['fitness']:.3f}{'' if steps[s[0]]['valid'] else ' (invalid)'}" for s in SETTINGS
        )
        out.append(
            f"| {d['environment']} | {Path(run).name} | {d['generation']} | {d['cells']} | "
            f"{d['median_frequency']:.2f} | {d['collisions']} | {d['min_area_ratio']:.3f} | {fits} | "
            f"{percent(d['fitness'], ref):.2f}% | {chaos:.2f}% |"
        )
    out.append("")
    out.append(
        "| h | genomes | invalid | fitness error median | p90 | max | within 1 % (or 0.05) | CPU ms per swim (median) | cost vs 1/60 |"
    )
    out.append("|---|---|---|---|---|---|---|---|---|")
    default_cpu = np.median([s[DEFAULT]["cpu_seconds"] for s in by_run.values()])
    for label, _, _ in SETTINGS:
        if label == REFERENCE:
            continue
        errs, ok, invalid, cpu = [], 0, 0, []
        for steps in by_run.values():
            ref = steps[REFERENCE]["fitness"]
            f = steps[label]["fitness"]
            errs.append(percent(f, ref))
            ok += abs(f - ref) <= max(0.01 * abs(ref), 0.05)
            invalid += not steps[label]["valid"]
            cpu.append(steps[label]["cpu_seconds"])
        e = np.array(errs)
        out.append(
            f"| {label}{' (default)' if label == DEFAULT else ''} | {len(e)} | {invalid} | {np.median(e):.2f}% | "
            f"{np.percentile(e, 90):.2f}% | {e.max():.2f}% | {ok}/{len(e)} | {1e3 * np.median(cpu):.1f} | "
            f"{np.median(cpu) / default_cpu:.2f}x |"
        )
    return "\n".join(out)


def plot(rows: list[dict], path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    by_run: dict[str, dict[str, dict]] = {}
    for r in rows:
        by_run.setdefault(r["run"], {})[r["step"]] = r
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    colours = {}
    for _run, steps in by_run.items():
        ref = steps[REFERENCE]["fitness"]
        hs = [steps[s[0]]["h"] for s in SETTINGS if s[0] != REFERENCE]
        es = [max(percent(steps[s[0]]["fitness"], ref), 1e-4) for s in SETTINGS if s[0] != REFERENCE]
        env = steps[DEFAULT]["environment"]
        colour = colours.setdefault(env, f"C{len(colours)}")
        ax.loglog(
            hs, es, "o-", color=colour, alpha=0.7, label=env if env not in ax.get_legend_handles_labels()[1] else None
        )
    ax.axhline(1.0, color="k", lw=0.8, ls="--")
    ax.axvline(DEFAULT_DT, color="grey", lw=0.8, ls=":")
    ax.set_xlabel("step h")
    ax.set_ylabel("fitness error vs h = 1/960 (%)")
    ax.set_title("Evolved bests: fitness error against the step")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("runs", nargs="+", help="run directories (config.toml + best/)")
    ap.add_argument("--csv", help="write every measurement here")
    ap.add_argument("--plot", help="write the error-vs-step figure here")
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    args = ap.parse_args()
    try:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    except OSError:
        commit = "?"
    print(
        f"# accuracy_evolved: {len(args.runs)} runs, {args.workers} workers, {platform.processor() or platform.machine()}, "
        f"{os.cpu_count()} cores, Python {platform.python_version()}, commit {commit}",
        file=sys.stderr,
    )
    rows = []
    with cf.ProcessPoolExecutor(args.workers) as pool:
        for part in pool.map(measure, args.runs):
            rows.extend(part)
    if args.csv:
        Path(args.csv).parent.mkdir(parents=True, exist_ok=True)
        with open(args.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    if args.plot:
        plot(rows, args.plot)
    print(summarize(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
