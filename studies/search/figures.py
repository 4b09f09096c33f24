"""The search comparison's figures and the locomotion modes of its class bests (docs/search.md).

Everything comes from the runs kept in ``studies/search/kept/`` (compare.py); nothing is evolved.

``--modes`` classifies every morphology class's best of every kept run (its ``class_bests.json``:
protrusions 0, 1, 2, 3 or more, and "symmetric pair") with the classifier's stroke path,
``animat.classify_locomotion(genome, config, stroke=True)``, next to the earlier rules
(``stroke=False``, the column ``default_label``; ``studies/regime/stroke_modes.py``'s ``classify_best``):
each best is developed and swum once with its run's config, deterministically (about 50 s for the 210
bests, one thread). It writes
``studies/search/results/class_modes.csv``, one row per run and class.

Then, from ``kept/*/archive.csv``, ``kept/*/history.csv``, ``results/summary.csv`` and
``results/class_modes.csv`` only (seconds), it draws into ``--images`` (default docs/images) small
palette PNGs:

- ``search_archives.png``: per environment (rows) and algorithm (columns), the archive grid (elongation ×
  protrusions): each cell's best fitness over the seeds' final archives, and in how many seeds it is
  filled;
- ``search_class_bests.png``: per environment, each class's best fitness in every run by algorithm,
  the marker giving the best's main locomotion mode by the stroke path;
- ``search_history.png``: QD-score and coverage against swims, every run;

and prints the markdown tables of docs/search.md (modes of the class bests per environment and
algorithm; which class holds each run's best)::

    OMP_NUM_THREADS=1 PYTHONPATH=build/python .venv/bin/python studies/search/figures.py --modes
    PYTHONPATH=build/python .venv/bin/python studies/search/figures.py
"""

from __future__ import annotations

import argparse
import csv
import io
import math
import statistics
import sys
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(ROOT / "studies" / "replication"))
sys.path.insert(0, str(ROOT / "studies" / "regime"))
sys.path.insert(0, str(HERE))
import compare  # noqa: E402
import stroke_modes as SM  # noqa: E402

KEPT = compare.RUNS
RESULTS = compare.RESULTS
MODES_CSV = RESULTS / "class_modes.csv"
ENVS = ("dn0.5", "dn2", "dn10", "dn0.2_64cells")
ENV_TITLE = {
    "dn0.5": "d_N = 0.5",
    "dn2": "d_N = 2",
    "dn10": "d_N = 10",
    "dn0.2_64cells": "d_N = 0.2, 64 cells",
}
ALGORITHMS = compare.ALGORITHMS
ALGO_TITLE = {"ga": "paper's GA", "protected": "protected GA", "map_elites": "MAP-Elites"}
ALGO_COLOR = {"ga": "#1f77b4", "protected": "#d62728", "map_elites": "#2ca02c"}
CLASSES = compare.CLASSES
CLASS_SHORT = {
    "0 protrusions": "0",
    "1 protrusion": "1",
    "2 protrusions": "2",
    "3+ protrusions": "3+",
    "symmetric pair": "pair",
}
#: Main modes of the stroke path, with their markers in search_class_bests.png.
MODE_MARKER = {
    "undulation": "o",
    "synchronous contraction": "s",
    "protrusions": "^",
    "tail": "D",
    "other": "x",
    "none": ".",
}
#: The archive grid of compare.py: elongation 1-4 in 6 bins (rows), protrusions 0-7 (columns).
ELONGATION_BINS, PROTRUSION_BINS = 6, 8


def run_name(folder: Path) -> Dict[str, Any]:
    """environment, algorithm and seed of a kept run's folder name (as compare.py's summary)."""
    env, rest = folder.name.split("_", 1)
    if rest.startswith("64cells_"):
        env, rest = f"{env}_64cells", rest[len("64cells_") :]
    algorithm, seed = rest.rsplit("_seed", 1)
    return {"environment": env, "algorithm": algorithm, "seed": int(seed)}


def kept_runs() -> List[Path]:
    return sorted(d for d in KEPT.iterdir() if (d / "archive.csv").is_file()) if KEPT.is_dir() else []


def _order(r: Dict[str, Any]) -> tuple:
    env = r["environment"]
    return (ENVS.index(env) if env in ENVS else len(ENVS), env, ALGORITHMS.index(r["algorithm"]), int(r["seed"]))


# --- modes ------------------------------------------------------------------------------------------------


def classify_runs(runs: Sequence[Path]) -> List[Dict[str, Any]]:
    """One row per kept run and class: the class best's fitness, its dt/16 reference, whether it is the
    run's best, its default and stroke labels and the stroke path's numbers."""
    rows = []
    for k, folder in enumerate(runs):
        bests = SM.search_class_bests(folder)
        top = max(sorted(bests), key=lambda c: bests[c].fitness)
        for c in CLASSES:
            if c not in bests:
                continue
            m = SM.classify_best(bests[c])
            rows.append(
                {
                    **run_name(folder),
                    "class": c,
                    "fitness": m["fitness"],
                    "run_best": int(c == top),
                    "default_label": m["default_label"],
                    "stroke_label": m["stroke_label"],
                    "stroke_mode": m["stroke_mode"],
                    "pair_score": m["pair_score"],
                    "pair_area": m["pair_area"],
                    "strokes": m["strokes"],
                    "protrusions_found": m["protrusions"],
                    "pairs": m["pairs"],
                    "travelling_index": m["travelling_index"],
                    "bend_p": m["bend_p"],
                }
            )
            print(f"[{k + 1}/{len(runs)}] {folder.name} {c}: {m['stroke_label']}", file=sys.stderr, flush=True)
    rows.sort(key=lambda r: (*_order(r), CLASSES.index(r["class"])))
    return rows


def read_csv(path: Path) -> List[Dict[str, str]]:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


# --- figures ----------------------------------------------------------------------------------------------


def save_png(fig, path: Path, dpi: int = 100, colors: int = 64) -> None:
    """Save and close a figure as a palette PNG (docs/images stays small: tests/python/test_docs_images.py)."""
    from PIL import Image

    buf = io.BytesIO()
    fig.savefig(buf, dpi=dpi, format="png")
    plt.close(fig)
    buf.seek(0)
    path.parent.mkdir(parents=True, exist_ok=True)
    with Image.open(buf) as im:
        im.convert("RGB").quantize(colors=colors, method=Image.Quantize.MEDIANCUT).save(path, optimize=True)
    print(f"wrote {path} ({path.stat().st_size / 1e3:.0f} kB)", file=sys.stderr)


def archive_grid(folder: Path) -> np.ndarray:
    """The final archive of a kept run as an (elongation bins, protrusion bins) array of fitness (NaN:
    empty cell); the cell index is row-major over (elongation, protrusions) as in animat.qd.GridArchive."""
    grid = np.full((ELONGATION_BINS, PROTRUSION_BINS), np.nan)
    for r in read_csv(folder / "archive.csv"):
        i, j = divmod(int(r["index"]), PROTRUSION_BINS)
        grid[i, j] = float(r["objective"])
    return grid


def draw_archives(runs: Sequence[Path], path: Path) -> None:
    """Per environment (rows) and algorithm (columns): each cell's best fitness over the seeds' final
    archives (colour, one scale per row) and the number of seeds that fill it (the digit)."""
    grids: Dict[tuple, List[np.ndarray]] = {}
    for f in runs:
        n = run_name(f)
        grids.setdefault((n["environment"], n["algorithm"]), []).append(archive_grid(f))
    envs = [e for e in ENVS if any(k[0] == e for k in grids)]
    fig, axes = plt.subplots(len(envs), len(ALGORITHMS), figsize=(8.4, 2.2 * len(envs) + 0.5), squeeze=False)
    edges = np.linspace(1.0, 4.0, ELONGATION_BINS + 1)
    images = []
    for row, env in enumerate(envs):
        stacks = {a: np.array(grids.get((env, a), [])) for a in ALGORITHMS}
        finite = [s[np.isfinite(s)] for s in stacks.values() if s.size]
        vmax = max(float(v.max()) for v in finite if v.size)
        image = None
        for col, a in enumerate(ALGORITHMS):
            ax = axes[row, col]
            s = stacks[a]
            if not s.size:
                ax.set_axis_off()
                continue
            with np.errstate(all="ignore"):
                best = np.where(
                    np.isfinite(s).any(axis=0), np.nanmax(np.where(np.isfinite(s), s, -np.inf), axis=0), np.nan
                )
            seeds = np.isfinite(s).sum(axis=0)
            image = ax.imshow(best, origin="lower", cmap="viridis", vmin=0.0, vmax=vmax, aspect="auto")
            for i in range(ELONGATION_BINS):
                for j in range(PROTRUSION_BINS):
                    if seeds[i, j]:
                        light = best[i, j] < 0.55 * vmax
                        ax.text(
                            j,
                            i,
                            str(seeds[i, j]),
                            ha="center",
                            va="center",
                            fontsize=6.5,
                            color="white" if light else "black",
                        )
            ax.set_xticks(range(PROTRUSION_BINS))
            ax.set_yticks(np.arange(ELONGATION_BINS + 1) - 0.5)
            ax.set_yticklabels([f"{e:g}" for e in edges] if col == 0 else [])
            ax.tick_params(labelsize=7, length=2)
            if row == 0:
                ax.set_title(ALGO_TITLE[a], fontsize=9)
            if row == len(envs) - 1:
                ax.set_xlabel("protrusions", fontsize=8)
            if col == 0:
                ax.set_ylabel(f"{ENV_TITLE[env]} ({len(s)} seeds)\nelongation", fontsize=8)
        images.append(image)
    fig.suptitle("Final archives: best fitness per cell over the seeds (digit: seeds that fill the cell)", fontsize=9)
    fig.subplots_adjust(left=0.09, right=0.9, top=0.94, bottom=0.06, wspace=0.06, hspace=0.22)
    for row, image in enumerate(images):
        if image is None:
            continue
        box = axes[row, -1].get_position()
        bar = fig.colorbar(image, cax=fig.add_axes((box.x1 + 0.012, box.y0, 0.012, box.height)))
        bar.set_label("best fitness", fontsize=7)
        bar.ax.tick_params(labelsize=7)
    save_png(fig, path)


def marker_of(label: str) -> tuple:
    """(marker, filled) of a stroke label in search_class_bests.png: a triangle when the protrusion stroke
    is the main mode (filled) or mixed in (open), otherwise the main mode's marker."""
    main = SM.main_mode(label)
    if main == "protrusions":
        return "^", True
    if SM.has_mode(label, "protrusions"):
        return "^", False
    return MODE_MARKER.get(main, "x"), True


def draw_class_bests(modes: Sequence[Dict[str, str]], path: Path) -> None:
    """Per environment: each class's best fitness in every run (points, one colour per algorithm, the
    marker its stroke-path mode) and the median over the seeds (bar)."""
    envs = [e for e in ENVS if any(r["environment"] == e for r in modes)]
    fig, axes = plt.subplots(2, 2, figsize=(8.4, 6.0), squeeze=False)
    width = 0.26
    for k, env in enumerate(envs):
        ax = axes.flat[k]
        for ci, c in enumerate(CLASSES):
            for ai, a in enumerate(ALGORITHMS):
                sel = [r for r in modes if r["environment"] == env and r["algorithm"] == a and r["class"] == c]
                if not sel:
                    continue
                x0 = ci + (ai - 1) * width
                ys = [float(r["fitness"]) for r in sel]
                ax.hlines(statistics.median(ys), x0 - 0.1, x0 + 0.1, color=ALGO_COLOR[a], lw=2)
                for si, r in enumerate(sel):
                    m, filled = marker_of(r["stroke_label"])
                    x = x0 + (si - (len(sel) - 1) / 2) * 0.035
                    y = float(r["fitness"])
                    if m == "x":  # an unfilled marker: its colour is the face colour
                        ax.scatter([x], [y], marker=m, s=22, c=ALGO_COLOR[a], linewidths=1.0)
                    else:
                        face = ALGO_COLOR[a] if filled else "none"
                        ax.scatter([x], [y], marker=m, s=22, facecolors=face, edgecolors=ALGO_COLOR[a], linewidths=1.0)
        ax.set_xticks(range(len(CLASSES)))
        ax.set_xticklabels([CLASS_SHORT[c] for c in CLASSES], fontsize=8)
        ax.set_title(ENV_TITLE[env], fontsize=9)
        ax.tick_params(labelsize=7)
        ax.grid(axis="y", color="0.9", lw=0.6)
        ax.set_axisbelow(True)
        if k % 2 == 0:
            ax.set_ylabel("class best fitness", fontsize=8)
        if k >= 2:
            ax.set_xlabel("protrusions of the body (class)", fontsize=8)
    for ax in axes.flat[len(envs) :]:
        ax.set_axis_off()
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color=ALGO_COLOR[a], lw=2, label=f"{ALGO_TITLE[a]} (bar: median)") for a in ALGORITHMS]
    gray = "0.35"
    handles += [
        Line2D([], [], ls="", marker="o", color=gray, label="undulation"),
        Line2D([], [], ls="", marker="s", color=gray, label="synchronous contraction"),
        Line2D([], [], ls="", marker="^", color=gray, label="protrusion stroke"),
        Line2D([], [], ls="", marker="^", color=gray, mfc="none", label="... mixed into another mode"),
        Line2D([], [], ls="", marker="D", color=gray, label="tail"),
        Line2D([], [], ls="", marker="x", color=gray, label="other"),
    ]
    fig.legend(handles=handles, loc="lower center", ncol=3, fontsize=7, frameon=False)
    fig.suptitle("Best fitness per morphology class, every run; marker: its locomotion mode (stroke path)", fontsize=9)
    fig.subplots_adjust(left=0.07, right=0.99, top=0.92, bottom=0.19, hspace=0.3, wspace=0.12)
    save_png(fig, path)


def draw_history(runs: Sequence[Path], path: Path) -> None:
    """QD-score and coverage of the passive archive against swims, every run."""
    envs = [e for e in ENVS if any(run_name(f)["environment"] == e for f in runs)]
    fig, axes = plt.subplots(2, len(envs), figsize=(8.4, 3.8), squeeze=False, sharex=True)
    for f in runs:
        n = run_name(f)
        col = envs.index(n["environment"])
        h = read_csv(f / "history.csv")
        swims = [int(r["swims"]) for r in h]
        for row, key in enumerate(("qd_score", "coverage")):
            axes[row, col].plot(swims, [float(r[key]) for r in h], color=ALGO_COLOR[n["algorithm"]], lw=0.8, alpha=0.8)
    for col, env in enumerate(envs):
        axes[0, col].set_title(ENV_TITLE[env], fontsize=9)
        axes[1, col].set_xlabel("swims", fontsize=8)
        axes[1, col].set_ylim(0, 1)
        for row in range(2):
            axes[row, col].tick_params(labelsize=7)
            axes[row, col].grid(color="0.9", lw=0.6)
    axes[0, 0].set_ylabel("QD-score", fontsize=8)
    axes[1, 0].set_ylabel("coverage", fontsize=8)
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color=ALGO_COLOR[a], lw=1.5, label=ALGO_TITLE[a]) for a in ALGORITHMS]
    fig.legend(handles=handles, loc="upper center", ncol=3, fontsize=7, frameon=False, bbox_to_anchor=(0.5, 1.0))
    fig.subplots_adjust(left=0.08, right=0.99, top=0.86, bottom=0.12, hspace=0.12, wspace=0.25)
    save_png(fig, path)


# --- tables -----------------------------------------------------------------------------------------------


def _num(x: str) -> float:
    return float(x) if x not in ("", None) else math.nan


def _groups(rows: Sequence[Dict[str, str]]) -> List[tuple]:
    keys = {(r["environment"], r["algorithm"]) for r in rows}
    return sorted(keys, key=lambda k: _order({"environment": k[0], "algorithm": k[1], "seed": 0}))


def per_seed_lines(summary: Sequence[Dict[str, str]]) -> List[str]:
    """QD-score, coverage and best of every run (seeds in order), per environment and algorithm."""
    out = [
        "| environment | algorithm | QD-score by seed | coverage by seed | best by seed |",
        "| --- | --- | --- | --- | --- |",
    ]
    for env, a in _groups(summary):
        sel = sorted(
            (r for r in summary if r["environment"] == env and r["algorithm"] == a), key=lambda r: int(r["seed"])
        )
        out.append(
            f"| {env} | {a} | "
            + " | ".join(
                ", ".join(fmt.format(_num(r[k])) for r in sel)
                for k, fmt in (("qd_score", "{:.0f}"), ("coverage", "{:.2f}"), ("best", "{:.1f}"))
            )
            + " |"
        )
    return out + [""]


def paired_lines(summary: Sequence[Dict[str, str]]) -> List[str]:
    """Per environment, seed by seed against the paper's GA of the same seed (the GA and the protected GA
    of a seed start from the same population): in how many seeds the other algorithm's value is higher."""
    cols = [("qd_score", "QD-score"), ("coverage", "coverage"), ("best", "best"), *((c, c) for c in CLASSES)]
    out = [
        "| environment | against the GA | " + " | ".join(t for _, t in cols) + " |",
        "| --- | --- | " + " | ".join("---" for _ in cols) + " |",
    ]
    by = {(r["environment"], r["algorithm"], int(r["seed"])): r for r in summary}
    for env in [e for e in ENVS if any(r["environment"] == e for r in summary)]:
        for a in ALGORITHMS[1:]:
            seeds = sorted(s for (e, al, s) in by if e == env and al == a and (e, "ga", s) in by)
            if not seeds:
                continue
            cells = []
            for key, _ in cols:
                pairs = [(_num(by[(env, a, s)][key]), _num(by[(env, "ga", s)][key])) for s in seeds]
                pairs = [p for p in pairs if not (math.isnan(p[0]) or math.isnan(p[1]))]
                cells.append(f"{sum(x > y for x, y in pairs)} of {len(pairs)}")
            out.append(f"| {env} | {ALGO_TITLE[a]} higher | " + " | ".join(cells) + " |")
    return out + [""]


def _distinct(rows: Sequence[Dict[str, str]]) -> List[Dict[str, str]]:
    """One row per body: a body that is the best of two classes (e.g. "2 protrusions" and "symmetric
    pair") counts once (same run and fitness)."""
    seen, out = set(), []
    for r in rows:
        key = (r["environment"], r["algorithm"], r["seed"], r["fitness"])
        if key not in seen:
            seen.add(key)
            out.append(r)
    return out


def _strokes(label: str) -> bool:
    return SM.has_mode(label, "protrusions")


def mode_lines(modes: Sequence[Dict[str, str]]) -> List[str]:
    """Per environment and algorithm: the stroke path's main modes of the class bests (distinct bodies),
    the bodies that use the protrusion stroke at all (main mode or mixed in), the runs that have one
    (with their seeds and classes), and the run bests that use it."""
    shown = ("undulation", "synchronous contraction", "protrusions")
    out = [
        "| environment | algorithm | class bests (bodies) | "
        + " | ".join(shown)
        + " | other, tail | bodies using the stroke | runs with one (seed: classes)"
        + " | run bests using it (seed: fitness) |",
        "| --- | --- | --- | " + " | ".join("---" for _ in shown) + " | --- | --- | --- | --- |",
    ]
    for env, a in _groups(modes):
        sel = [r for r in modes if r["environment"] == env and r["algorithm"] == a]
        bodies = _distinct(sel)
        main = [SM.main_mode(r["stroke_label"]) for r in bodies]
        counts = [str(main.count(m)) for m in shown]
        rest = sum(m not in shown for m in main)
        where: Dict[int, List[str]] = {}
        for r in sel:
            if _strokes(r["stroke_label"]):
                where.setdefault(int(r["seed"]), []).append(CLASS_SHORT[r["class"]])
        seeds = {int(r["seed"]) for r in sel}
        desc = "; ".join(f"{s}: {', '.join(c)}" for s, c in sorted(where.items()))
        tops = [r for r in bodies if r["run_best"] == "1"]
        top = [r for r in tops if _strokes(r["stroke_label"])]
        top_desc = "; ".join(
            f"{r['seed']}: {float(r['fitness']):.1f}"
            + (", main mode" if SM.main_mode(r["stroke_label"]) == "protrusions" else ", mixed")
            for r in top
        )
        out.append(
            f"| {env} | {a} | {len(bodies)} | "
            + " | ".join(counts)
            + f" | {rest} | {sum(_strokes(r['stroke_label']) for r in bodies)}"
            + f" | {len(where)} of {len(seeds)}"
            + (f" ({desc})" if desc else "")
            + f" | {len(top)} of {len(tops)}"
            + (f" ({top_desc})" if top_desc else "")
            + " |"
        )
    return out + [""]


def stroke_test_lines(modes: Sequence[Dict[str, str]]) -> List[str]:
    """Fisher's exact tests (studies/replication/replication_stats.py) on the runs, the independent units:
    whether a run has a class best that uses the protrusion stroke (main or mixed), against drag over the
    three 32-cell environments (all algorithms pooled, and the protected GA alone) and against the
    algorithm at d_N = 0.5."""
    import replication_stats as RS

    has: Dict[tuple, bool] = {}
    for r in modes:
        key = (r["environment"], r["algorithm"], int(r["seed"]))
        has[key] = has.get(key, False) or _strokes(r["stroke_label"])

    def test(title: str, groups: Dict[str, List[bool]]) -> str:
        table = [[sum(v) for v in groups.values()], [len(v) - sum(v) for v in groups.values()]]
        res = RS.fisher_exact(table)
        counts = ", ".join(f"{g} {sum(v)} of {len(v)}" for g, v in groups.items())
        return f"- {title}: {counts}; Fisher's exact test p = {res.p_value:.2g}."

    drags = ("dn0.5", "dn2", "dn10")
    out = ["Runs with a class best that uses the protrusion stroke (main mode or mixed in):", ""]
    out.append(test("by drag, all algorithms", {e: [v for k, v in has.items() if k[0] == e] for e in drags}))
    out.append(
        test(
            "by drag, the protected GA",
            {e: [v for k, v in has.items() if k[0] == e and k[1] == "protected"] for e in drags},
        )
    )
    out.append(
        test(
            "at d_N = 0.5, by algorithm",
            {a: [v for k, v in has.items() if k[0] == "dn0.5" and k[1] == a] for a in ALGORITHMS},
        )
    )
    return out + [""]


def run_best_class_lines(summary: Sequence[Dict[str, str]]) -> List[str]:
    """Which protrusion class holds each run's best (the class whose best equals the run's best)."""
    plain = CLASSES[:4]
    out = [
        "| environment | algorithm | " + " | ".join(plain) + " | of which with a symmetric pair |",
        "| --- | --- | " + " | ".join("---" for _ in plain) + " | --- |",
    ]
    for env, a in _groups(summary):
        sel = [r for r in summary if r["environment"] == env and r["algorithm"] == a]
        counts = dict.fromkeys(plain, 0)
        pair = 0
        for r in sel:
            holder = max(plain, key=lambda c, r=r: _num(r[c]) if r[c] else -math.inf)
            counts[holder] += 1
            pair += r["symmetric pair"] != "" and _num(r["symmetric pair"]) == _num(r[holder])
        out.append(f"| {env} | {a} | " + " | ".join(str(counts[c]) for c in plain) + f" | {pair} |")
    return out + [""]


def main(argv: Optional[Sequence[str]] = None) -> int:
    p = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    p.add_argument("--modes", action="store_true", help=f"classify every class best first (writes {MODES_CSV})")
    p.add_argument("--images", type=Path, default=ROOT / "docs" / "images", help="where the PNGs go")
    args = p.parse_args(argv)
    runs = kept_runs()
    if not runs:
        print(f"no runs in {KEPT}", file=sys.stderr)
        return 1
    if args.modes:
        SM.write_csv(classify_runs(runs), MODES_CSV)
        print(f"wrote {MODES_CSV}", file=sys.stderr)
    if not MODES_CSV.is_file():
        print(f"{MODES_CSV} is missing: run with --modes first", file=sys.stderr)
        return 1
    summary = read_csv(RESULTS / "summary.csv")
    modes = read_csv(MODES_CSV)
    draw_archives(runs, args.images / "search_archives.png")
    draw_class_bests(modes, args.images / "search_class_bests.png")
    draw_history(runs, args.images / "search_history.png")
    lines = ["### Per seed", ""] + per_seed_lines(summary)
    lines += ["### Seed by seed against the paper's GA", ""] + paired_lines(summary)
    lines += ["### The class that holds each run's best", ""] + run_best_class_lines(summary)
    lines += ["### Locomotion modes of the class bests (stroke path)", ""] + mode_lines(modes)
    lines += stroke_test_lines(modes)
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
