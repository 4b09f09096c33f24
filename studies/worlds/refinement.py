"""Does the ranking survive refinement? Re-swims every lineage best of a screen's kept runs.

For each run kept by ``crawl_screen.sh`` (``studies/worlds/crawl_screen/<name>/``, the default
``--runs``) or by ``studies/control/screen.sh`` (``--runs studies/control/screen``), every genome
that became the run's best is evaluated again, independently of the run's own monitor, with the
run's config at its step dt and at dt/16 (``physics.dt`` / 16 with 16 times the swim and settle
steps: the same simulated time). One row per lineage best goes to ``results/crawl_refinement.csv``;
the summary printed per grid point is what ``docs/worlds.md`` quotes.

    PYTHONPATH=build/python .venv/bin/python studies/worlds/refinement.py
    PYTHONPATH=build/python .venv/bin/python studies/worlds/refinement.py --ladder g1_record_seed2:4
    PYTHONPATH=build/python .venv/bin/python studies/worlds/refinement.py --runs studies/control/screen \
        --out studies/control/results/screen_refinement.csv

``--ladder RUN:GENERATION ...`` prints, for those lineage bests, the fitness and the airborne share
at dt, dt/2, dt/4, dt/8, dt/16 and dt/32 (does the fitness converge as the step shrinks?).

Columns: run, gravity, stiffness (scene.spring_stiffness), guard, seed, generation (at which the genome became the best), cells,
recorded (the fitness the run recorded), fitness (re-evaluated at dt), fitness_fine (at dt/16),
error (fitness / fitness_fine - 1), fitness_finest (at dt/32), ranked_error (the error of the fitness
the GA ranked by: fitness / fitness_fine - 1 under the guard's "record", and fitness_fine /
fitness_finest - 1 under "select", where the GA ranks by the reference at dt/16), valid, valid_fine (the body's invariants held for the whole
swim), airborne_share (Box2D steps in which the floor pushed no cell / Box2D steps, at dt; empty
without a floor), elongation, protrusions and symmetric_pair (``animat.shape`` of the developed body),
final (1 for the run's last lineage best).

``--cost POINT ...`` prints what the step costs for the final bests of those grid points: the fitness
error at dt to dt/16 against dt/32 and the CPU time of one evaluation.

``--only GLOB`` re-swims only the runs whose name matches; ``--set KEY=VALUE`` (repeatable) re-swims
them with that config value instead of the run's (another contact law, say), into its own ``--out``.

Runs already in ``--out`` are not swum again (delete it to redo them). The summary groups the runs by
their grid point (the run's name without its seed).
"""

from __future__ import annotations

import argparse
import csv
import fnmatch
import os
import platform
import re
import sys
import time
from pathlib import Path

import numpy as np

import animat
import animat.shape

HERE = Path(__file__).resolve().parent
FIELDS = (
    "run",
    "gravity",
    "stiffness",
    "guard",
    "seed",
    "generation",
    "cells",
    "recorded",
    "fitness",
    "fitness_fine",
    "error",
    "fitness_finest",
    "ranked_error",
    "valid",
    "valid_fine",
    "airborne_share",
    "elongation",
    "protrusions",
    "symmetric_pair",
    "final",
)


def refined(config, factor: int):
    """The same swim at dt / factor: factor times the swim and settle steps."""
    fine = config.copy()
    fine["physics.dt"] = config["physics.dt"] / factor
    fine["evaluation.steps"] = config["evaluation.steps"] * factor
    fine["evaluation.settle_steps"] = config["evaluation.settle_steps"] * factor
    return fine


def rows_of(run_dir: Path, overrides=()):
    run = animat.Run(run_dir)
    cfg = run.config.copy()
    for key, value in overrides:
        cfg[key] = value
    fine = refined(cfg, 16)
    finest = refined(cfg, 32)
    select = cfg["evaluation.reference_check"] == "select"
    lineage = run.best_genomes
    box2d_steps = cfg["evaluation.steps"] * cfg["physics.substeps"]
    for i, entry in enumerate(lineage):
        coarse = animat.evaluate(entry.genome, cfg)
        refined_result = animat.evaluate(entry.genome, fine)
        finest_result = animat.evaluate(entry.genome, finest)
        shape = animat.shape.genome_shape(entry.genome, cfg)
        ranked, truth = (
            (refined_result.fitness, finest_result.fitness) if select else (coarse.fitness, refined_result.fitness)
        )
        yield {
            "run": run_dir.name,
            "gravity": cfg["scene.gravity"],
            "stiffness": cfg["scene.spring_stiffness"],
            "guard": cfg["evaluation.reference_check"],
            "seed": run_dir.name.rsplit("seed", 1)[1],
            "generation": entry.generation,
            "cells": coarse.cell_count,
            "recorded": entry.fitness,
            "fitness": coarse.fitness,
            "fitness_fine": refined_result.fitness,
            "error": coarse.fitness / refined_result.fitness - 1.0 if refined_result.fitness else float("nan"),
            "fitness_finest": finest_result.fitness,
            "ranked_error": ranked / truth - 1.0 if truth else float("nan"),
            "valid": int(coarse.valid),
            "valid_fine": int(refined_result.valid),
            "airborne_share": coarse.airborne_steps / box2d_steps if "ground" in cfg["scene.effects"] else "",
            "elongation": shape.elongation,
            "protrusions": shape.protrusion_count,
            "symmetric_pair": int(shape.symmetric_pair),
            "final": int(i == len(lineage) - 1),
        }


def parse_value(text: str):
    """A --set value: a number where it reads as one, else the text."""
    try:
        return float(text)
    except ValueError:
        return text


def point_of(run: str) -> str:
    """A run's grid point: its name without the seed."""
    return re.sub(r"_seed\d+$", "", run)


def summarize(rows) -> None:
    points = list(dict.fromkeys(point_of(r["run"]) for r in rows))
    print(
        "| point | runs | lineage bests | invalid (dt, dt/16) | dt vs dt/16: abs error p50 / p90 / max "
        "| ranked vs next finer: abs error p50 / p90 / max | final bests: ranked error | final bests: fitness "
        "at dt | final bests: airborne share | final bests: protrusions (symmetric pair) |"
    )
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for point in points:
        sel = [r for r in rows if point_of(r["run"]) == point]
        fin = [r for r in sel if int(r["final"])]
        err = np.abs([float(r["error"]) for r in sel])
        rerr = np.abs([float(r["ranked_error"]) for r in sel])
        ferr = ", ".join(f"{abs(float(r['ranked_error'])):.2%}" for r in fin)
        inv = sum(1 - int(r["valid"]) for r in sel), sum(1 - int(r["valid_fine"]) for r in sel)
        fit = ", ".join(f"{float(r['fitness']):.{3 if float(r['fitness']) < 10 else 1}f}" for r in fin)
        shapes = ", ".join(f"{r['protrusions']}{' (pair)' if int(r['symmetric_pair']) else ''}" for r in fin)
        air = ", ".join("-" if r["airborne_share"] == "" else f"{float(r['airborne_share']):.0%}" for r in fin)
        print(
            f"| {point} | {len(fin)} | {len(sel)} | {inv[0]}, {inv[1]} | "
            f"{np.percentile(err, 50):.2%} / {np.percentile(err, 90):.2%} / {err.max():.2%} | "
            f"{np.percentile(rerr, 50):.2%} / {np.percentile(rerr, 90):.2%} / {rerr.max():.2%} | "
            f"{ferr} | {fit} | {air} | {shapes} |"
        )


def ladder(runs: Path, specs) -> None:
    factors = (1, 2, 4, 8, 16, 32)
    print("| lineage best | " + " | ".join(f"dt/{f}" if f > 1 else "dt" for f in factors) + " |")
    print("| --- |" + " --- |" * len(factors))
    for spec in specs:
        name, generation = spec.rsplit(":", 1)
        run = animat.Run(runs / name)
        entries = [e for e in run.best_genomes if e.generation == int(generation)]
        if not entries:
            raise SystemExit(f"{runs / name}: no lineage best of generation {generation}")
        cfg = run.config
        cells = []
        for f in factors:
            r = animat.evaluate(entries[0].genome, refined(cfg, f) if f > 1 else cfg)
            share = r.airborne_steps / (cfg["evaluation.steps"] * cfg["physics.substeps"] * f)
            cells.append(f"{r.fitness:.2f} ({share:.0%})")
        print(f"| {spec} | " + " | ".join(cells) + " |", flush=True)


def cost(runs: Path, points) -> None:
    """What the step costs in accuracy and time: for the final bests of each grid point, the fitness
    error at dt/f against dt/32 (median and largest) and the CPU time of one evaluation relative to
    dt's (median over the bests; each evaluation timed once, so the machine's load enters)."""
    factors = (1, 2, 4, 8, 16)
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores; CPU time per evaluation, one thread")
    print("| point | step | fitness error vs dt/32: median / max | CPU time per evaluation (× dt's) |")
    print("| --- | --- | --- | --- |")
    for point in points:
        dirs = sorted(d for d in runs.iterdir() if point_of(d.name) == point and (d / "history.csv").is_file())
        if not dirs:
            raise SystemExit(f"{runs}: no kept run of point {point}")
        errors = {f: [] for f in factors}
        seconds = {f: [] for f in factors}
        for d in dirs:
            run = animat.Run(d)
            genome, cfg = run.best_genomes[-1].genome, run.config
            truth = animat.evaluate(genome, refined(cfg, 32)).fitness
            for f in factors:
                start = time.process_time()
                r = animat.evaluate(genome, refined(cfg, f) if f > 1 else cfg)
                seconds[f].append(time.process_time() - start)
                errors[f].append(abs(r.fitness / truth - 1.0))
        base = float(np.median(seconds[1]))
        for f in factors:
            e = np.array(errors[f])
            label = "dt" if f == 1 else f"dt/{f}"
            print(
                f"| {point} | {label} | {np.median(e):.2%} / {e.max():.2%} | "
                f"{np.median(seconds[f]) * 1e3:.0f} ms ({np.median(seconds[f]) / base:.1f}×) |",
                flush=True,
            )


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", default=str(HERE / "crawl_screen"), help="folder of kept runs")
    p.add_argument("--out", default=str(HERE / "results" / "crawl_refinement.csv"))
    p.add_argument("--summary-only", action="store_true", help="summarize --out without re-swimming")
    p.add_argument("--ladder", nargs="+", metavar="RUN:GENERATION", help="refinement ladder of lineage bests")
    p.add_argument("--cost", nargs="+", metavar="POINT", help="accuracy and cost of the step for these points")
    p.add_argument("--only", metavar="GLOB", help="re-swim only the runs whose name matches")
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="re-swim with this config value instead of the run's (needs --out)",
    )
    args = p.parse_args(argv)
    if args.ladder:
        ladder(Path(args.runs), args.ladder)
        return 0
    if args.cost:
        cost(Path(args.runs), args.cost)
        return 0
    overrides = []
    for item in args.set:
        key, sep, value = item.partition("=")
        if not sep:
            p.error(f"--set {item!r}: expected KEY=VALUE")
        overrides.append((key, parse_value(value)))
    if overrides and args.out == p.get_default("out"):
        p.error("--set re-swims with other values: give its own --out")
    out = Path(args.out)
    if not args.summary_only:
        runs = sorted(
            d
            for d in Path(args.runs).iterdir()
            if (d / "history.csv").is_file() and (args.only is None or fnmatch.fnmatch(d.name, args.only))
        )
        if not runs:
            print(f"{args.runs}: no kept runs (run studies/worlds/crawl_screen.sh first)", file=sys.stderr)
            return 1
        # Runs already in --out are kept as they are (delete it to re-swim them).
        rows = []
        if out.is_file():
            with open(out, newline="") as f:
                rows = [r for r in csv.DictReader(f) if r["run"] in {d.name for d in runs}]
        done = {r["run"] for r in rows}
        rows += [row for d in runs if d.name not in done for row in rows_of(d, overrides)]
        rows.sort(key=lambda r: (r["run"], int(r["generation"])))
        out.parent.mkdir(parents=True, exist_ok=True)
        with open(out, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=FIELDS, lineterminator="\n")
            w.writeheader()
            for r in rows:
                w.writerow({k: (f"{v:.9g}" if isinstance(v, float) else v) for k, v in r.items()})
    with open(out, newline="") as f:
        rows = list(csv.DictReader(f))
    summarize(rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
