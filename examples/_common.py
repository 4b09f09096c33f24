"""Shared by the example scripts: a small fresh run, saving compact PNGs, and the command line of the
examples that run a search (DEAP, pymoo, MAP-Elites, NSGA-II).

Run the examples from the repository root with the built module on the path, e.g.

    PYTHONPATH=build/python .venv/bin/python examples/fig4_motion_cycle.py
"""

import argparse
import io
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from PIL import Image  # noqa: E402

import animat  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def parser(description, default_out):
    """Common options: --run DIR (use an existing run instead of a fresh one), the size of the fresh
    run, --out PNG."""
    p = argparse.ArgumentParser(description=description, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--run", type=Path, help="an existing run directory (default: evolve a small fresh run)")
    p.add_argument("--generations", type=int, default=10, help="generations of the fresh run (default 10)")
    p.add_argument("--population", type=int, default=30, help="population of the fresh run (default 30)")
    p.add_argument("--steps", type=int, default=2000, help="swim steps per evaluation (default 2000)")
    p.add_argument("--seed", type=int, default=1, help="run seed (default 1)")
    p.add_argument("--out", type=Path, default=Path(default_out), help=f"output file (default {default_out})")
    return p


def fresh_run(args):
    """animat.Run of args.run, or of a small run evolved now into a temporary directory."""
    if args.run is not None:
        return animat.Run(args.run)
    config = animat.Config()
    config["evolution.population"] = args.population
    config["evolution.generations"] = args.generations
    config["evaluation.steps"] = args.steps
    config["evolution.seed"] = args.seed
    out = Path(tempfile.mkdtemp(prefix="animat_example_")) / "run"
    print(f"evolving {args.generations} generations of {args.population} into {out} ...")
    animat.evolve(config, out=str(out))
    return animat.Run(out)


def search_parser(description, size="population", generations=20):
    """The command line of the examples that run a search (deap_ga.py, pymoo_nsga2.py, map_elites.py,
    nsga2_distance_vs_work.py): --generations, --population (or --batch: ``size``), --steps, --seed,
    --threads. Each adds its own options."""
    p = argparse.ArgumentParser(description=description, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--generations", type=int, default=generations)
    p.add_argument(f"--{size}", type=int, default=20)
    p.add_argument("--steps", type=int, default=1000, help="swim steps per evaluation (the paper: 4000)")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--threads", type=int, default=0, help="0 = all cores; the run does not depend on it")
    return p


def search_config(args):
    """The default config with the command line's --steps."""
    config = animat.Config()
    config["evaluation.steps"] = args.steps
    return config


def at_reference(genome, fitness, config):
    """The exploit guard's check, which DEAP's and pymoo's loops do not make: the genome's fitness at the
    reference step (``animat.reference_config``) and whether it agrees with ``fitness``, as words."""
    reference = animat.evaluate(genome, animat.reference_config(config)).fitness
    agrees = "disagrees" if animat.reference_disagrees(fitness, reference, config) else "agrees"
    return f"{reference:.4g} at the reference step ({agrees})"


def save_png(fig, path, dpi=100, colors=128):
    """Save a figure as a palette PNG (a fraction of the size, no visible loss) and close it."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    buffer = io.BytesIO()
    fig.savefig(buffer, dpi=dpi)
    plt.close(fig)
    Image.open(buffer).convert("RGB").quantize(colors=colors).save(path, optimize=True)
    print(f"wrote {path}")
    return path
