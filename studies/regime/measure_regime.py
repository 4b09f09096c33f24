"""The paper's regime, measured on a set of evolved bests (by default the 40 final bests of the
replication study in data/replication): where the actuation work goes (fluid, spring damping,
collisions), the body's elastic modes against the allowed frequency range, and how close the evolved
oscillators sit to their bounds. The criteria are defined in docs/regime.md.

    PYTHONPATH=build/python .venv/bin/python studies/regime/measure_regime.py \
        --data data/replication --out studies/regime/results/replication_today.csv

writes one row per best and prints the per-environment medians that docs/regime.md quotes.
``--reference`` swims at the exploit guard's reference step (dt/16 by default), the swim that a study
ranked with ``evaluation.reference_check = "select"`` selected on.
``--set scene.spring_damping=1`` re-swims the same bodies with a constant changed.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
from pathlib import Path

import numpy as np

import animat

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "replication"))
from replication_store import packed_runs, unpack_run  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from results_table import write_rows  # noqa: E402

COLUMNS = [
    "environment",
    "run",
    "fitness",
    "cells",
    "actuation",
    "fluid_share",
    "drag_normal_share",
    "drag_tangential_share",
    "damping_share",
    "collision_share",
    "residual_share",
    "frequency_median",
    "frequency_max",
    "at_frequency_bound",
    "amplitude_median_of_max",
    "mode_lowest",
    "mode_median",
    "modes_in_range",
    "damping_ratio_at_frequency",
]


def elastic_modes(body, config):
    """Undamped elastic modes of the body at rest (springs and pressure linearised; unit cell mass):
    angular frequencies (ascending, rigid-body modes dropped) and the modal damping ratio of the
    spring dampers, ζ = φᵀCφ / (2ω) for mass-normalised φ."""
    p = np.asarray(body.positions, float)
    n = len(p)
    k = config["scene.spring_stiffness"]
    c = config["scene.spring_damping"]
    cp = config["scene.pressure"]
    floor = config["scene.pressure_area_floor"]
    m = config["scene.cell_mass"]
    K = np.zeros((2 * n, 2 * n))
    C = np.zeros((2 * n, 2 * n))
    for i, j in np.asarray(body.springs):
        e = p[j] - p[i]
        e = e / np.linalg.norm(e)
        block = np.outer(e, e)
        for a, b, s in ((i, i, 1), (j, j, 1), (i, j, -1), (j, i, -1)):
            K[2 * a : 2 * a + 2, 2 * b : 2 * b + 2] += s * k * block
            C[2 * a : 2 * a + 2, 2 * b : 2 * b + 2] += s * c * block
    for loop, s0 in zip(body.regions, np.asarray(body.rest_areas)):
        loop = list(loop)
        L = len(loop)
        lmax2 = max(float(np.sum((p[loop[(q + 1) % L]] - p[loop[q]]) ** 2)) for q in range(L))
        area = max(s0, floor * lmax2)
        g = np.zeros(2 * n)
        for q in range(L):
            i, prev, nxt = loop[q], loop[(q - 1) % L], loop[(q + 1) % L]
            g[2 * i] += 0.5 * (p[nxt][1] - p[prev][1])
            g[2 * i + 1] += 0.5 * (p[prev][0] - p[nxt][0])
        K += (cp / area) * np.outer(g, g)
    w2, phi = np.linalg.eigh(K / m)
    keep = w2 > 1e-8 * w2.max()
    w = np.sqrt(w2[keep])
    phi = phi[:, keep] / np.sqrt(m)
    zeta = np.einsum("ik,ij,jk->k", phi, C, phi) / (2.0 * w)
    return w, zeta


def measure(genome, config):
    config["evaluation.energy_accounting"] = True
    r = animat.evaluate(genome, config)
    e = r.energy
    embryo = animat.develop(genome, config)
    body = animat.build_body(embryo)
    w, zeta = elastic_modes(body, config)
    f = np.asarray(body.frequency)
    a = np.asarray(body.amplitude)
    fmax = config["development.frequency_max"]
    amax = config["development.amplitude_max"]
    fmed = float(np.median(f))
    zeta_at_f = float(np.interp(fmed, w, zeta)) if len(w) else float("nan")
    total = e.actuation + e.external
    return {
        "fitness": r.fitness,
        "cells": r.cell_count,
        "actuation": e.actuation,
        "fluid_share": e.fluid / e.dissipated,
        "drag_normal_share": e.drag_normal / e.dissipated,
        "drag_tangential_share": e.drag_tangential / e.dissipated,
        "damping_share": e.spring_damping / e.dissipated,
        "collision_share": e.collisions / e.dissipated,
        "residual_share": e.residual / total,
        "frequency_median": fmed,
        "frequency_max": fmax,
        "at_frequency_bound": float(np.mean(f >= 0.95 * fmax)),
        "amplitude_median_of_max": float(np.median(a) / amax),
        "mode_lowest": float(w[0]) if len(w) else float("nan"),
        "mode_median": float(np.median(w)) if len(w) else float("nan"),
        "modes_in_range": int(np.sum((w >= config["development.frequency_min"]) & (w <= fmax))),
        "damping_ratio_at_frequency": zeta_at_f,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", type=Path, default=Path("data/replication"))
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="re-swim every best with this config value changed (e.g. scene.spring_damping=1): how "
        "the constants move the split for the same bodies",
    )
    ap.add_argument(
        "--reference",
        action="store_true",
        help="swim at the exploit guard's reference step (animat.reference_config: physics.substeps x "
        "evaluation.reference_substeps), the swim a study with evaluation.reference_check = 'select' "
        "ranks its elites by",
    )
    args = ap.parse_args(argv)
    overrides = []
    for item in args.set:
        key, sep, value = item.partition("=")
        if not sep:
            ap.error(f"--set {item!r}: expected KEY=VALUE")
        overrides.append((key, float(value)))
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for env, runs in sorted(packed_runs(args.data).items()):
            for packed in runs:
                work = Path(tmp) / env / packed.name
                unpack_run(packed, work)
                run = animat.Run(work)
                config = run.config
                for key, value in overrides:
                    config[key] = value
                if args.reference:
                    config = animat.reference_config(config)
                row = {"environment": env, "run": packed.name}
                row.update(measure(run.best().genome, config))
                rows.append(row)
                print(
                    f"{env} {packed.name}: fluid {row['fluid_share']:.3f} damping {row['damping_share']:.3f} "
                    f"f {row['frequency_median']:.2f} lowest mode {row['mode_lowest']:.2f}",
                    file=sys.stderr,
                )
    write_rows(args.out, rows, COLUMNS)
    print(
        "environment | bests | fluid share | damping share | frequency (median) | at bound (>= 0.95 f_max) | "
        "lowest elastic mode | modes within [f_min, f_max] | damping ratio at the frequency | max |residual|"
    )
    for env in sorted({r["environment"] for r in rows}):
        sel = [r for r in rows if r["environment"] == env]
        med = lambda key: statistics.median(r[key] for r in sel)  # noqa: E731, B023 (used in this iteration)
        print(
            f"{env} | {len(sel)} | {med('fluid_share'):.2f} | {med('damping_share'):.2f} | "
            f"{med('frequency_median'):.2f} | {sum(r['at_frequency_bound'] >= 0.5 for r in sel)} of {len(sel)} | "
            f"{med('mode_lowest'):.2f} | {med('modes_in_range'):.0f} | {med('damping_ratio_at_frequency'):.2f} | "
            f"{max(abs(r['residual_share']) for r in sel):.4f}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
