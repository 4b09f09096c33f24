"""Active control (docs/control.md): what an evolved GRN controller does while it swims.

Reads the best genome of a short chemotaxis run (data/control/<run>_*) and writes
  docs/images/control_<run>_terms.png  the actuation term u_i of every cell over time,
  docs/images/control_<run>_paths.png  centre-of-mass paths toward sources in 8 directions.

    PYTHONPATH=build/python .venv/bin/python examples/grn_control_trace.py [RUN ...]

RUN defaults to chemotaxis_grn_seed1 and chemotaxis_amplitude_seed2 (docs/control.md).
"""

import math
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import animat  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[1]
DATA = ROOT / "data" / "control"
OUT = ROOT / "docs" / "images"


def main(run: str) -> None:
    cfg = animat.load_config(str(DATA / f"{run}_config.toml"))
    genome = animat.Genome.load(str(DATA / f"{run}_best_genome.json"))
    steps = cfg["evaluation.steps"]
    r = float(np.hypot(*cfg["scene.chemical_source"]))

    t = animat.grn_swim(genome, cfg, steps=steps, every=10, source=[r, 0.0])
    order = np.argsort(t["terms"][-1])
    fig, ax = plt.subplots(figsize=(7, 3.2), dpi=110)
    if cfg["control.actuation"] == "amplitude":  # show the first 8 time units: the oscillation
        keep = t["times"] <= 8.0
        t = {k: v[keep] for k, v in t.items()}
    im = ax.imshow(
        t["terms"][:, order].T,
        aspect="auto",
        cmap="coolwarm",
        origin="lower",
        extent=(float(t["times"][0]), float(t["times"][-1]), 0.0, float(t["terms"].shape[1])),
        vmin=-cfg["development.amplitude_max"],
        vmax=cfg["development.amplitude_max"],
    )
    ax.set_xlabel("time")
    ax.set_ylabel("cell (sorted by final u)")
    ax.set_title(f"{run}: u_i per cell (source at +x)", fontsize=9)
    fig.colorbar(im, ax=ax, label="u_i")
    fig.tight_layout()
    fig.savefig(OUT / f"control_{run}_terms.png")

    fig, ax = plt.subplots(figsize=(4.2, 4.2), dpi=110)
    for k in range(8):
        a = 2 * math.pi * k / 8
        src = [r * math.cos(a), r * math.sin(a)]
        tr = animat.grn_swim(genome, cfg, steps=steps, every=20, source=src)
        com = tr["com"] - tr["com"][0]
        (line,) = ax.plot(com[:, 0], com[:, 1], lw=1.2)
        ax.annotate(
            "",
            xy=(0.25 * math.cos(a), 0.25 * math.sin(a)),
            xytext=(0, 0),
            arrowprops=dict(arrowstyle="->", color=line.get_color(), alpha=0.6),
        )
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title("COM paths (same colour: source direction)", fontsize=9)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    fig.tight_layout()
    fig.savefig(OUT / f"control_{run}_paths.png")


if __name__ == "__main__":
    for name in sys.argv[1:] or ["chemotaxis_grn_seed1", "chemotaxis_amplitude_seed2"]:
        main(name)
