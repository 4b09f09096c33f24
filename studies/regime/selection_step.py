"""At which swim step should selection rank? The GA ranks every individual by its swim at dt and, at
the regime presets (``evaluation.reference_check = "select"``), picks the elites among the four
fittest by their swim at dt/16. A tournament between two close individuals is decided by the
difference of their fitnesses, so what matters is whether the step keeps their order, not only how
far each fitness is from the converged one.

For each run of a packed study, the ``--top`` fittest distinct viable genomes of its last population
(``checkpoint.json.gz``: the individuals the GA was choosing among) are swum with the run's config at
``physics.substeps`` x1, x2, x4, x8, x16 and x32 (dt to dt/32, the same simulated time), and each
swim's CPU time is measured in the same process::

    PYTHONPATH=build/python .venv/bin/python studies/regime/selection_step.py \\
        --data data/replication_regime --out studies/regime/results/selection_step_regime.csv --jobs 2

writes one row per individual (run, its rank at dt, fitness and seconds at every step) and
``--summary CSV`` prints, per environment and step, against the finest step (dt/32): the median
relative fitness error and how many errors exceed 1 %, the share of discordant pairs (two
individuals whose order at that step is the reverse of their order at dt/32: a tournament the step
decides wrongly), the same among pairs more than 1 % apart at dt/32, how often the two elites are the
two best at dt/32, the shortfall of the step's best from the best at dt/32, and the cost of an
evaluation against the coarsest step; the "select" row is today's rule (elites by dt/16 among the
four fittest at dt).

``--set KEY=VALUE`` swims the same individuals with other constants and ``--substeps`` at other
steps: whether their swims converge at a higher spring damping, for instance::

    PYTHONPATH=build/python .venv/bin/python studies/regime/selection_step.py \\
        --data data/replication_regime --envs dn0.5 --substeps 16 32 --set scene.spring_damping=1 \\
        --out studies/regime/results/selection_step_dn0.5_damping1.csv
"""

from __future__ import annotations

import argparse
import gzip
import json
import sys
import time
import tomllib
from functools import partial
from multiprocessing import Pool
from pathlib import Path
from statistics import median
from typing import Dict, List, Sequence

import animat

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from results_table import write_rows  # noqa: E402

SUBSTEPS = (1, 2, 4, 8, 16, 32)


def last_population(run: Path) -> List[dict]:
    """The individuals of a packed run's checkpoint (its last population)."""
    with gzip.open(run / "checkpoint.json.gz", "rt") as fh:
        outer = json.load(fh)
    return json.loads(outer["payload"])["population"]


def candidates(run: Path, top: int) -> List[dict]:
    """The ``top`` fittest distinct viable individuals (elite copies share a genome: kept once)."""
    seen, out = set(), []
    for ind in sorted(last_population(run), key=lambda x: -x["fitness"]):
        key = json.dumps(ind["genome"], sort_keys=True)
        if not ind["viable"] or key in seen:
            continue
        seen.add(key)
        out.append(ind)
        if len(out) == top:
            break
    return out


def _config(run: Path, overrides: Sequence[str]):
    """The run's config with ``KEY=VALUE`` overrides (VALUE in TOML syntax)."""
    config = animat.load_config(str(run / "config.toml"))
    for item in overrides:
        key, _, value = item.partition("=")
        config[key.strip()] = tomllib.loads(f"v = {value}")["v"]
    return config


def swim_ladder(
    run: Path, top: int, substeps: Sequence[int] = SUBSTEPS, overrides: Sequence[str] = ()
) -> List[Dict[str, object]]:
    """One row per candidate of ``run``: fitness and CPU seconds at each of ``substeps`` (multiples of
    the run's physics.substeps), with the config ``overrides`` applied."""
    rows = []
    base = _config(run, overrides)
    for rank, ind in enumerate(candidates(run, top)):
        genome = animat.Genome.from_json(json.dumps(ind["genome"]))
        row: Dict[str, object] = {"run": f"{run.parent.name}/{run.name}", "rank_dt": rank, "id": ind["id"]}
        for s in substeps:
            config = _config(run, overrides)
            config.physics.substeps = base.physics.substeps * s
            started = time.process_time()
            result = animat.evaluate(genome, config)
            row[f"seconds_s{s}"] = time.process_time() - started
            row[f"fitness_s{s}"] = float(result.fitness)
        if not overrides and "fitness_s1" in row and row["fitness_s1"] != ind["fitness"]:
            raise SystemExit(
                f"{run}: individual {ind['id']} swims to {row['fitness_s1']} at dt, "
                f"its checkpoint says {ind['fitness']} (not the run's build or config?)"
            )
        rows.append(row)
    return rows


def _discordant(fit: Sequence[float], ref: Sequence[float], apart: float = 0.0) -> tuple:
    """Pairs ordered differently by ``fit`` and ``ref``, and pairs, among the pairs whose fitnesses at
    the reference differ by more than ``apart`` of the larger (ties always left out)."""
    bad = total = 0
    for i in range(len(ref)):
        for j in range(i + 1, len(ref)):
            if abs(ref[i] - ref[j]) <= apart * max(abs(ref[i]), abs(ref[j])) or ref[i] == ref[j]:
                continue
            total += 1
            bad += (fit[i] - fit[j]) * (ref[i] - ref[j]) <= 0
    return bad, total


def _top(values: Sequence[float], k: int, among: Sequence[int]) -> List[int]:
    return sorted(among, key=lambda i: -values[i])[:k]


def summary(path: Path) -> str:
    """The per-environment table of the module docstring, from a CSV written by this script."""
    import csv

    with open(path) as fh:
        rows = list(csv.DictReader(fh))
    steps = sorted(int(k[len("fitness_s") :]) for k in rows[0] if k.startswith("fitness_s"))
    reference, ladder = steps[-1], steps[:-1]
    runs: Dict[str, Dict[str, List[dict]]] = {}
    for r in rows:
        env, _ = r["run"].split("/")
        runs.setdefault(env, {}).setdefault(r["run"], []).append(r)
    lines = [
        "| environment | step | median error | errors over 1 % | discordant pairs | discordant pairs 1 % apart | "
        "elites right | best's shortfall (median, largest) | cost against the coarsest step |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for env in sorted(runs):
        per_step = {s: dict(err=[], bad=0, pairs=0, bad1=0, pairs1=0, elites=0, short=[], secs=[]) for s in ladder}
        select = dict(elites=0, short=[])
        for members in runs[env].values():
            ref = [float(m[f"fitness_s{reference}"]) for m in members]
            everyone = list(range(len(members)))
            truth = set(_top(ref, 2, everyone))
            best_ref = max(ref)
            base_secs = [float(m[f"seconds_s{steps[0]}"]) for m in members]
            for s in ladder:
                fit = [float(m[f"fitness_s{s}"]) for m in members]
                d = per_step[s]
                d["err"] += [abs(f / r - 1) for f, r in zip(fit, ref) if r > 0]
                bad, pairs = _discordant(fit, ref)
                d["bad"] += bad
                d["pairs"] += pairs
                bad, pairs = _discordant(fit, ref, apart=0.01)
                d["bad1"] += bad
                d["pairs1"] += pairs
                d["elites"] += set(_top(fit, 2, everyone)) == truth
                d["short"].append(1 - ref[_top(fit, 1, everyone)[0]] / best_ref)
                d["secs"] += [float(m[f"seconds_s{s}"]) / b for m, b in zip(members, base_secs)]
            if not {1, 16} <= set(ladder):
                continue
            # today's "select": the two best at dt/16 among the four fittest at dt
            ref16 = [float(m["fitness_s16"]) for m in members]
            chosen = _top(ref16, 2, _top([float(m["fitness_s1"]) for m in members], 4, everyone))
            select["elites"] += set(chosen) == truth
            select["short"].append(1 - ref[chosen[0]] / best_ref)
        n = len(runs[env])
        for s in ladder:
            d = per_step[s]
            step = "dt" if s == 1 else f"dt/{s}"
            over = sum(e > 0.01 for e in d["err"])
            lines.append(
                f"| {env} | {step} | {median(d['err']):.2%} | {over} of {len(d['err'])} | "
                f"{d['bad'] / max(d['pairs'], 1):.1%} ({d['bad']} of {d['pairs']}) | "
                f"{d['bad1'] / max(d['pairs1'], 1):.1%} ({d['bad1']} of {d['pairs1']}) | {d['elites']} of {n} | "
                f"{median(d['short']):.2%}, {max(d['short']):.1%} | {median(d['secs']):.2f}x |"
            )
        if not select["short"]:
            continue
        lines.append(
            f"| {env} | select (dt, elites by dt/16 among 4) | | | | | {select['elites']} of {n} | "
            f"{median(select['short']):.2%}, {max(select['short']):.1%} | |"
        )
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=(__doc__ or "").split("\n\n")[0])
    p.add_argument("--data", type=Path, help="a packed study (data/<study>)")
    p.add_argument("--out", type=Path, help="the CSV to write")
    p.add_argument("--top", type=int, default=16, help="distinct fittest individuals per run (default 16)")
    p.add_argument("--jobs", type=int, default=1, help="runs swum at once (default 1)")
    p.add_argument("--envs", nargs="+", help="only these environments (folder names)")
    p.add_argument(
        "--substeps",
        type=int,
        nargs="+",
        default=list(SUBSTEPS),
        help="multiples of physics.substeps to swim at, the last the reference (default 1 2 4 8 16 32)",
    )
    p.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override a config key of every run (TOML value), e.g. scene.spring_damping=0.5",
    )
    p.add_argument("--summary", type=Path, metavar="CSV", help="print the table of a written CSV and exit")
    args = p.parse_args(argv)
    if args.summary is not None:
        print(summary(args.summary))
        return 0
    if args.data is None or args.out is None:
        p.error("give --data DIR --out CSV (or --summary CSV)")
    if args.jobs < 1 or args.top < 2:
        p.error(f"--jobs must be >= 1 and --top >= 2, got {args.jobs} and {args.top}")
    if len(args.substeps) < 2 or min(args.substeps) < 1 or sorted(set(args.substeps)) != args.substeps:
        p.error(f"--substeps: at least two increasing positive multiples, got {args.substeps}")
    runs = sorted(r for r in args.data.glob("*/run_*") if (r / "checkpoint.json.gz").is_file())
    if args.envs:
        runs = [r for r in runs if r.parent.name in args.envs]
    if not runs:
        print(f"selection_step: no packed run under {args.data}", file=sys.stderr)
        return 1
    with Pool(args.jobs) as pool:
        per_run = pool.map(
            partial(swim_ladder, top=args.top, substeps=args.substeps, overrides=args.overrides), runs, chunksize=1
        )
    write_rows(args.out, [row for rows in per_run for row in rows])
    print(summary(args.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
