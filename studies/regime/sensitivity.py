"""Is a screen best's fitness a function of its genome, or of rounding? The perturbation spread.

For every run kept in ``studies/regime/screen/``, its final best is swum at the run's own step and
``--copies`` times with the drag coefficient d_N multiplied by 1 + k·``--perturbation`` (k = 1 …
copies), a change far below any physical meaning. The spread (standard deviation of the copies'
fitness over the fitness, and their range over it) says how far the swim amplifies a perturbation:
about the perturbation itself for a body whose swim is smooth in its parameters, per cent for a
swim that is sensitive to them (chaotic). A best whose spread is as large as its exploit-guard
error (the run's best against its dt/16 reference) cannot be brought closer to the reference by a
finer step: the step's own error is a perturbation like the others.

    PYTHONPATH=build/python .venv/bin/python studies/regime/sensitivity.py

Writes ``studies/regime/results/sensitivity.csv`` (one row per run; runs already there are not swum
again) and prints the medians per grid point.
"""

from __future__ import annotations

import argparse
import csv
import json
import statistics
import sys
from pathlib import Path

import numpy as np

import animat

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "control"))
from sensitivity import perturbed  # noqa: E402

FIELDS = ("run", "point", "fitness", "best_reference", "reference_error", "spread", "range", "perturbation", "copies")


def point_of(name: str) -> str:
    return name.rsplit("_seed", 1)[0]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--screen", default=str(HERE / "screen"))
    p.add_argument("--out", default=str(HERE / "results" / "sensitivity.csv"))
    p.add_argument("--perturbation", type=float, default=1e-6)
    p.add_argument("--copies", type=int, default=8)
    args = p.parse_args(argv)
    out = Path(args.out)
    rows = list(csv.DictReader(out.open())) if out.is_file() else []
    done = {r["run"] for r in rows}
    for d in sorted(Path(args.screen).iterdir()):
        if d.name in done or not (d / "best_genome.json").is_file():
            continue
        config = animat.load_config(str(d / "config.toml"))
        config["evaluation.reference_check"] = "off"
        entry = json.loads((d / "best_genome.json").read_text())
        genome = animat.Genome.from_json(json.dumps(entry["genome"]))
        with open(d / "history.csv") as fh:
            last = list(csv.DictReader(fh))[-1]
        fitness = animat.evaluate(genome, config).fitness
        copies = perturbed(genome, config, args.perturbation, args.copies)
        reference = float(last["best_reference"])
        rows.append(
            {
                "run": d.name,
                "point": point_of(d.name),
                "fitness": f"{fitness:.9g}",
                "best_reference": f"{reference:.9g}",
                "reference_error": f"{(float(last['best']) - reference) / reference:.4g}",
                "spread": f"{copies.std() / abs(fitness):.4g}",
                "range": f"{np.ptp(copies) / abs(fitness):.4g}",
                "perturbation": args.perturbation,
                "copies": args.copies,
            }
        )
        print(d.name, rows[-1]["spread"], rows[-1]["reference_error"], flush=True)
    out.parent.mkdir(parents=True, exist_ok=True)
    rows.sort(key=lambda r: r["run"])
    with out.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=FIELDS, lineterminator="\n")
        w.writeheader()
        w.writerows(rows)
    print("| point | runs | spread at 1e-6: median (max) | guard error: median of abs (max) |")
    print("| --- | --- | --- | --- |")
    for point in sorted({r["point"] for r in rows}):
        sel = [r for r in rows if r["point"] == point]
        spread = [float(r["spread"]) for r in sel]
        err = [abs(float(r["reference_error"])) for r in sel]
        print(
            f"| {point} | {len(sel)} | {statistics.median(spread):.2g} ({max(spread):.2g}) | "
            f"{statistics.median(err):.2%} ({max(err):.2%}) |"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
