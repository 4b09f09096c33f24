"""Why do the GA's controllers stall? The mutational neighbourhood of the regime replication's bests.

A local search on the controller alone improves the regime bests by a median 74 % (d_N = 0.5) and
94 % (d_N = 10) (controller_optimum.py, docs/regime.md "Does the stroke pay?"), yet the GA's best has
not improved for hundreds of generations. This study looks at what the GA can propose from a best: it
draws the GA's own mutations of the best's genome (animat.Genome.mutate at the run's config.mutation,
the operator every offspring goes through) and sorts each mutant by what development makes of it:

- ``nonviable``: development gives no body the GA would swim (the mutant is never selected);
- ``body``: a body other than the parent's (another cell count, or a cell moved);
- ``controller``: the parent's body, cell for cell, with another controller (a cell's amplitude,
  frequency or phase changed);
- ``silent``: the parent's body and controller (the same swim).

For comparison it perturbs the best's controller directly on its own body, as the controller search
moves: every cell's amplitude and phase by its own normal step, and the body's frequency by one step
shared by all cells (the bests' cells oscillate at one frequency; cells drifting apart in frequency
lose their coordination within the swim). A step has standard deviation sigma in the normalised units
of the controller search (amplitude / amplitude_max, frequency / (frequency_max - frequency_min),
phase in turns) and is clipped to the config's ranges; sigma = 0.01, 0.03 and 0.1 (rows
``random_<sigma>``).

Every swim runs the preset's evaluation.steps at physics.substeps 4 (dt/4, as the controller search;
within about 1 % of dt/32 on these bests). A mutant improves when it swims farther than its parent
at that step. Per best and class the CSV keeps the count, the count that improves, the median and the
largest relative change of the distance; for changed controllers the median fraction of cells whose
controls changed and the median RMS step (normalised units); for changed bodies how many have another
cell count, the median shape distance to the parent's (the mean distance from a cell to the nearest
cell of the other body, both ways, centroids aligned, in cell radii), and how many of them stay within
NEAR = 0.1 radii of it (nearly the parent's body) and how many of those improve. The bests are each run's best at
or before --generation (the packed study has reached it in every 32-cell run), so the same bodies are
read as the study grows:

    PYTHONPATH=build/python .venv/bin/python studies/regime/mutation_effects.py --jobs 2 \\
        --study data/replication_regime --envs dn0.5 dn2 dn10 --generation 424 --mutants 400 \\
        --out studies/regime/results/mutation_effects.csv
    # the same neighbourhoods with the jitter drawn from one stream for every genome
    PYTHONPATH=build/python .venv/bin/python studies/regime/mutation_effects.py --jobs 2 \\
        --study data/replication_regime --envs dn0.5 dn2 dn10 --generation 424 --mutants 400 \\
        --set development.jitter_stream=fixed --out studies/regime/results/mutation_effects_fixed.csv
    # the bests at generation 200 of runs 0-3 at d_N = 0.5 and 10, under each stream (jitter_stream.py)
    PYTHONPATH=build/python .venv/bin/python studies/regime/mutation_effects.py --jobs 2 \\
        --study data/replication_regime --envs dn0.5 dn10 --runs 0 1 2 3 --generation 200 \\
        --out studies/regime/results/mutation_effects_genome200.csv
    PYTHONPATH=build/python .venv/bin/python studies/regime/mutation_effects.py --jobs 2 \\
        --study data/replication_regime_fixed --envs dn0.5 dn10 --runs 0 1 2 3 --generation 200 \\
        --out studies/regime/results/mutation_effects_fixed200.csv
    # each best developed again with its jitter redrawn, scaled or off (no mutation)
    PYTHONPATH=build/python .venv/bin/python studies/regime/mutation_effects.py --jitter \\
        --study data/replication_regime --envs dn0.5 dn2 dn10 --generation 424 \\
        --out studies/regime/results/mutation_effects_jitter.csv
    # the tables of docs/regime.md from the committed CSVs
    PYTHONPATH=build/python .venv/bin/python studies/regime/mutation_effects.py --summary
"""

from __future__ import annotations

import argparse
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
from step_ladder import final_best  # noqa: E402

sys.path.insert(0, str(ROOT / "studies"))
from results_table import write_rows  # noqa: E402

OUT = ROOT / "studies" / "regime" / "results" / "mutation_effects.csv"
SUBSTEPS = 4
SIGMAS = (0.01, 0.03, 0.1)
GA_CLASSES = ("nonviable", "body", "controller", "silent")
CLASSES = GA_CLASSES + tuple(f"random_{s:g}" for s in SIGMAS)
SAME = 1e-9  # a cell position or control that moved by no more than this is unchanged
NEAR = 0.1  # a body within this shape distance (cell radii) of its parent's is nearly the same


def controls(embryo) -> np.ndarray:
    """Per cell (amplitude, frequency, phase) of a developed embryo, shape (cells, 3)."""
    return np.stack([np.asarray(v, dtype=np.float64) for v in (embryo.amplitude, embryo.frequency, embryo.phase)], 1)


def scales(config) -> np.ndarray:
    """The normalised units of the controller search: amplitude_max, the frequency range, a turn."""
    return np.array(
        [
            config["development.amplitude_max"],
            config["development.frequency_max"] - config["development.frequency_min"],
            math.tau,
        ]
    )


def step(a: np.ndarray, b: np.ndarray, config) -> np.ndarray:
    """b - a per cell in normalised units, the phase difference wrapped to half a turn."""
    d = (b - a) / scales(config)
    d[:, 2] = (d[:, 2] + 0.5) % 1.0 - 0.5
    return d


def swim(positions: np.ndarray, c: np.ndarray, config) -> float:
    r = animat.swim(animat.build_body(positions, c[:, 0], c[:, 1], c[:, 2], config=config), config=config)
    return float(r.distance) if r.stable and r.valid else 0.0


def shape_distance(p: np.ndarray, m: np.ndarray) -> float:
    """The mean distance from a cell to the nearest cell of the other body, both ways, centroids aligned
    (cell order and count may differ)."""
    p, m = p - p.mean(0), m - m.mean(0)
    d = np.linalg.norm(p[:, None, :] - m[None, :, :], axis=2)
    return 0.5 * float(d.min(1).mean() + d.min(0).mean())


def classify(parent, mutant, config) -> tuple:
    """(class, cells whose controls changed / cells, RMS step) of a mutant's embryo against its parent's;
    for a changed body (class, 1 if its cell count differs else 0, its shape distance in cell radii)."""
    if mutant is None or not mutant.viable:
        return "nonviable", math.nan, math.nan
    p, m = np.asarray(parent.positions), np.asarray(mutant.positions)
    if p.shape != m.shape or np.max(np.abs(p - m)) > SAME:
        return "body", float(p.shape != m.shape), shape_distance(p, m) / config["development.cell_radius"]
    d = step(controls(parent), controls(mutant), config)
    changed = np.any(np.abs(d) > SAME, axis=1)
    if not changed.any():
        return "silent", 0.0, 0.0
    return "controller", float(changed.mean()), float(np.sqrt(np.mean(d**2)))


def neighbourhood(task: tuple) -> list:
    """The rows of one best: its GA mutants by class, and its random controller perturbations."""
    run, generation, mutants, seed, overrides = task
    config = animat.load_config(str(run / "config.toml"))
    config.apply_overrides(list(overrides))  # e.g. smaller mutation steps than the run's
    config.physics.substeps = config.physics.substeps * SUBSTEPS
    entry = final_best(run, generation)
    genome = animat.Genome.from_json(json.dumps(entry["genome"]))
    parent = animat.develop(genome, config)
    positions, c0 = np.asarray(parent.positions, dtype=np.float64), controls(parent)
    base = float(animat.evaluate(genome, config).fitness)
    rng = animat.Rng(seed)
    found: dict = {k: [] for k in CLASSES}
    for _ in range(mutants):
        child = genome.mutate(rng, config)
        try:
            embryo = animat.develop(child, config)
        except (RuntimeError, ValueError):  # development leaves its valid domain: not viable
            embryo = None
        kind, cells, rms = classify(parent, embryo, config)
        distance = base
        if kind in ("body", "controller"):
            r = animat.evaluate(child, config)
            if r.viable:
                distance = float(r.fitness)
            else:  # the body the GA would not swim
                kind, cells, rms = "nonviable", math.nan, math.nan
        found[kind].append((distance, cells, rms))
    noise = np.random.default_rng(seed)
    lo = np.array([0.0, config["development.frequency_min"], -math.inf])
    hi = np.array([config["development.amplitude_max"], config["development.frequency_max"], math.inf])
    for sigma in SIGMAS:
        for _ in range(mutants):
            z = noise.standard_normal(c0.shape)
            z[:, 1] = z[0, 1]  # one frequency step for the body
            c = np.clip(c0 + sigma * scales(config) * z, lo, hi)
            d = step(c0, c, config)
            found[f"random_{sigma:g}"].append(
                (
                    swim(positions, c, config),
                    float(np.any(np.abs(d) > SAME, axis=1).mean()),
                    float(np.sqrt(np.mean(d**2))),
                )
            )
    rows = []
    for kind in CLASSES:
        got = found[kind]
        change = np.array([d / base - 1.0 for d, _, _ in got]) if got else np.array([])
        cells = [x for _, x, _ in got if not math.isnan(x)]
        rms = [x for _, _, x in got if not math.isnan(x)]
        body = kind == "body"
        near = [d for d, other, shift in got if body and other == 0 and shift <= NEAR]
        rows.append(
            {
                "environment": run.parent.name,
                "run": run.name,
                "generation": int(entry["generation"]),
                "parent_distance": base,
                "class": kind,
                "count": len(got),
                "improve": int(np.sum(change > SAME)),
                "change_median": float(np.median(change)) if len(got) and kind != "nonviable" else math.nan,
                "change_max": float(change.max()) if len(got) and kind != "nonviable" else math.nan,
                "cells_changed_median": float(np.median(cells)) if cells and not body else math.nan,
                "rms_step_median": float(np.median(rms)) if rms and not body else math.nan,
                "cell_count_changed": int(sum(cells)) if body else "",
                "shape_distance_median": float(np.median(rms)) if rms and body else math.nan,
                "near": len(near) if body else "",
                "near_improve": sum(d > base * (1 + SAME) for d in near) if body else "",
            }
        )
    return rows


NEIGHBOURHOODS = (
    "mutation_effects.csv",
    "mutation_effects_fixed.csv",
    "mutation_effects_genome200.csv",
    "mutation_effects_fixed200.csv",
)
JITTER = {
    "redrawn": {"development.jitter_stream": "fixed"},
    "x0.9": {"development.placement_jitter": 0.045},
    "x1.1": {"development.placement_jitter": 0.055},
    "off": {"development.placement_jitter": 0.0},
}


def jitter(task: tuple) -> list:
    """One best developed again with its placement jitter redrawn (the fixed stream instead of its
    genome's), scaled by 0.9 and 1.1, and off: the body's shape distance to its own and the distance."""
    run, generation = task
    config = animat.load_config(str(run / "config.toml"))
    config.physics.substeps = config.physics.substeps * SUBSTEPS
    entry = final_best(run, generation)
    genome = animat.Genome.from_json(json.dumps(entry["genome"]))
    own = np.asarray(animat.develop(genome, config).positions)
    base = float(animat.evaluate(genome, config).fitness)
    rows = []
    for variant, overrides in JITTER.items():
        c = config.copy()
        for key, value in overrides.items():
            c[key] = value
        e = animat.develop(genome, c)
        r = animat.evaluate(genome, c)
        p = np.asarray(e.positions)
        rows.append(
            {
                "environment": run.parent.name,
                "run": run.name,
                "generation": int(entry["generation"]),
                "parent_distance": base,
                "variant": variant,
                "viable": bool(r.viable),
                "same_cell_count": p.shape == own.shape,
                "shape_distance": shape_distance(own, p) / config["development.cell_radius"],
                "change": (float(r.fitness) / base - 1.0) if r.viable else math.nan,
            }
        )
    return rows


def jitter_summary(path: Path) -> str:
    """The table of the jitter variants from the committed CSV."""
    with open(path) as fh:
        rows = list(csv.DictReader(fh))
    out = [
        "| environment | the best developed with its jitter | bests | shape distance (radii): median (range) | "
        "distance change: median (range) |",
        "| --- | --- | --- | --- | --- |",
    ]
    names = {"redrawn": "redrawn (the fixed stream)", "x0.9": "× 0.9", "x1.1": "× 1.1", "off": "off"}
    for env in dict.fromkeys(r["environment"] for r in rows):
        for variant in JITTER:
            k = [r for r in rows if r["environment"] == env and r["variant"] == variant]
            d = np.array([float(r["shape_distance"]) for r in k])
            ch = np.array([float(r["change"]) for r in k if r["change"] not in ("", "nan")])
            ch = 100 * ch[~np.isnan(ch)]
            out.append(
                f"| {env} | {names[variant]} | {len(k)} | {np.median(d):.2f} ({d.min():.2f}–{d.max():.2f}) | "
                + (f"{np.median(ch):+.0f} % ({ch.min():+.0f} to {ch.max():+.0f} %)" if len(ch) else "—")
                + (f", {len(k) - len(ch)} not viable" if len(ch) < len(k) else "")
                + " |"
            )
    return "\n".join(out)


def summary(path: Path) -> str:
    """The table of docs/regime.md ("Why the GA's controllers stall") from the committed CSV."""
    with open(path) as fh:
        rows = list(csv.DictReader(fh))

    def median(sel, key):
        v = [float(r[key]) for r in sel if r[key] not in ("", "nan")]
        v = [x for x in v if not math.isnan(x)]
        return float(np.median(v)) if v else math.nan

    out = [
        "| environment | proposal | share of GA proposals | improve | median change | best change per best: "
        "median | what changed: median |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    for env in dict.fromkeys(r["environment"] for r in rows):
        sel = [r for r in rows if r["environment"] == env]
        ga_total = sum(int(r["count"]) for r in sel if r["class"] in GA_CLASSES)
        for kind in CLASSES:
            k = [r for r in sel if r["class"] == kind]
            n = sum(int(r["count"]) for r in k)
            moved = kind not in ("nonviable", "silent") and n > 0
            improve = sum(int(r["improve"]) for r in k)
            if kind == "body":
                other = sum(int(r["cell_count_changed"]) for r in k)
                near = sum(int(r["near"]) for r in k)
                what = (
                    f"another cell count in {100 * other / n:.0f} %; shape distance "
                    f"{median(k, 'shape_distance_median'):.2f} radii; within {NEAR:g} radii: "
                    f"{100 * near / n:.1f} %, of which {sum(int(r['near_improve']) for r in k)} improve"
                )
            elif moved:
                what = (
                    f"{100 * median(k, 'cells_changed_median'):.0f} % of cells, RMS step "
                    f"{median(k, 'rms_step_median'):.3f}"
                )
            else:
                what = "—"
            label = f"GA mutation: {kind}" if kind in GA_CLASSES else f"controller noise, sigma {kind.split('_')[1]}"
            out.append(
                f"| {env} | {label} | "
                + (f"{100 * n / ga_total:.1f} %" if kind in GA_CLASSES else "—")
                + " | "
                + (f"{improve} of {n} ({100 * improve / n:.1f} %)" if moved else "—")
                + " | "
                + (f"{100 * median(k, 'change_median'):+.1f} %" if moved else "—")
                + " | "
                + (f"{100 * median(k, 'change_max'):+.1f} %" if moved else "—")
                + f" | {what} |"
            )
    return "\n".join(out)


def study_arguments(doc: str) -> argparse.ArgumentParser:
    """The command line's choice of bests: a packed study, its environments and runs, a generation."""
    p = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--study", type=Path, default=ROOT / "data" / "replication_regime")
    p.add_argument("--envs", nargs="+", default=["dn0.5", "dn2", "dn10"])
    p.add_argument("--runs", type=int, nargs="+", default=list(range(10)))
    p.add_argument("--generation", type=int, default=424, help="each run's best at or before this generation")
    return p


def main(argv=None) -> int:
    p = study_arguments(__doc__)
    p.add_argument("--mutants", type=int, default=400, help="GA mutants, and perturbations per sigma, per best")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="change the runs' config for the mutants (e.g. mutation.move_rate=0.005); repeatable",
    )
    p.add_argument("--jobs", type=int, default=1)
    p.add_argument("--out", type=Path, default=OUT)
    p.add_argument(
        "--jitter", action="store_true", help="develop each best again with its jitter redrawn, scaled or off"
    )
    p.add_argument(
        "--summary",
        action="store_true",
        help="print the tables of docs/regime.md from the committed CSVs; swim nothing",
    )
    args = p.parse_args(argv)
    if args.summary:
        for name in NEIGHBOURHOODS:
            if (OUT.parent / name).is_file():
                print(f"{name}:\n{summary(OUT.parent / name)}\n")
        if (OUT.parent / "mutation_effects_jitter.csv").is_file():
            print(jitter_summary(OUT.parent / "mutation_effects_jitter.csv"))
        return 0
    study = args.study if args.study.is_absolute() else Path.cwd() / args.study
    if args.jitter:
        tasks = [(study / env / f"run_{i}", args.generation) for env in args.envs for i in args.runs]
        with Pool(args.jobs) as pool:
            rows = [r for got in pool.imap(jitter, tasks) for r in got]
        write_rows(args.out, rows)
        print(jitter_summary(args.out))
        return 0
    tasks = [
        (study / env / f"run_{i}", args.generation, args.mutants, args.seed + i, args.set)
        for env in args.envs
        for i in args.runs
    ]
    rows = []
    with Pool(args.jobs) as pool:
        for got in pool.imap(neighbourhood, tasks):
            rows += got
            r = got[0]
            print(
                f"{r['environment']} {r['run']} (best of generation {r['generation']}, {r['parent_distance']:.2f}): "
                + ", ".join(f"{g['class']} {g['improve']}/{g['count']}" for g in got),
                flush=True,
            )
    write_rows(args.out, rows)
    print()
    print(summary(args.out))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
