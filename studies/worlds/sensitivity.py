"""Do the crawl lineage bests that do not converge swim chaotically? Their perturbation spread.

For each lineage best of ``--refinement`` (``results/crawl_refinement.csv``, written by
``refinement.py``) whose run matches ``--only``, at the guard's reference step dt/16: its fitness and
that of ``--copies`` swims with ``scene.gravity`` multiplied by 1 + k·``--perturbation`` (k = 1 …
copies; the crawl world has no fluid drag to perturb). The spread (standard deviation over |fitness|)
is about the perturbation for a swim smooth in its parameters and per cent for a chaotic one, whose
fitness no finer step converges (docs/worlds.md).

    PYTHONPATH=build/python .venv/bin/python studies/worlds/sensitivity.py --only 'g1_compliant_select_seed*'

Writes ``results/crawl_sensitivity.csv`` (lineage bests already there are not swum again) and prints
the ranked error against the spread.
"""

from __future__ import annotations

import argparse
import csv
import fnmatch
import sys
from pathlib import Path

import animat

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "control"))
from refinement import refined  # noqa: E402
from sensitivity import perturbed  # noqa: E402

FIELDS = ("run", "generation", "ranked_error", "fitness_fine", "spread", "perturbation", "copies", "airborne_share")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", default=str(HERE / "crawl_screen"))
    p.add_argument("--refinement", default=str(HERE / "results" / "crawl_refinement.csv"))
    p.add_argument("--out", default=str(HERE / "results" / "crawl_sensitivity.csv"))
    p.add_argument("--only", default="*", help="runs whose name matches this glob")
    p.add_argument("--perturbation", type=float, default=1e-6)
    p.add_argument("--copies", type=int, default=4)
    args = p.parse_args(argv)
    out = Path(args.out)
    rows = list(csv.DictReader(out.open())) if out.is_file() else []
    done = {(r["run"], r["generation"]) for r in rows}
    for r in csv.DictReader(open(args.refinement)):
        if not fnmatch.fnmatch(r["run"], args.only) or (r["run"], r["generation"]) in done:
            continue
        run = animat.Run(Path(args.runs) / r["run"])
        genome = next(e.genome for e in run.best_genomes if e.generation == int(r["generation"]))
        cfg = refined(run.config, 16)
        cfg["evaluation.reference_check"] = "off"
        fitness = animat.evaluate(genome, cfg).fitness
        copies = perturbed(genome, cfg, args.perturbation, args.copies, "scene.gravity")
        rows.append(
            {
                "run": r["run"],
                "generation": r["generation"],
                "ranked_error": r["ranked_error"],
                "fitness_fine": f"{fitness:.9g}",
                "spread": f"{copies.std() / abs(fitness):.4g}",
                "perturbation": args.perturbation,
                "copies": args.copies,
                "airborne_share": r["airborne_share"],
            }
        )
        print(r["run"], r["generation"], r["ranked_error"], rows[-1]["spread"], flush=True)
    out.parent.mkdir(parents=True, exist_ok=True)
    rows.sort(key=lambda x: (x["run"], int(x["generation"])))
    with out.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=FIELDS, lineterminator="\n")
        w.writeheader()
        w.writerows(rows)
    big = [x for x in rows if abs(float(x["ranked_error"])) > 0.01]
    small = [x for x in rows if abs(float(x["ranked_error"])) <= 0.01]
    for label, sel in (("ranked error > 1 %", big), ("ranked error <= 1 %", small)):
        if sel:
            s = sorted(float(x["spread"]) for x in sel)
            chaotic = sum(v >= 1e-4 for v in s)
            print(f"{label}: {len(sel)} lineage bests, spread {s[0]:.2g} to {s[-1]:.2g}, {chaotic} at 1e-4 or more")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
