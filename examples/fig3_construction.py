"""Paper Fig. 3: from cell centres to the structure of an animat.

(a) the cell centres at the end of development, (b) their Delaunay triangulation, (c) the Gabriel
graph, the final structure: springs (thin), regions (shaded, each with its own rest area) and the
skin (thick), the only edges that feel drag. Drawn by animat.plot.construction.

Usage:
    PYTHONPATH=build/python .venv/bin/python examples/fig3_construction.py [--seed S | --run DIR] [--out PNG]

Without --seed or --run, the script develops random genomes (seeds 0, 1, ...) and draws the first
viable embryo whose body has at least --min-regions regions. If none of the --scan seeds gives one,
it draws a synthetic embryo (a random packing of unit cells) and says so in the title.
"""

import argparse
from pathlib import Path

import numpy as np

import animat

from _common import ROOT, save_png


def synthetic_embryo(n=32, seed=1):
    """n centres packed at distance >= 1 around the origin, grown one by one like dividing cells."""
    rng = np.random.default_rng(seed)
    pts = [np.zeros(2)]
    while len(pts) < n:
        parent = pts[rng.integers(len(pts))]
        angle = rng.uniform(0, 2 * np.pi)
        cand = parent + rng.uniform(1.0, 1.3) * np.array([np.cos(angle), np.sin(angle)])
        if min(np.linalg.norm(cand - q) for q in pts) >= 1.0:
            pts.append(cand)
    return np.array(pts), np.full(n, 0.5)


def pick_embryo(args):
    if args.run is not None:
        run = animat.Run(args.run)
        e = animat.develop(run.best().genome, run.config)
        return e.positions, e.radii, f"best of {args.run}, {len(e.positions)} cells"
    if args.seed is not None:
        e = animat.develop(animat.Genome.random(args.seed))
        return e.positions, e.radii, f"genome seed {args.seed}, {len(e.positions)} cells"
    for seed in range(args.scan):
        e = animat.develop(animat.Genome.random(seed))
        if not e.viable or len(e.positions) < 3:
            continue
        try:
            body = animat.build_body(e)
        except ValueError:
            continue
        if body.region_count >= args.min_regions:
            return e.positions, e.radii, f"genome seed {seed}, {len(e.positions)} cells"
    pos, radii = synthetic_embryo()
    return pos, radii, f"synthetic centres, {len(pos)} cells (no developed embryo had {args.min_regions} regions)"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seed", type=int, default=None, help="genome seed of the embryo to draw")
    parser.add_argument("--run", type=Path, default=None, help="draw the best genome of this run directory")
    parser.add_argument("--scan", type=int, default=500, help="genome seeds to try without --seed")
    parser.add_argument("--min-regions", type=int, default=6, help="fewest regions of an embryo worth drawing")
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "images" / "fig3_construction.png")
    args = parser.parse_args()

    pos, radii, label = pick_embryo(args)
    fig = animat.plot.construction(pos, radii=radii, title=f"From embryo to body (paper Fig. 3) - {label}")
    # A 64-colour palette keeps the committed PNG small without visible loss.
    save_png(fig, args.out, dpi=90, colors=64)
    print(f"({label}; {animat.build_body(pos)})")


if __name__ == "__main__":
    main()
