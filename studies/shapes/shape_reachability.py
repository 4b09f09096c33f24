"""Which shapes can development make? Shape descriptors (animat.shape) of

(a) the GA's initial population: N random viable genomes, drawn by animat.GA exactly as a run
    seeds generation 0 (the first viable draw of each slot's random stream);
(b) the bests and final populations of short GAs whose fitness is a shape descriptor (development
    and body only, no swimming): elongation; protrusions (count + 2 for a symmetric pair + a tenth
    of the largest height); protrusion_size (cells of the largest protrusion + a tenth of its
    height); concavity. Each score is multiplied by cells / max_cells: the paper's bests "always had
    the maximum number of cells", and without it selection for elongation shrinks the body to a
    chain of a few cells.

Writes, under --out, with --label L:
  random_L.csv          one row per random viable genome (descriptors)
  selection_L.csv       one row per (objective, seed): the best's descriptors and score per 10 generations
  summary_L.json        distributions (median, p90, max; fractions) of (a), of (b)'s bests and final
                        populations, and the command line

Usage (from the repository root, PYTHONPATH=python):
  python studies/shapes/shape_reachability.py --label baseline
  python studies/shapes/shape_reachability.py --label offset1 --set development.division_offset=1.0
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
import time
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional

import numpy as np

import animat
from animat import shape as S

ROOT = Path(__file__).resolve().parents[2]


def protrusion_score(sh: S.Shape) -> float:
    """Protrusions + 2 if a symmetric pair + a tenth of the largest height (a tie-breaker)."""
    best_height = max((p.height for p in sh.protrusions), default=0.0)
    return sh.protrusion_count + 2.0 * sh.symmetric_pair + 0.1 * min(best_height, 5.0)


def protrusion_size_score(sh: S.Shape) -> float:
    """Cells in the largest protrusion + a tenth of its height (a tie-breaker)."""
    if not sh.protrusions:
        return 0.0
    return sh.protrusions[0].size + 0.1 * min(sh.protrusions[0].height, 5.0)


OBJECTIVES: Dict[str, Callable[[S.Shape], float]] = {
    "elongation": lambda sh: sh.elongation,
    "protrusions": protrusion_score,
    "protrusion_size": protrusion_size_score,
    "concavity": lambda sh: sh.concavity,
}


def shape_or_none(genome: Any, config: Any) -> Optional[S.Shape]:
    return S.genome_shape(genome, config)


def load(config_path: str, overrides: List[str]) -> Any:
    config = animat.load_config(ROOT / config_path if not Path(config_path).is_absolute() else config_path)
    for item in overrides:
        key, _, value = item.partition("=")
        old = config[key]
        if isinstance(old, bool):
            config[key] = value.lower() in ("1", "true", "yes")
        elif isinstance(old, int):
            config[key] = int(value)
        elif isinstance(old, float):
            config[key] = float(value)
        elif isinstance(old, list):
            config[key] = [type(old[0])(v) if old else float(v) for v in value.split(",")]
        else:
            config[key] = value
    return config


def random_population(config: Any, n: int, seed: int) -> List[Dict[str, Any]]:
    """Generation 0 of a GA with population n: every slot's first viable random genome."""
    cfg = config.copy()
    cfg["evolution.population"] = n
    cfg["evolution.seed"] = seed
    ga = animat.GA(cfg)
    shapes: Dict[str, S.Shape] = {}
    while ga.generation < 0:
        genomes = ga.ask(lookahead=64)
        scores = []
        for g in genomes:
            sh = shape_or_none(g, cfg)
            if sh is not None:
                shapes[g.to_json()] = sh
            scores.append(None if sh is None else 1.0)
        ga.tell(scores)
    rows = []
    for i, ind in enumerate(ga.population):
        row = {"index": i, "tries": ind.tries}
        row.update(shapes[ind.genome.to_json()].as_dict())
        rows.append(row)
    return rows


def select(config: Any, objective: str, seed: int, population: int, generations: int) -> Dict[str, Any]:
    cfg = config.copy()
    cfg["evolution.population"] = population
    cfg["evolution.generations"] = generations
    cfg["evolution.seed"] = seed
    # Shape scores are not swims: no exploit guard (it would re-swim each new best at dt/16).
    cfg["evaluation.reference_check"] = "off"
    ga = animat.GA(cfg)
    score_of = OBJECTIVES[objective]
    max_cells = int(cfg["development.max_cells"])
    cache: Dict[str, Optional[S.Shape]] = {}
    while not ga.done:
        genomes = ga.ask(lookahead=64 if ga.generation < 0 else 1)
        scores: List[Optional[float]] = []
        for g in genomes:
            key = g.to_json()
            if key not in cache:
                cache[key] = shape_or_none(g, cfg)
            sh = cache[key]
            # full-size bodies only, as the paper's bests ("always had the maximum number of cells")
            scores.append(None if sh is None else float(score_of(sh)) * sh.cell_count / max_cells)
        ga.tell(scores)
        if len(cache) > 20000:
            cache.clear()
    best_history = [float(v) for v in ga.history["best"]]
    final = [S.genome_shape(ind.genome, cfg) for ind in ga.population]
    best = S.genome_shape(ga.best.genome, cfg)
    assert best is not None
    return {
        "objective": objective,
        "seed": seed,
        "best": best,
        "score": float(ga.best.fitness.fitness),
        "history": best_history,
        "final": [f for f in final if f is not None],
        "genome": ga.best.genome.to_json(),
    }


def distribution(values: List[float]) -> Dict[str, float]:
    a = np.asarray(values, dtype=float)
    return {
        "median": float(np.median(a)),
        "p90": float(np.percentile(a, 90)),
        "max": float(a.max()),
        "min": float(a.min()),
    }


def summarise(shapes: List[Dict[str, Any]]) -> Dict[str, Any]:
    n = len(shapes)
    return {
        "n": n,
        "elongation": distribution([s["elongation"] for s in shapes]),
        "concavity": distribution([s["concavity"] for s in shapes]),
        "protrusions": distribution([s["protrusions"] for s in shapes]),
        "largest_protrusion": distribution([s["largest_protrusion"] for s in shapes]),
        "max_height": distribution([s["max_height"] for s in shapes]),
        "core_cells": distribution([s["core_cells"] for s in shapes]),
        "fraction_with_protrusion": sum(s["protrusions"] >= 1 for s in shapes) / n,
        "fraction_with_multicell_protrusion": sum(s["largest_protrusion"] >= 2 for s in shapes) / n,
        "fraction_with_symmetric_pair": sum(s["symmetric_pairs"] >= 1 for s in shapes) / n,
        "fraction_elongation_ge_2": sum(s["elongation"] >= 2 for s in shapes) / n,
        "fraction_elongation_ge_3": sum(s["elongation"] >= 3 for s in shapes) / n,
        "fraction_without_core": sum(s["core_cells"] == 0 for s in shapes) / n,
        "cells": distribution([s["cells"] for s in shapes]),
    }


def r4(x: Any) -> Any:
    if isinstance(x, float):
        return round(x, 4) if math.isfinite(x) else x
    if isinstance(x, dict):
        return {k: r4(v) for k, v in x.items()}
    if isinstance(x, list):
        return [r4(v) for v in x]
    return x


def report(out: Path) -> str:
    """Markdown tables of every summary_*.json under `out` (the README's results)."""
    head = (
        "| config | population | n | elongation median / p90 / max | concavity median / p90 / max | "
        "protrusions median / max | largest protrusion max | ≥1 protrusion | multi-cell protrusion | "
        "symmetric pair | elongation ≥ 2 |\n|" + "---|" * 11
    )
    lines = [head]
    for path in sorted(out.glob("summary_*.json")):
        s = json.loads(path.read_text())
        label = path.stem[len("summary_") :]
        groups = [("random viable", s["random"])] if "random" in s else []
        for objective, res in s.get("selection", {}).items():
            if isinstance(res, dict) and "bests" in res:
                groups.append((f"bests, select {objective}", res["bests"]))
                groups.append((f"final pops, select {objective}", res["final_populations"]))
        for name, d in groups:
            e, c, p = d["elongation"], d["concavity"], d["protrusions"]
            lines.append(
                f"| {label} | {name} | {d['n']} | {e['median']:.2f} / {e['p90']:.2f} / {e['max']:.2f} | "
                f"{c['median']:.2f} / {c['p90']:.2f} / {c['max']:.2f} | {p['median']:g} / {p['max']:g} | "
                f"{d['largest_protrusion']['max']:g} | {d['fraction_with_protrusion']:.2f} | "
                f"{d['fraction_with_multicell_protrusion']:.2f} | {d['fraction_with_symmetric_pair']:.2f} | "
                f"{d['fraction_elongation_ge_2']:.2f} |"
            )
    return "\n".join(lines)


def replication_bests(out: Path) -> List[Dict[str, Any]]:
    """Descriptors of the last best genome of every run in data/replication (results/replication_bests.csv)."""
    import tarfile

    rows = []
    for run in sorted((ROOT / "data/replication").glob("*/run_*")):
        config = animat.load_config(run / "config.toml")
        with tarfile.open(run / "best.tar.gz") as tar:
            last = sorted(m.name for m in tar.getmembers() if m.name.endswith(".json"))[-1]
            member = tar.extractfile(last)
            assert member is not None
            genome = animat.Genome.from_json(json.dumps(json.loads(member.read())["genome"]))
        sh = S.genome_shape(genome, config)
        assert sh is not None
        row = {"environment": run.parent.name, "run": run.name, "best": Path(last).stem}
        row.update(sh.as_dict())
        row["protrusion_sizes"] = " ".join(str(p.size) for p in sh.protrusions)
        rows.append(row)
    with open(out / "replication_bests.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(r4(rows))
    return rows


def main(argv: Optional[List[str]] = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--config", default="configs/paper_dn0.5.toml")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="config override")
    ap.add_argument("--label", default="baseline")
    ap.add_argument("--random", type=int, default=200, help="random viable genomes (a)")
    ap.add_argument("--random-seed", type=int, default=1)
    ap.add_argument("--objectives", default="elongation,protrusions,protrusion_size,concavity")
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--population", type=int, default=50)
    ap.add_argument("--generations", type=int, default=100)
    ap.add_argument("--out", default=str(ROOT / "studies/shapes/results"))
    ap.add_argument("--report", action="store_true", help="print the tables of every summary under --out and stop")
    ap.add_argument(
        "--replication",
        action="store_true",
        help="describe the bests of data/replication into results/replication_bests.csv and stop",
    )
    args = ap.parse_args(argv)
    if args.replication:
        rows = replication_bests(Path(args.out))
        for env in sorted({r["environment"] for r in rows}):
            sel = [r for r in rows if r["environment"] == env]
            print(
                f"{env}: {len(sel)} bests, elongation max {max(r['elongation'] for r in sel):.2f}, "
                f"with >= 1 protrusion {sum(r['protrusions'] >= 1 for r in sel)}, "
                f"with a symmetric pair {sum(r['symmetric_pairs'] >= 1 for r in sel)}, "
                f"largest protrusion {max(r['largest_protrusion'] for r in sel)}"
            )
        return 0
    if args.report:
        print(report(Path(args.out)))
        return 0

    config = load(args.config, args.set)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.time()
    summary: Dict[str, Any] = {
        "command": "python studies/shapes/shape_reachability.py " + " ".join(argv or sys.argv[1:]),
        "config": args.config,
        "overrides": args.set,
        "shape_params": vars(S.ShapeParams()),
    }

    if args.random > 0:
        rows = random_population(config, args.random, args.random_seed)
        with open(out / f"random_{args.label}.csv", "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(r4(rows))
        summary["random"] = summarise(rows)
        summary["random"]["tries"] = distribution([r["tries"] for r in rows])
        print(f"[{time.time() - t0:.0f}s] random: {json.dumps(r4(summary['random']))}", flush=True)

    objectives = [o for o in args.objectives.split(",") if o]
    seeds = [int(s) for s in args.seeds.split(",") if s]
    sel_rows = []
    summary["selection"] = {"population": args.population, "generations": args.generations, "seeds": seeds}
    for objective in objectives:
        bests, finals = [], []
        for seed in seeds:
            res = select(config, objective, seed, args.population, args.generations)
            row = {"objective": objective, "seed": seed, "score": res["score"]}
            row.update(res["best"].as_dict())
            row["protrusion_sizes"] = " ".join(str(p.size) for p in res["best"].protrusions)
            row["best_score_by_10_generations"] = " ".join(
                f"{v:.3f}" for v in res["history"][::10] + res["history"][-1:]
            )
            sel_rows.append(row)
            bests.append(res["best"].as_dict())
            finals += [f.as_dict() for f in res["final"]]
            (out / f"best_{args.label}_{objective}_seed{seed}.json").write_text(res["genome"])
            print(
                f"[{time.time() - t0:.0f}s] {objective} seed {seed}: score {res['score']:.3f} "
                f"{json.dumps(r4(res['best'].as_dict()))}",
                flush=True,
            )
        summary["selection"][objective] = {"bests": summarise(bests), "final_populations": summarise(finals)}
    if sel_rows:
        with open(out / f"selection_{args.label}.csv", "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(sel_rows[0]))
            w.writeheader()
            w.writerows(r4(sel_rows))
    summary["wall_seconds"] = round(time.time() - t0, 1)
    (out / f"summary_{args.label}.json").write_text(json.dumps(r4(summary), indent=1) + "\n")
    print(f"[{time.time() - t0:.0f}s] wrote {out}/summary_{args.label}.json")
    return 0


if __name__ == "__main__":
    sys.exit(main())
