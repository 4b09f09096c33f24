#!/usr/bin/env python3
"""What keying the GA's fitness by the genome's network saves (docs/performance.md), on evolved runs:
each chosen packed run is resumed twice for the same generations on one thread,

  - "keyed": animat.evolve, whose engine takes the fitness of an offspring whose network
    (Grn::network_key) equals that of an individual of the previous generation instead of evaluating
    it (evaluation_key: the configs with development.jitter_stream = "fixed"),
  - "whole genome": animat.GA driven by ask()/tell() with animat.evaluate, whose engine knows
    nothing of the fitness function and so re-uses a fitness only for an equal genome,

and the two are compared: every history column that is a result and the final population (genomes,
fitness, reference fitness) must be equal, bit for bit (else exit 1). Printed per run: evaluations
and swims of the resumed generations, exact whatever the load (CPU times are not compared: the two
resumes evaluate through different paths, the C++ run layer and Python's animat.evaluate), and what
the keys cost: the CPU time of the network keys of one generation (the population and as many
offspring), the engine's only extra work.

    PYTHONPATH=build/python .venv/bin/python bench/network_key_savings.py --generations 10
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import animat

REPO = Path(__file__).resolve().parents[1]
COUNTERS = ("evaluations", "swims", "wall_seconds")  # what may differ: every other column is a result


def population(checkpoint_text: str) -> list:
    """The population of a checkpoint, without the run's counters: what must be equal."""
    return json.loads(json.loads(checkpoint_text)["payload"])["population"]


def same(a: float, b: float) -> bool:
    return a == b or (a != a and b != b)  # NaN (no reference) on both sides


def resume_keyed(run: Path, config, generations: int) -> tuple:
    config = config.copy()
    config["evolution.generations"] = generations
    result = animat.evolve(config, out=str(run), resume=True, quiet=True)
    return result.history, population((run / "checkpoint.json").read_text()), result.population


def resume_whole(run: Path, config, generations: int) -> tuple:
    ga = animat.GA.load(run, config)
    while ga.generation < generations:
        genomes = ga.ask()
        ga.tell([animat.evaluate(g, config) for g in genomes])
    return ga.history, population(ga.checkpoint())


def key_cpu_ms(individuals, config) -> float:
    """CPU milliseconds of the network keys of one generation: each genome of the population twice
    (its key as a parent, and an offspring's of the same size)."""
    genomes = [i.genome for i in individuals]
    t0 = time.process_time()
    for _ in range(2):
        for g in genomes:
            animat.Grn(g, config).network_key()
    return 1e3 * (time.process_time() - t0)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument(
        "--data", default=str(REPO / "data" / "replication_long"), help="packed runs (replication_store.py)"
    )
    ap.add_argument(
        "--runs", nargs="+", default=["dn0.5/run_0", "dn10/run_0", "dn0.2_64cells/run_0"], help="ENV/run_I under --data"
    )
    ap.add_argument("--generations", type=int, default=10, help="generations to resume each run for")
    args = ap.parse_args()
    failed = False
    with tempfile.TemporaryDirectory(prefix="network_key_") as tmp:
        work = Path(tmp) / "unpacked"
        subprocess.run(
            [
                sys.executable,
                str(REPO / "studies" / "replication" / "replication_store.py"),
                "unpack",
                args.data,
                str(work),
            ],
            check=True,
            capture_output=True,
        )
        print(
            f"{args.data}, {args.generations} generations resumed per run, one thread; load average {os.getloadavg()[0]:.1f}"
        )
        print(
            "| run | from generation | evaluations: whole genome | keyed | ratio | swims: whole genome | keyed "
            "| ratio | network keys of a generation, CPU ms |"
        )
        print("|---|---|---|---|---|---|---|---|---|")
        for name in args.runs:
            source = work / name
            config = animat.load_config(str(source / "config.toml"))
            config["evolution.threads"] = 1
            start = json.loads(json.loads((source / "checkpoint.json").read_text())["payload"])["generation"]
            target = start + args.generations
            keyed_dir, whole_dir = Path(tmp) / "keyed", Path(tmp) / "whole"
            for d in (keyed_dir, whole_dir):
                shutil.rmtree(d, ignore_errors=True)
                shutil.copytree(source, d)
            whole, whole_pop = resume_whole(whole_dir, config, target)
            keyed, keyed_pop, individuals = resume_keyed(keyed_dir, config, target)
            differences = [
                f"generation {int(w['generation'])} {c}: whole genome {w[c]!r}, keyed {k[c]!r}"
                for w, k in zip(whole, keyed)
                for c in whole.dtype.names
                if c not in COUNTERS and not same(w[c].item(), k[c].item())
            ]
            if len(whole) != len(keyed) or differences or whole_pop != keyed_pop:
                failed = True
                print(
                    f"{name}: the results differ: {len(whole)} against {len(keyed)} generations; "
                    + "; ".join(differences[:5])
                    + ("" if whole_pop == keyed_pop else "; final populations differ")
                )
                continue
            evaluations = [int(h["evaluations"][-1] - h["evaluations"][start]) for h in (whole, keyed)]
            swims = [int(h["swims"][start + 1 :].sum()) for h in (whole, keyed)]
            print(
                f"| {name} | {start} | {evaluations[0]} | {evaluations[1]} | {evaluations[0] / evaluations[1]:.3f}x "
                f"| {swims[0]} | {swims[1]} | {swims[0] / swims[1]:.3f}x | {key_cpu_ms(individuals, config):.1f} |"
            )
    print(f"load average at the end {os.getloadavg()[0]:.1f}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
