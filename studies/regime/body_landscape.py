"""How does a best's distance depend on its body? Development is smooth; the swim is not.

Under either jitter stream the GA's body-changing mutations of a best almost never improve it
(mutation_effects.py). This study asks where that ruggedness lives: in development (a small change of
the genome's effect making a very different body) or in the swim (a slightly different body swimming
very differently). It moves a best's development by a controlled, small amount, with no mutation:
every daughter's placement deviation is scaled by 1 + eps (development.placement_jitter times
1 + eps, the deviations' stream unchanged), for eps from 1e-6 to 0.1. Per best it counts its Delaunay edges and those within NEAR_ANGLE = 1 degree of the Gabriel rule's
threshold (gabriel_margins: the largest angle another centre sees the edge at is within 1 degree of
90); per best and eps it records

- ``shape_distance``: the body's shape distance to the best's own (mutation_effects.shape_distance, in
  cell radii) and ``control_step``, the RMS change of the cells' controls (normalised units of the
  controller search);
- ``springs_changed``: how many springs the body's Gabriel graph gained or lost (the spring network,
  its pressurised regions and its skin all follow from it);
- ``change``: the distance's relative change, and apart, ``change_body`` (the new body with the best's
  own controls) and ``change_controls`` (the best's body with the new controls), and ``path_change``,
  the relative change of the length of the centroid's path (the distance is its end-to-end length:
  a swim that only turns keeps its path length); ``springs_changed_distance`` and
  ``springs_changed_alpha_shape``, the springs the same two bodies' graphs differ by under body.graph's
  other rules (docs/model.md "Other body graphs"; no swim); for eps >= 1e-3, ``change_retuned``: the
  change once the frequency is re-tuned, the farthest swim of the new body with every cell's
  frequency scaled by 0.80, 0.81, ..., 1.20 against the same for the best (the bests are tuned sharply
  to their bodies' elastic modes, and a body change shifts the modes).

With ``--mutants`` it sorts the GA's body-changing mutations of a best (Genome.mutate at the run's
rates and seeds, the mutants of mutation_effects.py) by whether they keep the spring graph, to see
whether the GA's own proposals that keep it refine the body: per best and kind, the count, how many
improve, the median shape distance and springs changed, the median and largest change. Every swim runs at dt/4 (physics.substeps x 4), as in
mutation_effects.py; a best that moves by less than 1e-9 per cell is the same body.

    # the 30 regime bests at generation <= 424 (genome stream)
    PYTHONPATH=build/python .venv/bin/python studies/regime/body_landscape.py --jobs 2 \\
        --study data/replication_regime --envs dn0.5 dn2 dn10 --generation 424 \\
        --out studies/regime/results/body_landscape.csv
    # the GA's body-changing mutants of the same bests (the mutants of mutation_effects.csv)
    PYTHONPATH=build/python .venv/bin/python studies/regime/body_landscape.py --jobs 2 --mutants 400 \\
        --study data/replication_regime --envs dn0.5 dn2 dn10 --generation 424 \\
        --out studies/regime/results/body_landscape_mutants_genome.csv
    # and of the 8 fixed-stream bests at generation 200 (those of mutation_effects_fixed200.csv)
    PYTHONPATH=build/python .venv/bin/python studies/regime/body_landscape.py --jobs 2 --mutants 400 \\
        --study data/replication_regime_fixed --envs dn0.5 dn10 --runs 0 1 2 3 --generation 200 \\
        --out studies/regime/results/body_landscape_mutants_fixed200.csv
    # the tables of docs/regime.md from the committed CSVs
    PYTHONPATH=build/python .venv/bin/python studies/regime/body_landscape.py --summary
"""

from __future__ import annotations

import csv
import json
import math
import sys
from multiprocessing import Pool
from pathlib import Path

import numpy as np

import animat

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "studies" / "regime"))
from mutation_effects import (  # noqa: E402
    SAME,
    SUBSTEPS,
    controls,
    shape_distance,
    step,
    study_arguments,
    swim,
)
from step_ladder import final_best  # noqa: E402

sys.path.insert(0, str(ROOT / "studies"))
from results_table import write_rows  # noqa: E402

RESULTS = ROOT / "studies" / "regime" / "results"
LADDER = RESULTS / "body_landscape.csv"
MUTANTS = (RESULTS / "body_landscape_mutants_genome.csv", RESULTS / "body_landscape_mutants_fixed200.csv")
MEASURES = (
    "shape_distance",
    "control_step",
    "springs_changed",
    "change",
    "change_body",
    "change_controls",
    "path_change",
    "springs_changed_distance",
    "springs_changed_alpha_shape",
    "change_retuned",
)
RETUNE = np.round(np.arange(0.80, 1.2001, 0.01), 2)  # the frequency multipliers tried in re-tuning
RETUNE_FROM = 1e-3  # smaller eps change the distance too little to re-tune
OTHER_GRAPHS = ("distance", "alpha_shape")  # body.graph's other rules, at their default thresholds
NEAR_ANGLE = 1.0  # degrees: a Delaunay edge this close to the Gabriel rule's threshold is near a flip
EPS = (1e-6, 1e-5, 1e-4, 1e-3, 3e-3, 1e-2, 3e-2, 1e-1)


def springs(positions: np.ndarray, c: np.ndarray, config, graph: str = "") -> set:
    """The body's springs as a set of cell pairs: its config's body graph (the paper's Gabriel graph in
    every preset), or ``graph``."""
    if graph:
        config = config.copy()
        config["body.graph"] = graph
    body = animat.build_body(positions, c[:, 0], c[:, 1], c[:, 2], config=config)
    return {tuple(sorted(map(int, s))) for s in np.asarray(body.springs)}


def gabriel_margins(points: np.ndarray) -> np.ndarray:
    """Per Delaunay edge (i, j), in degrees, 90 minus the largest angle i-k-j over every other centre
    k: the Gabriel graph keeps the edge iff its margin is positive (the closed diametral disc), so an
    edge with a margin near 0 flips under a small move."""
    out = []
    for i, j in animat.delaunay_edges(points):
        u, v = points[i] - points, points[j] - points
        cos = np.einsum("ij,ij->i", u, v) / (np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1) + 1e-300)
        cos[[i, j]] = 1.0  # the ends themselves see the edge at no angle
        out.append(90.0 - np.degrees(np.arccos(np.clip(cos.min(), -1.0, 1.0))))
    return np.array(out)


def springs_changed(a: set, b: set) -> int:
    return len(a ^ b)


def load(run: Path, generation: int):
    config = animat.load_config(str(run / "config.toml"))
    config.physics.substeps = config.physics.substeps * SUBSTEPS
    entry = final_best(run, generation)
    return config, entry, animat.Genome.from_json(json.dumps(entry["genome"]))


def path_length(genome, config) -> float:
    """The length of the centroid's path over the swim, sampled every 50 control steps."""
    com = np.asarray(animat.record_evaluation(genome, config, 50).com)
    return float(np.sum(np.linalg.norm(np.diff(com, axis=0), axis=1)))


def retuned(positions: np.ndarray, c: np.ndarray, config) -> float:
    """The farthest swim of a body with every cell's frequency scaled by one of RETUNE (clipped to the
    frequency range): what re-tuning the body's one frequency recovers."""
    lo, hi = config["development.frequency_min"], config["development.frequency_max"]
    best = -math.inf
    for m in RETUNE:
        tuned = c.copy()
        tuned[:, 1] = np.clip(c[:, 1] * m, lo, hi)
        best = max(best, swim(positions, tuned, config))
    return best


def ladder(task: tuple) -> list:
    """One best developed with its placement deviations scaled by 1 + eps, for every eps."""
    run, generation = task
    config, entry, genome = load(run, generation)
    own = animat.develop(genome, config)
    p0, c0 = np.asarray(own.positions, dtype=np.float64), controls(own)
    s0 = springs(p0, c0, config)
    other0 = {g: springs(p0, c0, config, g) for g in OTHER_GRAPHS}
    base, base_path = swim(p0, c0, config), path_length(genome, config)
    margins = gabriel_margins(p0)
    base_retuned = retuned(p0, c0, config)
    radius = config["development.cell_radius"]
    rows = []
    for eps in EPS:
        c = config.copy()
        c["development.placement_jitter"] = config["development.placement_jitter"] * (1.0 + eps)
        e = animat.develop(genome, c)
        row = {
            "environment": run.parent.name,
            "run": run.name,
            "generation": int(entry["generation"]),
            "parent_distance": base,
            "delaunay_edges": len(margins),
            "near_gabriel_threshold": int(np.sum(np.abs(margins) < NEAR_ANGLE)),
            "eps": eps,
            "viable": bool(e.viable),
            "same_cell_count": len(e.positions) == len(p0),
        }
        row.update(dict.fromkeys(MEASURES, math.nan))
        if not (e.viable and row["same_cell_count"]):
            rows.append(row)
            continue
        p, ctl = np.asarray(e.positions, dtype=np.float64), controls(e)
        row.update(
            {
                "shape_distance": shape_distance(p0, p) / radius,
                "control_step": float(np.sqrt(np.mean(step(c0, ctl, config) ** 2))),
                "springs_changed": springs_changed(s0, springs(p, ctl, config)),
                "change": swim(p, ctl, config) / base - 1.0,
                "change_body": swim(p, c0, config) / base - 1.0,
                "change_controls": swim(p0, ctl, config) / base - 1.0,
                "path_change": path_length(genome, c) / base_path - 1.0,
            }
        )
        for g in OTHER_GRAPHS:
            row[f"springs_changed_{g}"] = springs_changed(other0[g], springs(p, ctl, config, g))
        if eps >= RETUNE_FROM:
            row["change_retuned"] = retuned(p, ctl, config) / base_retuned - 1.0
        rows.append(row)
    return rows


def mutants(task: tuple) -> list:
    """One best's body-changing GA mutants, in two rows: those that keep its springs and the others."""
    run, generation, count, seed = task
    config, entry, genome = load(run, generation)
    parent = animat.develop(genome, config)
    p0, c0 = np.asarray(parent.positions, dtype=np.float64), controls(parent)
    s0 = springs(p0, c0, config)
    base = swim(p0, c0, config)
    radius = config["development.cell_radius"]
    rng = animat.Rng(seed)
    found: dict = {"same": [], "other": []}
    for _ in range(count):
        child = genome.mutate(rng, config)
        try:
            e = animat.develop(child, config)
        except (RuntimeError, ValueError):  # development leaves its valid domain: not viable
            continue
        if not e.viable or len(e.positions) != len(p0):
            continue
        p, ctl = np.asarray(e.positions, dtype=np.float64), controls(e)
        if np.max(np.abs(p - p0)) <= SAME:
            continue  # the same body: a controller or silent mutation
        flipped = springs_changed(s0, springs(p, ctl, config))
        found["other" if flipped else "same"].append(
            (shape_distance(p0, p) / radius, flipped, swim(p, ctl, config) / base - 1.0)
        )
    rows = []
    for kind, got in found.items():
        shape, flipped, change = (np.array(v, dtype=float) for v in zip(*got)) if got else ([], [], [])
        rows.append(
            {
                "environment": run.parent.name,
                "jitter_stream": config["development.jitter_stream"],
                "run": run.name,
                "generation": int(entry["generation"]),
                "parent_distance": base,
                "springs": kind,
                "count": len(got),
                "improve": int(np.sum(np.asarray(change) > SAME)),
                "shape_distance_median": float(np.median(shape)) if got else math.nan,
                "springs_changed_median": float(np.median(flipped)) if got else math.nan,
                "change_median": float(np.median(change)) if got else math.nan,
                "change_max": float(np.max(change)) if got else math.nan,
            }
        )
    return rows


def read(path: Path) -> list:
    with open(path) as fh:
        return list(csv.DictReader(fh))


def number(row: dict, key: str) -> float:
    v = row.get(key, "")
    return float(v) if v not in ("", None) else math.nan


def pct(v) -> str:
    v = 100 * np.asarray(v, dtype=float)
    return f"{np.median(v):+.1f} % ({v.min():+.0f} to {v.max():+.0f} %)" if len(v) else "—"


def ladder_summary(path: Path) -> str:
    """Per environment and eps: the shape's and controls' change, the springs, and the distance's;
    then per environment the Delaunay edges near the Gabriel rule's threshold."""
    rows = [r for r in read(path) if r["viable"] == "True" and r["same_cell_count"] == "True"]

    def med(sel, key):
        return f"{100 * np.median([number(r, key) for r in sel]):+.1f} %" if sel else "—"

    out = [
        "| environment | eps | bests | shape distance (radii): median | control step: median | "
        "same springs: Gabriel, distance, alpha_shape | distance change: median (range) | "
        "with the same springs: median | with other springs: median | body alone: median | "
        "controls alone: median | path length change: median | frequency re-tuned: median |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    envs = list(dict.fromkeys(r["environment"] for r in rows))
    for env in envs:
        for eps in EPS:
            k = [r for r in rows if r["environment"] == env and math.isclose(float(r["eps"]), eps)]
            same = [r for r in k if int(r["springs_changed"]) == 0]
            other = [r for r in k if int(r["springs_changed"]) > 0]
            kept = [len(same)] + [sum(number(r, f"springs_changed_{g}") == 0 for r in k) for g in OTHER_GRAPHS]
            out.append(
                f"| {env} | {eps:g} | {len(k)} | {np.median([number(r, 'shape_distance') for r in k]):.1e} | "
                f"{np.median([number(r, 'control_step') for r in k]):.1e} | {', '.join(map(str, kept))} of {len(k)} | "
                f"{pct([number(r, 'change') for r in k])} | {med(same, 'change')} | {med(other, 'change')} | "
                f"{med(k, 'change_body')} | {med(k, 'change_controls')} | {med(k, 'path_change')} | "
                + (med(k, "change_retuned") if eps >= RETUNE_FROM else "—")
                + " |"
            )
    out += ["", "| environment | bests | Delaunay edges per best: median | within 1 degree of the Gabriel threshold |"]
    out.append("| --- | --- | --- | --- |")
    for env in envs:
        bests = {r["run"]: r for r in rows if r["environment"] == env}.values()
        near = [int(r["near_gabriel_threshold"]) for r in bests]
        out.append(
            f"| {env} | {len(bests)} | {np.median([int(r['delaunay_edges']) for r in bests]):.0f} | "
            f"{sum(near)} of {sum(int(r['delaunay_edges']) for r in bests)} edges; "
            f"{sum(n > 0 for n in near)} of {len(bests)} bests have one |"
        )
    return "\n".join(out)


def mutants_summary(path: Path) -> str:
    """Per environment: the body-changing mutants that keep the spring graph and those that do not."""
    rows = read(path)
    out = [
        "| environment | jitter stream | bests | body-changing mutants | springs | mutants | "
        "shape distance (radii): median over bests | improve | distance change: median over bests |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for env, stream in dict.fromkeys((r["environment"], r["jitter_stream"]) for r in rows):
        k = [r for r in rows if r["environment"] == env and r["jitter_stream"] == stream]
        total = sum(int(r["count"]) for r in k)
        for kind, label in (("same", "the same"), ("other", "other")):
            sel = [r for r in k if r["springs"] == kind and int(r["count"])]
            n = sum(int(r["count"]) for r in sel)
            out.append(
                f"| {env} | {stream} | {len({r['run'] for r in k})} | {total} | {label} | {n} | "
                + (f"{np.median([number(r, 'shape_distance_median') for r in sel]):.2f}" if sel else "—")
                + f" | {sum(int(r['improve']) for r in sel)} of {n} | "
                + (f"{100 * np.median([number(r, 'change_median') for r in sel]):+.1f} %" if sel else "—")
                + " |"
            )
    return "\n".join(out)


def main(argv=None) -> int:
    p = study_arguments(__doc__)
    p.add_argument("--mutants", type=int, default=0, help="sort this many GA mutants per best instead of the ladder")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--jobs", type=int, default=1)
    p.add_argument("--out", type=Path)
    p.add_argument("--summary", action="store_true", help="print the tables of docs/regime.md from the committed CSVs")
    args = p.parse_args(argv)
    if args.summary:
        for path, table in ((LADDER, ladder_summary),) + tuple((m, mutants_summary) for m in MUTANTS):
            if path.is_file():
                print(f"{path.name}:\n{table(path)}\n")
        return 0
    study = args.study if args.study.is_absolute() else Path.cwd() / args.study
    runs = [(study / env / f"run_{i}", i) for env in args.envs for i in args.runs]
    if args.mutants:
        tasks, work, table, out = (
            [(r, args.generation, args.mutants, args.seed + i) for r, i in runs],
            mutants,
            mutants_summary,
            args.out or MUTANTS[0],
        )
    else:
        tasks, work, table, out = [(r, args.generation) for r, _ in runs], ladder, ladder_summary, args.out or LADDER
    rows = []
    with Pool(args.jobs) as pool:
        for got in pool.imap(work, tasks):
            rows += got
            print(f"{got[0]['environment']} {got[0]['run']}: {len(got)} rows" if got else "(no rows)", flush=True)
    write_rows(out, rows)
    print(table(out))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
