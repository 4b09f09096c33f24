"""NSGA-II (animat.moo): swimmers that go far against swimmers that spend little, the Pareto front of
distance (maximised) and positive actuation work (minimised), written as a run directory and drawn.

    PYTHONPATH=build/python .venv/bin/python examples/nsga2_distance_vs_work.py [--generations 20] [--population 20]

Every swim meters its actuation work (docs/worlds.md), so the paper's setting needs no change; the swims
are shortened to ``--steps`` (1000 by default; the paper: 4000). ``--resume`` continues the run in
``--out-dir`` up to ``--generations``.
"""

import csv
import time
from pathlib import Path

import animat

from _common import plt, save_png, search_config, search_parser

OBJECTIVES = [("distance", "max"), ("actuation_work_positive", "min")]


def front_of(path: Path):
    """(distance, work) of every genome of a front CSV written by the run."""
    with path.open(newline="") as f:
        return [(float(r["distance"]), float(r["actuation_work_positive"])) for r in csv.DictReader(f)]


def plot_fronts(nsga: animat.Nsga2, out_dir: Path, title: str):
    """The population, the first front and the front of generation 0, work against distance."""
    fig, ax = plt.subplots(figsize=(5.5, 4))
    feasible = [s.objectives for s in nsga.population if s.feasible]
    ax.scatter([d for d, _ in feasible], [w for _, w in feasible], s=12, color="0.75", label="population")
    first = out_dir / "front" / "gen_000000.csv"
    if first.is_file():
        start = sorted(front_of(first))
        ax.plot(
            [d for d, _ in start], [w for _, w in start], "o--", color="tab:gray", ms=4, label="front, generation 0"
        )
    front = sorted(tuple(s.objectives) for s in nsga.front())
    ax.plot(
        [d for d, _ in front],
        [w for _, w in front],
        "o-",
        color="tab:blue",
        ms=5,
        label=f"front, generation {nsga.generation}",
    )
    ax.set_xlabel("distance (length units)")
    ax.set_ylabel("positive actuation work")
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def main() -> None:
    p = search_parser(__doc__)
    p.add_argument("--out-dir", type=Path, default=Path("runs/nsga2"))
    p.add_argument("--resume", action="store_true")
    p.add_argument("--out", type=Path, default=Path("runs/nsga2/front.png"))
    args = p.parse_args()

    config = search_config(args)
    # The exploit guard's reference for every genome that reaches the front (16 x the step): "off" is faster.
    config["evaluation.reference_check"] = "record"

    def report(row) -> None:
        print(
            f"generation {row.generation:3d}: front {row.front_size:3d}, hypervolume {row.hypervolume:.4g}, "
            f"best distance {row.best_distance:.4g}, least work {row.best_actuation_work_positive:.4g}, "
            f"disagreements {row.disagreements}"
        )

    start = time.perf_counter()
    nsga = animat.run_nsga2(
        config,
        None if args.resume else OBJECTIVES,
        args.out_dir,
        args.generations,
        population=args.population,
        seed=args.seed,
        threads=args.threads,
        front_every=5,
        resume=args.resume,
        overwrite=not args.resume,
        callback=report,
    )
    seconds = time.perf_counter() - start
    print(
        f"{nsga.evaluations} evaluations and {int(nsga.history['reference_evaluations'][-1])} reference swims "
        f"in {seconds:.1f} s; hypervolume reference point {nsga.reference_point}"
    )
    print("the front (distance, positive work, distance per work):")
    for s in nsga.front():
        distance, work = s.objectives
        print(f"  {distance:10.4g} {work:12.4g} {distance / work if work > 0 else float('nan'):12.4g}")
    print(f"run directory: {args.out_dir} (history.csv, front/gen_*.csv, checkpoint.json)")
    save_png(plot_fronts(nsga, args.out_dir, f"NSGA-II, seed {args.seed}, {args.steps}-step swims"), args.out)


if __name__ == "__main__":
    main()
