#!/usr/bin/env python3
"""Write docs/replication.md from the replication study kept in data/replication.

    PYTHONPATH=build/python .venv/bin/python studies/replication/replication_report.py \\
        --data data/replication --doc docs/replication.md --causes data/replication_causes

(``--runs DIR`` reads unpacked run directories instead, e.g. runs/replication while replication.sh
runs; ``--causes data/replication_causes`` adds the section of controlled runs.) First the
classifier's calibration on hand-built swimmers of known mode (the confusion matrices of its stroke
path on the calibration and held-out sets of studies/locomotion/known_swimmers.py, swum here as
studies/locomotion/confusion.py swims them), then the statistics (mode counts against the paper's
with Fisher's exact test of whether the mode depends on the drag, best fitness with bootstrap
intervals, generations to the last morphology change and to the last new best, reference fitness of
every best), then for
every environment directory (dn0.5, dn2, dn10, dn0.2_64cells, then any other) and every run_<i> in
it, finished or still running: the best-fitness curves (paper Figs. 8-9), the motion cycle (Figs.
4-6), phase map (Fig. 7) and GIF of the environment's best run, the paper's claims about the best
individuals measured (animat.locomotion), the locomotion mode of every best against the paper's
counts, and the scale of the runs. Nothing is evolved: the bests are only developed and replayed
(one 4000-step swim each) and the hand-built swimmers swum (about 500 swims of 2000 steps), so it
takes a few minutes. The output depends only on the run directories (no dates, no timings of this
script).

Figures (studies/replication/README.md, "Figures"): the page embeds only what ``--images`` (default
docs/images/replication, kept in git) receives, small: per environment the fitness plot and the best
run's motion cycle, phase map and GIF, under fixed names (``<env>_fitness.png``,
``<env>_best_motion.png``, ``<env>_best_phase.png``, ``<env>_best.gif``), so a study round rewrites
the same 16 files instead of adding new ones. ``--all-figures`` also draws every run's motion cycle,
phase map and GIF at full size into ``--figures`` (default studies/replication/figures, ignored by
git), rebuilt on demand.
"""

from __future__ import annotations

import argparse
import io
import json
import os
import statistics
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Dict, List, Optional, Tuple

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import animat  # noqa: E402
from animat import locomotion as L  # noqa: E402
from animat import protrusion as P  # noqa: E402

# Study modules: this folder's own, and the hand-built swimmers of studies/locomotion.
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "locomotion"))
# confusion: the sets and classes of the stroke path's confusion matrices (docs/locomotion.md).
import confusion as CF  # noqa: E402

import known_swimmers as KS  # noqa: E402
import replication_stats as RS  # noqa: E402
import replication_store  # noqa: E402

ENV_ORDER = ["dn0.5", "dn2", "dn10", "dn0.2_64cells"]
PAPER_RUNS = 10
PAPER_GENERATIONS = "about 5,000 (rarely above 10,000)"

# What the paper reports per environment (§6), quoted.
PAPER_MODES: Dict[str, Dict[str, str]] = {
    "dn0.5": {
        "undulation": '0 ("rarely if at all": only 1 mixed strategy with limited undulation)',
        "synchronous contraction": "1",
        "protrusions": "9 (1 of them mixed with some undulation)",
        "other": "—",
    },
    "dn2": {
        "undulation": "4 (3 of them mixed with other strategies)",
        "synchronous contraction": "6 (1 of them with undulation)",
        "protrusions": "2 (only mixed with undulation)",
        "other": "—",
    },
    "dn10": {
        "undulation": '5 ("half", including the two best solutions overall)',
        "synchronous contraction": "2",
        "protrusions": '4 (strategy "less clear"; 1 mixed with undulation)',
        "other": "—",
    },
    "dn0.2_64cells": {
        "undulation": "not reported",
        "synchronous contraction": "not reported",
        "protrusions": '9 (1 of them mixed with a "tail")',
        "tail": '1 (a "tail" only; 1 more mixed a tail into protrusions)',
        "other": "—",
    },
}
PAPER_QUOTES = {
    "dn0.5": '"animats often evolved protrusions ("appendages"; in nine out of 10 runs with d_N = 0.5, in one '
    'of these nine the best strategy was mixed with some undulation)"; synchronous contraction '
    '"emerged in all environmental settings (d_N = 0.5: one out of 10 ...)"; undulation appeared '
    '"rarely if at all when the drag was low (d_N = 0.5; only one mixed strategy involved limited '
    'undulation)".',
    "dn2": '"when d_N = 2, four out of 10 used undulation, three mixed it with other strategies"; synchronous '
    'contraction "was the most successful when drag coefficients were moderate (d_N = 2: six best '
    'individuals in 10 independent runs, one of them with undulation)"; "protrusions appeared, but only '
    'in strategies mixed with undulation (d_N = 2: in two out of 10)".',
    "dn10": '"In 10 independent runs with a high drag coefficient (d_N = 10), half of the best individuals in 10 '
    'independent runs, including the two best solutions overall, moved by undulation"; synchronous '
    'contraction "d_N = 10: two out of 10"; "protrusions also appeared (in four out of 10), but the '
    'movement strategy was less clear or (in one of these four best individuals) mixed with undulation".',
    "dn0.2_64cells": '"Much more clearly defined protrusions, consisting of multiple cells (Fig. 6b), emerged when '
    "the cell limit was increased to 64 cells and the drag was put at an even lower value "
    "(d_N = 0.2; under these conditions nine out of 10 best individuals used protrusions, but one "
    'had a mixed strategy, using a "tail", the remaining one used only the "tail")".',
}
MODE_COLUMNS = ["undulation", "synchronous contraction", "protrusions", "tail", "other", "none"]
#: The paper's main counts per environment (of 10 runs), mixed strategies under their main mode where the
#: paper says which; used only for the side-by-side count table (its words are in PAPER_MODES).
PAPER_COUNTS: Dict[str, Dict[str, Optional[int]]] = {
    "dn0.5": {"undulation": 0, "synchronous contraction": 1, "protrusions": 9, "tail": 0},
    "dn2": {"undulation": 4, "synchronous contraction": 6, "protrusions": None, "tail": 0},
    "dn10": {"undulation": 5, "synchronous contraction": 2, "protrusions": 4, "tail": 0},
    "dn0.2_64cells": {"undulation": None, "synchronous contraction": None, "protrusions": 9, "tail": 1},
}
CALIBRATION_DRAGS = (0.5, 2.0)
CALIBRATION_STEPS = 2000
#: The hand-built sets (names of studies/locomotion/confusion.py) that calibrated the stroke path, and the
#: one held out to test it, run once (docs/locomotion.md).
CALIBRATION_SETS = ("calibration", "held-out", "third", "fourth", "fifth", "sixth", "seventh")
HELD_OUT_SETS = ("eighth",)


@dataclass(frozen=True)
class FigureStyle:
    """How the per-run figures are drawn."""

    gif_size: Tuple[int, int]  # (width, height) in pixels
    gif_frames: int  # at most this many frames (8 per period: the last gif_frames / 8 periods)
    png_colors: Optional[int]  # palette PNG of at most this many colours; None: matplotlib's RGBA


#: The figures the page embeds, kept in git under docs/images/replication: palette PNGs (a quarter of
#: matplotlib's RGBA size, no visible loss on these flat drawings) and a short, small GIF (5 periods,
#: 100-135 KB). tests/python/test_docs_images.py holds docs/images to its size budget.
PAGE_STYLE = FigureStyle(gif_size=(256, 160), gif_frames=40, png_colors=128)
#: Every run's figures (--all-figures), rebuilt on demand into the ignored studies/replication/figures.
FULL_STYLE = FigureStyle(gif_size=(320, 200), gif_frames=60, png_colors=None)
#: Where --all-figures writes by default: ignored by git (.gitignore).
FIGURES_DIR = Path(__file__).resolve().parent / "figures"
REPO_ROOT = Path(__file__).resolve().parents[2]

# Verdict thresholds for the claims (the classification thresholds live in animat.locomotion).
GROW_MAXIMAL = 0.9  # realised grow level >= 0.9 of the maximum counts as "maximal"
AMPLITUDE_NEAR_MAX = 0.9  # mean amplitude >= 90 % of amplitude_max counts as "near maximum"


@dataclass
class RunReport:
    env: str
    index: int
    path: Path
    seed: int
    generations: int  # last completed generation (0-based), -1 if none yet
    wall_seconds: float
    evaluations: int
    stop: str
    history: np.ndarray
    best: Optional[animat.LineageEntry] = None
    lineage_size: int = 0
    changes: List[int] = field(default_factory=list)
    stats: Optional[L.BestStatistics] = None
    tries: float = float("nan")
    mode: Optional[L.LocomotionMode] = None
    paddling: Optional[L.Paddling] = None
    replay_distance: float = float("nan")
    images: Dict[str, str] = field(default_factory=dict)  # the page's figures (set for the best run only)
    trajectory: Optional[animat.Trajectory] = None  # the best's swim, kept until its figures are drawn

    @property
    def reference(self) -> float:
        """The best's fitness at the exploit guard's reference step (lineage field reference_fitness)."""
        return self.best.reference_fitness if self.best is not None else float("nan")

    @property
    def history_reference(self) -> float:
        """The last history row's best_reference (the same individual's, as recorded per generation)."""
        h = self.history
        return float(h["best_reference"][-1]) if len(h) and "best_reference" in h.dtype.names else float("nan")


@dataclass
class EnvReport:
    name: str
    path: Path
    config: animat.Config
    runs: List[RunReport]
    finished: bool
    images: Dict[str, str] = field(default_factory=dict)
    not_started: List[int] = field(default_factory=list)

    @property
    def best_run(self) -> Optional[RunReport]:
        """The run whose best has the highest fitness (the first of equals): its figures are on the page."""
        rs = [r for r in self.runs if r.best is not None]
        return max(rs, key=lambda r: r.best.fitness) if rs else None

    @property
    def drag_normal(self) -> float:
        return float(self.config["scene.drag_normal"])

    @property
    def drag_tangential(self) -> float:
        dt = float(self.config["scene.drag_tangential"])
        return self.drag_normal / 200 if dt < 0 else dt

    @property
    def max_cells(self) -> int:
        return int(self.config["development.max_cells"])

    @property
    def title(self) -> str:
        return f"d_N = {self.drag_normal:g}, {self.max_cells} cells"


# --- reading ----------------------------------------------------------------------------------------------


def _retry(fn, what: str, tries: int = 4):
    """Files of a running run can be caught half-written: read again a moment later."""
    for k in range(tries):
        try:
            return fn()
        except ValueError:
            if k == tries - 1:
                raise
            print(f"  {what}: being written, reading again", file=sys.stderr)
            time.sleep(1.0)


def read_env(path: Path) -> Optional[EnvReport]:
    run_dirs = sorted(
        (p for p in path.glob("run_*") if p.is_dir() and p.name[4:].isdigit()), key=lambda p: int(p.name[4:])
    )
    run_dirs = [p for p in run_dirs if (p / "config.toml").is_file()]
    if not run_dirs:
        return None
    summary = {}
    if (path / "summary.json").is_file():
        data = json.loads((path / "summary.json").read_text())
        summary = {int(r["index"]): r for r in data.get("runs", [])}
    runs = []
    for p in run_dirs:
        run = animat.Run(p)
        i = int(p.name[4:])
        h = _retry(lambda: run.history, f"{p}/history.csv")  # noqa: B023 (called at once)
        cfg = run.config
        rec = summary.get(i)
        status = json.loads((p / "status.json").read_text()) if (p / "status.json").is_file() else {}
        stop = rec["stop_reason"] if rec else status.get("stop_reason", "in progress")
        runs.append(
            RunReport(
                env=path.name,
                index=i,
                path=p,
                seed=int(cfg["evolution.seed"]),
                generations=int(h["generation"][-1]) if len(h) else -1,
                wall_seconds=float(h["wall_seconds"][-1]) if len(h) else 0.0,
                evaluations=int(h["evaluations"][-1]) if len(h) else 0,
                stop=stop,
                history=h,
            )
        )
    config = animat.Run(run_dirs[0]).config
    finished = all(r.stop not in ("in progress", "interrupted") and not r.stop.startswith("wall-clock") for r in runs)
    return EnvReport(path.name, path, config, runs, finished=finished)


# --- per-run analysis -------------------------------------------------------------------------------------

#: New bests within this many generations of the last one reached count as recent (a run still refining).
RECENT_GENERATIONS = 100


def new_best_generations(history: np.ndarray) -> List[int]:
    """The generations whose best fitness (history column ``best``, the fitness the tournaments compare)
    exceeds that of every earlier generation: the improvements the stall rule counts."""
    if len(history) == 0:
        return []
    f = np.asarray(history["best"], dtype=float)
    gens = np.asarray(history["generation"], dtype=int)
    out, top = [], f[0]
    for g, v in zip(gens[1:], f[1:]):
        if v > top:
            out.append(int(g))
            top = v
    return out


def analyse_run(r: RunReport) -> None:
    """Develop and replay the run's best and measure it; the swim stays in ``r.trajectory`` for the figures."""
    run = animat.Run(r.path)
    cfg = run.config
    lineage = _retry(lambda: run.best_genomes, f"{r.path}/best")
    r.lineage_size = len(lineage)
    r.tries = L.tries_per_viable(r.history, int(cfg["evolution.population"])) if len(r.history) else float("nan")
    if not lineage:
        return
    r.best = lineage[-1]
    r.changes = [e.generation for e in L.morphology_changes(lineage, cfg)]
    r.stats = L.best_statistics(r.best, cfg)
    tr = animat.replay(r.best, cfg)
    r.replay_distance = tr.distance
    r.mode = L.classify_locomotion(tr)
    r.paddling = L.paddling(tr, r.mode)
    r.trajectory = tr


def save_figure(fig, path: Path, dpi: int, colors: Optional[int]) -> None:
    """Save and close a matplotlib figure; with ``colors``, as a palette PNG of at most that many colours."""
    if colors is None:
        fig.savefig(path, dpi=dpi)
    else:
        from PIL import Image

        buf = io.BytesIO()
        fig.savefig(buf, dpi=dpi, format="png")
        buf.seek(0)
        with Image.open(buf) as im:
            im.convert("RGB").quantize(colors=colors, method=Image.Quantize.MEDIANCUT).save(path, optimize=True)
    plt.close(fig)


def run_figures(r: RunReport, out: Path, stem: str, style: FigureStyle, gif: bool) -> Dict[str, str]:
    """Draw a run's motion cycle, phase map and (with ``gif``) GIF into ``out`` as ``<stem>_motion.png``,
    ``<stem>_phase.png`` and ``<stem>.gif``; returns their names by kind."""
    tr = r.trajectory
    label = f"{r.env} run {r.index}: best of generation {r.best.generation}, fitness {r.best.fitness:.2f}"
    names = {"motion": f"{stem}_motion.png", "phase": f"{stem}_phase.png"}
    fig = animat.plot.motion_cycle(tr, count=6, title=f"Motion cycle (paper Figs. 4-6), {label}; mode: {r.mode.label}")
    save_figure(fig, out / names["motion"], 72, style.png_colors)

    ph = np.asarray(tr.body.phase)
    fig = animat.plot.phase_map(
        tr.body,
        title=f"{r.env} run {r.index}: phase shifts (Fig. 7)\nmax φ = {ph.max():.2f} rad"
        + (" (all equal)" if np.ptp(ph) == 0 else f", min {ph.min():.2f} rad"),
    )
    save_figure(fig, out / names["phase"], 72, style.png_colors)

    if gif:
        names["gif"] = f"{stem}.gif"
        animat.animate(
            tr, out / names["gif"], fps=16, max_frames=style.gif_frames, size=style.gif_size, colors=16, progress=False
        )
    return names


def fitness_figure(env: EnvReport, images: Path, png_colors: Optional[int] = PAGE_STYLE.png_colors) -> str:
    fig, ax = plt.subplots(figsize=(8.0, 4.2))
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for k, r in enumerate(env.runs):
        c = colors[k % len(colors)]
        h = r.history
        if not len(h):
            continue
        ax.plot(
            h["generation"], h["best"], drawstyle="steps-post", color=c, lw=1.6, label=f"run {r.index} (seed {r.seed})"
        )
        ax.plot(h["generation"], h["mean"], color=c, lw=0.7, alpha=0.5)
        if r.changes:
            best_at = {int(g): float(b) for g, b in zip(h["generation"], h["best"])}
            gs = [g for g in r.changes if g in best_at]
            ax.plot(gs, [best_at[g] for g in gs], "D", ms=5, mfc=c, mec="k", mew=0.6)
    ax.plot([], [], "D", ms=5, mfc="white", mec="k", mew=0.6, label="morphology of the best changed")
    ax.plot([], [], color="#777777", lw=0.7, label="mean fitness (viable), thin")
    ax.set_xlabel("generation")
    ax.set_ylabel("best fitness (distance travelled in 4000 steps)")
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.25)
    ax.legend(fontsize=8, loc="upper left")
    ax.set_title(
        f"Best fitness per generation (paper Figs. 8-9): {env.title}, d_T = {env.drag_tangential:g}", fontsize=10
    )
    fig.tight_layout()
    name = f"{env.name}_fitness.png"
    save_figure(fig, images / name, 80, png_colors)
    return name


# --- text helpers ----------------------------------------------------------------------------------------


def fmt_range(values: List[float], digits: int = 2) -> str:
    vals = [v for v in values if v == v]
    if not vals:
        return "—"
    lo, hi = min(vals), max(vals)
    return f"{lo:.{digits}f}" if abs(hi - lo) < 0.5 * 10**-digits else f"{lo:.{digits}f}–{hi:.{digits}f}"


def hours(seconds: float) -> str:
    return f"{seconds / 3600:.2f} h"


def count_word(k: int, n: int) -> str:
    return "all" if k == n and n > 1 else ("none" if k == 0 else f"{k} of {n}")


def env_claims(env: EnvReport) -> Dict[str, Dict[str, str]]:
    """Per claim: our numbers and a verdict sentence generated from them."""
    rs = [r for r in env.runs if r.stats is not None]
    n = len(rs)
    out: Dict[str, Dict[str, str]] = {}
    if not n:
        return out
    full = [r for r in rs if r.stats.cells == r.stats.max_cells]
    out["cells"] = {
        "ours": ", ".join(str(r.stats.cells) for r in rs) + f" (max {env.max_cells})",
        "verdict": (
            "agrees: every best has the maximum number of cells"
            if len(full) == n
            else f"differs: {n - len(full)} of {n} bests have fewer than {env.max_cells} cells "
            f"({', '.join(f'run {r.index}: {r.stats.cells}' for r in rs if r not in full)})"
        ),
    }
    realized = [r.stats.grow.realized for r in rs]
    final = [r.stats.grow.final_mean for r in rs]
    maximal = [r for r in rs if r.stats.grow.realized >= GROW_MAXIMAL]
    out["grow"] = {
        "ours": f"at divisions {fmt_range(realized)}; final {fmt_range(final)}",
        "verdict": (
            "agrees: every best grows its cells at ≥ 90 % of the maximum"
            if len(maximal) == n
            else f"differs: {count_word(n - len(maximal), n)} best{'s' if n - len(maximal) != 1 else ''} "
            f"grow{'s' if n - len(maximal) == 1 else ''} cells at less than 90 % of the maximum "
            f"(realised grow level {fmt_range([r.stats.grow.realized for r in rs if r not in maximal])})"
        ),
    }
    rel = [r.stats.oscillators.amplitude_relative for r in rs]
    rng = [r.stats.oscillators.amplitude_range for r in rs]
    near = [r for r in rs if r.stats.oscillators.amplitude_relative >= AMPLITUDE_NEAR_MAX]
    diff = [r for r in rs if r.stats.oscillators.amplitude_differentiated]
    parts = []
    parts.append(
        "near maximum in all" if len(near) == n else f"below 90 % of the maximum in {count_word(n - len(near), n)}"
    )
    parts.append("differentiated in none" if not diff else f"differentiated in {count_word(len(diff), n)}")
    agrees = len(near) == n and not diff
    out["amplitude"] = {
        "ours": f"mean {fmt_range(rel)} of max; spread (max−min) {fmt_range(rng)} of max",
        "verdict": ("agrees: " if agrees else "differs: ") + ", ".join(parts),
    }
    fdiff = [r for r in rs if r.stats.oscillators.frequency_differentiated]
    out["frequency"] = {
        "ours": "spread "
        + fmt_range([r.stats.oscillators.frequency_max - r.stats.oscillators.frequency_min for r in rs], 3)
        + " rad/time",
        "verdict": (
            "agrees: not differentiated in any best"
            if not fdiff
            else f"{'differs' if len(fdiff) > n / 2 else 'mostly agrees'}: differentiated in "
            f"{count_word(len(fdiff), n)}"
        ),
    }
    pr = [r.stats.oscillators.phase.range for r in rs]
    pdiff = [r for r in rs if r.stats.oscillators.phase.differentiated]
    same = n - len(pdiff)
    out["phase"] = {
        "ours": f"range {fmt_range(pr)} rad",
        "verdict": (
            f"agrees: differentiated (range > {L.PHASE_DIFFERENTIATED} rad) in every best"
            if not same
            else f"{'differs' if same > n / 2 else 'partly agrees'}: differentiated (range > "
            f"{L.PHASE_DIFFERENTIATED} rad) in {count_word(len(pdiff), n)}; "
            f"{'every best oscillates' if same == n else count_word(same, n) + (' bests oscillate' if same > 1 else ' best oscillates')}"
            " with all cells in phase"
        ),
    }
    tries = [r.tries for r in rs if r.tries == r.tries]
    if tries:
        lo, hi = min(tries), max(tries)
        if 200 <= lo and hi < 1000:
            v = "agrees: a few hundred"
        elif 100 <= lo and hi < 1000:
            v = "close: the same order of magnitude, at the low end (the paper: a few hundred)"
        elif hi < 100:
            v = "differs: fewer than a hundred"
        else:
            v = "differs: " + ("a thousand or more" if lo >= 1000 else "spread over orders of magnitude")
        out["tries"] = {"ours": fmt_range(tries, 1), "verdict": v}
    last = [r.changes[-1] for r in rs if r.changes]
    reached = [r.generations for r in rs]
    if last:
        late = [g for g in last if g > 500]
        out["morphology"] = {
            "ours": "generation " + ", ".join(str(g) for g in last) + f" (of {fmt_range(reached, 0)} reached)",
            "verdict": (
                (
                    f"agrees within our horizon: every last change by generation {max(last)}"
                    if not late
                    else f"differs: {count_word(len(late), len(last))} after generation 500"
                )
                + (
                    f"; our runs stopped at generation {max(reached)}, so changes after thousands of "
                    "generations (paper: rare) cannot be seen"
                    if max(reached) < 2000
                    else ""
                )
            ),
        }
    return out


CLAIMS = [
    (
        "cells",
        "Cell count of the best",
        '"the best individuals we obtained always had the maximum number of cells that was allowed" (§7)',
    ),
    (
        "grow",
        "Grow output of the best (size increase)",
        '"In almost all cases, the factor responsible for an '
        "increase of cell sizes during development was found to be "
        'expressed at the maximum level" (§6)',
    ),
    (
        "amplitude",
        "Amplitude across cells",
        '"The amplitude of oscillation almost universally evolved to be close '
        'to maximum for all cells"; "the amplitude and frequency of the '
        'oscillations is rarely differentiated between cells" (§6)',
    ),
    ("frequency", "Frequency across cells", "rarely differentiated (§6, as above)"),
    ("phase", "Phase across cells", '"the differentiation of phase did evolve" (§6)'),
    (
        "tries",
        "Random tries per viable initial individual",
        '"Typically, this required a few hundred tries for each random individual" (§5)',
    ),
    (
        "morphology",
        "Generation of the last morphological change of the best",
        '"entirely new combinations of morphology and control sweep through the population for the first hundreds '
        'of generations"; "Only rarely would the best morphology change after many thousands of generations" (§7)',
    ),
]


# --- the document ----------------------------------------------------------------------------------------


def _score(p: Optional[L.Paddling]) -> str:
    """A paddle pair score for a table: the score (bold when the swim paddles), or — without a pair."""
    if p is None or p.score != p.score:
        return "—"
    return f"**{p.score:+.2f}**" if p.paddles else f"{p.score:+.2f}"


def _count(k: int, one: str, many: str = "") -> str:
    """``k`` and the noun, singular or plural (``many``; default ``one`` + s)."""
    return f"{k} {one if k == 1 else (many or one + 's')}"


def _nan(x: float, fmt: str = ".2f") -> str:
    """A number for a table, — for nan."""
    return "—" if x != x else format(x, fmt)


def calibration_lines(results: Dict[str, List[KS.KnownResult]]) -> List[str]:
    """The classifier's confusion matrices on the hand-built swimmers (``results``: set name -> swims, as
    :data:`CALIBRATION_SETS` and :data:`HELD_OUT_SETS` name them), its misses, and the paddling test on
    the same swims."""
    out: List[str] = []
    w = out.append
    classes = list(CF.CLASSES)
    found_cols = classes + ["none", "unstable"]
    w("## Calibration: the classifier on swimmers of known mode")
    w("")
    w(
        "Before any evolved swimmer is classified, `animat.classify_locomotion` (its stroke path, see [How the "
        "locomotion mode is decided](#how-the-locomotion-mode-is-decided)) is checked on swimmers built by hand "
        "(`studies/locomotion/known_swimmers.py`, nothing evolved): cell positions on a jittered triangular "
        "lattice, every cell's amplitude, frequency and phase set directly. Undulators (a contraction wave along "
        "the body, a bending wave with the two sides in antiphase, a wave across the body), synchronous "
        "contractors (tear-drops, some with a short lag, wedges, ellipses), protrusion swimmers of the paper's "
        "kind (an elliptic core with a symmetric pair of appendages of one cell, chains of two or three cells or "
        "2 × 2 blocks, every cell actuated, the appendages driven to row), tails (a passive core with one beating "
        "tail) and standing swimmers (two halves in antiphase, or random phases). Each body is labelled by a "
        "ground truth measured from its motion, not by the classifier: the paper's stroke (`stroke_truth`) for "
        "the protrusion swimmers, a travelling wave of the cells' contraction (`undulation_truth`) for the "
        "whole-body ones; tails keep their built label. Each is swum "
        f"{CALIBRATION_STEPS} steps at d_N = "
        + " and ".join(f"{d:g}" for d in CALIBRATION_DRAGS)
        + ". The *calibration* sets ("
        + ", ".join(f"`{CF.SETS[n].__name__}`" for n in CALIBRATION_SETS)
        + ") set the stroke path's rules and thresholds; the *held-out* set ("
        + ", ".join(f"`{CF.SETS[n].__name__}`" for n in HELD_OUT_SETS)
        + ") was fixed before the classifier saw it and run once, with the target that every class reach "
        "80 %. `docs/locomotion.md` describes the sets, the ground truths and the reason for every miss; "
        "`studies/locomotion/confusion.py` prints the same matrices set by set."
    )
    w("")
    groups = [("Calibration sets", CALIBRATION_SETS), ("Held-out set", HELD_OUT_SETS)]
    for title, names in groups:
        res = [r for n in names for r in results.get(n, [])]
        if not res:
            continue
        m = KS.confusion_matrix(res, classes, found_cols)
        cols = [j for j, c in enumerate(found_cols) if c in classes or m[:, j].any()]
        rows = [i for i, c in enumerate(classes) if m[i].any()]
        per_class = [f"{c} {m[i, found_cols.index(c)]} of {m[i].sum()}" for i, c in enumerate(classes) if m[i].any()]
        bodies, drags = len({r.swimmer.name for r in res}), len({r.drag_normal for r in res})
        w(
            f"**{title}** ({_count(bodies, 'body', 'bodies')} × {_count(drags, 'drag')}, "
            f"{_count(len(res), 'swim')}): "
            + ", ".join(per_class)
            + ". Rows: label by the ground truth; columns: found."
        )
        w("")
        w("| label \\ found | " + " | ".join(found_cols[j] for j in cols) + " |")
        w("| --- | " + " | ".join("---" for _ in cols) + " |")
        for i in rows:
            w(f"| {classes[i]} | " + " | ".join(str(int(m[i, j])) for j in cols) + " |")
        w("")
    misses = [
        (n, r)
        for _, names in groups
        for n in names
        for r in sorted(results.get(n, []), key=lambda r: (r.swimmer.name, r.drag_normal))
        if not r.correct
    ]
    if misses:
        w(
            "The swims found otherwise (the stroke's best symmetric pair: its score and smaller loop area in "
            "spacings², — without a pair; the contraction wave's fit and lag; the bending wave's fit and "
            "permutation p-value; the contraction's coherence R):"
        )
        w("")
        w(
            "| set | swimmer | d_N | label | found | pair score | pair area | wave fit | lag (rad) | "
            "bending fit | bending p | R |"
        )
        w("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
        for name, r in misses:
            md = r.mode
            if md is None:
                w(f"| {name} | `{r.swimmer.name}` | {r.drag_normal:g} | {r.swimmer.expected} | unstable |" + " — |" * 7)
                continue
            st, wv, bd = md.stroke, md.wave, md.bend
            w(
                f"| {name} | `{r.swimmer.name}` | {r.drag_normal:g} | {r.swimmer.expected} | {md.label} | "
                f"{_nan(st.score if st else float('nan'), '+.2f')} | {_nan(st.area if st else float('nan'), '.3f')} | "
                f"{_nan(wv.fit if wv else float('nan'))} | {_nan(wv.lag if wv else float('nan'))} | "
                f"{_nan(bd.fit if bd else float('nan'))} | {_nan(bd.p_value if bd else float('nan'), '.3f')} | "
                f"{md.coherence:.2f} |"
            )
        w("")
    allres = [r for _, names in groups for n in names for r in results.get(n, []) if r.mode is not None]

    def paddle(kinds: Tuple[str, ...]) -> str:
        """The pair scores of the swims labelled ``kinds``: their range and how many paddle."""
        sel = [r for r in allres if r.swimmer.expected in kinds and r.paddling is not None]
        v = [r.paddling.score for r in sel if r.paddling.score == r.paddling.score]
        if not v:
            return f"no pair in any of {len(sel)} swims"
        k = sum(1 for r in sel if r.paddling.paddles)
        return (
            f"{min(v):+.2f} to {max(v):+.2f}"
            + (f" ({len(sel) - len(v)} swims without a pair)" if len(v) < len(sel) else "")
            + f", {k} of {len(sel)} paddling"
        )

    whole = ("undulation", "synchronous contraction")
    w(
        "**The paper's stroke, read more simply** (`animat.locomotion.paddling`, the column *paddle pair score* in "
        'the table of evolved bests; it decides no mode): the paper says its protrusions are "fully extended when '
        'moving backwards (generating thrust) but are contracted during their return", placed symmetrically, and in '
        '32-cell bodies "often built from one cell extending beyond the main outline". Per skin cell, over the '
        "classifier's window in the body frame: it *protrudes* when it stands at least "
        f"{L.PADDLE_SPIKE:g} median rest spring lengths above the chord of its two skin neighbours at some time (a "
        "cell standing out of a straight edge: 0.87 at rest), and it *rows* with the correlation of its distance "
        "from the centre with its backward velocity (+1: a loop traversed out, back, in, forward). The pair score is "
        "the best min(rowing) of two protruding cells on opposite sides of the axis of motion (— where there is no "
        f"such pair); a swim *paddles* from {L.PADDLE_ROWING:g}. On the hand-built swims above: undulators and "
        f"synchronous contractors {paddle(whole)}; protrusion swimmers {paddle(('protrusions',))}; tails "
        f"{paddle(('tail',))}; other {paddle(('other',))}."
    )
    w("")
    return out


def stall_rule_words(envs: List[EnvReport]) -> str:
    """What the stall rule (evolution.stall_generations, 0: none) of the environments does."""
    stalls = {e.name: int(e.config["evolution.stall_generations"]) for e in envs}
    if len(set(stalls.values())) > 1:
        return (
            "the stall rule stops a run "
            + ", ".join(f"`{n}` {k} generations" if k else f"`{n}` never" for n, k in stalls.items())
            + " after its last"
        )
    k = next(iter(stalls.values()), 0)
    return f"the stall rule stops a run {k} generations after its last" if k else "no stall rule stops the runs"


def statistics_lines(envs: List[EnvReport]) -> List[str]:
    """Mode counts next to the paper's with Fisher's exact test, best fitness with bootstrap intervals,
    generations to the last morphology change and to the last new best, reference fitness."""
    out: List[str] = []
    w = out.append
    w("## Statistics")
    w("")
    w("### Locomotion modes against the paper's counts")
    w("")
    w(
        "Main mode of every best (a mixed best counts under its main mode), ours next to the paper's (of 10 runs; "
        '"?" where the paper\'s words give no main-mode count: at d_N = 2 its 2 protrusion swimmers are mixed '
        "into undulation, at d_N = 0.2 it reports only protrusions and tails; its d_N = 10 counts overlap, 5 + 2 + 4 "
        "of 10, one best being mixed)."
    )
    w("")
    modes = [m for m in MODE_COLUMNS if m != "none"] + ["none"]
    labels = {e.name: [r.mode.mode for r in e.runs if r.mode is not None] for e in envs}
    used = [
        m
        for m in modes
        if any(m in v for v in labels.values()) or m in ("undulation", "synchronous contraction", "protrusions", "tail")
    ]
    w(
        "| mode | "
        + " | ".join(f"`{e.name}` ours (of {len(labels[e.name])}) | `{e.name}` paper (of 10)" for e in envs)
        + " |"
    )
    w("| --- | " + " | ".join("--- | ---" for _ in envs) + " |")
    for m in used:
        cells = []
        for e in envs:
            paper = PAPER_COUNTS.get(e.name, {}).get(m, 0 if m in ("other", "none") else None)
            cells.append(f"{labels[e.name].count(m)} | {'?' if paper is None else paper}")
        w(f"| {m} | " + " | ".join(cells) + " |")
    paddlers = {e.name: sum(1 for r in e.runs if r.paddling is not None and r.paddling.paddles) for e in envs}
    w(
        "| *paddles (the paper's stroke; any mode)* | "
        + " | ".join(
            f"{paddlers[e.name]} | {PAPER_COUNTS.get(e.name, {}).get('protrusions') or '?'} (protrusions)" for e in envs
        )
        + " |"
    )
    w("")
    drag_envs = [e for e in envs if e.max_cells == 32]
    count_words = {2: "two", 3: "three", 4: "four", 5: "five"}
    drag_title = (
        f"the {count_words.get(len(drag_envs), str(len(drag_envs)))} 32-cell environments "
        f"(d_N = {', '.join(f'{e.drag_normal:g}' for e in drag_envs)}: does the mode depend on the drag?)"
    )
    for title, group in (
        (drag_title, drag_envs),
        ("all environments", envs),
    ):
        if len(group) < 2:
            continue
        rows, cols, table = RS.mode_table({e.name: labels[e.name] for e in group}, modes)
        res = RS.fisher_exact(table)
        w(
            f"Fisher's exact test (Freeman–Halton, r × c) over {title}: p = {res.p_value:.3g} "
            f"({res.method}, {res.tables} tables with the observed margins; {res.shape[0]} modes × {res.shape[1]} "
            f"environments, {int(table.sum())} bests)."
        )
        w("")
    counts = sorted({len(labels[e.name]) for e in envs}) or [0]
    per_env = f"{counts[0]}" if len(counts) == 1 else f"{counts[0]}–{counts[-1]}"
    w(
        f"With {per_env} runs per environment a p-value above 0.05 says little: the test has little power. "
        "The paper's counts are quoted, not tested: its modes were judged by eye from videos."
    )
    w("")
    w("### Best fitness")
    w("")
    w(
        "Distance travelled by each environment's final bests: median and mean with percentile bootstrap 95 % "
        f"intervals (10,000 resamples, seed 0; with {per_env} runs the interval cannot reach beyond the sample's "
        "range and is narrower than its nominal level)."
    )
    w("")
    w("| environment | runs | bests | median [95 % CI] | mean [95 % CI] |")
    w("| --- | --- | --- | --- | --- |")
    for e in envs:
        fit = [r.best.fitness for r in e.runs if r.best is not None]
        if not fit:
            continue
        med = RS.bootstrap_ci(fit, lambda a: np.median(a, axis=1))
        mean = RS.bootstrap_ci(fit)
        w(
            f"| `{e.name}` | {len(fit)} | {', '.join(f'{v:.2f}' for v in fit)} | {med.estimate:.2f} "
            f"[{med.low:.2f}, {med.high:.2f}] | {mean.estimate:.2f} [{mean.low:.2f}, {mean.high:.2f}] |"
        )
    w("")
    w("### Generations to the last morphology change")
    w("")
    w("| environment | last change of the best's morphology, per run | median | generations reached |")
    w("| --- | --- | --- | --- |")
    for e in envs:
        last = [r.changes[-1] for r in e.runs if r.changes]
        if not last:
            continue
        w(
            f"| `{e.name}` | {', '.join(str(g) for g in last)} | {statistics.median(last):g} | "
            f"{fmt_range([float(r.generations) for r in e.runs], 0)} |"
        )
    w("")
    w("### Generations of the last new best")
    w("")
    w(
        "A new best is a generation whose best fitness (history column `best`, the fitness the tournaments compare) "
        "exceeds that of every earlier generation: the improvements the stall rule counts. A run still refining "
        f"sets new bests late; {stall_rule_words(envs)}."
    )
    w("")
    w(
        f"| environment | last new best, per run | new bests in each run's last {RECENT_GENERATIONS} generations | "
        f"runs with one there | generations reached |"
    )
    w("| --- | --- | --- | --- | --- |")
    for e in envs:
        news = [new_best_generations(r.history) for r in e.runs]
        recent = [sum(1 for g in n if g > r.generations - RECENT_GENERATIONS) for n, r in zip(news, e.runs)]
        w(
            f"| `{e.name}` | {', '.join(str(n[-1]) if n else '—' for n in news)} | "
            f"{', '.join(str(k) for k in recent)} | {sum(1 for k in recent if k > 0)} of {len(e.runs)} | "
            f"{fmt_range([float(r.generations) for r in e.runs], 0)} |"
        )
    w("")
    w("### Reference fitness of every best")
    w("")
    w(
        "The engine's exploit guard re-evaluates every new best at a finer reference time step "
        "(`evaluation.reference_check`); its fitness there (lineage field `reference_fitness`, history column "
        "`best_reference`) next to the evolved fitness:"
    )
    w("")
    w("| environment | run | evolved fitness | reference fitness | difference |")
    w("| --- | --- | --- | --- | --- |")
    # Each best against the guard's own rule (animat.reference_disagrees), with its environment's tolerances.
    checked, outside, tolerances = 0, [], {}
    for e in envs:
        cfg = e.config  # one config per environment (the runs differ only in their seed)
        for r in e.runs:
            if r.best is None:
                continue
            ref = r.reference if r.reference == r.reference else r.history_reference
            rel_diff = 100 * (ref - r.best.fitness) / r.best.fitness if ref == ref and r.best.fitness else None
            diff = f"{rel_diff:+.2f} %" if rel_diff is not None else "—"
            w(f"| `{e.name}` | {r.index} | {r.best.fitness:.3f} | {ref:.3f} | {diff} |")
            if ref != ref:
                continue
            checked += 1
            tolerances[e.name] = (
                float(cfg["evaluation.reference_tolerance"]),
                float(cfg["evaluation.reference_abs_tolerance"]),
            )
            if animat.reference_disagrees(r.best.fitness, ref, cfg):
                side = (
                    "farther at the finer step: the default step costs it distance"
                    if ref > r.best.fitness
                    else "**shorter at the finer step: the default step gives it distance**"
                )
                outside.append(f"`{e.name}` run {r.index} ({rel_diff:+.2f} %, {side})")
    w("")
    if checked:
        # One statement when every environment uses the same tolerances, else one per environment.
        if len(set(tolerances.values())) == 1:
            rel, absolute = next(iter(tolerances.values()))
            tol = (
                f"`evaluation.reference_tolerance` = {100 * rel:g} % and "
                f"`evaluation.reference_abs_tolerance` = {absolute:g}"
            )
        else:
            tol = (
                "the environment's `evaluation.reference_tolerance` and `evaluation.reference_abs_tolerance`: "
                + ", ".join(f"`{n}` {100 * t[0]:g} % and {t[1]:g}" for n, t in tolerances.items())
            )
        w(
            f"Within the guard's tolerance (it warns where the two differ by more than both "
            f"{tol}): "
            f"{checked - len(outside)} of {checked} bests"
            + (f"; outside it: {'; '.join(outside)}." if outside else ".")
        )
        w("")
    return out


def _shown_path(path: Path) -> str:
    """A path as the page shows it: relative to the repository when inside it."""
    full = path.resolve()
    try:
        return full.relative_to(REPO_ROOT).as_posix()
    except ValueError:
        return path.as_posix()


def _differs_from_paper(envs: List[EnvReport]) -> Dict[str, Dict[str, object]]:
    """Per environment whose configs/paper_<env>.toml exists: the keys (but the run's own: seed,
    generations, wall time, threads) in which its runs' config differs from the paper's environment,
    with their values."""
    own = {"evolution.seed", "evolution.generations", "evolution.wall_seconds", "evolution.threads"}
    out: Dict[str, Dict[str, object]] = {}
    for e in envs:
        paper = REPO_ROOT / "configs" / f"paper_{e.name}.toml"
        if not paper.is_file():
            continue
        ref = animat.load_config(str(paper))
        d = {k: e.config[k] for k in ref.keys() if k not in own and e.config[k] != ref[k]}
        if d:
            out[e.name] = d
    return out


def write_doc(
    envs: List[EnvReport],
    runs_dir: Path,
    doc: Path,
    images: Path,
    commit: str,
    discussion: Optional[Path] = None,
    calibration: Optional[Dict[str, List[KS.KnownResult]]] = None,
    data: Optional[Path] = None,
    target_runs: int = PAPER_RUNS,
    causes: Optional[List[str]] = None,
    figures: Path = FIGURES_DIR,
    causes_data: Optional[Path] = None,
) -> None:
    rel_img = Path(os.path.relpath(images, doc.parent))
    img = lambda name: f"{rel_img.as_posix()}/{name}"  # noqa: E731
    # Every run's figures are not on the page: the command that draws them, and where.
    figures_shown = _shown_path(figures)
    all_figures = "--all-figures" + ("" if figures.resolve() == FIGURES_DIR else f" --figures {figures_shown}")
    all_figures_note = (
        f"    # also every run's motion cycle, phase map and GIF, into {figures_shown}/ (not kept in git)"
    )
    all_runs = [r for e in envs for r in e.runs]
    finished = all(e.finished for e in envs)
    lines: List[str] = []
    w = lines.append
    w("# Replication of the paper's experiments")
    w("")
    source = (data or runs_dir).as_posix()
    from_discussion = (
        f" (the discussion at the end comes from {_shown_path(discussion)})"
        if discussion is not None and discussion.exists()
        else ""
    )
    w(
        f"<!-- Generated by studies/replication/replication_report.py from {source}; do not edit by hand"
        f"{from_discussion}. -->"
    )
    w("")
    w(
        "We evolved swimmers in the four environments of Joachimczak & Wróbel (GECCO 2012, §6) with the "
        "paper's genetic algorithm (population 100, elitism, tournament of two with p rising from 0.8 to 1 over "
        "1000 generations, 20 % crossover, 4000 swim steps, stop after 500 generations without improvement) "
        "and compare what emerged with what the paper reports. Every number and figure below is computed from "
        f"the runs under `{(data or runs_dir).as_posix()}/` by `studies/replication/replication_report.py`; the best "
        "swimmers are developed and replayed, nothing is evolved again."
    )
    w("")
    differs = _differs_from_paper(envs)
    if differs:
        w(
            "**Not the paper's constants:** these runs' configs differ from the paper's environments "
            "(`configs/paper_<env>.toml`) in "
            + "; ".join(f"`{e}`: " + ", ".join(f"`{k}` = {v!r}" for k, v in d.items()) for e, d in differs.items())
            + "."
        )
        w("")
    if not finished:
        w(
            f"**Status: runs still in progress.** This page was generated from partial runs; "
            f"{sum(1 for r in all_runs if r.stop == 'in progress')} of {len(all_runs)} runs had not finished."
        )
        w("")
    if data is not None:
        gens = sorted({r.generations for r in all_runs})
        caps = sorted({r.stop for r in all_runs})
        w(
            f"**Scale, exactly:** {len(all_runs)} runs: "
            + ", ".join(f"{len(e.runs)} in `{e.name}`" for e in envs)
            + f" of the {target_runs} per environment the study aims at (the paper's {PAPER_RUNS}); generations "
            f"reached: {', '.join(map(str, gens))} (the paper: about 5,000); every run stopped by: "
            f"{'; '.join(caps)}. Runs not started yet: "
            + "; ".join(f"`{e.name}` " + (", ".join(f"run {i}" for i in e.not_started) or "none") for e in envs)
            + "."
        )
        w("")
    if calibration:
        lines.extend(calibration_lines(calibration))
    lines.extend(statistics_lines(envs))

    # scale
    w("## Scale")
    w("")
    w(f"The paper: {PAPER_RUNS} independent runs per environment of {PAPER_GENERATIONS} generations. Ours:")
    w("")
    w(
        "| environment | d_N | d_T | max cells | runs | generations reached per run | wall time per run | "
        "evaluations per run | stopped by |"
    )
    w("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for e in envs:
        gens = ", ".join(str(r.generations) if r.generations >= 0 else "—" for r in e.runs)
        wall = fmt_range([r.wall_seconds / 3600 for r in e.runs]) + " h"
        ev = fmt_range([float(r.evaluations) for r in e.runs], 0)
        stops = ", ".join(sorted(set(r.stop for r in e.runs)))
        w(
            f"| `{e.name}` | {e.drag_normal:g} | {e.drag_tangential:g} | {e.max_cells} | {len(e.runs)} | {gens} | "
            f"{wall} | {ev} | {stops} |"
        )
    w("")
    total_gens = [r.generations for r in all_runs if r.generations >= 0]
    if total_gens:
        w(
            f"So we ran {len(all_runs)} runs ({len(envs)} environments × "
            f"{fmt_range([float(len(e.runs)) for e in envs], 0)}) of {min(total_gens)}–{max(total_gens)} "
            f"generations (median {statistics.median(total_gens):g}): {len(envs[0].runs) if envs else 0} of the paper's "
            f"{PAPER_RUNS} runs per environment, each {100 * statistics.median(total_gens) / 5000:.1f} % of its "
            f"typical run length (about 5,000 generations). Wall time per run is the history's wall_seconds "
            f"(machine- and load-dependent, summed over sessions). Everything the paper "
            f"observed after {max(total_gens)} generations is beyond what these runs can show."
        )
        w("")
    if data is not None:
        w(
            "To regenerate this page from the data alone, and to grow the study (resume every run, start the "
            "missing ones, pack them back into the data, rewrite this page):"
        )
        w("")
        w("```bash")
        with_causes = f" --causes {causes_data.as_posix()}" if causes_data is not None else ""
        w(
            f"PYTHONPATH=build/python .venv/bin/python studies/replication/replication_report.py --data {data.as_posix()} "
            f"--doc {doc.as_posix()}{with_causes}"
        )
        w(
            f"PYTHONPATH=build/python .venv/bin/python studies/replication/replication_report.py --data {data.as_posix()} "
            f"--doc {doc.as_posix()}{with_causes} {all_figures}{all_figures_note}"
        )
        w(
            "studies/replication/replication.sh 5400    # one session of 5400 s; cap 1000 generations or 500 without improvement"
        )
        w(
            "ANIMAT_REPLICATION_ROUND=150 studies/replication/replication.sh 5400    # the same, breadth first: rounds of 150 "
            "generations past the least advanced run"
        )
        w("```")
    else:
        w(f"Commit of the runs: `{commit}` (`{runs_dir.as_posix()}/commit.txt`). To regenerate:")
        w("")
        w("```bash")
        w("studies/replication/replication.sh 5400    # resumes every run of data/replication, 5400 s per session")
        w(
            f"PYTHONPATH=build/python .venv/bin/python studies/replication/replication_report.py --runs {runs_dir.as_posix()} "
            f"--doc {doc.as_posix()}"
        )
        w(
            f"PYTHONPATH=build/python .venv/bin/python studies/replication/replication_report.py --runs {runs_dir.as_posix()} "
            f"--doc {doc.as_posix()} {all_figures}{all_figures_note}"
        )
        w("```")
    w("")
    seeds = {e.name: [r.seed for r in e.runs] for e in envs}
    if len({tuple(v) for v in seeds.values()}) == 1 and envs:
        para = f"The seeds are {', '.join(map(str, next(iter(seeds.values()))))} in every environment."
    else:
        para = "Seeds: " + "; ".join(f"`{k}` {', '.join(map(str, v))}" for k, v in seeds.items()) + "."
    groups: Dict[tuple, List[str]] = {}
    for e in envs:
        key = tuple((r.seed, round(r.tries, 6)) for r in e.runs if r.tries == r.tries)
        if key:
            groups.setdefault(key, []).append(e.name)
    shared = [names for names in groups.values() if len(names) > 1]
    for names in shared:
        para += (
            f" The initial population depends only on the seed and the development settings, not on the drag, "
            f"so {', '.join(f'`{n}`' for n in names)} start from the same random genomes (with different "
            f"fitness) and have the same tries per viable individual."
        )
    w(para)
    w("")

    # per environment
    for e in envs:
        w(f"## {e.title} (`{e.name}`, d_T = {e.drag_tangential:g})")
        w("")
        w(f"![best fitness, {e.name}]({img(e.images['fitness'])})")
        w("")
        w(
            "| run | seed | generations | best fitness (reference) | found at generation | cells | grow (at divisions / final) | "
            "amplitude mean (spread) of max | frequency | phase range (rad) | tries per viable | "
            "last morphology change | locomotion mode |"
        )
        w("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
        for r in e.runs:
            if r.best is None:
                w(f"| {r.index} | {r.seed} | {r.generations} | — | — | — | — | — | — | — | — | — | no best yet |")
                continue
            s = r.stats
            o = s.oscillators
            freq = (
                f"{o.frequency_min:.2f}"
                if o.frequency_max - o.frequency_min < 5e-3
                else f"{o.frequency_min:.2f}–{o.frequency_max:.2f}"
            )
            w(
                f"| {r.index} | {r.seed} | {r.generations} | {r.best.fitness:.3f} ({r.reference:.3f}) | {r.best.generation} | "
                f"{s.cells}/{s.max_cells} | {s.grow.realized:.2f} / {s.grow.final_mean:.2f} | "
                f"{o.amplitude_relative:.2f} ({o.amplitude_range:.2f}) | {freq} | {o.phase.range:.2f} | "
                f"{r.tries:.1f} | {r.changes[-1] if r.changes else '—'} | {r.mode.label} |"
            )
        w("")
        mism = [r for r in e.runs if r.best is not None and abs(r.replay_distance - r.best.fitness) > 1e-6]
        if mism:
            w(
                "**Replay check failed:** "
                + "; ".join(
                    f"run {r.index} replays to {r.replay_distance:.6f}, recorded {r.best.fitness:.6f}" for r in mism
                )
                + ". The module used for this report does not reproduce the runs exactly."
            )
            w("")
        shown = e.best_run
        if shown is not None:
            w(
                f"Figures of run {shown.index}, this environment's best, follow its paragraph; the other runs' are not "
                f"kept (`{all_figures}` draws every run's, see [Scale](#scale))."
            )
            w("")
        for r in e.runs:
            if r.best is None:
                continue
            m = r.mode
            w(
                f"**Run {r.index}** (seed {r.seed}): best of generation {r.best.generation}, fitness "
                f"{r.best.fitness:.3f}, {r.stats.cells} cells. Mode: **{m.label}** — {m.reason}."
            )
            w("")
            if r is not shown or not r.images:
                continue
            if "gif" in r.images:
                w("| swimming (the end of the 4000-step swim, 8 frames per period) | phase shifts (paper Fig. 7) |")
                w("| --- | --- |")
                w(
                    f"| ![{e.name} run {r.index}]({img(r.images['gif'])}) | "
                    f"![{e.name} run {r.index} phases]({img(r.images['phase'])}) |"
                )
            else:
                w(f"![{e.name} run {r.index} phases]({img(r.images['phase'])})")
            w("")
            w(f"![{e.name} run {r.index} motion cycle]({img(r.images['motion'])})")
            w("")

    # method
    w("## How the locomotion mode is decided")
    w("")
    w(
        "`animat.classify_locomotion` (module `animat.locomotion`, with the paper's stroke from "
        "`animat.protrusion`: its *stroke path*, the default) replays the best genome for the full 4000 steps and "
        "looks at the last four periods of its dominant oscillation (at most the second half of the swim). Each "
        "frame is aligned onto the mean shape by the best rotation and translation, so only the deformation "
        "remains. For every cell it measures, at the dominant frequency, its displacement and its *contraction* "
        "(the mean relative length change of its springs — what the paper's figures colour blue and red, here "
        "measured from the motion). Then, in this order:"
    )
    w("")
    w(
        f"1. **none** if the displacement amplitude is below {L.NONE_DEFORMATION:g} of the body's RMS radius "
        "(a rigid body);"
    )
    w(
        "2. **protrusions** if the body performs the paper's stroke (Fig. 6): a symmetric pair of protrusions, "
        "cells standing out of the body's core at rest, each grown to the neighbouring cells that row with it, "
        "is extended across the direction of motion while it moves backwards and contracted on its return. Per "
        "protrusion, the amplitude-weighted correlation of that extension with the backward velocity (its "
        "*score*, +1 for the paper's loop) and the area of its cells' loops in spacings²; the pair strokes when "
        f"its smaller score is at least {P.STROKE_SCORE:g} and its smaller area at least {P.STROKE_AREA:g}. A "
        "stroking body whose contraction also travels as a wave (rule 4) is **undulation** mixed with protrusions "
        "(a slow wave makes an undulator's corners row);"
    )
    w(
        f"3. **tail** if the deformation is localised (the most mobile 20 % of the cells carry at least "
        f"{L.PROTRUSION_CONCENTRATION:g} of the displacement energy, or the most strained 20 % contract at least "
        f"{L.LOCAL_CONTRAST:g} times as much as the median cell) and either those cells form one group joined by "
        "springs or the outline has one protrusion; otherwise a localised deformation without a stroking pair is "
        "left to the rules below;"
    )
    w(
        f"4. **undulation** if the contraction phases follow a travelling wave: a circular-linear fit "
        f"φ_i ≈ φ_0 + g·x_i explains them (resultant ≥ {L.WAVE_FIT:g}), the phase lag across the body |g|·extent "
        f"is at least π/2 (a quarter period), and the contraction field is travelling rather than standing "
        f"(travelling index ≥ {L.WAVE_TI:g}: two halves in antiphase fit a gradient but do not travel); or if "
        "the body bends as a travelling wave: the strain of the springs along the body, signed by the side they "
        f"lie on, fits such a wave (resultant ≥ {L.BEND_FIT:g}, the same lag and travelling index), better than "
        f"the same springs with their positions shuffled (p ≤ {L.BEND_P:g}, {L.BEND_PERMUTATIONS} permutations), "
        f"running backward against the motion (at least {L.BEND_BACKWARD:g}° from it);"
    )
    w(
        f"5. **synchronous contraction** if the contraction phases are coherent, R = |Σ a_i e^(iφ_i)| / Σ a_i ≥ "
        f"{L.SYNC_COHERENCE:g}; also listed as mixed with an undulation that keeps R ≥ {L.SYNC_COHERENCE:g};"
    )
    w("6. **other** otherwise (no travelling wave, phases incoherent).")
    w("")
    w(
        "The wave and synchrony thresholds were set on real swims with imposed phase patterns before looking at "
        "the evolved bests (6 bodies × 3 frequencies × 3 drags per pattern): synchronous phases gave R ≥ 0.94 and "
        "lags ≤ 0.74 rad (all 54 classified synchronous contraction); phase ramps of π or 2π gave fits ≥ 0.94 and "
        "lags ≥ 2.2 rad (all 162 undulation); halves or ends in antiphase gave a travelling index ≤ 0.11 or a fit "
        "≤ 0.78 (all 108 other). The stroke, the bending wave and the tail rule were set on the calibration sets "
        "and tested on the held-out set of the calibration section above; `docs/locomotion.md` gives the rule, "
        "its calibration sets and the held-out confusion matrix. `classify_locomotion(..., stroke=False)` gives "
        "the earlier rules (protrusions from a localised deformation in two or more groups, no stroke, no bending "
        "wave), for comparison with results classified by them. Details in the module docstrings, tests in "
        "`tests/python/test_locomotion*.py` and `tests/python/test_protrusion.py`. The measured numbers of every "
        "best (the stroke's best symmetric pair: its score and smaller area, — without a pair; the bending "
        "wave's fit and p-value):"
    )
    w("")
    w(
        "| environment | run | mode | deformation | coherence R | wave fit | phase lag (rad) | travelling index | "
        "wave travels (against the motion: backward) | bending fit (p) | stroke pair score | stroke pair area | "
        "top-20 % share | strain contrast | paddle pair score |"
    )
    w("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for e in envs:
        for r in e.runs:
            m = r.mode
            if m is None:
                continue
            wv, bd, st = m.wave, m.bend, m.stroke
            bend = f"{bd.fit:.2f} ({bd.p_value:.3f})" if bd is not None and bd.p_value == bd.p_value else "—"
            w(
                f"| `{e.name}` | {r.index} | {m.label} | {m.deformation:.3f} | {m.coherence:.2f} | "
                f"{wv.fit if wv else float('nan'):.2f} | {wv.lag if wv else float('nan'):.2f} | "
                f"{m.travelling_index:.2f} | {wv.travel if wv and wv.is_wave else '—'} | {bend} | "
                f"{_nan(st.score if st else float('nan'), '+.2f')} | {_nan(st.area if st else float('nan'), '.2f')} | "
                f"{m.concentration:.2f} | {m.contrast:.2f} | {_score(r.paddling)} |"
            )
    w("")
    w(
        "The paper classified its bests by eye from videos and reports mixed strategies; our rule gives one main "
        "mode per best and lists a second one only where a second criterion also holds, so counts are "
        "comparable only roughly. Frequencies of the figures: motion cycles show six frames over the last "
        "dominant period (red expanding, blue contracting, green neutral: the commanded actuation, eq. 2); the "
        "GIFs show the last part of the swim at 8 frames per period."
    )
    w("")
    # claims
    w("## The paper's claims, measured")
    w("")
    w(
        "Per environment: our numbers over its runs (a range when they differ), and whether they agree. "
        "Grow: the grow output level a cell's mother had when the cell was made (what sets its radius, "
        "r0·(1 + 0.5·grow)) and the final grow output of the cells; amplitude: the mean over the cells "
        "relative to the maximum 0.2 and the spread max − min relative to it; phase range: the shortest arc "
        "holding every cell's phase."
    )
    w("")
    claims = {e.name: env_claims(e) for e in envs}
    w("| claim | the paper | " + " | ".join(f"`{e.name}`" for e in envs) + " |")
    w("| --- | --- | " + " | ".join("---" for _ in envs) + " |")
    for key, title, paper in CLAIMS:
        cells = []
        for e in envs:
            c = claims[e.name].get(key)
            cells.append(f"{c['ours']}: {c['verdict']}" if c else "—")
        w(f"| {title} | {paper} | " + " | ".join(cells) + " |")
    w("")

    # modes
    w("## Locomotion modes against the paper's counts")
    w("")
    w(
        "Counts of the best individuals' modes: ours (of our runs) next to the paper's (of 10 runs). A mixed "
        "strategy counts under its main mode and is listed after the count; see the method below."
    )
    w("")
    for e in envs:
        rs = [r for r in e.runs if r.mode is not None]
        w(f"**{e.title}** (`{e.name}`): the paper: {PAPER_QUOTES.get(e.name, '')}")
        w("")
        w(f"| mode | the paper (of {PAPER_RUNS}) | ours (of {len(rs)}) |")
        w("| --- | --- | --- |")
        for mode in MODE_COLUMNS:
            ours = [r for r in rs if r.mode.mode == mode]
            mixed = [r for r in rs if mode in r.mode.mixed]
            txt = str(len(ours))
            if ours:
                txt += (
                    " ("
                    + ", ".join(
                        f"run {r.index}" + (f" + {', '.join(r.mode.mixed)}" if r.mode.mixed else "") for r in ours
                    )
                    + ")"
                )
            if mixed:
                txt += f"; mixed into {len(mixed)} other" + ("s" if len(mixed) > 1 else "")
            paper = PAPER_MODES.get(e.name, {}).get(mode, "—")
            if mode == "none" and paper == "—" and not ours:
                continue
            w(f"| {mode} | {paper} | {txt} |")
        w("")

    # differences
    w("## Where we differ from the paper")
    w("")
    diffs = []
    for e in envs:
        for key, title, _ in CLAIMS:
            c = claims[e.name].get(key)
            if c and c["verdict"].startswith(("differs", "close", "mostly", "partly")):
                diffs.append(f"- `{e.name}`, {title.lower()}: {c['verdict']} ({c['ours']}).")
        rs = [r for r in e.runs if r.mode is not None]
        modes = {}
        for r in rs:
            modes[r.mode.mode] = modes.get(r.mode.mode, 0) + 1
        expected = {
            "dn0.5": "protrusions",
            "dn2": "synchronous contraction",
            "dn10": "undulation",
            "dn0.2_64cells": "protrusions",
        }.get(e.name)
        if expected and rs:
            got = modes.get(expected, 0)
            main = max(modes.items(), key=lambda kv: (kv[1], kv[0]))[0]
            if main != expected:
                diffs.append(
                    f"- `{e.name}`, locomotion: the paper's most frequent mode here is {expected}; ours is "
                    f"{main} ({modes[main]} of {len(rs)}; {expected}: {got} of {len(rs)})."
                )
    if diffs:
        lines.extend(diffs)
    else:
        w("Nothing measured here differs from the paper's claims.")
    w("")
    if causes:
        lines.extend(causes)
    w("<!-- DISCUSSION -->")
    w("")
    if discussion is not None and discussion.exists():
        # Written by hand from the final runs; kept across regenerations.
        w(discussion.read_text(encoding="utf-8").rstrip("\n"))
    else:
        w("*The likely reasons for these differences are discussed by hand here after the final runs.*")
    w("")

    doc.parent.mkdir(parents=True, exist_ok=True)
    doc.write_text("\n".join(lines) + "\n", encoding="utf-8")


CAUSE_BASELINE = "dn0.5"
CAUSE_TITLES = {
    "frequency_max_12": "frequency bound doubled (`development.frequency_max = 12`)",
    "substeps_2": "half the physics step (`physics.substeps = 2`)",
    "no_collisions": "no collision handling (`scene.effects` without `collisions`)",
    "drag_tangential_x10": "tangential drag ×10 (`scene.drag_tangential = 0.025`, d_T = d_N/20)",
}


def _best_until(run: animat.Run, generation: int) -> Optional[animat.LineageEntry]:
    lineage = [e for e in run.best_genomes if e.generation <= generation]
    return lineage[-1] if lineage else None


def _cause_row(label: str, index: int, entry: animat.LineageEntry, cfg: animat.Config) -> List[str]:
    tr = animat.replay(entry, cfg)
    mode = L.classify_locomotion(tr)
    body = tr.body
    f = np.asarray(body.frequency)
    fmin, fmax = float(cfg["development.frequency_min"]), float(cfg["development.frequency_max"])
    at_bound = float(np.mean(f >= fmax - 0.02 * (fmax - fmin)))  # the output saturates: within 2 % of the range
    ph = L.phase_spread(np.asarray(body.phase))
    return [
        label,
        str(index),
        str(entry.generation),
        f"{entry.fitness:.2f}",
        f"{entry.reference_fitness:.2f}",
        mode.label,
        f"{f.max():.2f}",
        f"{at_bound:.0%}",
        f"{ph.range:.2f}",
        f"{mode.contrast:.2f}",
    ]


def causes_lines(causes: Path, baseline_runs: Path, generation: int = 100) -> List[str]:
    """Small controlled runs at d_N = 0.5 (seeds 1-3, `generation` generations), one change each,
    against the study's own runs of the same seeds at the same generation."""
    header = [
        "variant",
        "run",
        "best of generation",
        "fitness",
        "fitness at dt/16",
        "mode",
        "highest frequency",
        "cells within 2 % of the frequency bound",
        "phase range (rad)",
        "strain contrast",
    ]
    rows: List[List[str]] = []
    summary: Dict[str, List[str]] = {}
    variants = [("baseline (the study's dn0.5 runs)", baseline_runs)] + [
        (CAUSE_TITLES.get(d.name, d.name), d) for d in sorted(causes.iterdir()) if d.is_dir()
    ]
    for label, root in variants:
        for run_dir in sorted(root.glob("run_*"), key=lambda q: int(q.name[4:])):
            index = int(run_dir.name[4:])
            if index > 2 or not (run_dir / "config.toml").is_file():
                continue
            run = animat.Run(run_dir)
            entry = _best_until(run, generation)
            if entry is None:
                continue
            row = _cause_row(label, index, entry, run.config)
            rows.append(row)
            summary.setdefault(label, []).append(row[5])
    lines = [
        "## Controlled runs: what changes the mode at low drag",
        "",
        f"Small controlled runs test the likely causes of the differences at low drag. Each "
        f"variant changes one thing in `configs/paper_dn0.5.toml` and evolves seeds 1–3 for {generation} "
        "generations; the baseline is the study's own runs of the same seeds, their best at the same generation. "
        "Packed in `data/replication_causes/<variant>/run_<i>` (run i has seed i + 1); this table is rebuilt from "
        "there by `studies/replication/replication_report.py --causes data/replication_causes`. Three runs of 100 generations "
        "per variant can show a large effect only: they are a screen, not a test.",
        "",
        "| " + " | ".join(header) + " |",
        "| " + " | ".join("---" for _ in header) + " |",
    ]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    lines += ["", "Modes per variant: " + "; ".join(f"{k}: {', '.join(v)}" for k, v in summary.items()) + ".", ""]
    return lines


def main(argv: Optional[List[str]] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    src = p.add_mutually_exclusive_group()
    src.add_argument("--data", type=Path, help="packed study (default data/replication when --runs is not given)")
    src.add_argument("--runs", type=Path, help="unpacked experiment root (one directory per environment)")
    p.add_argument("--doc", type=Path, default=Path("docs/replication.md"), help="Markdown file to write")
    p.add_argument(
        "--images",
        type=Path,
        help="the page's figures, kept in git (default: <doc dir>/images/replication): per environment the "
        "fitness plot and the best run's motion cycle, phase map and GIF, small",
    )
    p.add_argument(
        "--all-figures",
        action="store_true",
        help="also draw every run's motion cycle, phase map and GIF, full size, into --figures",
    )
    p.add_argument(
        "--figures",
        type=Path,
        default=FIGURES_DIR,
        help="where --all-figures writes (default: studies/replication/figures, ignored by git)",
    )
    p.add_argument("--no-gif", action="store_true", help="skip the animations")
    p.add_argument("--no-calibration", action="store_true", help="skip the known-swimmer calibration section")
    p.add_argument("--target-runs", type=int, default=PAPER_RUNS, help="runs per environment the study aims at")
    p.add_argument(
        "--discussion",
        type=Path,
        default=Path("docs/notes/replication_discussion.md"),
        help="hand-written discussion inserted after the tables (if the file exists)",
    )
    p.add_argument(
        "--causes", type=Path, default=None, help="packed controlled runs (data/replication_causes): adds their section"
    )
    args = p.parse_args(argv)
    if args.runs is None and args.data is None:
        args.data = Path("data/replication")
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="replication_report_") as tmp:
        if args.data is not None:
            if not args.data.is_dir():
                print(f"replication_report: {args.data}: no such directory", file=sys.stderr)
                return 1
            runs_dir = Path(tmp)
            replication_store.unpack_tree(args.data, runs_dir)
        else:
            runs_dir = args.runs
            if not runs_dir.is_dir():
                print(f"replication_report: {runs_dir}: no such directory", file=sys.stderr)
                return 1
        images = args.images or args.doc.parent / "images" / "replication"
        images.mkdir(parents=True, exist_ok=True)
        if args.all_figures:
            args.figures.mkdir(parents=True, exist_ok=True)
        written: List[str] = []
        names = [d.name for d in sorted(runs_dir.iterdir()) if d.is_dir()]
        ordered = [n for n in ENV_ORDER if n in names] + [n for n in names if n not in ENV_ORDER]
        envs: List[EnvReport] = []
        for name in ordered:
            env = read_env(runs_dir / name)
            if env is None:
                continue
            have = {r.index for r in env.runs}
            env.not_started = [i for i in range(args.target_runs) if i not in have]
            for r in env.runs:
                print(f"{name} run {r.index}: generation {r.generations}", file=sys.stderr, flush=True)
                analyse_run(r)
            best = env.best_run
            if best is not None:  # the page's figures: the best run's, small, under fixed names
                best.images = run_figures(best, images, f"{name}_best", PAGE_STYLE, gif=not args.no_gif)
                written += best.images.values()
            if args.all_figures:
                for r in env.runs:
                    if r.trajectory is not None:
                        print(f"{name} run {r.index}: figures", file=sys.stderr, flush=True)
                        run_figures(r, args.figures, f"{name}_run{r.index}", FULL_STYLE, gif=not args.no_gif)
            for r in env.runs:
                r.trajectory = None
            env.images = {"fitness": fitness_figure(env, images)}
            written.append(env.images["fitness"])
            envs.append(env)
        if not envs:
            print(
                f"replication_report: {args.data or args.runs}: no runs (expected <env>/run_<i>/config.toml)",
                file=sys.stderr,
            )
            return 1
        calibration = None
        if not args.no_calibration:
            print("calibration: swimming the known swimmers", file=sys.stderr, flush=True)
            calibration = {
                name: KS.classify_known(CF.SETS[name](), CALIBRATION_DRAGS, CALIBRATION_STEPS, stroke_rule=True)
                for name in CALIBRATION_SETS + HELD_OUT_SETS
            }
        commit_file = runs_dir / "commit.txt"
        commit = commit_file.read_text().strip() if commit_file.is_file() else "unknown"
        causes = None
        if args.causes is not None:
            causes_dir = Path(tmp) / "_causes"
            replication_store.unpack_tree(args.causes, causes_dir)
            causes = causes_lines(causes_dir, runs_dir / CAUSE_BASELINE)
        write_doc(
            envs,
            args.runs or runs_dir,
            args.doc,
            images,
            commit,
            args.discussion,
            calibration=calibration,
            data=args.data,
            target_runs=args.target_runs,
            causes=causes,
            figures=args.figures,
            causes_data=args.causes if causes is not None else None,
        )
        stale = sorted(q.name for q in images.iterdir() if q.suffix in (".png", ".gif") and q.name not in written)
        if stale:
            print(
                f"replication_report: {images}: {len(stale)} figure(s) the page no longer shows (remove them, "
                f"git rm where tracked): {', '.join(stale)}",
                file=sys.stderr,
            )
    print(f"{args.doc} ({time.perf_counter() - t0:.0f} s)", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
