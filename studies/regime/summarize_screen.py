"""Summarises the calibration screen kept in studies/regime/screen/ (one folder per run: config.toml,
history.csv, best_genome.json, written by studies/regime/screen.sh): for every run's final best its
fitness and the exploit guard's reference at dt/16, the energy split (docs/regime.md), the
oscillators against their bounds, the body's shape (animat.shape) and its locomotion mode; then the
medians per grid point. Writes studies/regime/results/screen.csv and studies/regime/screen.md:

    PYTHONPATH=build/python .venv/bin/python studies/regime/summarize_screen.py
"""

from __future__ import annotations

import csv
import json
import statistics
import sys
from pathlib import Path

import animat
from animat import shape

sys.path.insert(0, str(Path(__file__).resolve().parent))
from measure_regime import measure  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from results_table import write_rows  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
SCREEN = ROOT / "studies" / "regime" / "screen"
OUT_CSV = ROOT / "studies" / "regime" / "results" / "screen.csv"
OUT_MD = ROOT / "studies" / "regime" / "screen.md"


def point_of(folder: Path, config) -> tuple:
    """(environment, growth, guard, substeps, repeats, damping, stiffness, frequency_max, seed) of a run kept by
    screen.sh: the environment and seed from its name, the rest from its config. repeats is "1", or
    "K mean" / "K min" (evaluation.repeats and repeat_statistic)."""
    parts = folder.name.split("_")
    env = "_".join(parts[:2]) if parts[1] == "64cells" else parts[0]
    contacts = config.development.division_max_contacts
    growth = f"tips{contacts}" if contacts > 0 else "paper"
    return (
        env,
        growth,
        config.evaluation.reference_check,
        config.physics.substeps,
        repeats_of(config),
        config.scene.spring_damping,
        config.scene.spring_stiffness,
        config.development.frequency_max,
        int(parts[-1][4:]),
    )


def drag_of(env: str) -> float:
    """d_N of an environment's name: "dn0.5" -> 0.5, "dn0.2_64cells" -> 0.2."""
    return float(env[2:].split("_")[0])


def repeats_of(config) -> str:
    k = config.evaluation.repeats
    return "1" if k == 1 else f"{k} {config.evaluation.repeat_statistic}"


def summarise_run(folder: Path) -> dict:
    config = animat.load_config(str(folder / "config.toml"))
    entry = json.loads((folder / "best_genome.json").read_text())
    genome = animat.Genome.from_json(json.dumps(entry["genome"]))
    with open(folder / "history.csv") as fh:
        last = list(csv.DictReader(fh))[-1]
    env, growth, guard, substeps, repeats, c, k, f, seed = point_of(folder, config)
    row = {
        "environment": env,
        "growth": growth,
        "reference_check": guard,
        "substeps": substeps,
        "repeats": repeats,
        "spring_damping": c,
        "spring_stiffness": k,
        "frequency_max": f,
        "seed": seed,
        "generations": int(last["generation"]),
        "best_reference": float(last["best_reference"]),
    }
    row.update(measure(genome, config))
    row["reference_error"] = (row["fitness"] - row["best_reference"]) / row["best_reference"]
    s = shape.genome_shape(genome, config)
    row.update(
        {
            "elongation": s.elongation,
            "concavity": s.concavity,
            "protrusions": s.protrusion_count,
            "symmetric_pair": int(s.symmetric_pair),
        }
    )
    row["mode"] = animat.classify_locomotion(genome, config).label
    return row


def main() -> int:
    rows = [summarise_run(f) for f in sorted(SCREEN.iterdir()) if (f / "best_genome.json").is_file()]
    if not rows:
        print(f"no kept runs in {SCREEN}", file=sys.stderr)
        return 1
    write_rows(OUT_CSV, rows)
    lines = [
        "# Calibration screen: results",
        "",
        "Rebuilt by `PYTHONPATH=build/python .venv/bin/python studies/regime/summarize_screen.py` from the",
        "runs kept in `studies/regime/screen/` (grown by `studies/regime/screen.sh`); per run:",
        "`studies/regime/results/screen.csv`. Medians over the seeds of each point; the criteria are those",
        "of `docs/regime.md`.",
        "",
        "| environment | growth | guard | substeps | repeats | damping | stiffness | frequency max | runs | generations | distance | "
        "reference error (max) | fluid share | at frequency bound | median frequency | elongation | protrusions | "
        "symmetric pair | modes |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    point = lambda r: (  # noqa: E731
        r["environment"],
        r["growth"],
        r["reference_check"],
        r["substeps"],
        r["repeats"],
        r["spring_damping"],
        r["spring_stiffness"],
        r["frequency_max"],
    )
    points = sorted({point(r) for r in rows}, key=lambda p: (drag_of(p[0]), p[1], p[2], p[3], p[4], -p[5], -p[6], p[7]))
    for env, growth, guard, substeps, repeats, c, k, f in points:
        sel = [r for r in rows if point(r) == (env, growth, guard, substeps, repeats, c, k, f)]
        med = lambda key: statistics.median(r[key] for r in sel)  # noqa: E731, B023 (used in this iteration)
        modes = ", ".join(f"{m} {sum(r['mode'] == m for r in sel)}" for m in sorted({r["mode"] for r in sel}))
        lines.append(
            f"| {env} | {growth} | {guard} | {substeps} | {repeats} | {c:g} | {k:g} | {f:g} | {len(sel)} | "
            f"{min(r['generations'] for r in sel)} | {med('fitness'):.1f} | "
            f"{max(abs(r['reference_error']) for r in sel):.2%} | {med('fluid_share'):.2f} | "
            f"{sum(r['at_frequency_bound'] >= 0.5 for r in sel)} of {len(sel)} | {med('frequency_median'):.2f} | "
            f"{med('elongation'):.2f} | {med('protrusions'):.0f} | {sum(r['symmetric_pair'] for r in sel)} of {len(sel)} | "
            f"{modes} |"
        )
    OUT_MD.write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
