#!/usr/bin/env python3
"""What accuracy costs in time (docs/accuracy.md): sweep the Box2D step, substeps and drag scheme
over a fixed set of bodies and measure, against a fine reference (the default dt / 16):

- the error of the final centre-of-mass displacement (a vector, so it includes the heading),
- the fitness error (|displacement|, what the GA ranks),
- the trajectory error (RMS distance between the COM paths, sampled 40 times over the horizon),
- the cost per simulated time unit (CPU time, single thread).

The horizon is a simulated duration: 4000 steps at the default dt (1/60), i.e. 66.7 time units, so a
setting with a larger step takes fewer steps. Bodies: hand-made lattice swimmers plus the first
viable random genomes at fixed seeds; environments d_N = 0.5, 2, 10 (paper §6).

Also measured, per body: the chaos floor, i.e. how much the reference fitness itself changes when the
initial cell positions are perturbed by 1e-6. A discretisation error below that floor is noise.

    PYTHONPATH=build-phys/python .venv/bin/python bench/accuracy_vs_time.py \
        --csv bench/accuracy_vs_time.csv --plot docs/images/accuracy_vs_time.png

prints the summary table (Markdown) that docs/accuracy.md quotes.
"""

import argparse
import concurrent.futures as cf
import csv
import math
import os
import platform
import subprocess
import sys
import time

import numpy as np

import animat

DEFAULT_DT = 1.0 / 60.0
HORIZON = 4000 * DEFAULT_DT  # simulated time of one evaluation
REF_DIV = 16  # reference step = DEFAULT_DT / 16
SAMPLES = 40  # COM samples along the horizon
STEPS = [1 / 15, 1 / 30, 1 / 60, 1 / 120, 1 / 240]
DEFAULT_SCHEME = "semi_implicit"
SCHEMES = ["semi_implicit", "explicit", "stable", "implicit"]
VELOCITY_FORCES = ["midpoint", "start"]
SUBSTEP_COMBOS = [(1 / 30, 2), (1 / 15, 4)]  # (dt, substeps) for the default scheme
ENVIRONMENTS = [0.5, 2.0, 10.0]


def lattice(nx, ny, jitter, seed):
    rng = np.random.default_rng(seed)
    p = np.array([(i + (0.5 if j % 2 else 0.0), j * math.sqrt(3) / 2) for j in range(ny) for i in range(nx)])
    return p + rng.uniform(-jitter, jitter, p.shape)


def hand_made():
    """(name, points, amplitude, frequency, phase)"""
    out = []
    p = lattice(8, 4, 0.05, 1)
    n = len(p)
    wave = (2 * np.pi * p[:, 0] / 4.0) % (2 * np.pi)
    for f in (1.0, 4.0, 12.0):
        out.append((f"wave f={f:g} (32)", p, np.full(n, 0.2), np.full(n, f), wave))
    q = lattice(6, 6, 0.05, 2)
    out.append(("sync f=2 (36)", q, np.full(len(q), 0.2), np.full(len(q), 2.0), np.zeros(len(q))))
    r = lattice(8, 8, 0.15, 3)
    rng = np.random.default_rng(4)
    out.append(
        ("random (64)", r, rng.uniform(0, 0.2, len(r)), rng.uniform(0.5, 12, len(r)), rng.uniform(0, 2 * np.pi, len(r)))
    )
    return out


def genome_bodies(count, seed):
    """The first `count` viable random genomes (seeds Rng.derive(seed, i, 0), i = 0, 1, ...) whose
    cells oscillate at all (max amplitude > 0.01): most viable random genomes do not actuate."""
    cfg = animat.Config()
    out = []
    i = 0
    while len(out) < count:
        g = animat.Genome.random(animat.Rng.derive(seed, i, 0))
        e = animat.develop(g, cfg)
        if e.viable and e.amplitude.max() > 0.01:
            out.append((f"genome {seed}/{i} ({e.cell_count})", e.positions, e.amplitude, e.frequency, e.phase))
        i += 1
    return out


def run(body_spec, dn, h, scheme, substeps=1, perturb=0.0, velocity_forces="midpoint"):
    """COM samples (SAMPLES + 1, 2) over the horizon, or None if the swim failed."""
    name, p, a, f, ph = body_spec
    if perturb:
        p = p + perturb * np.random.default_rng(99).standard_normal(p.shape)
    body = animat.build_body(p, a, f, ph)
    cfg = animat.Config()
    cfg.physics.dt = h * substeps
    cfg.physics.substeps = substeps
    cfg.physics.drag_scheme = scheme
    cfg.physics.velocity_forces = velocity_forces
    sim = animat.Simulation(body, animat.Scene(drag_normal=dn), config=cfg)
    control = HORIZON / (h * substeps)
    every = int(round(control / SAMPLES))
    assert abs(every * SAMPLES - control) < 1e-6, (h, substeps)
    try:
        frames = sim.record(every * SAMPLES, every=every)
    except RuntimeError:
        return None
    return frames.mean(axis=1)


def errors(com, ref):
    if com is None:
        return dict(failed=1, fitness=float("nan"), fit_err=float("inf"), disp_err=float("inf"), traj_err=float("inf"))
    d, dr = com[-1] - com[0], ref[-1] - ref[0]
    fit, fit_ref = np.linalg.norm(d), np.linalg.norm(dr)
    traj = np.sqrt(np.mean(np.sum((com - com[0] - (ref - ref[0])) ** 2, axis=1)))
    scale = fit_ref if fit_ref > 0 else float("nan")  # relative errors; near-zero references are left out later
    return dict(
        failed=0,
        fitness=fit,
        fit_err=abs(fit - fit_ref) / scale,
        disp_err=np.linalg.norm(d - dr) / scale,
        traj_err=traj / scale,
    )


def case(body_spec, dn):
    ref = run(body_spec, dn, DEFAULT_DT / REF_DIV, DEFAULT_SCHEME)
    floor = run(body_spec, dn, DEFAULT_DT / REF_DIV, DEFAULT_SCHEME, perturb=1e-6)
    fit_ref = float(np.linalg.norm(ref[-1] - ref[0]))
    rows = []
    floor_err = errors(floor, ref)
    for vf in VELOCITY_FORCES:
        for scheme in SCHEMES:
            for h in STEPS:
                rows.append(
                    dict(
                        body=body_spec[0],
                        d_N=dn,
                        h=h,
                        dt=h,
                        substeps=1,
                        scheme=scheme,
                        velocity_forces=vf,
                        fitness_ref=fit_ref,
                        chaos_floor=floor_err["fit_err"],
                        **errors(run(body_spec, dn, h, scheme, velocity_forces=vf), ref),
                    )
                )
    for dt, s in SUBSTEP_COMBOS:
        rows.append(
            dict(
                body=body_spec[0],
                d_N=dn,
                h=dt / s,
                dt=dt,
                substeps=s,
                scheme=DEFAULT_SCHEME,
                velocity_forces="midpoint",
                fitness_ref=fit_ref,
                chaos_floor=floor_err["fit_err"],
                **errors(run(body_spec, dn, dt / s, DEFAULT_SCHEME, s), ref),
            )
        )
    return rows


def cost_table(repeats=3):
    """CPU seconds per simulated time unit for each (h, scheme, velocity_forces), 32-cell lattice
    swimmer, d_N = 2."""
    spec = hand_made()[1]
    out = {}
    for scheme, vf in [(s, v) for v in VELOCITY_FORCES for s in SCHEMES]:
        for h in STEPS:
            cfg = animat.Config()
            cfg.physics.dt = h
            cfg.physics.drag_scheme = scheme
            cfg.physics.velocity_forces = vf
            body = animat.build_body(*spec[1:])
            steps = int(round(HORIZON / h))
            best = float("inf")
            for _ in range(repeats):
                sim = animat.Simulation(body, animat.Scene(), config=cfg)
                t0 = time.process_time()
                try:
                    sim.step(steps)
                except RuntimeError:  # unstable at this step: no cost to report
                    best = float("nan")
                    break
                best = min(best, time.process_time() - t0)
            out[(h, scheme, vf)] = best / HORIZON
    return out


def machine():
    cpu = platform.processor() or "?"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return (
        f"{cpu}, {os.cpu_count()} cores, {platform.system()} {platform.release()}, Python {platform.python_version()}"
    )


def summarise(rows, costs, min_fitness):
    """Per (h, scheme, substeps): median/max fitness error over cases with reference fitness >=
    min_fitness, share within 1%, median trajectory error, failures, cost."""
    keys = sorted(
        {(r["dt"], r["substeps"], r["scheme"], r["velocity_forces"]) for r in rows},
        key=lambda k: (VELOCITY_FORCES.index(k[3]), SCHEMES.index(k[2]), -k[0] / k[1], k[1]),
    )
    out = []
    for dt, s, scheme, vf in keys:
        sel = [
            r
            for r in rows
            if r["dt"] == dt and r["substeps"] == s and r["scheme"] == scheme and r["velocity_forces"] == vf
        ]
        good = [r for r in sel if r["fitness_ref"] >= min_fitness]
        fe = np.array([r["fit_err"] for r in good], dtype=float)
        te = np.array([r["traj_err"] for r in good], dtype=float)
        ae = np.array([abs(r["fitness"] - r["fitness_ref"]) if not r["failed"] else float("inf") for r in sel])
        h = dt / s
        out.append(
            dict(
                dt=dt,
                substeps=s,
                h=h,
                scheme=scheme,
                velocity_forces=vf,
                cases=len(good),
                failed=sum(r["failed"] for r in sel),
                abs_max=float(ae.max()),
                fit_median=float(np.median(fe)),
                fit_p90=float(np.percentile(fe, 90)),
                fit_max=float(fe.max()),
                within_1pct=float(np.mean(fe <= 0.01)),
                traj_median=float(np.median(te)),
                cost=costs.get((h, scheme, vf), float("nan")) if s == 1 else float("nan"),
            )
        )
    return out


def frac(x):
    return f"1/{round(1 / x)}" if x < 1 else f"{x:g}"


def markdown(summary, floors, default_cost):
    lines = [
        "| h = dt/substeps | dt | substeps | velocity forces | drag scheme | failed | fitness error median | p90 | max | within 1% | "
        "trajectory error median | max abs. fitness error, all cases | CPU ms per time unit | cost vs default |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]

    def pct(x):
        return "∞" if not math.isfinite(x) else f"{100 * x:.2f}%"

    for s in summary:
        cost = s["cost"]
        lines.append(
            f"| {frac(s['h'])} | {frac(s['dt'])} | {s['substeps']} | {s['velocity_forces']} | {s['scheme']} | {s['failed']} | "
            f"{pct(s['fit_median'])} | {pct(s['fit_p90'])} | {pct(s['fit_max'])} | {100 * s['within_1pct']:.0f}% | "
            f"{pct(s['traj_median'])} | {s['abs_max']:.3g} | {1e3 * cost:.2f} | {cost / default_cost:.2f}× |"
            if math.isfinite(cost)
            else f"| {frac(s['h'])} | {frac(s['dt'])} | {s['substeps']} | {s['velocity_forces']} | {s['scheme']} | {s['failed']} | "
            f"{pct(s['fit_median'])} | {pct(s['fit_p90'])} | {pct(s['fit_max'])} | {100 * s['within_1pct']:.0f}% | "
            f"{pct(s['traj_median'])} | {s['abs_max']:.3g} | = h row | = h row |"
        )
    lines.append("")
    lines.append(
        f"Chaos floor (fitness change from a 1e-6 perturbation of the initial positions, at the reference "
        f"step): median {100 * np.median(floors):.3f}%, max {100 * np.max(floors):.2f}%."
    )
    return "\n".join(lines)


def plot(summary, path):
    import matplotlib
    import matplotlib.ticker

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for (scheme, vf), marker, ls in zip(
        [(s, v) for v in VELOCITY_FORCES for s in SCHEMES], "osdosd", ["-", "-", "-", ":", ":", ":"]
    ):
        pts = [
            s
            for s in summary
            if s["scheme"] == scheme
            and s["velocity_forces"] == vf
            and s["substeps"] == 1
            and math.isfinite(s["cost"])
            and math.isfinite(s["fit_median"])
        ]
        x = [1e3 * s["cost"] for s in pts]
        for ax, key, label in [
            (axes[0], "fit_median", "median fitness error"),
            (axes[1], "traj_median", "median trajectory error"),
        ]:
            y = [max(s[key], 1e-6) for s in pts]
            ax.plot(x, y, marker=marker, ls=ls, label=f"{scheme}, {vf}")
            for s, xi, yi in zip(pts, x, y):
                if scheme == DEFAULT_SCHEME and vf == "midpoint":
                    ax.annotate(f"h={frac(s['h'])}", (xi, yi), textcoords="offset points", xytext=(4, 4), fontsize=7)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
            ax.set_xlabel("CPU ms per simulated time unit (32 cells)")
            ax.set_ylabel(label + " vs dt/16")
            ax.axhline(0.01, color="grey", lw=0.8, ls="--")
            ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.suptitle("Swim accuracy vs cost: median over cases with fitness >= 0.5")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--csv", default="bench/accuracy_vs_time.csv")
    ap.add_argument("--plot", default="docs/images/accuracy_vs_time.png")
    ap.add_argument("--genomes", type=int, default=6, help="random viable genomes")
    ap.add_argument("--seed", type=int, default=2012)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument(
        "--min-fitness",
        type=float,
        default=0.5,
        help="cases whose reference fitness is below this are left out of relative summaries",
    )
    ap.add_argument("--quick", action="store_true", help="2 hand-made bodies, 1 genome, d_N = 2 only")
    args = ap.parse_args()

    bodies = hand_made() + genome_bodies(args.genomes, args.seed)
    envs = ENVIRONMENTS
    if args.quick:
        bodies, envs = bodies[:2] + genome_bodies(1, args.seed), [2.0]
    t0 = time.time()
    rows = []
    cases = [(b, dn) for b in bodies for dn in envs + ([0.2] if len(b[1]) >= 64 and not args.quick else [])]
    with cf.ThreadPoolExecutor(args.threads) as pool:  # swims release the GIL
        for res in pool.map(lambda c: case(*c), cases):
            rows.extend(res)
    sweep_seconds = time.time() - t0
    costs = cost_table()
    with open(args.csv, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    summary = summarise(rows, costs, args.min_fitness)
    floors = sorted(
        {(r["body"], r["d_N"]): r["chaos_floor"] for r in rows if r["fitness_ref"] >= args.min_fitness}.values()
    )
    default_cost = costs[(DEFAULT_DT, DEFAULT_SCHEME, "midpoint")]
    plot(summary, args.plot)
    try:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    except OSError:
        commit = "?"
    print(f"machine: {machine()}; commit {commit}; sweep {sweep_seconds:.0f} s wall on {args.threads} threads")
    print(
        f"bodies: {len(bodies)} x d_N {envs}; horizon {HORIZON:.2f} time units; reference h = 1/{round(REF_DIV / DEFAULT_DT)}"
    )
    print(
        f"cases in summaries (reference fitness >= {args.min_fitness}): "
        f"{sum(1 for r in rows if r['fitness_ref'] >= args.min_fitness) // (len(VELOCITY_FORCES) * len(SCHEMES) * len(STEPS) + len(SUBSTEP_COMBOS))}"
        f" of {len(cases)}"
    )
    print(
        f"default (h = 1/60, semi-implicit drag, midpoint velocity forces): {1e3 * default_cost:.2f} CPU ms per time unit, "
        f"{1e3 * default_cost * HORIZON:.0f} ms per evaluation horizon, "
        f"{1e6 * default_cost * DEFAULT_DT:.1f} us per step"
    )
    print()
    print(markdown(summary, floors, default_cost))
    print()
    print("per case (fitness error %, default: semi-implicit drag, midpoint velocity forces):")
    for b in bodies:
        for dn in sorted({r["d_N"] for r in rows}):
            sel = {
                r["h"]: r
                for r in rows
                if r["body"] == b[0]
                and r["d_N"] == dn
                and r["scheme"] == DEFAULT_SCHEME
                and r["substeps"] == 1
                and r["velocity_forces"] == "midpoint"
            }
            if not sel:
                continue
            any_row = next(iter(sel.values()))
            cells = " ".join(f"{frac(h)}:{100 * sel[h]['fit_err']:.2f}" for h in STEPS)
            print(
                f"  {b[0]:28s} d_N={dn:<4g} fit_ref={any_row['fitness_ref']:8.3f} floor={100 * any_row['chaos_floor']:.3f}%  {cells}"
            )


if __name__ == "__main__":
    sys.exit(main())
