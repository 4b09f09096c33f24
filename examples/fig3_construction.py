"""Paper Fig. 3: from cell centres to the structure of an animat.

(a) the cell centres at the end of development, (b) their Delaunay triangulation, (c) the Gabriel
graph, the final structure: springs (thin), regions (shaded, each with its own rest area) and the
skin (thick), the only edges that feel drag.

Usage:
    PYTHONPATH=build/python .venv/bin/python examples/fig3_construction.py [--seed S] [--out PNG]

Without --seed, the script develops random genomes (seeds 0, 1, ...) and draws the first viable
embryo whose body has at least --min-regions regions. If none of the --scan seeds gives one, it
draws a synthetic embryo (a random packing of unit cells) and says so in the title.
"""
import argparse
import io
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection, PatchCollection  # noqa: E402
from matplotlib.patches import Circle, Polygon  # noqa: E402
from PIL import Image  # noqa: E402

import animat  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


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


def draw_edges(ax, pos, edges, **kw):
    ax.add_collection(LineCollection([(pos[i], pos[j]) for i, j in edges], **kw))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seed", type=int, default=None, help="genome seed of the embryo to draw")
    parser.add_argument("--scan", type=int, default=500, help="genome seeds to try without --seed")
    parser.add_argument("--min-regions", type=int, default=6, help="fewest regions of an embryo worth drawing")
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "images" / "fig3_construction.png")
    args = parser.parse_args()

    pos, radii, label = pick_embryo(args)
    delaunay = animat.delaunay_edges(pos)
    body = animat.build_body(pos)

    fig, axes = plt.subplots(1, 3, figsize=(12, 4.2))
    pad = radii.max() + 0.3
    lo, hi = pos.min(axis=0) - pad, pos.max(axis=0) + pad
    for ax in axes:
        ax.set_aspect("equal")
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_xticks([])
        ax.set_yticks([])

    ax = axes[0]
    ax.add_collection(PatchCollection([Circle(p, r) for p, r in zip(pos, radii)],
                                      facecolor="#dde8f3", edgecolor="#8aa6c1", linewidth=0.6))
    ax.plot(pos[:, 0], pos[:, 1], "o", color="k", ms=3.5)
    ax.set_title("(a) cell centres")

    ax = axes[1]
    draw_edges(ax, pos, delaunay, colors="#555555", linewidths=0.9)
    ax.plot(pos[:, 0], pos[:, 1], "o", color="k", ms=3.5)
    ax.set_title(f"(b) Delaunay triangulation ({len(delaunay)} edges)")

    ax = axes[2]
    cmap = plt.get_cmap("Pastel1")
    ax.add_collection(PatchCollection([Polygon(pos[r]) for r in body.regions],
                                      facecolor=[cmap(k % 9) for k in range(body.region_count)], edgecolor="none"))
    draw_edges(ax, pos, body.springs, colors="#555555", linewidths=0.9)
    draw_edges(ax, pos, body.skin, colors="#b2182b", linewidths=2.8)
    ax.plot(pos[:, 0], pos[:, 1], "o", color="k", ms=3.5, zorder=3)
    ax.set_title(f"(c) Gabriel graph: {body.spring_count} springs,\n{body.region_count} regions, "
                 f"{len(body.skin)} skin edges (thick)", fontsize=10)

    fig.suptitle(f"From embryo to body (paper Fig. 3) - {label}", fontsize=10)
    fig.tight_layout()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    buffer = io.BytesIO()
    fig.savefig(buffer, dpi=90)
    # A 64-colour palette keeps the committed PNG small without visible loss.
    Image.open(buffer).convert("RGB").quantize(colors=64).save(args.out, optimize=True)
    print(f"wrote {args.out} ({label}; {body})")


if __name__ == "__main__":
    main()
