"""A development sequence like paper Fig. 2: circles with orientation ticks at chosen steps.

    PYTHONPATH=build/python .venv/bin/python examples/fig2_development.py [--seed N] [--steps 0 60 90 ...] [--out PNG]
    PYTHONPATH=build/python .venv/bin/python examples/fig2_development.py --run RUN_DIR   # a run's best genome

Without --seed or --run it searches random genomes (animat.Genome.random(seed), seeds 0, 1, ...) for
the first viable one that reaches the cell limit with a 2-D shape (most viable random genomes never
express `rotate`, so their daughters all point the same way and form a straight chain). Without
--steps, animat.plot.development picks: the first cell, every round of division (daughters still
overlapping their mothers), 30 steps after the last one (pushed apart) and the end of development.
"""

import argparse
import pathlib

import numpy as np

import animat

from _common import ROOT, save_png


def find_genome(config, first_seed=0, tries=5000):
    """First seed whose random genome gives a viable, 2-D embryo with the maximum number of cells."""
    cap = config.development.max_cells
    for seed in range(first_seed, first_seed + tries):
        embryo = animat.develop(animat.Genome.random(seed, config), config)
        if embryo.viable and embryo.cell_count == cap:
            centred = embryo.positions - embryo.positions.mean(axis=0)
            if np.linalg.svd(centred, compute_uv=False)[1] > 1.0:  # not a straight chain
                return seed
    raise SystemExit(f"no viable {cap}-cell genome among seeds {first_seed}..{first_seed + tries - 1}")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seed", type=int, help="random genome seed (default: first viable full-size one)")
    parser.add_argument("--run", type=pathlib.Path, help="draw the best genome of this run directory instead")
    parser.add_argument("--steps", type=int, nargs="+", help="steps to draw (default: chosen from the divisions)")
    parser.add_argument("--out", type=pathlib.Path, default=ROOT / "docs" / "images" / "fig2_development.png")
    args = parser.parse_args()

    if args.run:
        run = animat.Run(args.run)
        config, genome = run.config, run.best().genome
        label = f"the best of {args.run} (generation {run.best().generation})"
    else:
        config = animat.Config()
        seed = args.seed if args.seed is not None else find_genome(config)
        genome = animat.Genome.random(seed, config)
        label = f"random genome {seed}"
    config.development.trace_every = 1  # record every step
    embryo = animat.develop(genome, config)
    print(f"{label}: {embryo}")
    fig = animat.plot.development(embryo, steps=args.steps, title=f"Development of {label}; lines: orientation vectors")
    save_png(fig, args.out, dpi=110)


if __name__ == "__main__":
    main()
