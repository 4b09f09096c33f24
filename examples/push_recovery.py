"""Active control (docs/control.md): do GRN-controlled swimmers recover from a push better than open-loop ones?

For every best given (packed runs, as data/control/push/<name>/run_<i> or data/replication/dn2/run_<i>),
at the paper's d_N = 2 setting, 4000 steps:
  1. an undisturbed evaluation, recorded every 10 steps (``animat.record_evaluation``);
  2. the same evaluation with a push at step 2000 (``evaluation.push_step``): every cell (``--cells
     all``), or the cells at x >= the centre's x (``--cells front``, a torque), gets the impulse J
     perpendicular to the direction the body swam over steps 1000-2000 (to its left);
and reports, from the centre of mass: the speed over steps 1000-2000 (before) and 3000-4000 (after)
in the pushed swim, their ratio (recovery of speed) beside the same ratio undisturbed, the pushed
swim's speed after over the undisturbed one's, the turn of the heading between the two windows
(degrees), and the deflection: the angle between the pushed and the undisturbed swims' headings over
steps 3000-4000 (what the push changed for good).

    PYTHONPATH=build/python .venv/bin/python examples/push_recovery.py \
        open_loop=data/replication/dn2:0,1,2@60 grn=data/control/push/grn_amplitude_dn2:0,1,2 [--impulse 1.0]

Each argument is LABEL=PACKED_ENV_DIR:RUNS[@GENERATION] (the best at or before GENERATION; default the last).
"""

import argparse
import math
import pathlib
import sys
import tempfile

import numpy as np

import animat

# The packed-run store is study code (studies/replication), not part of the package.
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "studies" / "replication"))
from replication_store import unpack_run  # noqa: E402

PUSH_STEP = 2000


def windows(rec):
    steps = np.asarray(rec.steps)
    com = np.asarray(rec.positions).mean(axis=1)
    times = np.asarray(rec.times)

    def seg(a, b):
        i, j = int(np.searchsorted(steps, a)), int(np.searchsorted(steps, b))
        d = com[j] - com[i]
        return d, d / (times[j] - times[i])

    return seg


def analyse(entry, cfg, impulse, cells):
    cfg = cfg.copy()
    cfg["evaluation.steps"] = 4000
    base = animat.record_evaluation(entry.genome, cfg, every=10)
    seg = windows(base)
    d_before, v_before = seg(1000, PUSH_STEP)
    d_after0, v_after0 = seg(3000, 4000)
    heading = d_before / np.linalg.norm(d_before)
    left = np.array([-heading[1], heading[0]])
    pushed_cfg = cfg.copy()
    pushed_cfg["evaluation.push_step"] = PUSH_STEP
    pushed_cfg["evaluation.push_impulse"] = [float(impulse * left[0]), float(impulse * left[1])]
    pushed_cfg["evaluation.push_cells"] = cells
    rec = animat.record_evaluation(entry.genome, pushed_cfg, every=10)
    seg2 = windows(rec)
    d_after, v_after = seg2(3000, 4000)
    turn = math.degrees(math.atan2(heading[0] * d_after[1] - heading[1] * d_after[0], heading @ d_after))
    # What the push changed: the pushed swim's heading over steps 3000-4000 against the undisturbed one's.
    deflection = math.degrees(math.atan2(d_after0[0] * d_after[1] - d_after0[1] * d_after[0], d_after0 @ d_after))
    sp_b, sp_a, sp_a0 = (float(np.linalg.norm(v)) for v in (v_before, v_after, v_after0))
    return {
        "valid": bool(rec.result.valid),
        "speed_before": sp_b,
        "speed_after": sp_a,
        "recovery": sp_a / sp_b,
        "recovery_undisturbed": sp_a0 / sp_b,
        "turn": turn,
        "speed_vs_undisturbed": sp_a / sp_a0,
        "deflection": deflection,
    }


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=(__doc__ or "").split("\n\n")[0])
    p.add_argument("groups", nargs="+", help="LABEL=PACKED_ENV_DIR:RUNS[@GENERATION]")
    p.add_argument("--impulse", type=float, default=1.0, help="impulse per cell (cell mass 1: the velocity change)")
    p.add_argument(
        "--cells",
        choices=("all", "front"),
        default="all",
        help="cells pushed: all, or those at x >= the centre's x (evaluation.push_cells): a torque",
    )
    args = p.parse_args(argv)
    print(
        f"push at step {PUSH_STEP} of 4000, impulse {args.impulse} per cell ({args.cells} cells), perpendicular "
        "to the heading of steps 1000-2000"
    )
    print(
        "| controller | run | best of generation | fitness | speed before | speed after | after / before "
        "| same, undisturbed | speed after, pushed / undisturbed | heading turn (°) | deflection by the push (°) |"
    )
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    summary = {}
    with tempfile.TemporaryDirectory() as tmp:
        for g in args.groups:
            label, rest = g.split("=", 1)
            where, runs = rest.split(":", 1)
            generation = None
            if "@" in runs:
                runs, gen = runs.split("@")
                generation = int(gen)
            for i in (int(x) for x in runs.split(",")):
                run = animat.Run(unpack_run(pathlib.Path(where) / f"run_{i}", pathlib.Path(tmp) / label / f"run_{i}"))
                lineage = [e for e in run.best_genomes if generation is None or e.generation <= generation]
                entry = lineage[-1]
                r = analyse(entry, run.config, args.impulse, args.cells)
                summary.setdefault(label, []).append(r)
                print(
                    f"| {label} | {i} | {entry.generation} | {entry.fitness:.2f} | {r['speed_before']:.3f} | "
                    f"{r['speed_after']:.3f} | {r['recovery']:.2f} | {r['recovery_undisturbed']:.2f} | "
                    f"{r['speed_vs_undisturbed']:.3f} | {r['turn']:+.0f} | {r['deflection']:+.0f} |"
                    + ("" if r["valid"] else " invalid swim")
                )
    print()
    for label, rs in summary.items():
        print(
            f"{label}: mean after/before {np.mean([r['recovery'] for r in rs]):.2f} (undisturbed "
            f"{np.mean([r['recovery_undisturbed'] for r in rs]):.2f}), mean |turn| "
            f"{np.mean([abs(r['turn']) for r in rs]):.0f}°, mean |deflection by the push| "
            f"{np.mean([abs(r['deflection']) for r in rs]):.0f}°"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
