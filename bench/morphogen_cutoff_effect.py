#!/usr/bin/env python3
"""What `development.morphogen_cutoff` changes (docs/performance.md).

For each cut-off, every genome is evaluated with the paper's every-pair morphogen field and with the
cut-off: how many develop to a different number of cells, how many fitnesses differ at all (bit for
bit), and the relative fitness changes. Genomes: the best of every replication run under
data/replication (each with its run's config) and the first N random viable genomes of the default
config.

    PYTHONPATH=build/python .venv/bin/python bench/morphogen_cutoff_effect.py [--random 40] [--cutoffs 4 8 12]
"""

from __future__ import annotations

import argparse
import glob
import sys
import tempfile
from pathlib import Path

import numpy as np

import animat

# The packed-run store is study code (studies/replication), not part of the package.
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "studies" / "replication"))
from replication_store import unpack_run  # noqa: E402


def compare(label: str, cases: list, cutoffs: list[float]) -> None:
    print(f"{label}: {len(cases)} genomes")
    if not cases:
        return
    reference = [animat.evaluate(genome, config) for genome, config in cases]
    for cut in cutoffs:
        same_cells = same_fitness = 0
        changes = []
        for (genome, config), ref in zip(cases, reference):
            cut_config = animat.Config.from_toml(config.to_toml())
            cut_config.development.morphogen_cutoff = cut
            res = animat.evaluate(genome, cut_config)
            same_cells += res.cell_count == ref.cell_count
            same_fitness += res.fitness == ref.fitness
            changes.append(abs(res.fitness - ref.fitness) / max(abs(ref.fitness), 1e-12))
        rel = np.array(changes)
        print(
            f"  cutoff {cut:g}: same cell count {same_cells}/{len(cases)}, fitness bitwise unchanged "
            f"{same_fitness}/{len(cases)}, largest relative change {rel.max():.3g}, over 5 %: {(rel > 0.05).sum()}"
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", default="data/replication", help="folder of packed replication runs")
    ap.add_argument("--random", type=int, default=40, help="random viable genomes of the default config")
    ap.add_argument("--cutoffs", type=float, nargs="+", default=[4.0, 8.0, 12.0])
    args = ap.parse_args()
    evolved = []
    with tempfile.TemporaryDirectory() as tmp:
        for run_dir in sorted(glob.glob(f"{args.data}/*/run_*")):
            run = animat.Run(unpack_run(Path(run_dir), Path(tmp) / run_dir.replace("/", "_")))
            evolved.append((run.best().genome, run.config))
    compare(f"evolved bests of {args.data}", evolved, args.cutoffs)
    config = animat.Config()
    randoms = [(animat.Genome.random_viable(seed=s, config=config)[0], config) for s in range(args.random)]
    compare("random viable genomes (default config)", randoms, args.cutoffs)


if __name__ == "__main__":
    main()
