#!/usr/bin/env python3
"""What the exploit guard's reference swims cost per generation (docs/performance.md): a GA run of
a config (default: the regime preset, configs/regime_dn0.5.toml, evaluation.reference_check =
"select") driven through animat.GA on one thread, with the CPU time of the generation's own
evaluations (animat.evaluate, here) apart from the CPU time inside ask() and tell(), which is the
reference swims at dt/reference_substeps of the elite candidates plus the GA's own work (about a
millisecond a generation, docs/performance.md).

It also counts the reference swims from the checkpoint after each generation (exact, independent of
load): "swum" are the referenced individuals whose genome no individual referenced in the previous
generation had (the engine reuses a remembered genome's reference), "without reuse" those that are not
the elites carried over with their reference (what the engine swam before it remembered references).

    PYTHONPATH=build/python .venv/bin/python bench/reference_swim_cost.py --generations 20 --seed 1
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

import animat
from animat.pipeline import load_config

REPO = Path(__file__).resolve().parents[1]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--config", default=str(REPO / "configs" / "regime_dn0.5.toml"))
    ap.add_argument("--generations", type=int, default=20)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    config = load_config(args.config)
    config["evolution.seed"] = args.seed
    config["evolution.threads"] = 1  # the reference swims on this thread too
    ga = animat.GA(config)
    elites = int(config["evolution.elites"])
    if int(config["evolution.islands"]) != 1:
        ap.error("the counts assume one island (the elites are the population's first places)")
    # per completed generation: (generation, evaluations, evaluation CPU s, guard CPU s, swum, without reuse)
    rows = []
    evaluations, eval_cpu, guard_cpu = 0, 0.0, 0.0
    previous: set = set()
    while len(rows) <= args.generations:
        t0 = time.process_time()
        genomes = ga.ask()
        guard_cpu += time.process_time() - t0
        t0 = time.process_time()
        results = [animat.evaluate(g, config) for g in genomes]
        eval_cpu += time.process_time() - t0
        evaluations += len(genomes)
        t0 = time.process_time()
        stats = ga.tell(results)
        guard_cpu += time.process_time() - t0
        if stats is not None:
            population = json.loads(json.loads(ga.checkpoint())["payload"])["population"]
            referenced = [
                (i, json.dumps(p["genome"])) for i, p in enumerate(population) if p.get("reference") is not None
            ]
            swum = sum(1 for _, g in referenced if g not in previous)
            without_reuse = sum(1 for i, _ in referenced if i >= elites or stats.generation == 0)
            previous = {g for _, g in referenced}
            rows.append((stats.generation, evaluations, eval_cpu, guard_cpu, swum, without_reuse))
            evaluations, eval_cpu, guard_cpu = 0, 0.0, 0.0
    print(
        f"config {args.config}, seed {args.seed}, reference_check = {config['evaluation.reference_check']}, "
        f"reference_substeps = {config['evaluation.reference_substeps']}; CPU seconds, one thread"
    )
    print(
        "| generation | evaluations | their CPU s | CPU s in ask() + tell() (reference swims) | guard over evaluations "
        "| reference swims | without reuse |"
    )
    print("|---|---|---|---|---|---|---|")
    for g, n, e, r, s, w in rows:
        print(f"| {g} | {n} | {e:.2f} | {r:.2f} | {r / e:.2f}x | {s} | {w} |")
    later = rows[1:]
    if later:
        e = statistics.median(r[2] for r in later)
        r = statistics.median(r[3] for r in later)
        evaluation_cpu = sum(x[2] for x in later)
        guard = sum(x[3] for x in later)
        swum = sum(x[4] for x in later)
        without = sum(x[5] for x in later)
        print(
            f"\nlater generations (median): evaluations {e:.2f} s, guard {r:.2f} s; "
            f"the guard is {guard / (evaluation_cpu + guard):.0%} of their CPU time in all"
        )
        if swum:
            # the guard's CPU is almost all reference swims (the GA's own work is about a millisecond)
            per_swim = guard / swum
            guard_without = per_swim * without
            print(
                f"reference swims: {swum} ({swum / len(later):.1f} a generation) against {without} without reuse "
                f"({without / len(later):.1f}); at {per_swim:.3f} CPU s a swim the guard would take "
                f"{guard_without:.2f} s without reuse, {guard_without / (evaluation_cpu + guard_without):.0%} of "
                f"the CPU time; a generation costs {(evaluation_cpu + guard) / (evaluation_cpu + guard_without):.2f} "
                "of what it would"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
