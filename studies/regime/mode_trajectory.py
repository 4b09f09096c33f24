"""How a packed study's locomotion modes move as its runs grow: the main mode of every run's best at
a series of generations, with Fisher's exact test of mode against drag over the 32-cell environments
at each. The best at generation G is the last entry of the run's best lineage (best.tar.gz) found at or
before G, replayed and classified as the replication report classifies (``animat.classify_locomotion``,
its stroke path), so every count is rebuilt from the committed runs:

    PYTHONPATH=build/python .venv/bin/python studies/regime/mode_trajectory.py \\
        --data data/replication_regime --out studies/regime/results/mode_trajectory_regime.csv

A run stopped by the paper's stall rule keeps its final best at every later generation (the run is
over); a run that has not grown to G yet is left out of G, and the printed table says how many bests
each generation counts. Writes one row per run and generation and prints the counts per environment.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path
from typing import Dict, List, Optional, Sequence

import animat
from animat import locomotion as L

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "replication"))
import replication_stats as RS  # noqa: E402
from replication_store import STALLED, packed_runs, unpack_run  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from results_table import write_rows  # noqa: E402

COLUMNS = ["environment", "run", "generation", "best_generation", "fitness", "reference_fitness", "mode", "mixed"]
#: the report's row order (studies/replication/replication_report.py, MODE_COLUMNS)
MODES = ["undulation", "synchronous contraction", "protrusions", "tail", "other", "none"]


def best_at(lineage: Sequence[animat.LineageEntry], generation: int) -> Optional[animat.LineageEntry]:
    """The last lineage entry found at or before ``generation``; None before the first."""
    found = [e for e in lineage if e.generation <= generation]
    return found[-1] if found else None


def run_rows(env: str, packed: Path, work: Path, generations: Sequence[int]) -> List[Dict[str, object]]:
    """One row per generation the run counts at (see the module's docstring); a best reached at several
    generations is replayed once."""
    unpack_run(packed, work)
    status = json.loads((packed / "status.json").read_text())
    last, stalled = int(status["generation"]), STALLED in status.get("stop_reason", "")
    run = animat.Run(work)
    config = run.config
    lineage = run.best_genomes
    classified: Dict[int, L.LocomotionMode] = {}
    rows = []
    for g in generations:
        if g > last and not stalled:
            continue
        entry = best_at(lineage, g)
        if entry is None:
            continue
        if entry.generation not in classified:
            classified[entry.generation] = L.classify_locomotion(animat.replay(entry, config))
        mode = classified[entry.generation]
        rows.append(
            {
                "environment": env,
                "run": packed.name,
                "generation": g,
                "best_generation": entry.generation,
                "fitness": entry.fitness,
                "reference_fitness": entry.reference_fitness,
                "mode": mode.mode,
                "mixed": ";".join(mode.mixed),
            }
        )
    return rows


def _drag_order(env: str):
    """32-cell environments by drag (dn0.5 before dn10), then the others by name."""
    try:
        return (0, float(env[2:]), env)
    except ValueError:
        return (1, 0.0, env)


def summary_lines(rows: Sequence[Dict[str, object]]) -> List[str]:
    """A markdown table: per generation, the mode counts per environment and Fisher's p over the 32-cell
    environments (the 64-cell one, at another drag and size, is counted but not tested)."""
    envs = sorted({str(r["environment"]) for r in rows}, key=_drag_order)
    drag_envs = [e for e in envs if "64cells" not in e]
    out = [
        "| generation | " + " | ".join(f"{e}: und / sync / prot / other (bests)" for e in envs) + " | p (32 cells) |",
        "| --- | " + " | ".join("---" for _ in envs) + " | --- |",
    ]
    for g in sorted({int(r["generation"]) for r in rows}):
        labels = {e: [str(r["mode"]) for r in rows if r["environment"] == e and r["generation"] == g] for e in envs}
        cells = []
        for e in envs:
            v = labels[e]
            rest = len(v) - sum(v.count(m) for m in MODES[:3])
            cells.append(
                f"{v.count('undulation')} / {v.count('synchronous contraction')} / {v.count('protrusions')} / "
                f"{rest} ({len(v)})"
            )
        _, _, table = RS.mode_table({e: labels[e] for e in drag_envs}, MODES)
        p = RS.fisher_exact(table).p_value if len(drag_envs) >= 2 else float("nan")
        out.append(f"| {g} | " + " | ".join(cells) + f" | {p:.3g} |")
    return out


def main(argv: Optional[Sequence[str]] = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", type=Path, required=True, help="packed study (data/<study>/<env>/run_<i>)")
    ap.add_argument("--out", type=Path, required=True, help="CSV to write, one row per run and generation")
    ap.add_argument(
        "--generations",
        type=int,
        nargs="+",
        default=[150, 300, 450, 600, 750, 900, 1000],
        help="the generations to count at (default: every 150 and 1000)",
    )
    args = ap.parse_args(argv)
    if any(g < 0 for g in args.generations):
        ap.error(f"--generations: every generation must be >= 0, got {args.generations}")
    studies = packed_runs(args.data)
    if not studies:
        ap.error(f"--data {args.data}: no packed runs (expected <env>/run_<i>/manifest.json)")
    rows: List[Dict[str, object]] = []
    with tempfile.TemporaryDirectory() as tmp:
        for env, runs in sorted(studies.items()):
            for packed in runs:
                rows += run_rows(env, packed, Path(tmp) / env / packed.name, sorted(set(args.generations)))
                print(f"{env} {packed.name}: {len(rows)} rows", file=sys.stderr)
    write_rows(args.out, rows, COLUMNS)
    print("\n".join(summary_lines(rows)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
