"""The refinement ladder of the GRN-control bests (docs/control.md): each best of data/control
re-evaluated at physics.substeps 1 to 64, with the GRN updated every control.update_interval Box2D
steps (the schedule refines with the step) and every control.update_period time units (the same
schedule at every step). Writes studies/control/results/ladder.csv and prints the table:

    PYTHONPATH=build/python .venv/bin/python studies/control/refinement_ladder.py
"""

from __future__ import annotations

import sys
from pathlib import Path

import animat

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from results_table import write_rows  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "data" / "control"
OUT = ROOT / "studies" / "control" / "results" / "ladder.csv"
BESTS = ["chemotaxis_grn_seed1", "chemotaxis_amplitude_seed1", "chemotaxis_amplitude_seed2"]
SUBSTEPS = [1, 2, 4, 16, 32, 64]


def main() -> int:
    rows = []
    for name in BESTS:
        config = animat.load_config(DATA / f"{name}_config.toml")
        genome = animat.Genome.from_json((DATA / f"{name}_best_genome.json").read_text())
        # the run's own schedule, as a time
        period = int(config["control.update_interval"]) * float(config["physics.dt"]) / int(config["physics.substeps"])
        for schedule in ("update_interval", "update_period"):
            for s in SUBSTEPS:
                c = config.copy()
                c["physics.substeps"] = s
                if schedule == "update_period":
                    c["control.update_period"] = period
                r = animat.evaluate(genome, c)
                rows.append(
                    {
                        "best": name,
                        "schedule": schedule,
                        "substeps": s,
                        "fitness": r.fitness,
                        "grn_updates": r.grn_updates,
                    }
                )
    write_rows(OUT, rows)
    print("| best | GRN schedule | " + " | ".join(f"dt/{s}" if s > 1 else "dt" for s in SUBSTEPS) + " | dt vs dt/64 |")
    print("| --- | --- | " + " | ".join("---" for _ in SUBSTEPS) + " | --- |")
    for name in BESTS:
        for schedule in ("update_interval", "update_period"):
            f = [r["fitness"] for r in rows if r["best"] == name and r["schedule"] == schedule]
            print(
                f"| {name} | {schedule} | "
                + " | ".join(f"{x:.4f}" for x in f)
                + f" | {100 * (f[0] - f[-1]) / abs(f[-1]):+.1f} % |"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
