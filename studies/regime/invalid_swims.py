"""Find every invalid swim of a packed study and re-swim it at finer steps.

history.csv counts, per generation, the viable individuals whose swim broke an invariant or went
unstable (column ``invalid``; they get fitness 0). This replays each run that has any with the GA's
ask/tell from its config.toml (the very run: the replayed history must equal the stored one, which is
checked), evaluates every asked genome as the engine does, and re-swims the invalid ones with
physics.substeps multiplied by 2, 4 and 16. One row per invalid swim:

    PYTHONPATH=build/python .venv/bin/python studies/regime/invalid_swims.py \
        --data data/replication_regime --out studies/regime/results/invalid_swims.csv [--jobs 2] \
        [--envs dn0.5 dn2 dn10] [--through 449]

A replay costs the run again up to its last invalid swim, so ``--envs`` and ``--through`` (the last
generation whose invalid swims are looked for) keep a pass to the runs and generations asked for.

Reads the packed files directly (config.toml, history.csv.gz); writes nothing else.
"""

from __future__ import annotations

import argparse
import csv
import gzip
import io
import sys
from concurrent.futures import ProcessPoolExecutor
from functools import partial
from pathlib import Path
from typing import List, Optional, Set

import animat

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from results_table import write_rows  # noqa: E402

REFINEMENTS = (2, 4, 16)
COLUMNS = ["env", "run", "generation", "reason", "first_invalid_step", "cells"] + [
    f"fitness_dt{k}" for k in REFINEMENTS
]


def stored_history(run: Path) -> List[List[str]]:
    with gzip.open(run / "history.csv.gz", "rt") as f:
        return list(csv.reader(io.StringIO(f.read())))


def invalid_generations(rows: List[List[str]], through: Optional[int] = None) -> Set[int]:
    """The generations of a stored history (header first) that count invalid swims, up to ``through``."""
    header, body = rows[0], rows[1:]
    g, col = header.index("generation"), header.index("invalid")
    return {int(r[g]) for r in body if int(r[col]) > 0 and (through is None or int(r[g]) <= through)}


def trace(run: Path, through: Optional[int] = None) -> List[dict]:
    rows = stored_history(run)
    header, body = rows[0], rows[1:]
    wanted = invalid_generations(rows, through)
    if not wanted:
        return []
    config = animat.load_config(str(run / "config.toml"))
    ga = animat.GA(config)
    found = []
    while ga.generation < max(wanted):
        generation = ga.generation + 1
        genomes = ga.ask(1)
        results = [animat.evaluate(g, config) for g in genomes]
        if generation in wanted:
            found += [(generation, g, r) for g, r in zip(genomes, results) if r.viable and not r.valid]
        ga.tell(results)
    # The replay is the run: its history agrees with the stored one.
    history = ga.history
    for name in ("best", "mean", "median", "evaluations", "swims", "invalid"):
        j = header.index(name)
        for g, theirs in enumerate(body[: len(history)]):
            if float(history[name][g]) != float(theirs[j]):
                raise RuntimeError(f"{run}: the replay's {name} differs from history.csv at generation {g}")
    out = []
    base = int(config["physics.substeps"])
    for generation, genome, result in found:
        row = {
            "env": run.parent.name,
            "run": run.name,
            "generation": generation,
            "reason": "; ".join(result.reasons),
            "first_invalid_step": result.first_invalid_step,
            "cells": result.cell_count,
        }
        for k in REFINEMENTS:
            fine = config.copy()
            fine["physics.substeps"] = base * k
            again = animat.evaluate(genome, fine)
            row[f"fitness_dt{k}"] = f"{again.fitness:.6g}" if again.valid else "invalid"
        out.append(row)
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--data", type=Path, required=True, help="a packed study (data/<study>)")
    p.add_argument("--out", type=Path, required=True, help="the CSV to write")
    p.add_argument("--jobs", type=int, default=1, help="runs replayed at once")
    p.add_argument("--envs", nargs="+", help="only these environments (default: all)")
    p.add_argument("--through", type=int, help="only invalid swims up to this generation (default: all)")
    args = p.parse_args(argv)
    if args.through is not None and args.through < 0:
        p.error(f"--through: must be >= 0, got {args.through}")
    runs = sorted(r for r in args.data.glob("*/run_*") if (r / "history.csv.gz").is_file())
    if not runs:
        print(f"invalid_swims: no packed runs under {args.data}", file=sys.stderr)
        return 1
    if args.envs:
        missing = sorted(set(args.envs) - {r.parent.name for r in runs})
        if missing:
            p.error(f"--envs: {missing} not under --data {args.data}")
        runs = [r for r in runs if r.parent.name in args.envs]
    with ProcessPoolExecutor(args.jobs) as pool:
        rows = [row for found in pool.map(partial(trace, through=args.through), runs) for row in found]
    write_rows(args.out, rows, COLUMNS)
    print(f"{len(rows)} invalid swims in {len(runs)} runs -> {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
