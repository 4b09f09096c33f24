"""Why some GRN-control lineage bests do not converge: cancellation and sensitivity.

For every lineage best of ``studies/control/screen`` whose ranked error (``screen_refinement.csv``)
is above ``--above`` (1 % by default), at dt/16 and dt/32 (the guard's reference step and the next
finer one):

- the **progress per source direction** p_t (the chemotaxis fitness is their mean) and the
  **cancellation factor** κ = Σ|p_t| / |Σ p_t|: an error ε in each direction's progress moves the
  fitness by up to κ·ε relative to it;
- the **sensitivity**: the fitness of ``--copies`` swims whose drag coefficient d_N is multiplied by
  1 + k·``--perturbation`` (k = 1 … copies), a change far below any physical meaning; their spread
  (standard deviation over |fitness|) is how far the outcome itself is fixed. A fitness whose spread
  at 1e-6 is as large as its step error cannot converge to less than that spread by refinement.

    PYTHONPATH=build/python .venv/bin/python studies/control/sensitivity.py \
        --out studies/control/results/sensitivity.csv

Rows already in ``--out`` are not swum again (delete the file to redo them).
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
from pathlib import Path

import numpy as np

import animat

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "worlds"))
from refinement import refined  # noqa: E402

FIELDS = (
    "run",
    "generation",
    "step",
    "fitness",
    "progress_per_direction",
    "cancellation",
    "perturbation",
    "copies",
    "perturbed_mean",
    "perturbed_spread",
)


def progress_per_direction(genome, config) -> list:
    """The chemotaxis progress toward each of the evaluation's source directions, in the engine's order
    (evaluate() turns scene.chemical_source by one offset plus 2πt/T; with T = 1 it turns by the offset
    alone, so the source is turned here by 2πt/T first)."""
    count = int(config["evaluation.source_directions"])
    x, y = config["scene.chemical_source"]
    out = []
    for t in range(count):
        a = 2.0 * math.pi * t / count
        c = config.copy()
        c["evaluation.source_directions"] = 1
        c["scene.chemical_source"] = [math.cos(a) * x - math.sin(a) * y, math.sin(a) * x + math.cos(a) * y]
        out.append(animat.evaluate(genome, c).fitness)
    return out


def perturbed(genome, config, size: float, copies: int, key: str = "scene.drag_normal") -> np.ndarray:
    """The fitness of ``copies`` swims with ``key`` multiplied by 1 + k·size, k = 1 … copies (a world
    without drag needs another key: the crawl world's scene.gravity)."""
    value = config[key]
    out = []
    for k in range(1, copies + 1):
        c = config.copy()
        c[key] = value * (1.0 + k * size)
        out.append(animat.evaluate(genome, c).fitness)
    return np.array(out)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", default=str(HERE / "screen"))
    p.add_argument("--refinement", default=str(HERE / "results" / "screen_refinement.csv"))
    p.add_argument("--out", default=str(HERE / "results" / "sensitivity.csv"))
    p.add_argument("--above", type=float, default=0.01, help="ranked error above which a best is examined")
    p.add_argument("--perturbation", type=float, default=1e-6)
    p.add_argument("--copies", type=int, default=8)
    p.add_argument("--only", default="amplitude_select", help="runs whose name starts with this")
    args = p.parse_args(argv)

    out = Path(args.out)
    done = set()
    if out.is_file():
        done = {(r["run"], r["generation"], r["step"]) for r in csv.DictReader(out.open())}
    new = not out.is_file()
    with out.open("a", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=FIELDS, lineterminator="\n")
        if new:
            w.writeheader()
        for row in csv.DictReader(open(args.refinement)):
            if not row["run"].startswith(args.only) or abs(float(row["ranked_error"])) <= args.above:
                continue
            run = animat.Run(Path(args.runs) / row["run"])
            genome = next(e.genome for e in run.best_genomes if e.generation == int(row["generation"]))
            for factor in (16, 32):
                if (row["run"], row["generation"], f"dt/{factor}") in done:
                    continue
                cfg = refined(run.config, factor)
                fitness = animat.evaluate(genome, cfg).fitness
                per = progress_per_direction(genome, cfg)
                copies = perturbed(genome, cfg, args.perturbation, args.copies)
                w.writerow(
                    {
                        "run": row["run"],
                        "generation": row["generation"],
                        "step": f"dt/{factor}",
                        "fitness": f"{fitness:.9g}",
                        "progress_per_direction": " ".join(f"{v:.6g}" for v in per),
                        "cancellation": f"{sum(abs(v) for v in per) / abs(sum(per)):.4g}",
                        "perturbation": args.perturbation,
                        "copies": args.copies,
                        "perturbed_mean": f"{copies.mean():.9g}",
                        "perturbed_spread": f"{copies.std() / abs(fitness):.4g}",
                    }
                )
                fh.flush()
                print(row["run"], row["generation"], factor, f"{fitness:.6g}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
