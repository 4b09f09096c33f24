"""What the engine's locomotion classifier (``_core._classify_motion``, include/animat/locomotion.hpp) costs
against one evaluation, on the stored bests (data/replication/*/run_*): per best, the evaluation of its
genome with its run's config (`animat.evaluate`), the C++ classifier on the frames a recorder keeps
during the swim (from ``_core._locomotion_window_start`` on, with and without the bending wave), and what
the ``locomotion`` descriptor costs today (`animat.locomotion.classify_locomotion` of the genome: develop,
swim again and classify in Python).

    PYTHONPATH=build/python .venv/bin/python bench/locomotion_engine_cost.py [--runs 10] [--repeat 5]

Prints the machine and load, then per condition and overall the median ms of each and the median and largest ratio to the
evaluation (each timing the median of ``--repeat`` calls). The recording itself is not timed (copying
cells × 2 doubles per step of the window).
"""

import argparse
import glob
import os
import platform
import statistics
import time
from pathlib import Path

import animat
from animat import _core
from animat import locomotion as L

ROOT = Path(__file__).resolve().parents[1]


def timed(fn, repeat):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return 1000 * statistics.median(times)


def measure(directory, repeat, python):
    """The timings (ms) of one stored best."""
    run = animat.Run(directory)
    genome, config = run.best().genome, run.config
    tr = animat.replay(run.best(), config)
    omega = _core._dominant_frequency(tr.body.amplitude, tr.body.frequency)
    steps = int(config["evaluation.steps"])
    first = _core._locomotion_window_start(steps, float(config["physics.dt"]), omega)
    P, t, springs = tr.positions[first:], tr.times[first:], tr.body.springs
    row = {
        "condition": Path(directory).parent.name,
        "frames": len(t),
        "evaluate": timed(lambda: animat.evaluate(genome, config), repeat),
        "engine": timed(lambda: _core._classify_motion(P, t, springs, omega, 4.0, False, 0.0), repeat),
        "engine_bending": timed(lambda: _core._classify_motion(P, t, springs, omega, 4.0, True, 0.0), repeat),
    }
    if python:
        row["python"] = timed(lambda: L.classify_locomotion(genome, config), 1)
    return row


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--runs", type=int, default=10, help="runs per condition (of 10)")
    p.add_argument("--repeat", type=int, default=5)
    p.add_argument("--python", action="store_true", help="also time the Python descriptor (slow)")
    args = p.parse_args()
    print(
        f"machine: {platform.machine()}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}; animat "
        f"{animat.__version__}; median of {args.repeat} calls per best"
    )
    rows = [
        measure(d, args.repeat, args.python)
        for cond in sorted(glob.glob(str(ROOT / "data" / "replication" / "*")))
        for d in sorted(glob.glob(cond + "/run_*"))[: args.runs]
    ]
    keys = ["evaluate", "engine", "engine_bending"] + (["python"] if args.python else [])
    for name in sorted({r["condition"] for r in rows}) + ["all"]:
        sel = [r for r in rows if name in ("all", r["condition"])]
        med = {k: statistics.median(r[k] for r in sel) for k in keys}
        ratio = {k: statistics.median(r[k] / r["evaluate"] for r in sel) for k in keys[1:]}
        worst = {k: max(r[k] / r["evaluate"] for r in sel) for k in keys[1:]}
        frames = statistics.median(r["frames"] for r in sel)
        print(
            f"{name:16s} {len(sel):3d} bests, {frames:.0f} window frames: evaluate {med['evaluate']:.1f} ms; "
            + "; ".join(
                f"{k} {med[k]:.2f} ms ({ratio[k]:.3f} of an evaluation, at most {worst[k]:.3f})" for k in keys[1:]
            )
        )


if __name__ == "__main__":
    main()
