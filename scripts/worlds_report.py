#!/usr/bin/env python3
"""The runs of docs/worlds.md, re-checked from the packed runs in data/worlds alone.

    PYTHONPATH=build/python .venv/bin/python scripts/worlds_report.py energy [--data data/worlds/energy]
    PYTHONPATH=build/python .venv/bin/python scripts/worlds_report.py crawl  [--data data/worlds/crawl] \
        [--images docs/images/worlds]

``energy``: the paper's hypothesis (§7) that a cost of actuation makes evolution use only some cells
as actuators. For the best of every run of every objective (data/worlds/energy/<objective>/run_<i>,
run i has seed i + 1) it develops the best genome, swims it with the run's own config and prints a
Markdown table: cells, distance, positive actuation work W+, the fraction of cells with a near-zero
amplitude (a_i < 5 % of development.amplitude_max), the mean amplitude over the maximum, and the fraction of cells that do almost no
positive work (less than 10 % of the body's mean per-cell W+), then the mean of each per objective.

``crawl``: the crawl world's best: its history, the re-measured fitness and floor counters, the
fraction of frames with no cell on the floor, and (with --images) a motion-cycle figure and a GIF.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

import animat

# The packed-run store is study code (studies/replication), not part of the package.
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "studies" / "replication"))
from replication_store import packed_runs, unpack_run  # noqa: E402

NEAR_ZERO_AMPLITUDE = 0.05  # of development.amplitude_max
IDLE_WORK = 0.10  # of the body's mean positive work per cell


def unpacked(root: Path, tmp: Path):
    """{group: [(index, animat.Run)]} of every packed run under root."""
    out = {}
    for group, runs in packed_runs(root).items():
        out[group] = []
        for p in runs:
            out[group].append((int(p.name[4:]), animat.Run(unpack_run(p, tmp / group / p.name))))
    return out


def best_body_and_swim(run: animat.Run):
    cfg = run.config
    entry = run.best()
    body = animat.build_body(animat.develop(entry.genome, cfg))
    return entry, body, animat.swim(body, config=cfg), cfg


def energy(args) -> int:
    with tempfile.TemporaryDirectory() as t:
        groups = unpacked(Path(args.data), Path(t))
        rows, means = [], {}
        for group, runs in groups.items():
            acc = []
            for index, run in runs:
                entry, body, r, cfg = best_body_and_swim(run)
                a = np.asarray(body.amplitude)
                w = np.asarray(r.cell_work_positive)
                near_zero = float(np.mean(a < NEAR_ZERO_AMPLITUDE * cfg["development.amplitude_max"]))
                idle = float(np.mean(w < IDLE_WORK * w.mean())) if w.size and w.mean() > 0 else 1.0
                gens = int(run.history[-1]["generation"])
                rel = float(a.mean() / cfg["development.amplitude_max"])
                acc.append((r.distance, r.actuation_work_positive, near_zero, idle, rel))
                rows.append(
                    f"| {group} | {index} | {gens} | {entry.fitness:.6g} | {body.node_count} | {r.distance:.2f} | "
                    f"{r.actuation_work_positive:.3g} | {rel:.2f} | {near_zero:.2f} | {idle:.2f} |"
                )
            means[group] = np.mean(np.asarray(acc), axis=0)
    print(
        "| objective | run | generations | best fitness | cells | distance | W+ | mean amplitude / max | "
        "near-zero amplitude | idle cells |"
    )
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    print("\n".join(rows))
    print()
    print(
        "| objective | runs | mean distance | mean W+ | mean fraction near-zero amplitude | mean fraction idle | "
        "mean amplitude / max |"
    )
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for group, m in means.items():
        print(f"| {group} | {len(groups[group])} | {m[0]:.2f} | {m[1]:.3g} | {m[2]:.2f} | {m[3]:.2f} | {m[4]:.2f} |")
    return 0


def crawl(args) -> int:
    with tempfile.TemporaryDirectory() as t:
        groups = unpacked(Path(args.data), Path(t))
        for group, runs in groups.items():
            for index, run in runs:
                entry, body, r, cfg = best_body_and_swim(run)
                h = run.history
                print(
                    f"## {group}/run_{index}: {len(h)} generations, best {h[-1]['best']:.4g} "
                    f"(lineage entry at generation {entry.generation}: {entry.fitness:.6g}), {body.node_count} cells"
                )
                for g in (0, len(h) // 4, len(h) // 2, 3 * len(h) // 4, len(h) - 1):
                    print(f"  generation {int(h[g]['generation'])}: best {h[g]['best']:.4g}, mean {h[g]['mean']:.4g}")
                fine = cfg.copy()
                fine["physics.dt"] = cfg["physics.dt"] / 16
                fine["evaluation.steps"] = cfg["evaluation.steps"] * 16
                fine["evaluation.settle_steps"] = cfg["evaluation.settle_steps"] * 16
                rf = animat.swim(body, config=fine)
                print(
                    f"  re-swum: distance_x objective {animat.evaluate(entry.genome, cfg).fitness:.6g}; "
                    f"at dt/16 {animat.evaluate(entry.genome, fine).fitness:.6g} (swim distance {r.distance:.4g} "
                    f"vs {rf.distance:.4g})"
                )
                tr = animat.replay(entry.genome, cfg, every=10)
                y = np.asarray(tr.positions)[:, :, 1]
                floor = cfg["scene.ground_height"]
                airborne = float(np.mean(y.min(axis=1) > floor + 1e-3))
                print(
                    f"  floor contacts {r.ground_contacts}, slips {r.ground_slips}; airborne share (Box2D steps in "
                    f"which the floor pushed no cell) {r.airborne_steps / (cfg['evaluation.steps'] * cfg['physics.substeps']):.0%}; "
                    f"frames with no cell within 1e-3 of the floor: {airborne:.0%}; lowest centre "
                    f"{y.min() - floor:.2e} above the floor"
                )
                print(
                    f"  actuation work: positive {r.actuation_work_positive:.3g}, absolute {r.actuation_work_absolute:.3g}"
                )
                a = np.asarray(body.amplitude)
                print(
                    f"  amplitudes: min {a.min():.3f}, median {np.median(a):.3f}, max {a.max():.3f}; "
                    f"frequencies {np.unique(np.round(np.asarray(body.frequency), 3))}"
                )
                if args.images:
                    import matplotlib

                    matplotlib.use("Agg")
                    from animat import plot

                    out = Path(args.images)
                    out.mkdir(parents=True, exist_ok=True)
                    full = animat.replay(entry.genome, cfg)
                    fig = plot.motion_cycle(full, align=False, count=6)
                    fig.savefig(out / f"{group}_run{index}_motion_cycle.png", dpi=90)
                    fig = plot.phase_map(body, config=cfg)
                    fig.savefig(out / f"{group}_run{index}_phase_map.png", dpi=90)
                    animat.animate(
                        full,
                        out / f"{group}_run{index}.gif",
                        align=False,
                        fps=16,
                        max_frames=64,
                        size=(360, 220),
                        colors=16,
                        progress=False,
                    )
                    print(f"  images: {out}/{group}_run{index}_motion_cycle.png, _phase_map.png, .gif")
    return 0


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=(__doc__ or "").split("\n\n")[0])
    sub = p.add_subparsers(dest="what", required=True)
    e = sub.add_parser("energy")
    e.add_argument("--data", default="data/worlds/energy")
    c = sub.add_parser("crawl")
    c.add_argument("--data", default="data/worlds/crawl")
    c.add_argument("--images", default=None)
    args = p.parse_args(argv)
    return energy(args) if args.what == "energy" else crawl(args)


if __name__ == "__main__":
    sys.exit(main())
