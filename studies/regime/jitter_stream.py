"""Does the GA improve when a mutation no longer redraws the development's jitter?

Every regime best loses most of its distance when its placement jitter is redrawn, and every mutation
redraws it (development.jitter_stream = "genome", the seed is the genome's hash), so none of the GA's
mutations keeps a best's body (mutation_effects.py). With jitter_stream = "fixed" the jitter is one
stream for every genome and a mutation changes the body only through the GRN. This study evolves the
regime preset at d_N = 0.5 and 10 under both streams, 4 runs each (evolution.seed + 0..3, the same seeds
for both) to generation 200, and compares them: the best's reference fitness (dt/16, what the preset
ranks by) over the generations, when it last rose, and the best's body and mode (stroke path) at
generation 200. Under the genome's stream these runs are runs 0-3 of the regime replication
(data/replication_regime), bit for bit (evolving them again to 200 gave the same histories), so they
are read from there up to generation 200. Under the fixed stream they are runs 0-3 of the same study
at the fixed stream's preset (configs/regime_fixed_<env>.toml, data/replication_regime_fixed, grown
by studies/replication/replication.sh as docs/regime.md says), read up to generation 200 too. A third
arm, at d_N = 0.5 only, adds the niching the paper suggests (§7) to the fixed stream: a new body plan is
protected for 20 generations (evolution.protection_generations = 20, docs/model.md), the same 4 seeds
(data/regime_protection). The first two arms were made first on their own, in about one core-hour:

    PYTHONPATH=build/python .venv/bin/python -m animat experiment dn0.5=configs/regime_fixed_dn0.5.toml \\
        dn10=configs/regime_fixed_dn10.toml --runs 4 --parallel 2 --threads 2 --generations 200 \\
        --out runs/replication_regime_fixed
    PYTHONPATH=build/python .venv/bin/python studies/replication/replication_store.py pack \\
        runs/replication_regime_fixed data/replication_regime_fixed
    # the protected arm (about 40 core-minutes)
    PYTHONPATH=build/python .venv/bin/python -m animat experiment dn0.5=configs/regime_fixed_dn0.5.toml \\
        --set evolution.protection_generations=20 --runs 4 --parallel 2 --threads 2 --generations 200 \\
        --out runs/regime_fixed_protection20
    PYTHONPATH=build/python .venv/bin/python studies/replication/replication_store.py pack \\
        runs/regime_fixed_protection20 data/regime_protection
    PYTHONPATH=build/python .venv/bin/python studies/regime/jitter_stream.py \\
        --out studies/regime/results/jitter_stream.csv
    # each best at generation 200 with its controller searched on its body (controller_optimum.py)
    for s in genome fixed; do
      d=data/replication_regime_fixed; [ $s = genome ] && d=data/replication_regime
      PYTHONPATH=build/python .venv/bin/python studies/regime/controller_optimum.py --seeds 1 --jobs 2 \\
          --evolved $d/dn0.5/run_0@200 $d/dn0.5/run_1@200 $d/dn0.5/run_2@200 $d/dn0.5/run_3@200 \\
          $d/dn10/run_0@200 $d/dn10/run_1@200 $d/dn10/run_2@200 $d/dn10/run_3@200 \\
          --out studies/regime/results/controller_optimum_${s}200.csv
    done
    # the tables of docs/regime.md from the committed CSVs
    PYTHONPATH=build/python .venv/bin/python studies/regime/jitter_stream.py --summary
"""

from __future__ import annotations

import argparse
import csv
import gzip
import json
import math
import sys
from pathlib import Path

import numpy as np

import animat
from animat.shape import genome_shape

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "studies" / "regime"))
from step_ladder import final_best  # noqa: E402

sys.path.insert(0, str(ROOT / "studies"))
from results_table import write_rows  # noqa: E402

DATA = {"genome": ROOT / "data" / "replication_regime", "fixed": ROOT / "data" / "replication_regime_fixed"}
ENVS = ("dn0.5", "dn10")
RUNS = 4
OUT = ROOT / "studies" / "regime" / "results" / "jitter_stream.csv"
STREAMS = ("genome", "fixed")
# The fixed stream with the paper's suggested niching (evolution.protection_generations = 20), at
# d_N = 0.5 only: the same seeds, so each run starts from the population of the fixed stream's run.
PROTECTED = ROOT / "data" / "regime_protection"
PROTECTION = 20
PROTECTED_ENVS = ("dn0.5",)
CHECKPOINTS = (50, 100, 200)
CAP = CHECKPOINTS[-1]


def history(run: Path) -> list:
    with gzip.open(run / "history.csv.gz", "rt") as fh:
        return list(csv.DictReader(fh))


def last_rise(rows: list) -> int:
    """The generation at which the best's reference fitness last rose."""
    found, best = 0, -math.inf
    for r in rows:
        ref = float(r["best_reference"])
        if ref > best:
            found, best = int(r["generation"]), ref
    return found


def row_of(run: Path) -> dict:
    """The run up to generation CAP: its history and its best at CAP."""
    rows = [r for r in history(run) if int(r["generation"]) <= CAP]
    by_gen = {int(r["generation"]): r for r in rows}
    config = animat.load_config(str(run / "config.toml"))
    entry = final_best(run, CAP)
    genome = animat.Genome.from_json(json.dumps(entry["genome"]))
    shape = genome_shape(genome, config)
    mode = animat.classify_locomotion(genome, config)
    out = {
        "stream": str(config["development.jitter_stream"]),
        "protection_generations": int(config["evolution.protection_generations"]),
        "environment": run.parent.name,
        "run": run.name,
        "generation": int(rows[-1]["generation"]),
    }
    for g in CHECKPOINTS:
        out[f"best_reference_{g}"] = float(by_gen[g]["best_reference"]) if g in by_gen else math.nan
    out["last_rise"] = last_rise(rows)
    # viable individuals of a new body plan still protected, per generation (runs with protection only)
    protected = [int(r["protected"]) for r in rows[1:] if r.get("protected")]
    out["protected_median"] = float(np.median(protected)) if protected else math.nan
    out["cells"] = shape.cell_count if shape else 0
    out["elongation"] = shape.elongation if shape else math.nan
    out["protrusions"] = len(shape.protrusions) if shape else 0
    out["mode"] = mode.label
    return out


def summary(path: Path) -> str:
    with open(path) as fh:
        rows = list(csv.DictReader(fh))
    out = [
        "| environment | jitter stream | runs | best reference at generation "
        + ", ".join(str(g) for g in CHECKPOINTS)
        + ": median (range) | last rise: median (range) | protected per generation: median | elongation: median "
        "| modes |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    arms = dict.fromkeys((r["stream"], int(r.get("protection_generations") or 0)) for r in rows)
    for env in dict.fromkeys(r["environment"] for r in rows):
        for stream, protection in arms:
            sel = [
                r
                for r in rows
                if r["environment"] == env
                and r["stream"] == stream
                and int(r.get("protection_generations") or 0) == protection
            ]
            if not sel:
                continue
            label = f"{stream}, protection {protection}" if protection else stream
            cells = []
            for g in CHECKPOINTS:
                v = np.array([float(r[f"best_reference_{g}"]) for r in sel])
                cells.append(f"{np.median(v):.1f} ({v.min():.1f}–{v.max():.1f})")
            rise = np.array([int(r["last_rise"]) for r in sel])
            modes: dict = {}
            for r in sel:
                modes[r["mode"]] = modes.get(r["mode"], 0) + 1
            out.append(
                f"| {env} | {label} | {len(sel)} | "
                + "; ".join(cells)
                + f" | {int(np.median(rise))} ({rise.min()}–{rise.max()}) | "
                + (f"{np.median([float(r['protected_median']) for r in sel]):.0f} | " if protection else "— | ")
                + f"{np.median([float(r['elongation']) for r in sel]):.2f} | "
                + ", ".join(f"{m} {n}" for m, n in sorted(modes.items(), key=lambda kv: -kv[1]))
                + " |"
            )
    return "\n".join(out)


def controller_gains(results: Path) -> str:
    """What a controller search adds to each stream's bests at generation 200, from
    results/controller_optimum_<stream>200.csv."""
    out = [
        "| environment | jitter stream | bests | GA's controller at dt/16: median (range) | searched: median (range) | "
        "gain: median (range) |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    rows = {}
    for s in STREAMS:
        with open(results / f"controller_optimum_{s}200.csv") as fh:
            rows[s] = list(csv.DictReader(fh))
    for env in ENVS:
        for stream in STREAMS:
            sel = [r for r in rows[stream] if r["environment"] == env]
            ga = np.array([float(r["distance_evolved_s16"]) for r in sel])
            cm = np.array([float(r["distance_s16"]) for r in sel])
            gain = 100 * (cm / ga - 1.0)
            out.append(
                f"| {env} | {stream} | {len(sel)} | {np.median(ga):.1f} ({ga.min():.1f}–{ga.max():.1f}) | "
                f"{np.median(cm):.1f} ({cm.min():.1f}–{cm.max():.1f}) | {np.median(gain):+.0f} % "
                f"({gain.min():+.0f} to {gain.max():+.0f} %) |"
            )
    return "\n".join(out)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", type=Path, default=OUT)
    p.add_argument("--summary", action="store_true", help="print the table of docs/regime.md from --out")
    args = p.parse_args(argv)
    if not args.summary:
        runs = [DATA[s] / env / f"run_{i}" for s in STREAMS for env in ENVS for i in range(RUNS)]
        runs += [PROTECTED / env / f"run_{i}" for env in PROTECTED_ENVS for i in range(RUNS)]
        write_rows(args.out, [row_of(run) for run in runs])
    print(summary(args.out))
    if (args.out.parent / "controller_optimum_fixed200.csv").is_file():
        print()
        print(controller_gains(args.out.parent))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
