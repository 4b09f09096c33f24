#!/usr/bin/env python3
"""The peers' row of docs/performance.md: the same 32-cell body, time step and spring constants in
pymunk (Chipmunk2D), as its users would write it, beside our own swim step, measured in one run.

    .venv/bin/python bench/peers.py            # installs pymunk into bench/.venv-peers on first use

Three pymunk variants of one 32-cell triangular-lattice body (the springs of its Gabriel graph,
k = 100, c = 4, unit masses, dt = 1/60, one solver iteration, no gravity):
  1. springs only (cpDampedSpring, Chipmunk's own C loop): `space.step(dt)`;
  2. springs + actuation (eq. 2: each spring's rest length driven by its two cells' oscillators)
     and the skin's quadratic drag (eqs. 4-5), both written in Python, as a pymunk user would;
  3. as 2 with numpy for the drag.
Ours (build/bench_physics, the same process order): BM_Effect/0 (springs only) and BM_SwimStep/32
(every effect of the default scene: springs, actuation, pressure, drag, swept collisions).
Times are medians of --repeat runs of --steps steps each (CPU time of this process, variants
interleaved); callgrind counts the instructions of Chipmunk's cpSpaceStep per step beside ours.
Writes bench/results/peers.csv and prints a markdown table.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PEER_VENV = ROOT / "bench" / ".venv-peers"
PYMUNK = "pymunk==7.3.1"

PEER_SCRIPT = r"""
import json, math, sys, time
import pymunk
spec = json.load(open(sys.argv[1])); variant = sys.argv[2]; steps = int(sys.argv[3])
dt, k, c, d_n, d_t = spec["dt"], spec["k"], spec["c"], spec["d_n"], spec["d_t"]
space = pymunk.Space(); space.iterations = 1; space.gravity = (0, 0)
bodies = []
for x, y in spec["positions"]:
    b = pymunk.Body(1.0, float("inf")); b.position = (x, y); space.add(b); bodies.append(b)
springs = []
for (i, j), L0 in zip(spec["springs"], spec["rest"]):
    s = pymunk.DampedSpring(bodies[i], bodies[j], (0, 0), (0, 0), L0, k, c); space.add(s); springs.append((s, i, j, L0))
amp, freq, phase = spec["amplitude"], spec["frequency"], spec["phase"]
skin = spec["skin"]
t = 0.0
def actuate(t):
    for s, i, j, L0 in springs:
        s.rest_length = L0 * (1.0 + 0.5 * (amp[i] * math.sin(freq[i] * t + phase[i]) + amp[j] * math.sin(freq[j] * t + phase[j])))
def drag():
    for i, j in skin:
        a, b = bodies[i], bodies[j]
        ex, ey = b.position.x - a.position.x, b.position.y - a.position.y
        L = math.hypot(ex, ey)
        if L == 0.0: continue
        tx, ty = ex / L, ey / L; nx, ny = -ty, tx
        vx = 0.5 * (a.velocity.x + b.velocity.x); vy = 0.5 * (a.velocity.y + b.velocity.y)
        vn = vx * nx + vy * ny; vt = vx * tx + vy * ty
        fn = -d_n * L * vn * abs(vn); ft = -d_t * L * vt * abs(vt)
        fx, fy = 0.5 * (fn * nx + ft * tx), 0.5 * (fn * ny + ft * ty)
        a.force = (a.force.x + fx, a.force.y + fy); b.force = (b.force.x + fx, b.force.y + fy)
def drag_numpy():
    import numpy as np
    P = np.array([b.position for b in bodies]); V = np.array([b.velocity for b in bodies])
    I, J = SK[:, 0], SK[:, 1]
    E = P[J] - P[I]; L = np.hypot(E[:, 0], E[:, 1]); T = E / L[:, None]; N = np.stack([-T[:, 1], T[:, 0]], 1)
    Vm = 0.5 * (V[I] + V[J]); vn = (Vm * N).sum(1); vt = (Vm * T).sum(1)
    F = 0.5 * ((-d_n * L * vn * np.abs(vn))[:, None] * N + (-d_t * L * vt * np.abs(vt))[:, None] * T)
    acc = np.zeros_like(P); np.add.at(acc, I, F); np.add.at(acc, J, F)
    for b, f in zip(bodies, acc): b.force = (b.force.x + f[0], b.force.y + f[1])
if variant == "numpy":
    import numpy as np
    SK = np.array(skin)
def step():
    global t
    if variant != "springs":
        actuate(t)
        drag() if variant == "python" else drag_numpy()
    space.step(dt); t += dt
for _ in range(100): step()
t0 = time.process_time()
for _ in range(steps): step()
print(json.dumps({"us_per_step": (time.process_time() - t0) / steps * 1e6,
                  "pymunk": pymunk.version, "chipmunk": pymunk.chipmunk_version}))
"""


def peer_python() -> Path:
    py = PEER_VENV / "bin" / "python"
    if not py.exists():
        subprocess.run([sys.executable, "-m", "venv", str(PEER_VENV)], check=True)
    have = subprocess.run([str(py), "-c", "import pymunk, numpy"], capture_output=True).returncode == 0
    if not have:
        subprocess.run(
            [str(py), "-m", "pip", "install", "-q", "--disable-pip-version-check", PYMUNK, "numpy"], check=True
        )
    return py


def body_spec() -> dict:
    """The 32-cell lattice swimmer of bench_physics (8 x 4 triangular lattice, spacing 1, travelling
    wave a = 0.2, f = 4), built by animat itself: positions, springs, rest lengths, skin."""
    import numpy as np

    import animat

    rng = np.random.default_rng(1)
    pts = np.array([[i + (0.5 if j % 2 else 0.0), j * np.sqrt(3.0) / 2.0] for j in range(4) for i in range(8)])
    pts += rng.uniform(-0.05, 0.05, pts.shape)
    n = len(pts)
    phase = np.mod(2 * np.pi * pts[:, 0] / 4.0, 2 * np.pi)
    body = animat.build_body(pts, np.full(n, 0.2), np.full(n, 4.0), phase)
    cfg = animat.Config()
    return {
        "positions": np.asarray(body.positions).tolist(),
        "springs": np.asarray(body.springs).tolist(),
        "rest": np.asarray(body.rest_lengths).tolist(),
        "skin": np.asarray(body.skin).tolist(),
        "amplitude": [0.2] * n,
        "frequency": [4.0] * n,
        "phase": phase.tolist(),
        "dt": cfg["physics.dt"],
        "k": cfg["scene.spring_stiffness"],
        "c": cfg["scene.spring_damping"],
        "d_n": cfg["scene.drag_normal"],
        "d_t": cfg["scene.drag_normal"] / 200.0,
    }


def ours(filt: str) -> float:
    out = subprocess.run(
        [
            str(ROOT / "build" / "bench_physics"),
            f"--benchmark_filter={filt}",
            "--benchmark_format=json",
            "--benchmark_min_time=0.5",
        ],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    b = [r for r in json.loads(out)["benchmarks"] if r.get("run_type") == "iteration"][0]
    return b["cpu_time"] * {"ns": 1e-3, "us": 1.0, "ms": 1e3}[b["time_unit"]]


def callgrind(cmd: list[str], toggle: str, calls_of: str) -> tuple[int, int]:
    """Instructions inside `toggle` and the number of calls of `calls_of` (callgrind)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "cg.out"
        subprocess.run(
            ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", f"--toggle-collect={toggle}", *cmd],
            check=True,
            capture_output=True,
            env={**os.environ, "LD_BIND_NOW": "1"},
        )
        ann = subprocess.run(
            ["callgrind_annotate", "--inclusive=yes", "--tree=caller", str(out)],
            capture_output=True,
            text=True,
            check=True,
        ).stdout
    total = int(re.search(r"([\d,]+) \([ \d.]+%\)\s+PROGRAM TOTALS", ann).group(1).replace(",", ""))
    calls = 0
    lines = ann.splitlines()
    for i, line in enumerate(lines):
        if re.search(r"\*\s+\S*?:" + re.escape(calls_of), line):
            j = i - 1
            while j >= 0 and "  < " in lines[j]:
                m = re.search(r"\((\d[\d,]*)x\)", lines[j])
                calls += int(m.group(1).replace(",", "")) if m else 0
                j -= 1
            break
    return total, calls


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--steps", type=int, default=20000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--no-callgrind", action="store_true")
    args = ap.parse_args()
    py = peer_python()
    results = ROOT / "bench" / "results"
    results.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        spec_path = Path(tmp) / "body.json"
        spec_path.write_text(json.dumps(body_spec()))
        script = Path(tmp) / "peer.py"
        script.write_text(PEER_SCRIPT)
        times: dict[str, list[float]] = {k: [] for k in ("springs", "python", "numpy", "ours_springs", "ours_all")}
        version = {}
        for _ in range(args.repeat):
            for variant in ("springs", "python", "numpy"):
                steps = args.steps if variant == "springs" else args.steps // 10
                r = json.loads(
                    subprocess.run(
                        [str(py), str(script), str(spec_path), variant, str(steps)],
                        capture_output=True,
                        text=True,
                        check=True,
                    ).stdout
                )
                times[variant].append(r["us_per_step"])
                version = {"pymunk": r["pymunk"], "chipmunk": r["chipmunk"]}
            times["ours_springs"].append(ours("^BM_Effect/0$"))
            times["ours_all"].append(ours("^BM_SwimStep/32$"))
        med = {k: statistics.median(v) for k, v in times.items()}
        ins = {}
        if not args.no_callgrind:
            total, calls = callgrind(
                [str(py), str(script), str(spec_path), "springs", "2000"], "cpSpaceStep", "cpSpaceStep"
            )
            ins["springs"] = total / calls if calls else float("nan")
            for key, filt in (("ours_springs", "^BM_Effect/0$"), ("ours_all", "^BM_SwimStep/32$")):
                total, calls = callgrind(
                    [str(ROOT / "build" / "bench_physics"), f"--benchmark_filter={filt}", "--benchmark_min_time=0.05"],
                    "animat::Simulation::step*",
                    "animat::Simulation::step",
                )
                ins[key] = total / calls if calls else float("nan")
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
    print(
        f"machine: {cpu}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}; pymunk {version.get('pymunk')} "
        f"(Chipmunk {version.get('chipmunk')}); 32 cells, dt 1/60, one iteration; medians of {args.repeat} interleaved runs"
    )
    rows = [
        ("pymunk, springs only (cpDampedSpring, one iteration)", med["springs"], ins.get("springs")),
        ("pymunk, springs + actuation + skin drag in Python", med["python"], None),
        ("pymunk, springs + actuation in Python, skin drag in numpy", med["numpy"], None),
        ("animat, springs only (BM_Effect/0)", med["ours_springs"], ins.get("ours_springs")),
        ("animat, every effect of the default scene (BM_SwimStep/32)", med["ours_all"], ins.get("ours_all")),
    ]
    print()
    print("| step of a 32-cell body | µs per step | over animat's whole step | instructions per step |")
    print("|---|---|---|---|")
    with open(results / "peers.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["variant", "us_per_step", "instructions_per_step"])
        for name, us, n in rows:
            w.writerow([name, f"{us:.3f}", "" if n is None else f"{n:.0f}"])
            print(f"| {name} | {us:.2f} | {us / med['ours_all']:.2f}× | {'—' if n is None else f'{n / 1e3:.1f}k'} |")
    print()
    print("runs (µs):", json.dumps({k: [round(x, 2) for x in v] for k, v in times.items()}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
