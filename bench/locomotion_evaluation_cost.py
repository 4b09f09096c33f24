"""What an evaluation costs when a search reads the locomotion measure, which the engine classifies
during the evaluation's own swim (include/animat/locomotion.hpp, ``EvaluationResult.locomotion``),
against the GA's evaluation of the same genomes: per stored best (data/replication/*/run_*, each
with its run's config), ``animat.evaluate`` under

  (a) the run's config (search.algorithm "ga": nothing recorded),
  (b) MAP-Elites with descriptors [elongation, protrusions] (the shape measures, always computed),
  (c) MAP-Elites with descriptors [locomotion, cells] (the window recorded and classified),

and, with ``--shape``, what the always-on shape measures add to (a): timed as ``_core.describe_shape`` of
the developed body (the call evaluate() makes, plus its Python arguments and result), counted as the
inclusive instructions of ``body_shape`` inside the GA's evaluations.

    PYTHONPATH=build/python .venv/bin/python bench/locomotion_evaluation_cost.py [--runs 10] [--repeat 3]

Prints the machine, load and settings, then per configuration the median ms per evaluation (each
genome's time the median of ``--repeat`` calls, the three configurations interleaved per genome) and
the instructions per evaluation (callgrind, ``--count`` bests per condition evaluated once in a child
process per configuration: the inclusive cost of the ``evaluate`` that animat.evaluate runs), and their
ratios to (a).
"""

import argparse
import glob
import os
import platform
import statistics
import subprocess
import sys
import tempfile
from functools import partial
from pathlib import Path

from locomotion_engine_cost import timed  # bench/, this script's folder

import animat
from animat import _core

ROOT = Path(__file__).resolve().parents[1]


def instructions(label, per_condition, functions):
    """Instructions per genome in each of ``functions`` (their inclusive costs, by callgrind_annotate)
    when a child process evaluates ``per_condition`` bests of each condition under configuration
    ``label``: valgrind's callgrind, as bench/speed_budget.py counts (reproducible on a shared machine)."""
    with tempfile.TemporaryDirectory() as d:
        out = f"{d}/cg.out"
        child = [sys.executable, __file__, "--child", label, "--count", str(per_condition)]
        r = subprocess.run(
            ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", *child],
            capture_output=True,
            text=True,
            env={**os.environ, "LD_BIND_NOW": "1"},
        )
        if r.returncode != 0:
            raise RuntimeError(f"callgrind of {label}: {r.stderr[-2000:]}")
        report = subprocess.run(
            ["callgrind_annotate", "--inclusive=yes", "--threshold=100", out], capture_output=True, text=True
        ).stdout
    genomes = len(bests(per_condition))
    out = {}
    for function in functions:
        costs = [int(line.split()[0].replace(",", "")) for line in report.splitlines() if f":{function} [" in line]
        if not costs:
            raise RuntimeError(f"callgrind of {label}: no {function} in the profile")
        out[function] = max(costs) / genomes
    return out


def bests(per_condition):
    """The stored bests, ``per_condition`` of each replication condition, with their runs' configs."""
    out = []
    for cond in sorted(glob.glob(str(ROOT / "data" / "replication" / "*"))):
        for d in sorted(glob.glob(cond + "/run_*"))[:per_condition]:
            run = animat.Run(d)
            out.append((run.best().genome, run.config))
    return out


def configurations(config):
    """The three configurations (a), (b), (c) of one run's config."""
    out = {"a: GA": config}
    for name, descriptors in (
        ("b: MAP-Elites elongation, protrusions", ["elongation", "protrusions"]),
        ("c: MAP-Elites locomotion, cells", ["locomotion", "cells"]),
    ):
        c = config.copy()
        c["search.algorithm"] = "map_elites"
        c["search.descriptors"] = descriptors
        out[name] = c
    return out


SHAPE = "shape measures alone"
#: What animat.evaluate runs (bindings/bind_physics.cpp), and what evaluate() calls for the shape measures.
EVALUATE_FUNCTION = "animat::evaluate(animat::Genome const&, animat::Config const&, animat::Objective const&)"
SHAPE_FUNCTION = "animat::body_shape(animat::Body const&, animat::ShapeParams const&)"


def shape_call(genome, config):
    """``_core.describe_shape`` of the genome's body, as evaluate() calls it (body_shape)."""
    body = animat.build_body(animat.develop(genome, config), config=config)
    loops = body.skin_loops
    args = (
        body.positions,
        [int(v) for v in loops[0]] if len(loops) else [],
        [int(v) for v in body.springs.reshape(-1)],
        1.0,
        0.75,
        0.5,
        1.0,
        None,
    )
    return partial(_core.describe_shape, *args)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--runs", type=int, default=10, help="stored bests per condition (of 10), timed")
    p.add_argument("--repeat", type=int, default=3, help="timed calls per genome and configuration")
    p.add_argument("--count", type=int, default=2, help="bests per condition counted by callgrind (0: none)")
    p.add_argument("--shape", action="store_true", help="also time and count the shape measures alone")
    p.add_argument("--child", help=argparse.SUPPRESS)  # one configuration's evaluations, under callgrind
    args = p.parse_args()
    if args.child:
        for genome, config in bests(args.count):
            animat.evaluate(genome, configurations(config)[args.child])
        return
    print(
        f"machine: {platform.machine()} {platform.processor() or ''}, {os.cpu_count()} cores, load "
        f"{os.getloadavg()[0]:.1f}; animat {animat.__version__}; {args.runs} bests per condition timed, "
        f"median of {args.repeat} calls per genome; {args.count} per condition counted (callgrind, "
        "instructions per evaluation)"
    )
    rows = []
    for genome, config in bests(args.runs):
        row = {}
        for name, c in configurations(config).items():
            call = partial(animat.evaluate, genome, c)
            call()  # warm
            row[name] = timed(call, args.repeat)
        if args.shape:
            row[SHAPE] = timed(shape_call(genome, config), args.repeat)
        rows.append(row)
    names = list(rows[0])
    counted = {}
    if args.count:
        for name in names:
            if name != SHAPE:
                ins = instructions(name, args.count, [EVALUATE_FUNCTION, SHAPE_FUNCTION])
                counted[name] = ins[EVALUATE_FUNCTION]
                if name == "a: GA":  # body_shape inside the GA's evaluations
                    counted[SHAPE] = ins[SHAPE_FUNCTION]
    base = "a: GA"
    print(f"{len(rows)} genomes timed")
    print("| configuration | ms per evaluation | / (a) | instructions per evaluation | / (a) |")
    print("| --- | --- | --- | --- | --- |")
    for name in names:
        ms = statistics.median(r[name] for r in rows)
        ratio = statistics.median(r[name] / r[base] for r in rows)
        ins = counted.get(name)
        count = f"{ins / 1e6:.1f}M | {ins / counted[base]:.3f}" if ins else "n/a | n/a"
        print(f"| {name} | {ms:.2f} | {ratio:.3f} | {count} |")


if __name__ == "__main__":
    main()
