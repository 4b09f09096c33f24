"""The paper's GA, the protected GA and MAP-Elites at equal budgets (issue: quality diversity).

The paper ends (§7) by asking whether protecting novel morphologies would keep body plans that
need time to adjust their control. For each environment (``configs/paper_<env>.toml``), algorithm
and seed, one search of ``--budget`` swims (viable evaluations: every algorithm asks non-viable
genomes too, which cost a development only):

- ``ga``: ``animat.GA`` (the paper's GA) at ``--population``;
- ``protected``: the same with ``evolution.protection_generations = --protection``;
- ``map_elites``: ``animat.MapElites`` with batches of ``--population``.

Every viable, valid evaluation of every algorithm is offered to one passive archive of the same
grid (elongation × protrusions, ``--bins``), so QD-score and coverage compare like with like; for
MAP-Elites that archive is its own. The exploit guard is off during the searches (its reference
swims would count against the budgets unequally: the GA checks new bests, MAP-Elites every new
elite); instead every run's final per-class bests are re-swum at dt/16 afterwards (``reference``,
``reference_error``).

    PYTHONPATH=build/python .venv/bin/python studies/search/compare.py \\
        --envs dn0.5,dn2,dn10,dn0.2_64cells --seeds 1,2,3 --budget 6000
    PYTHONPATH=build/python .venv/bin/python studies/search/compare.py --summary

Per run, ``studies/search/kept/<env>_<algorithm>_seed<k>/``: ``config.toml``, ``history.csv``
(swims, qd_score, coverage, best after each generation), ``archive.csv`` (the final archive: one row
per elite, its descriptors and whether its body has a symmetric pair, no genomes) and
``class_bests.json`` (per morphology class, protrusions 0, 1, 2, 3 or more and "symmetric pair": the
best elite's fitness, its dt/16 reference and its genome). A run already kept is skipped (delete it
to redo it). ``--summary`` writes ``studies/search/results/summary.csv`` and prints the table per
environment: median QD-score, coverage and best fitness over the seeds, and the median best fitness
per morphology class (in brackets, the runs that have the class).
"""

from __future__ import annotations

import argparse
import csv
import json
import statistics
import sys
import time
from pathlib import Path
from typing import Any, Dict, List

import numpy as np

import animat
import animat.shape
from animat import qd

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
RUNS = HERE / "kept"
RESULTS = HERE / "results"
ALGORITHMS = ("ga", "protected", "map_elites")
DESCRIPTORS = (("elongation", 1.0, 4.0), ("protrusions", 0.0, 8.0))
CLASSES = ("0 protrusions", "1 protrusion", "2 protrusions", "3+ protrusions", "symmetric pair")


def archive_of(bins) -> qd.GridArchive:
    return qd.GridArchive(DESCRIPTORS, bins)


def config_of(env: str, args, algorithm: str, seed: int) -> Any:
    path = ROOT / "configs" / f"paper_{env}.toml"
    if not path.is_file():
        raise SystemExit(f"--envs: no config {path}")
    c = animat.load_config(str(path))
    c["evolution.population"] = args.population
    c["evolution.seed"] = seed
    c["evolution.threads"] = args.threads
    c["evaluation.reference_check"] = "off"
    if args.steps:
        c["evaluation.steps"] = args.steps
    if algorithm == "protected":
        c["evolution.protection_generations"] = args.protection
    return c


def swim(genomes: List[Any], config: Any) -> List[Any]:
    """One animat.Fitness per genome (OpenMP threads, the same for any thread count)."""
    return animat.evaluate_population(genomes, config, int(config["evolution.threads"]))


def offer(archive: qd.GridArchive, genomes, results, config, generation: int) -> int:
    """Offer every viable, stable, valid evaluation to the passive archive; returns the swims."""
    swims = 0
    for g, r in zip(genomes, results):
        if not r.viable:
            continue
        swims += 1
        if not (r.stable and r.valid):
            continue
        values = qd.measure(g, config, archive.descriptors, r)
        if values is not None:
            archive.add(g, float(r.fitness), values, generation=generation)
    return swims


def run_one(env: str, algorithm: str, seed: int, args) -> None:
    name = f"{env}_{algorithm}_seed{seed}"
    out = RUNS / name
    if (out / "archive.csv").is_file():
        return
    config = config_of(env, args, algorithm, seed)
    rows: List[Dict[str, Any]] = []
    swims, generation, start = 0, -1, time.time()
    if algorithm == "map_elites":
        me = qd.MapElites(config, archive_of(args.bins), batch=args.population, seed=seed)
        archive = me.archive
        while swims < args.budget:
            genomes = me.ask()
            results = swim(genomes, config)
            swims += sum(bool(r.viable) for r in results)
            me.tell(results)
            generation = me.generation
            rows.append(row_of(generation, swims, archive))
    else:
        ga = animat.GA(config)
        archive = archive_of(args.bins)
        while swims < args.budget:
            genomes = ga.ask()
            results = swim(genomes, config)
            ga.tell(results)
            swims += offer(archive, genomes, results, config, ga.generation)
            if ga.generation > generation:
                generation = ga.generation
                rows.append(row_of(generation, swims, archive))
    tmp = RUNS / f"{name}.tmp"
    tmp.mkdir(parents=True, exist_ok=True)
    with open(tmp / "history.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]), lineterminator="\n")
        w.writeheader()
        w.writerows(rows)
    write_archive(archive, config, tmp)
    (tmp / "config.toml").write_text(config.to_toml())
    tmp.rename(out)
    print(f"{name}: {swims} swims, {generation} generations, {time.time() - start:.0f} s", flush=True)


def row_of(generation: int, swims: int, archive) -> Dict[str, Any]:
    best = archive.best()
    return {
        "generation": generation,
        "swims": swims,
        "qd_score": f"{archive.qd_score():.6g}",
        "coverage": f"{archive.coverage():.6g}",
        "best": f"{best.objective if best is not None else float('nan'):.6g}",
    }


def class_of(protrusions: float, pair: bool) -> List[str]:
    out = [CLASSES[min(int(protrusions), 3)]]
    if pair:
        out.append("symmetric pair")
    return out


def write_archive(archive, config, folder: Path) -> None:
    """archive.csv without genomes, and class_bests.json with each class's best and its reference."""
    best: Dict[str, Any] = {}
    with open(folder / "archive.csv", "w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(["index", "objective", "generation", *archive.names, "symmetric_pair"])
        for e in archive.elites():
            pair = bool(animat.shape.genome_shape(e.genome, config).symmetric_pair)
            values = dict(zip(archive.names, e.descriptors))
            w.writerow([e.index, f"{e.objective:.9g}", e.generation, *(f"{v:.6g}" for v in e.descriptors), int(pair)])
            for c in class_of(values["protrusions"], pair):
                if c not in best or e.objective > best[c].objective:
                    best[c] = e
    fine = config.copy()
    fine["physics.substeps"] = config["physics.substeps"] * 16
    out = {
        c: {
            "fitness": e.objective,
            "reference": animat.evaluate(e.genome, fine).fitness,
            "genome": json.loads(e.genome.to_json()),
        }
        for c, e in best.items()
    }
    (folder / "class_bests.json").write_text(json.dumps(out, indent=1) + "\n")


def summarise(args) -> int:
    runs = sorted(d for d in RUNS.iterdir() if (d / "archive.csv").is_file()) if RUNS.is_dir() else []
    if not runs:
        print(f"no runs in {RUNS}", file=sys.stderr)
        return 1
    RESULTS.mkdir(parents=True, exist_ok=True)
    table = []
    for d in runs:
        env, rest = d.name.split("_", 1)
        if rest.startswith("64cells_"):
            env, rest = f"{env}_64cells", rest[len("64cells_") :]
        algorithm, seed = rest.rsplit("_seed", 1)
        last = list(csv.DictReader(open(d / "history.csv")))[-1]
        row = {"environment": env, "algorithm": algorithm, "seed": int(seed), **last}
        best = json.loads((d / "class_bests.json").read_text())
        for c in CLASSES:
            row[c] = f"{best[c]['fitness']:.4g}" if c in best else ""
            row[f"{c} reference"] = f"{best[c]['reference']:.4g}" if c in best else ""
        table.append(row)
    keys = list(dict.fromkeys(k for r in table for k in r))
    with open(RESULTS / "summary.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys, lineterminator="\n")
        w.writeheader()
        w.writerows(table)
    print("| environment | algorithm | runs | swims | QD-score | coverage | best | " + " | ".join(CLASSES) + " |")
    print("| --- " * (7 + len(CLASSES)) + "|")
    for env in sorted({r["environment"] for r in table}):
        for algorithm in ALGORITHMS:
            sel = [r for r in table if r["environment"] == env and r["algorithm"] == algorithm]
            if not sel:
                continue
            med = lambda k: statistics.median(float(r[k]) for r in sel)  # noqa: E731, B023
            per_class = []
            for c in CLASSES:
                v = [float(r[c]) for r in sel if r[c] != ""]
                per_class.append(f"{statistics.median(v):.1f} ({len(v)})" if v else "–")
            print(
                f"| {env} | {algorithm} | {len(sel)} | {med('swims'):.0f} | {med('qd_score'):.0f} | "
                f"{med('coverage'):.2f} | {med('best'):.1f} | " + " | ".join(per_class) + " |"
            )
    return 0


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--envs", default="dn0.5,dn10", help="comma-separated: configs/paper_<env>.toml")
    p.add_argument("--algorithms", default=",".join(ALGORITHMS))
    p.add_argument("--seeds", default="1")
    p.add_argument("--population", type=int, default=60)
    p.add_argument("--budget", type=int, default=6000, help="swims per run")
    p.add_argument("--protection", type=int, default=20, help="evolution.protection_generations of 'protected'")
    p.add_argument("--bins", type=int, nargs=2, default=(6, 8), metavar=("ELONGATION", "PROTRUSIONS"))
    p.add_argument("--steps", type=int, default=0, help="evaluation.steps (0: the config's)")
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--summary", action="store_true", help="summarise the runs kept in studies/search/runs")
    args = p.parse_args(argv)
    if args.summary:
        return summarise(args)
    algorithms = args.algorithms.split(",")
    for a in algorithms:
        if a not in ALGORITHMS:
            raise SystemExit(f"--algorithms: unknown '{a}' (expected {', '.join(ALGORITHMS)})")
    for env in args.envs.split(","):
        for seed in (int(s) for s in args.seeds.split(",")):
            for a in algorithms:
                run_one(env, a, seed, args)
    return 0


if __name__ == "__main__":
    np.seterr(all="ignore")
    raise SystemExit(main())
