"""A development sequence like paper Fig. 2: circles with orientation ticks at chosen steps.

    python examples/fig2_development.py [--seed N] [--steps 0 60 90 ...] [--out docs/images/fig2_development.png]

Without --seed it searches random genomes (animat.Genome.random(seed), seeds 0, 1, ...) for the
first viable one that reaches the cell limit with a 2-D shape (most viable random genomes never
express `rotate`, so their daughters all point the same way and form a straight chain). Without
--steps it picks: the first cell, the first division (daughter still overlapping its mother), the
later rounds of division, 30 steps after the last one (pushed apart), and the end of development.
"""
import argparse
import pathlib

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import LineCollection, PatchCollection  # noqa: E402
from matplotlib.patches import Circle  # noqa: E402

import animat  # noqa: E402


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


def default_steps(embryo):
    d = sorted(set(embryo.division_steps))
    picks = [0] + d + [d[-1] + 30, embryo.steps_run]
    return sorted({s for s in picks if 0 <= s <= embryo.steps_run})


def draw(ax, positions, radii, orientations, step):
    ax.add_collection(PatchCollection([Circle(p, r) for p, r in zip(positions, radii)],
                                      facecolor="#cfe3f7", edgecolor="#1f4e79", linewidth=0.8))
    ticks = [(p, p + r * o) for p, r, o in zip(positions, radii, orientations)]
    ax.add_collection(LineCollection(ticks, colors="#b22222", linewidths=1.2))
    ax.set_title(f"step {step} ({len(radii)} cell{'s' if len(radii) != 1 else ''})", fontsize=9)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seed", type=int, help="random genome seed (default: first viable full-size one)")
    parser.add_argument("--steps", type=int, nargs="+", help="steps to draw (default: chosen from the divisions)")
    parser.add_argument("--out", default="docs/images/fig2_development.png")
    args = parser.parse_args()

    config = animat.Config()
    seed = args.seed if args.seed is not None else find_genome(config)
    config.development.trace_every = 1
    embryo = animat.develop(animat.Genome.random(seed, config), config)
    print(f"seed {seed}: {embryo}")
    trace = embryo.trace
    steps = args.steps or default_steps(embryo)
    index = {s: k for k, s in enumerate(trace.steps)}
    steps = [s for s in steps if s in index]

    # One common frame for all panels, so that growth is visible.
    final = trace.positions[index[steps[-1]]]
    reach = float(max(abs(final).max() + trace.radii[index[steps[-1]]].max(), 1.0)) * 1.1
    cols = min(4, len(steps))
    rows = (len(steps) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(2.0 * cols, 2.35 * rows + 0.4), squeeze=False)
    for ax in axes.flat[len(steps):]:
        ax.set_visible(False)
    for ax, s, label in zip(axes.flat, steps, "abcdefghijklmnop"):
        k = index[s]
        draw(ax, trace.positions[k], trace.radii[k], trace.orientations[k], s)
        ax.set_xlim(-reach, reach)
        ax.set_ylim(-reach, reach)
        ax.text(0.03, 0.97, f"({label})", transform=ax.transAxes, va="top", fontsize=8)
    fig.suptitle(f"Development of random genome {seed}; lines: orientation vectors", fontsize=10)
    fig.tight_layout(h_pad=1.2)
    out = pathlib.Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
