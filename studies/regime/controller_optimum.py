"""Does the paper's protrusion stroke pay in this physics? Fixed bodies, optimised controllers.

The regime replication (docs/regime.md) evolves synchronous contractors at low drag where the paper
found protrusion swimmers. Either the stroke does not pay here (the physics), or it pays and
evolution does not reach it (development, the GRN, the search). This study separates the two: it
takes hand-built bodies of about 32 cells with and without a symmetric pair of appendages
(studies/locomotion/known_swimmers.py builds them) and searches each one's controller directly with
CMA-ES, at the regime preset's constants (configs/regime_<env>.toml), with no development and no
GRN in the way.

The controller is eq. 2's oscillator with one frequency for the whole body, and per mirror pair of
cells (mirror image about the body's long axis) one amplitude in [0, amplitude_max] and one phase:
the symmetric control the paper's protrusion swimmers show (Fig. 6, 7b), under which a symmetric
body swims along its axis. Every candidate swims the preset's evaluation.steps at physics.substeps
4 (dt/4, within about 1 % of dt/32 on the replication's bests; the default step is up to 41 % off
at d_N = 0.5); the best controller of each search is swum again at dt/16 (the preset's reference,
what its GA ranks by) and dt/32, classified by the stroke path (animat.classify_locomotion), and,
for a body with appendages, measured by the stroke's ground truth (known_swimmers.stroke_truth:
whether every appendage rows, out on the backward stroke and in on the return).

CMA-ES (the `cma` package) starts from a random controller of the seed, with step 0.3 in the
normalised parameters (frequency and amplitude in [0, 1], phase in turns), and stops after
--evaluations swims; a search finds a good controller, not the best one (two seeds of one body can
differ by a factor of two), so a body's distance here is what it can at least do. Three sets:

    # hand-built bodies, symmetric control (results/controller_optimum_mirror.csv)
    PYTHONPATH=build/python .venv/bin/python studies/regime/controller_optimum.py --jobs 2 \\
        --out studies/regime/results/controller_optimum_mirror.csv
    # the compact and the elongated body with one amplitude and phase per cell (bending allowed)
    PYTHONPATH=build/python .venv/bin/python studies/regime/controller_optimum.py --free \\
        --bodies blob elongated --evaluations 4000 --out studies/regime/results/controller_optimum_free.csv
    # the regime replication's bests (their bodies), from their GA-evolved controllers
    PYTHONPATH=build/python .venv/bin/python studies/regime/controller_optimum.py --seeds 1 --jobs 2 \\
        --evolved data/replication_regime/dn0.5/run_0@447 \\
        data/replication_regime/dn0.5/run_1@230 data/replication_regime/dn0.5/run_2@415 \\
        data/replication_regime/dn0.5/run_3@104 data/replication_regime/dn0.5/run_4@446 \\
        data/replication_regime/dn0.5/run_5@148 data/replication_regime/dn0.5/run_6@389 \\
        data/replication_regime/dn0.5/run_7@187 data/replication_regime/dn0.5/run_8@208 \\
        data/replication_regime/dn0.5/run_9@65 data/replication_regime/dn10/run_0@398 \\
        data/replication_regime/dn10/run_1@214 data/replication_regime/dn10/run_2@193 \\
        data/replication_regime/dn10/run_3@267 data/replication_regime/dn10/run_4@214 \\
        data/replication_regime/dn10/run_5@262 data/replication_regime/dn10/run_6@195 \\
        data/replication_regime/dn10/run_7@92 data/replication_regime/dn10/run_8@379 \\
        data/replication_regime/dn10/run_9@238 \\
        --out studies/regime/results/controller_optimum_evolved.csv

(the evolved set names each run's best by its generation, the column `generation` of its CSV, so
that it is rebuilt from the same bodies as the study grows). Each writes its CSV (one row per body,
drag and seed) and a JSON beside it with each search's best controller (to swim it again), and
prints a table.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
from dataclasses import replace
from multiprocessing import Pool
from pathlib import Path

import numpy as np

import animat

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "studies" / "locomotion"))
from known_swimmers import KnownSwimmer, appendage_swimmer, hex_region, stroke_truth  # noqa: E402

sys.path.insert(0, str(ROOT / "studies" / "regime"))
from step_ladder import final_best  # noqa: E402

sys.path.insert(0, str(ROOT / "studies"))
from results_table import write_rows  # noqa: E402

OUT = ROOT / "studies" / "regime" / "results" / "controller_optimum.csv"
SEARCH_SUBSTEPS = 4
DRAGS = {env: f"configs/regime_{env}.toml" for env in ("dn0.5", "dn2", "dn10", "dn0.2_64cells")}


def ellipse(name: str, length: float, width: float) -> KnownSwimmer:
    """A body of lattice cells inside an ellipse (long axis x), no appendages."""
    pos = hex_region(lambda x, y: (x / (length / 2)) ** 2 + (y / (width / 2)) ** 2 <= 1.0)
    n = len(pos)
    return KnownSwimmer(
        name, "", pos, np.zeros(n), np.ones(n), np.zeros(n), f"{n} cells, ellipse {length:g} x {width:g}"
    )


#: The bodies: name -> builder. Cell counts 31-33 (the lattice does not give every count); the
#: appendage bodies are the calibration builder's (one pair at mid-body, x = 0).
BODIES = {
    "blob": lambda: ellipse("blob", 7.6, 5.2),
    "elongated": lambda: ellipse("elongated", 13.0, 3.2),
    "single": lambda: appendage_swimmer("single", core_length=7.0, core_width=5.0, at=(0.0,), name="single"),
    "chain2": lambda: appendage_swimmer("chain2", core_length=7.0, core_width=4.5, at=(0.0,), name="chain2"),
    "block2x2": lambda: appendage_swimmer("block2x2", core_length=7.0, core_width=4.0, at=(0.0,), name="block2x2"),
}


def mirror_groups(positions: np.ndarray) -> list:
    """Cells paired with their mirror image about the x axis (within 0.2 spacings; on-axis cells alone)."""
    groups, seen = [], set()
    for k, (x, y) in enumerate(positions):
        if k in seen:
            continue
        d = np.linalg.norm(positions - np.array([x, -y]), axis=1)
        j = int(np.argmin(d))
        pair = sorted({k, j}) if d[j] < 0.2 and j not in seen else [k]
        seen.update(pair)
        groups.append(pair)
    return groups


def controls(x: np.ndarray, groups: list, n: int, config) -> tuple:
    """Amplitude, frequency and phase per cell from the search vector x = [f, (a, phase) per group]."""
    fmin, fmax = config["development.frequency_min"], config["development.frequency_max"]
    amax = config["development.amplitude_max"]
    amp, phase = np.zeros(n), np.zeros(n)
    for g, members in enumerate(groups):
        amp[members] = amax * float(np.clip(x[1 + 2 * g], 0.0, 1.0))
        phase[members] = math.tau * float(x[2 + 2 * g]) % math.tau
    freq = np.full(n, fmin + (fmax - fmin) * float(np.clip(x[0], 0.0, 1.0)))
    return amp, freq, phase


def config_for(env: str, substeps: int, energy: bool = False):
    config = animat.load_config(str(ROOT / DRAGS[env]))
    config.physics.substeps = config.physics.substeps * substeps
    if energy:
        config["evaluation.energy_accounting"] = True
    return config


def distance(swimmer: KnownSwimmer, config) -> float:
    r = animat.swim(swimmer.body(config), config=config)
    return float(r.distance) if r.stable and r.valid else 0.0


def evolved(spec: str) -> tuple:
    """The body of a packed run's best (``data/<study>/<env>/run_<i>[@GENERATION]``, the repository's
    path: its final best, or its best at GENERATION) as a KnownSwimmer with its GA-evolved controller,
    that controller's search vector (the median frequency for all cells) and the best's generation."""
    path, _, generation = spec.partition("@")
    run = ROOT / path
    config = animat.load_config(str(run / "config.toml"))
    entry = final_best(run, int(generation) if generation else None)
    genome = animat.Genome.from_json(json.dumps(entry["genome"]))
    e = animat.develop(genome, config)
    pos = np.asarray(e.positions, dtype=np.float64)
    amp, freq, phase = (np.asarray(v, dtype=np.float64) for v in (e.amplitude, e.frequency, e.phase))
    name = f"{run.parent.name}/{run.name}"
    fmin, fmax = config["development.frequency_min"], config["development.frequency_max"]
    x = np.empty(1 + 2 * len(pos))
    x[0] = (np.median(freq) - fmin) / (fmax - fmin)
    x[1::2] = amp / config["development.amplitude_max"]
    x[2::2] = phase / math.tau
    swimmer = KnownSwimmer(name, "", pos, amp, freq, phase, f"{len(pos)} cells, evolved ({name})")
    return swimmer, x, int(entry["generation"])


def search(task: tuple) -> dict:
    """One CMA-ES search of one body's controller at one drag, from a random controller of the seed.
    An evolved body (a packed run's folder; every cell its own group, the body has no mirror
    symmetry) starts from its GA-evolved controller instead, with a smaller step (0.1); the seed
    seeds the search's samples."""
    import cma

    body, env, seed, evaluations, free = task
    start = None
    if body in BODIES:
        base = BODIES[body]()
        groups = [[k] for k in range(base.cells)] if free else mirror_groups(base.positions)
    else:
        base, start, generation = evolved(body)
        groups = [[k] for k in range(base.cells)]
        body = base.name
    n = base.cells
    config = config_for(env, SEARCH_SUBSTEPS)

    def with_controls(x):
        amp, freq, phase = controls(x, groups, n, config)
        return replace(base, amplitude=amp, frequency=freq, phase=phase)

    rng = np.random.default_rng(seed)
    dim = 1 + 2 * len(groups)
    x0 = rng.uniform(0.0, 1.0, dim) if start is None else start
    lower = [0.0] + [0.0, -np.inf] * len(groups)
    upper = [1.0] + [1.0, np.inf] * len(groups)
    es = cma.CMAEvolutionStrategy(
        x0,
        0.3 if start is None else 0.1,
        {"bounds": [lower, upper], "seed": seed, "maxfevals": evaluations, "verbose": -9},
    )
    best_x, best_d = x0, distance(with_controls(x0), config)
    while not es.stop():
        xs = es.ask()
        ds = [distance(with_controls(np.asarray(x)), config) for x in xs]
        es.tell(xs, [-d for d in ds])
        k = int(np.argmax(ds))
        if ds[k] > best_d:
            best_x, best_d = np.asarray(xs[k]), ds[k]
    swimmer = with_controls(best_x)
    row = {
        "body": body,
        "environment": env,
        "seed": seed,
        "control": "per cell" if len(groups) == n else "mirror pairs",
        "cells": n,
        "appendage_cells": sum(len(g) for g in base.appendages),
        "evaluations": es.countevals + 1,
        "frequency": float(swimmer.frequency[0]),
        "amplitude_median_of_max": float(np.median(swimmer.amplitude) / config["development.amplitude_max"]),
        "distance_search": best_d,
    }
    if body not in BODIES:  # the best's generation; the GA's own controller (its cells' own frequencies) at dt/16
        row["generation"] = generation
        row["distance_evolved_s16"] = distance(base, config_for(env, 16))
    for s in (16, 32):
        row[f"distance_s{s}"] = distance(swimmer, config_for(env, s))
    reference = config_for(env, 16, energy=True)
    r = animat.swim(swimmer.body(reference), config=reference)
    e = r.energy
    row["fluid_share"] = e.fluid / e.dissipated if e.dissipated > 0 else float("nan")
    trajectory = animat.replay(swimmer.body(reference), reference)
    mode = animat.classify_locomotion(trajectory) if trajectory.stable else None
    row["mode"] = mode.label if mode is not None else "unstable"
    truth = stroke_truth(swimmer, trajectory) if trajectory.stable and swimmer.appendages else None
    row["rows"] = "" if truth is None else bool(truth.strokes)
    row["rowing_min"] = "" if truth is None else min(truth.rowing)
    row["why_not"] = "" if truth is None else truth.why_not()
    row["_controller"] = {
        "amplitude": swimmer.amplitude.tolist(),
        "frequency": swimmer.frequency.tolist(),
        "phase": swimmer.phase.tolist(),
    }
    return row


def summary(paths: list) -> str:
    """The tables of docs/regime.md ("Does the stroke pay?") from committed result CSVs."""
    rows = []
    for path in paths:
        if path.is_file():
            with open(path) as fh:
                rows += list(csv.DictReader(fh))
    hand = [r for r in rows if r["body"] in BODIES]
    out = [
        "| environment | body | cells | control | distance at dt/16, per seed | mode, per seed | appendages row |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    keys = dict.fromkeys((r["environment"], r["body"], r["control"]) for r in hand)
    for env, body, control in sorted(keys, key=lambda k: (list(DRAGS).index(k[0]), list(BODIES).index(k[1]), k[2])):
        sel = [r for r in hand if (r["environment"], r["body"], r["control"]) == (env, body, control)]
        rowing = [r["rows"] == "True" for r in sel if r["rows"] != ""]
        rows_text = f"{sum(rowing)} of {len(rowing)}" if rowing else "—"
        out.append(
            f"| {env} | {body} | {sel[0]['cells']} | {control} | "
            + ", ".join(f"{float(r['distance_s16']):.1f}" for r in sel)
            + " | "
            + ", ".join(r["mode"] for r in sel)
            + f" | {rows_text} |"
        )
    ev = [r for r in rows if r["body"] not in BODIES]
    if ev:
        out += [
            "",
            "| environment | bests | GA's controller at dt/16: median (range) | searched: median (range) | "
            "gain: median (range) | searched controllers' modes |",
            "| --- | --- | --- | --- | --- | --- |",
        ]
        for env in DRAGS:
            sel = [r for r in ev if r["environment"] == env]
            if not sel:
                continue
            ga = np.array([float(r["distance_evolved_s16"]) for r in sel])
            cm = np.array([float(r["distance_s16"]) for r in sel])
            gain = cm / ga - 1.0
            modes: dict = {}
            for r in sel:
                modes[r["mode"]] = modes.get(r["mode"], 0) + 1
            out.append(
                f"| {env} | {len(sel)} | {np.median(ga):.1f} ({ga.min():.1f}–{ga.max():.1f}) | "
                f"{np.median(cm):.1f} ({cm.min():.1f}–{cm.max():.1f}) | {100 * np.median(gain):+.0f} % "
                f"({100 * gain.min():+.0f} to {100 * gain.max():+.0f} %) | "
                + ", ".join(f"{m} {n}" for m, n in sorted(modes.items(), key=lambda kv: -kv[1]))
                + " |"
            )
    return "\n".join(out)


def figure(path: Path) -> None:
    """One motion cycle (animat.plot.motion_cycle, at dt/16) of the farthest searched swimmer at
    d_N = 0.5 of each hand-built body with symmetric control, from results/controller_optimum_mirror.*."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from animat.plot import motion_cycle

    results = OUT.parent / "controller_optimum_mirror.csv"
    with open(results) as fh:
        rows = [r for r in csv.DictReader(fh) if r["environment"] == "dn0.5"]
    controllers = json.loads(results.with_suffix(".json").read_text())
    config = config_for("dn0.5", 16)
    images = []
    for body in ("blob", "single"):
        row = max((r for r in rows if r["body"] == body), key=lambda r: float(r["distance_s16"]))
        c = controllers[f"dn0.5/{body}/mirror pairs/seed{row['seed']}"]
        swimmer = replace(BODIES[body](), **{k: np.asarray(c[k]) for k in ("amplitude", "frequency", "phase")})
        trajectory = animat.replay(swimmer.body(config), config, every=4)
        fig = motion_cycle(
            trajectory,
            count=6,
            title=f"{body}, d_N = 0.5, seed {row['seed']}: {float(row['distance_s16']):.1f} at dt/16 ({row['mode']})",
        )
        fig.canvas.draw()
        images.append(np.asarray(fig.canvas.buffer_rgba()))
        plt.close(fig)
    width = max(im.shape[1] for im in images)
    stacked = np.concatenate(
        [np.pad(im, ((0, 0), (0, width - im.shape[1]), (0, 0)), constant_values=255) for im in images]
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    from PIL import Image

    # a 64-colour palette: the drawing has a few flat colours, and the page keeps the file small
    Image.fromarray(stacked[..., :3]).convert("P", palette=Image.Palette.ADAPTIVE, colors=64).save(path, optimize=True)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--bodies", nargs="+", default=list(BODIES), choices=list(BODIES))
    p.add_argument("--envs", nargs="+", default=["dn0.5", "dn10"], choices=list(DRAGS))
    p.add_argument("--seeds", nargs="+", type=int, default=[1, 2])
    p.add_argument("--evaluations", type=int, default=2400, help="swims per search (default 2400)")
    p.add_argument(
        "--evolved",
        nargs="+",
        default=[],
        metavar="RUN[@GENERATION]",
        help="packed runs (data/<study>/<env>/run_<i>, from the repository root) whose final best's body (or "
        "best at GENERATION) to search instead, each at its own environment (configs/regime_<env>.toml)",
    )
    p.add_argument(
        "--free", action="store_true", help="hand-built bodies: one amplitude and phase per cell, not per mirror pair"
    )
    p.add_argument("--jobs", type=int, default=1)
    p.add_argument("--out", type=Path, default=OUT)
    p.add_argument(
        "--summary",
        action="store_true",
        help="print the tables of docs/regime.md from the committed results/controller_optimum_*.csv; swim nothing",
    )
    p.add_argument(
        "--figure",
        type=Path,
        help="draw the figure of docs/regime.md from the committed results to this PNG; swim no search",
    )
    args = p.parse_args(argv)
    if any(s < 1 for s in args.seeds):
        p.error("--seeds: every seed must be >= 1 (cma draws seed 0 from the clock)")
    if args.figure:
        figure(args.figure)
        return 0
    if args.summary:
        print(summary([OUT.parent / f"controller_optimum_{s}.csv" for s in ("mirror", "free", "evolved")]))
        return 0
    if args.evolved:
        tasks = [
            (run, Path(run.partition("@")[0]).parent.name, s, args.evaluations, True)
            for run in args.evolved
            for s in args.seeds
        ]
    else:
        tasks = [(b, e, s, args.evaluations, args.free) for e in args.envs for b in args.bodies for s in args.seeds]
    with Pool(args.jobs) as pool:
        rows = []
        for row in pool.imap(search, tasks):
            rows.append(row)
            print(
                f"{row['environment']} {row['body']} seed {row['seed']}: {row['distance_s16']:.2f} at dt/16 "
                f"(search {row['distance_search']:.2f}), f {row['frequency']:.2f}, {row['mode']}"
                + (f", rows {row['rows']} ({row['rowing_min']:+.2f})" if row["rows"] != "" else ""),
                flush=True,
            )
    write_rows(args.out, rows)
    controllers = {f"{r['environment']}/{r['body']}/{r['control']}/seed{r['seed']}": r["_controller"] for r in rows}
    args.out.with_suffix(".json").write_text(json.dumps(controllers, indent=0) + "\n")
    print(
        "\n| environment | body | control | cells | seed | distance at dt/16 | dt/32 | frequency | fluid share | mode | rows |"
    )
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for r in rows:
        print(
            f"| {r['environment']} | {r['body']} | {r['control']} | {r['cells']} | {r['seed']} | {r['distance_s16']:.2f} | "
            f"{r['distance_s32']:.2f} | {r['frequency']:.2f} | {r['fluid_share']:.2f} | {r['mode']} | {r['rows']} |"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
