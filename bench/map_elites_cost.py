"""Cost of a MAP-Elites evaluation against a GA evaluation, on a tiny example: the paper's setting (32
cells, 4000 swim steps) with batches of 20 = a population of 20, generations 1..G timed (generation 0,
the random draws, is excluded from both), on `--threads` threads.

    PYTHONPATH=build/python .venv/bin/python bench/map_elites_cost.py [--generations 5] [--threads 1] [--repeat 3]

For each setting it prints the wall time per evaluated offspring (the median of `--repeat` runs). MAP-Elites
runs on the engine's search (`animat.MapElites` over `_core.SearchEngine`): the descriptors that every
evaluation measures during its own swim (cells, elongation, protrusions, ...) cost nothing more, and
the exploit guard's reference swims (`physics.substeps x evaluation.reference_substeps` = 16 x the step,
per new elite under "record") are part of `tell()`. The GA's guard re-evaluates only each new best of a
generation.
"""

import argparse
import os
import platform
import statistics
import time

import animat


def ga_cost(config, generations):
    ga = animat.GA(config)
    ga.step()  # generation 0
    n0, t = ga.evaluations, time.perf_counter()
    while ga.generation < generations:
        ga.step()
    return (time.perf_counter() - t) / (ga.evaluations - n0), ga.evaluations - n0


def map_elites_cost(config, generations, batch, descriptors, bins):
    me = animat.MapElites(config, animat.GridArchive(descriptors, bins), batch=batch)
    me.step()  # generation 0
    n0, t = me.evaluations, time.perf_counter()
    while me.generation < generations:
        me.step()
    return (time.perf_counter() - t) / (me.evaluations - n0), me.evaluations - n0, me


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--generations", type=int, default=5)
    p.add_argument("--batch", type=int, default=20)
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--repeat", type=int, default=3)
    args = p.parse_args()
    base = animat.Config()
    base["evolution.population"] = args.batch
    base["evolution.threads"] = args.threads
    print(
        f"machine: {platform.machine()}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}; animat "
        f"{animat.__version__}; {int(base['evaluation.steps'])} steps, batch = population = {args.batch}, "
        f"generations 1..{args.generations}, threads {args.threads}, median of {args.repeat}"
    )
    for guard in ("off", "record"):
        config = base.copy()
        config["evaluation.reference_check"] = guard
        runs = [ga_cost(config, args.generations) for _ in range(args.repeat)]
        per, n = statistics.median(r[0] for r in runs), runs[0][1]
        print(f"GA          reference_check={guard:6s}  {1000 * per:7.1f} ms per evaluation ({n} evaluations)")
        for descriptors, bins in (
            (["frequency", "cells"], (10, 64)),
            (["elongation", "protrusions"], (10, 8)),
            (["locomotion", "cells"], (6, 64)),
        ):
            runs = [
                map_elites_cost(config, args.generations, args.batch, descriptors, bins) for _ in range(args.repeat)
            ]
            per, n, me = statistics.median(r[0] for r in runs), runs[0][1], runs[0][2]
            print(
                f"MAP-Elites  reference_check={guard:6s}  {1000 * per:7.1f} ms per evaluation ({n} evaluations; "
                f"{'+'.join(descriptors)}; {len(me.archive)} elites, "
                f"{me.history['reference_evaluations'][-1]} reference swims in all)"
            )


if __name__ == "__main__":
    main()
