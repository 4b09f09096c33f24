"""MAP-Elites (animat.qd): an archive of swimmers over two descriptors of the body, filled by varying its
elites, written as a run directory, and drawn as a map of the best fitness per cell.

    PYTHONPATH=build/python .venv/bin/python examples/map_elites.py [--generations 30] [--batch 20]

With the defaults (1000 swim steps, batches of 20, 30 generations) it took 17 s on the project machine (2 cores).
``--resume`` continues the run in ``--out-dir`` up to ``--generations``.
"""

from pathlib import Path

import numpy as np

import animat

from _common import plt, save_png, search_config, search_parser


def heatmap(archive: animat.GridArchive, title: str):
    """The best fitness of every cell of a 2-D grid archive (empty cells blank)."""
    grid = np.full(archive.bins, np.nan)
    for e in archive.elites():
        grid[np.unravel_index(e.index, archive.bins)] = e.objective
    fig, ax = plt.subplots(figsize=(5.5, 4))
    (x, y) = archive.descriptors
    image = ax.imshow(
        grid.T, origin="lower", aspect="auto", extent=(x.lo, x.hi, y.lo, y.hi), cmap="viridis", interpolation="nearest"
    )
    ax.set_xlabel(f"{x.name}: {x.meaning}", fontsize=8)
    ax.set_ylabel(f"{y.name}", fontsize=8)
    ax.set_title(title, fontsize=9)
    fig.colorbar(image, ax=ax, label="best fitness (distance)")
    fig.tight_layout()
    return fig


def main() -> None:
    p = search_parser(__doc__, size="batch", generations=30)
    p.add_argument("--out-dir", type=Path, default=Path("runs/map_elites"))
    p.add_argument("--resume", action="store_true")
    p.add_argument("--out", type=Path, default=Path("runs/map_elites/archive.png"))
    args = p.parse_args()

    config = search_config(args)
    # The exploit guard's reference for every new elite (16 x the step): "off" would be faster.
    config["evaluation.reference_check"] = "record"
    archive = animat.GridArchive(["elongation", "protrusions"], bins=(12, 8))  # 0..7 protrusions, one bin each

    def report(row) -> None:
        print(
            f"generation {row.generation:3d}: {row.elites:3d} elites, coverage {row.coverage:.3f}, "
            f"QD-score {row.qd_score:.4g}, best {row.best:.4g}"
        )

    me = animat.run_map_elites(
        config,
        args.out_dir,
        args.generations,
        None if args.resume else archive,
        batch=args.batch,
        seed=args.seed,
        threads=args.threads,
        archive_every=5,
        resume=args.resume,
        overwrite=not args.resume,
        callback=report,
    )
    archive = me.archive
    best = archive.best()
    assert isinstance(archive, animat.GridArchive) and best is not None
    print(
        f"{len(archive)} elites in {archive.cells} cells; the best: fitness {best.fitness:.4g} "
        f"(reference {best.reference:.4g}), {dict(zip(archive.names, best.descriptors))}"
    )
    print(f"run directory: {args.out_dir} (history.csv, archive/gen_*.csv, checkpoint.json)")
    save_png(heatmap(archive, f"MAP-Elites, generation {me.generation}, seed {args.seed}"), args.out)


if __name__ == "__main__":
    main()
