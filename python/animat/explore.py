"""One self-contained HTML page per run or per study: ``animat explore RUN_DIR... --out FILE.html``.

The page works offline from a file: its script and style are inlined from the package's
``explore_template.html`` (plain JavaScript drawing on ``<canvas>``, no library) and the data are
embedded as JSON. It shows

- the fitness curves of every run overlaid (best, mean, best at the exploit guard's reference step,
  viable fraction), with the generations where viable swims were invalid, where the drag limiter acted,
  or where the guard did not confirm the new best marked; long histories are downsampled to
  ``max_points`` generations per run (every change of the best kept);
- per run: the lineage of the best (``best/gen_*.json``), the genealogy of the best when the run
  directory has a ``genealogy.csv`` (its ancestry traced through the parent ids, drawn by
  generation; a note otherwise), the best's swim replayed (:func:`animat.replay`) and animated from
  its recorded frames (play, pause, a scrubber; nodes coloured by actuation state, actuation term,
  phase, evolved stiffness or the chemical they sense), in its world as :mod:`animat.plot` draws it
  (the floor with effect ``ground``, the chemical source, the body graph), and the phase map;
- the config keys whose values differ between the runs (for one run: from the animat defaults);
- with ``modes=True``, the locomotion mode of every run's best (:func:`animat.classify_locomotion`);
- per group of runs (an environment folder of a study, or runs whose configs differ only by seed) the
  median and interquartile band of the best, with group toggles, a log scale and the plot exported as
  PNG, SVG or CSV;
- for a MAP-Elites or NSGA-II run, its own measures and its last archive (a heatmap) or front; a click
  on a cell, a front point, a lineage row or a record holder of the genealogy replays that genome.

Any run :class:`animat.Run` reads is shown: a GA run directory, a packed run of ``data/`` (read in
place) or a search run directory (docs/explore.md).

:func:`serve` serves the page from a local HTTP server (127.0.0.1 only); with ``live=True`` the page
polls ``/live.json`` and redraws the curves and the lineage while runs grow.

``genealogy.csv``: header ``generation,id,parent_a,parent_b,fitness,cells``, one row per individual
born (generation 0 individuals have ``parent_a = parent_b = -1``, a mutant ``parent_b = -1``; a run
with ``evolution.protection_generations`` > 0 adds ``morphology_kind,morphology_age``); each
``best/gen_*.json`` then names its individual with an integer ``"id"``.
"""

from __future__ import annotations

import base64
import csv
import datetime as _dt
import html
import json
import math
import re
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

__all__ = [
    "find_runs",
    "build_data",
    "render_html",
    "write_page",
    "make_server",
    "serve",
    "read_genealogy",
    "ancestry",
    "downsample_indices",
    "live_data",
    "individual",
    "individual_swim",
    "TEMPLATE",
    "GENEALOGY_COLUMNS",
]

#: The page template: style and script inline; the data go where ``__ANIMAT_DATA__`` stands.
TEMPLATE = Path(__file__).with_name("explore_template.html")
#: Header of a run directory's ``genealogy.csv``.
GENEALOGY_COLUMNS = ("generation", "id", "parent_a", "parent_b", "fitness", "cells")

#: Line colours of the runs (matplotlib's tab10), and how groups of a study shade them.
_PALETTE = (
    "#1f77b4",
    "#ff7f0e",
    "#2ca02c",
    "#d62728",
    "#9467bd",
    "#8c564b",
    "#e377c2",
    "#7f7f7f",
    "#bcbd22",
    "#17becf",
)

PathLike = Union[str, Path]


# --- finding the runs ------------------------------------------------------------------------------------


def _natural(text: str) -> list:
    return [int(t) if t.isdigit() else t for t in re.split(r"(\d+)", text)]


@dataclass(frozen=True)
class RunRef:
    """A run directory of the page: its ``label`` (unique on the page), ``path`` and ``group`` (the
    environment of a study, or "")."""

    label: str
    path: Path
    group: str = ""


def find_runs(paths: Sequence[PathLike]) -> List[RunRef]:
    """The run directories named by ``paths``: each a run directory (it holds ``config.toml``) or an
    experiment directory of ``python -m animat experiment`` (``run_<i>/`` or ``NAME/run_<i>/`` below
    it, any folder one or two levels down holding a ``config.toml``).

    Labels: a run given directly is named by its folder (its parent's too when two names clash); the
    runs of an experiment directory by their path below it (``dn2/run_0``).

    Raises:
        FileNotFoundError: a path does not exist, or holds no run.
        NotADirectoryError: a path is a file.
    """
    if not paths:
        raise ValueError("explore: no RUN_DIR given")
    found: List[Tuple[Path, str, str]] = []  # (path, label, group)
    for p in map(Path, paths):
        if not p.exists():
            raise FileNotFoundError(f"{p}: no such run or experiment directory")
        if not p.is_dir():
            raise NotADirectoryError(f"{p}: not a directory (expected a run or experiment directory)")
        if (p / "config.toml").is_file():
            found.append((p, "", ""))
            continue
        below = sorted(
            {c.parent for c in list(p.glob("*/config.toml")) + list(p.glob("*/*/config.toml"))},
            key=lambda d: _natural(d.relative_to(p).as_posix()),
        )
        if not below:
            raise FileNotFoundError(
                f"{p}: neither a run directory (no config.toml) nor an experiment directory "
                "(no run_<i>/config.toml or NAME/run_<i>/config.toml below it)"
            )
        for d in below:
            rel = d.relative_to(p)
            group = rel.parts[0] if len(rel.parts) > 1 else (p.name if len(paths) > 1 else "")
            label = rel.as_posix() if len(paths) == 1 else f"{p.name}/{rel.as_posix()}"
            found.append((d, label, group))
    names = [f[0].name for f in found if not f[1]]
    out = []
    for path, label, group in found:
        if not label:
            label = path.name if names.count(path.name) == 1 else f"{path.parent.name}/{path.name}"
        out.append([path, label, group])
    seen: Dict[str, int] = {}
    for item in out:  # still the same label (the same folder twice): number them
        seen[item[1]] = seen.get(item[1], 0) + 1
        if seen[item[1]] > 1:
            item[1] = f"{item[1]} ({seen[item[1]]})"
    return [RunRef(label, path, group) for path, label, group in out]


# --- small encoders ----------------------------------------------------------------------------------------


def _num(v: Any, digits: int = 6) -> Optional[float]:
    """A float rounded to ``digits`` significant digits for JSON (None for NaN or inf)."""
    v = float(v)
    if not math.isfinite(v):
        return None
    return float(f"{v:.{digits}g}")


def _nums(values: Any, digits: int = 6) -> list:
    return [_num(v, digits) for v in np.asarray(values, dtype=float).ravel()]


def _b64(array: np.ndarray) -> str:
    return base64.b64encode(np.ascontiguousarray(array).tobytes()).decode("ascii")


def downsample_indices(n: int, max_points: int, keep: Any = ()) -> np.ndarray:
    """At most ``max_points`` sorted row indices of ``n`` rows: all of them when they fit, else the
    first and last, as many of ``keep`` (e.g. the rows where the best changed) as three quarters of
    the budget allow (evenly chosen), and an even grid for the rest."""
    if n <= max_points:
        return np.arange(n)
    max_points = max(int(max_points), 2)
    kept = np.unique(np.asarray(keep, dtype=np.int64))
    kept = kept[(kept >= 0) & (kept < n)]
    budget = (3 * max_points) // 4
    if len(kept) > budget:
        kept = kept[np.unique(np.linspace(0, len(kept) - 1, budget).round().astype(np.int64))]
    grid = np.linspace(0, n - 1, max(max_points - len(kept), 2)).round().astype(np.int64)
    picked = np.unique(np.concatenate([grid, kept, [0, n - 1]]))
    if len(picked) > max_points:  # grid and keep overlap rarely: trim the grid points in between
        extra = len(picked) - max_points
        inner = np.setdiff1d(picked, np.concatenate([kept, [0, n - 1]]))
        drop = inner[np.unique(np.linspace(0, len(inner) - 1, extra).round().astype(np.int64))]
        picked = np.setdiff1d(picked, drop)
    return picked


# --- history, flags, lineage ----------------------------------------------------------------------------


def _best_column(history: np.ndarray) -> str:
    """The column of the best value: ``best`` (the GA, MAP-Elites), else NSGA-II's first ``best_<objective>``."""
    names = history.dtype.names or ()
    return "best" if "best" in names else next((n for n in names if n.startswith("best_")), "best")


#: The columns of a search run's history drawn beside its best, and their names on the page.
_SEARCH_SERIES = {
    "map_elites": (("qd_score", "QD-score"), ("coverage", "coverage"), ("elites", "elites")),
    "nsga2": (("hypervolume", "hypervolume"), ("front_size", "front size")),
}


def _history_payload(history: np.ndarray, config: Any, max_points: int) -> Tuple[dict, dict]:
    """The curves (downsampled) and the flagged generations (all of them) of one run's history. A
    search run's history (MAP-Elites, NSGA-II) gives its best (NSGA-II: of the first objective) and,
    under ``extra``, its own measures (:data:`_SEARCH_SERIES`); it has no mean, reference or flags."""
    n = len(history)
    names = history.dtype.names or ()
    no_flags: Dict[str, list] = {"invalid": [], "drag_limited": [], "guard": []}
    if n == 0:
        empty: Dict[str, list] = {k: [] for k in ("generation", "best", "mean", "reference", "viable")}
        return {**empty, "total": 0, "changes_kept": True}, no_flags
    if "mean" not in names:  # a search run
        column = _best_column(history)
        best = np.asarray(history[column], dtype=float)
        changes = np.nonzero(np.diff(best) != 0)[0] + 1
        idx = downsample_indices(n, max_points, changes)
        h = history[idx]
        search = "map_elites" if "qd_score" in names else "nsga2"
        nothing = [None] * len(idx)
        return {
            "generation": [int(g) for g in h["generation"]],
            "best": _nums(h[column]),
            "best_column": column,
            "mean": nothing,
            "reference": nothing,
            "viable": nothing,
            "extra": {label: _nums(h[key]) for key, label in _SEARCH_SERIES[search] if key in names},
            "total": n,
            "changes_kept": bool(np.isin(changes, idx).all()),
        }, no_flags
    best = np.asarray(history["best"], dtype=float)
    # The best is constant between its changes, so its step curve is exact when every change is kept.
    changes = np.nonzero(np.diff(best) != 0)[0] + 1
    idx = downsample_indices(n, max_points, changes)
    h = history[idx]
    curves = {
        "generation": [int(g) for g in h["generation"]],
        "best": _nums(h["best"]),
        "mean": _nums(h["mean"]),
        "reference": _nums(h["best_reference"]),
        "viable": _nums(h["viable_fraction"], 4),
        "total": n,
        "changes_kept": bool(np.isin(changes, idx).all()),
    }
    gens = np.asarray(history["generation"], dtype=np.int64)
    invalid = np.asarray(history["invalid"], dtype=np.int64)
    limited = np.asarray(history["drag_limited"], dtype=np.int64)
    ref = np.asarray(history["best_reference"], dtype=float)
    rel, absolute = float(config["evaluation.reference_tolerance"]), float(config["evaluation.reference_abs_tolerance"])
    gap = np.abs(best - ref)
    unconfirmed = np.isfinite(ref) & (gap > rel * np.abs(ref)) & (gap > absolute)
    # a guard flag where an unconfirmed best first appears (the next rows repeat the same pair)
    new_pair = np.ones(n, dtype=bool)
    new_pair[1:] = (best[1:] != best[:-1]) | ~np.isclose(ref[1:], ref[:-1], equal_nan=True)
    flags = {
        "invalid": [[int(gens[k]), int(invalid[k])] for k in np.nonzero(invalid > 0)[0]],
        "drag_limited": [[int(gens[k]), int(limited[k])] for k in np.nonzero(limited > 0)[0]],
        "guard": [[int(gens[k]), _num(best[k]), _num(ref[k])] for k in np.nonzero(unconfirmed & new_pair)[0]],
    }
    return curves, flags


def _entry_id(entry: Any) -> Optional[int]:
    """The ``"id"`` of a lineage entry (runs with a genealogy.csv write it), or None."""
    value = getattr(entry, "id", -1)
    return int(value) if value >= 0 else None


def _summary(history: np.ndarray, path: Path, status: Optional[dict] = None) -> Dict[str, Any]:
    """The runs table's row: the last generation's numbers, and why the run stopped (stopped.txt, or a
    packed run's status.json)."""
    out: Dict[str, Any] = {"generations": len(history)}
    names = history.dtype.names or ()
    if len(history) and "mean" not in names:  # a search run: its own measures instead of the GA's
        last = history[-1]
        out.update(last_generation=int(last["generation"]), best=_num(last[_best_column(history)]))
        out["evaluations"] = int(last["evaluations"])
        if "qd_score" in names:
            out["search"] = (
                f"MAP-Elites: {int(last['elites'])} elites, coverage {last['coverage']:.3g}, "
                f"QD-score {last['qd_score']:.4g}"
            )
        else:
            out["search"] = f"NSGA-II: front of {int(last['front_size'])}, hypervolume {last['hypervolume']:.4g}"
    elif len(history):
        last = history[-1]
        out.update(
            last_generation=int(last["generation"]),
            best=_num(last["best"]),
            reference=_num(last["best_reference"]),
            cells=int(last["best_cells"]),
            evaluations=int(last["evaluations"]),
            invalid=int(np.sum(history["invalid"])),
            wall_seconds=_num(last["wall_seconds"], 4),
        )
    stopped = path / "stopped.txt"
    out["stopped"] = stopped.read_text(errors="replace").strip()[:200] if stopped.is_file() else ""
    if status and isinstance(status.get("stop_reason"), str) and status["stop_reason"] != "in progress":
        out["stopped"] = status["stop_reason"][:200]
    return out


def _lineage_payload(lineage: Sequence[Any]) -> List[dict]:
    return [
        {
            "generation": int(e.generation),
            "fitness": _num(e.fitness),
            "reference": _num(e.reference_fitness),
            "cells": int(e.cell_count),
            "id": _entry_id(e),
        }
        for e in lineage
    ]


# --- genealogy --------------------------------------------------------------------------------------------


def read_genealogy(path: PathLike) -> Dict[int, Tuple[int, int, int, float, int]]:
    """Read a ``genealogy.csv``: ``{id: (generation, parent_a, parent_b, fitness, cells)}``.

    A last line without its newline (a row being written) is ignored; any other malformed line
    raises ValueError naming the file and the line; a missing file FileNotFoundError.
    """
    path = Path(path)
    text = path.read_text(encoding="utf-8", errors="replace")
    lines = text.split("\n")[:-1]  # the last element is "" when complete, else a partial row
    if not lines:
        return {}
    header = lines[0].strip().split(",")
    # a run with morphological innovation protection adds morphology_kind and morphology_age
    if header[len(GENEALOGY_COLUMNS) :] == ["morphology_kind", "morphology_age"]:
        header = header[: len(GENEALOGY_COLUMNS)]
    if header != list(GENEALOGY_COLUMNS):
        raise ValueError(f"{path}:1: unexpected header {lines[0].strip()!r}; expected {','.join(GENEALOGY_COLUMNS)!r}")
    out: Dict[int, Tuple[int, int, int, float, int]] = {}
    for number, row in enumerate(csv.reader(lines[1:]), start=2):
        if not row:
            continue
        if len(row) != len(lines[0].strip().split(",")):
            raise ValueError(
                f"{path}:{number}: expected {len(lines[0].strip().split(','))} comma-separated values, got {row}"
            )
        try:
            g, i, a, b, c = (int(row[k]) for k in (0, 1, 2, 3, 5))
            f = float(row[4])
        except ValueError:
            raise ValueError(f"{path}:{number}: not a number in {','.join(row)!r}") from None
        out[i] = (g, a, b, f, c)
    return out


def ancestry(genealogy: Dict[int, Tuple[int, int, int, float, int]], start: int) -> Tuple[List[int], List[int]]:
    """The ancestors of individual ``start`` (itself included) and its primary line.

    Returns (ancestors, primary): every id reached from ``start`` through ``parent_a`` and
    ``parent_b``, youngest generation first; and the chain ``start, parent_a, parent_a's parent_a,
    ...`` down to a founder. Parents missing from the genealogy end their branch.
    """
    seen = {start}
    stack = [start]
    while stack:
        i = stack.pop()
        row = genealogy.get(i)
        if row is None:
            continue
        for parent in (row[1], row[2]):
            if parent >= 0 and parent not in seen:
                seen.add(parent)
                stack.append(parent)
    primary, on_line = [start], {start}
    while True:
        row = genealogy.get(primary[-1])
        if row is None or row[1] < 0 or row[1] in on_line:
            break
        primary.append(row[1])
        on_line.add(row[1])
    ordered = sorted(seen, key=lambda i: (-genealogy[i][0] if i in genealogy else 1, i))
    return ordered, primary


def _genealogy_payload(run_path: Path, lineage: List[dict], max_nodes: int) -> dict:
    path = run_path / "genealogy.csv"
    if not path.is_file():
        return {
            "note": f"no genealogy.csv in {run_path.name}: this run did not record its genealogy "
            "(runs written by animat versions with genealogy.csv do); the lineage above lists its bests"
        }
    table = read_genealogy(path)
    if not lineage:
        return {"note": "no best yet (best/ is empty)"}
    if not table:
        return {"note": f"{path.name} has no rows yet"}
    best = lineage[-1]
    start = best.get("id")
    how = "id"
    if start is None or start not in table:  # a lineage file without an id: the individual born then with that fitness
        how = "match"
        candidates = [
            i
            for i, (g, _, _, f, c) in table.items()
            if g <= best["generation"]
            and best["fitness"] is not None
            and abs(f - best["fitness"]) <= 1e-9 * max(1, abs(f))
        ]
        if not candidates:
            return {"note": f"{path.name}: the best (generation {best['generation']}) is not in it (no id, no match)"}
        start = max(candidates, key=lambda i: (table[i][0], i))
    ancestors, primary = ancestry(table, start)
    ancestors = [i for i in ancestors if i in table]  # a parent without its row ends the branch: not drawn
    primary = [i for i in primary if i in table]
    total = len(ancestors)
    keep = set(primary)
    for i in ancestors:  # youngest first, after the primary line
        if len(keep) >= max_nodes:
            break
        keep.add(i)
    nodes = [i for i in ancestors if i in keep]
    index = {i: k for k, i in enumerate(nodes)}
    lineage_ids = {e["id"] for e in lineage if e.get("id") is not None}
    rows = []
    for i in nodes:
        g, a, b, f, c = table[i]
        rows.append([i, g, index.get(a, -1), index.get(b, -1), _num(f), c, 1 if i in lineage_ids else 0])
    founders = sum(1 for i in ancestors if table[i][1] < 0 and table[i][2] < 0)
    return {
        "nodes": rows,  # [id, generation, parent_a index, parent_b index, fitness, cells, in lineage]
        "primary": [index[i] for i in primary if i in index],
        "best": index[start],
        "total": total,
        "shown": len(nodes),
        "founders": founders,
        "born": len(table),
        "matched_by": how,
    }


# --- the swim ----------------------------------------------------------------------------------------------


def _progress(tr: Any, config: Any, source: Optional[np.ndarray]) -> Tuple[str, np.ndarray]:
    """The swim's progress by the objective at every frame, as :func:`animat.animate` writes it."""
    d = tr.com - tr.com[0]
    objective = str(config["evaluation.objective"])
    if source is not None and objective == "chemotaxis":
        return "to source", np.linalg.norm(source) - np.linalg.norm(source[None, :] - d, axis=1)
    if objective == "distance_x":
        return "x distance", np.abs(d[:, 0])
    if objective == "speed_toward":
        u = np.asarray(config["evaluation.direction"], dtype=float)
        return "along dir.", d @ (u / (np.linalg.norm(u) or 1.0))
    return "distance", np.linalg.norm(d, axis=1)


def _swim_payload(entry: Any, config: Any, frames: int) -> dict:
    import warnings

    from . import _core
    from . import plot as aplot
    from .animation import default_frames
    from .trajectory import replay

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # an unstable swim: said on the page
        tr = replay(entry, config)
    config = tr.config  # a chemotaxis replay swims one of the evaluation's sources, not scene.chemical_source
    scene: Any = _core.Scene.from_config(config)
    effects = list(scene.effects)
    idx = np.asarray(default_frames(tr, max_frames=max(2, frames)), dtype=np.int64)
    align = "gravity" not in effects and "ground" not in effects
    rot = aplot.rotation_to(tr.direction) if align else np.eye(2)
    origin = tr.com[0] if align else np.zeros(2)

    def view(p):
        return (np.asarray(p, dtype=float) - origin) @ rot.T

    pos = view(tr.positions[idx])  # (F, n, 2)
    lo, hi = pos.reshape(-1, 2).min(axis=0), pos.reshape(-1, 2).max(axis=0)
    scale = np.maximum(hi - lo, 1e-9) / 65534.0
    q = np.round((pos - lo) / scale - 32767.0).clip(-32767, 32767).astype("<i2")
    body = tr.body
    amax = float(config["development.amplitude_max"]) or 1.0
    terms = np.round(np.clip(tr.node_terms[idx] / amax, -1, 1) * 127).astype(np.int8)
    source_rel = aplot.chemical_source_of(config)
    label, progress = _progress(tr, config, source_rel)
    path_idx = np.unique(np.linspace(0, tr.frame_count - 1, min(tr.frame_count, 240)).round().astype(np.int64))
    stiffness = np.asarray(getattr(body, "stiffness", np.empty(0)), dtype=float)
    banner = aplot.world_text(config, source_trial=tr.meta.get("source_trial"))
    world: Dict[str, Any] = {"banner": banner, "floor": None, "source": None, "chemical": None}
    if "ground" in effects:
        world["floor"] = _num(scene.ground_height)
    if source_rel is not None:
        world["source"] = _nums(view((tr.com[0] + source_rel)[None, :])[0])
    if scene.chemical != "none":
        n_vec = np.asarray(scene.chemical_source, dtype=float)
        n_vec = n_vec / (np.linalg.norm(n_vec) or 1.0)
        world["chemical"] = {
            "kind": str(scene.chemical),
            "source": _nums(view((tr.com[0] + np.asarray(scene.chemical_source, dtype=float))[None, :])[0]),
            "normal": _nums(n_vec @ rot.T),
            "decay": _num(scene.chemical_decay_length),
        }
    return {
        "generation": int(entry.generation),
        "n": int(tr.node_count),
        "frames": len(idx),
        "recorded": int(tr.frame_count),
        "pos": _b64(q),
        "lo": _nums(lo, 9),
        "scale": _nums(scale, 9),
        "state": _b64(tr.node_state[idx].astype(np.int8)),
        "term": _b64(terms),
        "amplitude_max": _num(amax),
        "times": _nums(tr.times[idx], 5),
        "steps": [int(s) for s in tr.steps[idx]],
        "progress_label": label,
        "progress": _nums(progress[idx], 5),
        "path": _nums(view(tr.com[path_idx]), 5),
        "springs": [int(v) for v in np.asarray(body.springs).ravel()],
        "skin": [[int(v) for v in loop] for loop in body.skin_loops],
        "regions": [[int(v) for v in reg] for reg in body.regions],
        "radius": _num(aplot._node_radius(body)),
        "rest": _nums(np.asarray(body.positions), 5),
        "phase": _nums(body.phase, 5),
        "stiffness": _nums(stiffness, 5) if len(stiffness) == tr.node_count else None,
        "graph": aplot.graph_name(config),
        "aligned": bool(align),
        "world": world,
        "stable": bool(tr.stable),
        "failure": tr.failure,
        "distance": _num(tr.distance),
        "period": _num(tr.period()),
        "control": tr.meta.get("control", "open_loop"),
    }


# --- config differences ------------------------------------------------------------------------------------


def _config_value(v: Any) -> Any:
    if isinstance(v, float):
        return _num(v, 12)
    if isinstance(v, (list, tuple)):
        return [_config_value(x) for x in v]
    return v if isinstance(v, (int, str, bool)) or v is None else str(v)


def _config_diff(configs: List[Any]) -> dict:
    from . import _core

    against = "defaults" if len(configs) == 1 else "runs"
    tables = [{k: _config_value(c[k]) for k in c.keys()} for c in configs]
    if against == "defaults":
        default = _core.Config()
        tables.insert(0, {k: _config_value(default[k]) for k in default.keys()})
    keys = []
    for k in sorted(set().union(*tables)):
        values = [t.get(k) for t in tables]
        if any(v != values[0] for v in values[1:]):
            keys.append([k, values])
    return {"against": against, "keys": keys}


# --- the page's data ---------------------------------------------------------------------------------------


def _colors(refs: List[RunRef]) -> List[str]:
    groups = list(dict.fromkeys(r.group for r in refs))
    if len(groups) <= 1 or len(groups) > len(_PALETTE):
        return [_PALETTE[k % len(_PALETTE)] for k in range(len(refs))]
    out = []
    for r in refs:  # a study: one hue per environment, lighter for its later runs
        base = _PALETTE[groups.index(r.group)]
        k = [x for x in refs if x.group == r.group].index(r)
        out.append(_shade(base, (0.0, 0.3, 0.5, 0.65)[k % 4]))
    return out


def _shade(color: str, amount: float) -> str:
    rgb = [int(color[i : i + 2], 16) for i in (1, 3, 5)]
    return "#" + "".join(f"{int(round(c + (255 - c) * amount)):02x}" for c in rgb)


def _search_payload(run: Any, max_rows: int) -> Optional[dict]:
    """A search run's last snapshot for the page (None for a GA run): the MAP-Elites archive as a
    heatmap over its first two descriptors (the grid of the checkpoint's archive; one row per elite),
    or the NSGA-II front over its first two objectives (one row per genome)."""
    if run.search not in ("map_elites", "nsga2"):
        return None
    try:
        snap = run.snapshot()
    except (OSError, ValueError) as e:
        return {"kind": run.search, "note": str(e)}
    n = len(snap)
    order = list(range(n))
    out: Dict[str, Any] = {"kind": run.search, "generation": snap.generation, "path": str(snap.path), "total": n}
    if snap.kind == "archive":
        names = snap.descriptors[:2]
        geometry = _archive_geometry(run, snap)
        values = [snap.columns[d] for d in names]
        objective = snap.columns["objective"]
        order = sorted(order, key=lambda k: -float(objective[k]) if math.isfinite(objective[k]) else math.inf)
        rows = [
            [k, *[_num(v[k]) for v in values], _num(objective[k]), int(snap.columns["generation"][k])]
            for k in order[:max_rows]
        ]
        out.update(descriptors=geometry, objective="objective", rows=rows)
    else:
        names = [name for name, _ in snap.objectives[:2]]
        first = np.asarray(snap.columns[names[0]], dtype=float)
        sign = -1.0 if snap.objectives[0][1] == "max" else 1.0  # best first, by the first objective
        order = sorted(order, key=lambda k: sign * float(first[k]) if math.isfinite(first[k]) else math.inf)
        out.update(objectives=[[name, sense] for name, sense in snap.objectives])
        rows = [
            [k, *[_num(snap.columns[name][k]) for name in names], int(snap.columns["generation"][k])]
            for k in order[:max_rows]
        ]
        out.update(rows=rows)
    out["best"] = snap.best()
    return out


def _archive_geometry(run: Any, snap: Any) -> List[dict]:
    """The first two descriptors of an archive: name, range and bins of the checkpoint's grid archive;
    for another archive (CVT) the range of the elites' values and no bins."""
    geometry = {}
    try:
        state = (run.checkpoint or {}).get("archive") or {}
    except (OSError, ValueError):
        state = {}
    if state.get("kind") == "grid":
        for d, bins in zip(state.get("descriptors", []), state.get("bins", [])):
            geometry[d.get("name")] = {"lo": _num(d.get("lo")), "hi": _num(d.get("hi")), "bins": int(bins)}
    out = []
    for name in snap.descriptors[:2]:
        g = geometry.get(name)
        if g is None:
            v = np.asarray(snap.columns[name], dtype=float)
            v = v[np.isfinite(v)]
            g = {"lo": _num(v.min()) if len(v) else 0.0, "hi": _num(v.max()) if len(v) else 1.0, "bins": None}
        out.append({"name": name, **g})
    return out


def individual(run: Any, key: str) -> Any:
    """The individual of a run named by a page key: ``"lineage:J"`` (entry J of :attr:`Run.best_genomes`)
    or ``"row:G:I"`` (row I of a search run's snapshot of generation G), as a :class:`animat.LineageEntry`.
    ValueError for another key."""
    from .run import LineageEntry

    kind, _, number = key.partition(":")
    generation, _, row = number.partition(":") if kind == "row" else ("", "", number)
    if not row.isdigit() or not (generation.isdigit() or kind != "row"):
        raise ValueError(f"no individual {key!r} (expected lineage:J or row:G:I)")
    j = int(row)
    if kind == "lineage":
        lineage = run.best_genomes
        if j >= len(lineage):
            raise ValueError(f"{run.path}: no lineage entry {j} ({len(lineage)} there)")
        return lineage[j]
    if kind == "row":
        snap = run.snapshot(int(generation))
        if j >= len(snap):
            raise ValueError(f"{snap.path}: no row {j} ({len(snap)} there)")
        name = snap.objectives[0][0]
        return LineageEntry(
            int(snap.columns["generation"][j]), float(snap.columns[name][j]), 0, snap.genome(j), snap.path
        )
    raise ValueError(f"no individual {key!r} (expected lineage:J or row:G:I)")


def _replay_keys(lineage: List[dict], search: Optional[dict], count: int) -> List[str]:
    """The individuals whose swims a page embeds besides the best's: the last ``count`` record holders
    before the best (a GA run), or the ``count`` first rows of the snapshot payload (the best elites;
    a front spread along its first objective)."""
    if count <= 0:
        return []
    if search and search.get("rows"):
        rows = search["rows"]
        if search["kind"] == "nsga2" and len(rows) > count:
            by_first = sorted(rows, key=lambda r: (r[1] is None, r[1] or 0.0))
            rows = [by_first[k] for k in np.unique(np.linspace(0, len(rows) - 1, count).round().astype(int))]
        return [f"row:{search['generation']}:{r[0]}" for r in rows[:count] if r[0] != search.get("best")]
    return [f"lineage:{j}" for j in range(max(0, len(lineage) - 1 - count), len(lineage) - 1)]


def run_data(
    ref: RunRef,
    *,
    frames: int = 200,
    max_points: int = 500,
    modes: bool = False,
    max_nodes: int = 1500,
    replays: int = 0,
):
    """The page's data for one run (a dict, JSON-ready): summary, curves, flags, lineage, genealogy,
    swim, config (an :class:`animat.Config`, under ``"_config"``) and the whole best curve (``"_best"``:
    generations and values), both removed before embedding; a search
    run's last archive or front (``"search"``). ``replays``: swims of that many more individuals
    (:func:`_replay_keys`) embedded under ``"replays"`` (key -> swim, at most 60 frames each)."""
    from . import plot as aplot
    from .run import Run

    run = Run(ref.path)
    config = run.config
    history = run.history
    lineage_entries = run.best_genomes
    lineage = _lineage_payload(lineage_entries)
    curves, flags = _history_payload(history, config, max_points)
    name, meaning, nonnegative = aplot.objective_info(config)
    search = _search_payload(run, max_rows=2000)
    if search and search["kind"] == "nsga2" and search.get("objectives"):
        first, sense = search["objectives"][0]
        name, meaning = first, f"the first NSGA-II objective ({sense}imised); the front trades it against the others"
        nonnegative = None
    data: Dict[str, Any] = {
        "label": ref.label,
        "group": ref.group,
        "path": str(ref.path),
        "kind": run.search,
        "packed": bool(run.packed),
        "objective": {"name": name, "meaning": meaning, "nonnegative": nonnegative},
        "world": aplot.world_text(config),
        "history": curves,
        "flags": flags,
        "lineage": lineage,
        "genealogy": _genealogy_payload(ref.path, lineage, max_nodes)
        if run.search == "ga"
        else {
            "note": f"a {run.search} run records no genealogy: its {'archive' if run.search == 'map_elites' else 'front'} is below"
        },
        "search": search,
        "swim": None,
        "swim_note": "",
        "best_key": f"lineage:{len(lineage_entries) - 1}" if lineage_entries else None,
        "replays": {},
        "mode": None,
        "_config": config,
    }
    data["summary"] = _summary(history, ref.path, run.status)
    column = _best_column(history) if len(history) else "best"
    data["_best"] = (
        (np.asarray(history["generation"], dtype=np.int64), np.asarray(history[column], dtype=float))
        if len(history)
        else (np.zeros(0, dtype=np.int64), np.zeros(0))
    )
    if not lineage_entries:
        data["swim_note"] = "no best yet (best/ is empty)" if run.search == "ga" else "no best yet (no snapshot)"
        return data
    best = lineage_entries[-1]
    try:
        data["swim"] = _swim_payload(best, config, frames)
    except (ValueError, RuntimeError) as e:
        data["swim_note"] = f"the best of generation {best.generation} could not be replayed: {e}"
    for key in _replay_keys(lineage, search, replays):
        data["replays"][key] = individual_swim(run, key, min(frames, 60))
    if modes:
        from .locomotion import classify_locomotion

        try:
            data["mode"] = classify_locomotion(best.genome, config).label
        except (ValueError, RuntimeError) as e:
            data["mode"] = f"(not classified: {e})"
    return data


def individual_swim(run: Any, key: str, frames: int) -> dict:
    """The swim payload of the individual ``key`` (:func:`individual`) of ``run`` (an :class:`animat.Run`);
    ``{"error": ...}`` when it cannot be replayed."""
    try:
        return _swim_payload(individual(run, key), run.config, frames)
    except (ValueError, RuntimeError) as e:
        return {"error": f"{key} could not be replayed: {e}"}


def _live_version(refs: Sequence[RunRef]) -> str:
    """Changes whenever a history.csv or the lineage of one of the runs does."""
    parts = []
    for r in refs:
        for name in ("history.csv", "best", "genealogy.csv", "history.csv.gz", "best.tar.gz", "archive", "front"):
            p = r.path / name
            try:
                st = p.stat()
                parts.append(f"{st.st_mtime_ns}:{st.st_size}")
            except OSError:
                parts.append("-")
    return "|".join(parts)


def live_data(refs: Sequence[RunRef], max_points: int = 500) -> dict:
    """What the live page polls: every run's curves, flags, summary and lineage, read afresh."""
    from .run import Run

    runs = []
    for ref in refs:
        try:
            run = Run(ref.path)
            config = run.config
            history = run.history
            curves, flags = _history_payload(history, config, max_points)
            entry = {"label": ref.label, "history": curves, "flags": flags}
            entry["lineage"] = _lineage_payload(run.best_genomes)
            entry["summary"] = _summary(history, ref.path, run.status)
        except (OSError, ValueError) as e:  # a file being rewritten: said, and tried again next poll
            entry = {"label": ref.label, "error": str(e)}
        runs.append(entry)
    return {"version": _live_version(refs), "runs": runs, "time": _dt.datetime.now().isoformat(timespec="seconds")}


#: Runs on a page beyond which the defaults shrink: each best's swim gets :data:`STUDY_FRAMES` frames
#: (not 200) and no other individual's swim is embedded (a served page replays any on demand).
STUDY_RUNS = 8
STUDY_FRAMES = 60
#: Swims embedded besides the best's on a page of at most :data:`STUDY_RUNS` runs (:func:`_replay_keys`).
REPLAYS = 12


def _config_groups(refs: List[RunRef], configs: List[Any]) -> List[RunRef]:
    """Runs given one by one (no group from an experiment directory) grouped by their config with
    ``evolution.seed`` and ``evolution.threads`` left out: each group named by its runs' common parent
    folder when that names the groups apart, else "config 1", "config 2", ..."""
    if len(refs) < 2 or any(r.group for r in refs):
        return refs
    keys = []
    for c in configs:
        d = c.to_dict()
        d.get("evolution", {}).pop("seed", None)
        d.get("evolution", {}).pop("threads", None)
        keys.append(json.dumps(d, sort_keys=True, default=str))
    distinct = list(dict.fromkeys(keys))
    parents = []
    for key in distinct:
        folders = {r.path.resolve().parent.name for r, k in zip(refs, keys) if k == key}
        parents.append(folders.pop() if len(folders) == 1 else "")
    names = (
        parents
        if all(parents) and len(set(parents)) == len(parents)
        else [f"config {k + 1}" for k in range(len(distinct))]
    )
    return [RunRef(r.label, r.path, names[distinct.index(k)]) for r, k in zip(refs, keys)]


def _group_payload(refs: List[RunRef], bests: List[Tuple[np.ndarray, np.ndarray]], max_points: int) -> List[dict]:
    """Per group of runs (an environment of a study): the median and the quartiles of the best over the
    runs that reached each generation (``n``: how many), downsampled to ``max_points`` generations."""
    import warnings

    out = []
    for name in dict.fromkeys(r.group for r in refs):
        members = [k for k, r in enumerate(refs) if r.group == name]
        series = [bests[k] for k in members if len(bests[k][0])]
        if not series:
            out.append({"name": name, "runs": members, "generation": [], "median": [], "q1": [], "q3": [], "n": []})
            continue
        last = int(max(g.max() for g, _ in series))
        table = np.full((len(series), last + 1), np.nan)
        for row, (g, b) in enumerate(series):
            keep = (g >= 0) & (g <= last)
            table[row, g[keep]] = b[keep]
        count = np.sum(np.isfinite(table), axis=0)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # a generation no run reached (a gap)
            q1, median, q3 = np.nanpercentile(table, [25, 50, 75], axis=0)
        reached = np.nonzero(count > 0)[0]
        changes = np.nonzero(np.diff(median[reached]) != 0)[0] + 1
        idx = reached[downsample_indices(len(reached), max_points, changes)]
        out.append(
            {
                "name": name,
                "runs": members,
                "generation": [int(g) for g in idx],
                "median": _nums(median[idx]),
                "q1": _nums(q1[idx]),
                "q3": _nums(q3[idx]),
                "n": [int(c) for c in count[idx]],
            }
        )
    return out


def build_data(
    paths: Sequence[PathLike],
    *,
    frames: Optional[int] = None,
    max_points: int = 500,
    modes: bool = False,
    max_nodes: int = 1500,
    replays: Optional[int] = None,
    title: Optional[str] = None,
    live: Optional[dict] = None,
    refs: Optional[List[RunRef]] = None,
) -> dict:
    """The page's data (a dict, JSON-ready) for the runs of ``paths`` (see :func:`find_runs`).

    frames: at most this many frames of each best's swim (:func:`animat.animation.default_frames`:
    the end of the swim, at least 8 frames per oscillation period; default 200, or
    :data:`STUDY_FRAMES` on a page of more than :data:`STUDY_RUNS` runs). max_points: generations per
    curve at most (downsampled beyond, every change of the best kept). modes: classify each best's
    locomotion (a few seconds per run). max_nodes: ancestors drawn at most in a genealogy (the
    primary line and the youngest others). replays: swims embedded per run besides the best's
    (default :data:`REPLAYS`, none on a page of more than :data:`STUDY_RUNS` runs). live:
    ``{"poll": seconds, "max_polls": N}`` for a served live page.

    The runs are grouped (``"groups"``: median and quartiles of the best per generation): by the
    environment folder of an experiment directory (``NAME/run_<i>``), else by config with the seed left out.
    """
    from . import __version__

    refs = find_runs(paths) if refs is None else refs
    study = len(refs) > STUDY_RUNS
    frames = (STUDY_FRAMES if study else 200) if frames is None else frames
    replays = (0 if study else REPLAYS) if replays is None else replays
    runs = [
        run_data(r, frames=frames, max_points=max_points, modes=modes, max_nodes=max_nodes, replays=replays)
        for r in refs
    ]
    configs = [r.pop("_config") for r in runs]
    bests = [r.pop("_best") for r in runs]
    group_by = "folders" if any(r.group for r in refs) else "config"
    refs = _config_groups(refs, configs)
    for r, ref, color in zip(runs, refs, _colors(refs)):
        r["color"], r["group"] = color, ref.group
    groups = _group_payload(refs, bests, max_points)
    for k, g in enumerate(groups):
        g["color"] = _PALETTE[k % len(_PALETTE)]
    diff = _config_diff(configs)
    if title is None:
        title = (
            f"animat run {refs[0].label}"
            if len(refs) == 1
            else f"animat study: {len(refs)} runs ({', '.join(str(p) for p in paths)})"
        )
    return {
        "title": title,
        "generated": _dt.datetime.now().isoformat(timespec="seconds"),
        "version": __version__,
        "runs": runs,
        "groups": groups,
        "group_by": group_by,
        "config_diff": diff,
        "modes": bool(modes),
        "limits": {"frames": frames, "max_points": max_points, "max_nodes": max_nodes, "replays": replays},
        "live": {**live, "version": _live_version(refs)} if live else None,
    }


def render_html(data: dict) -> str:
    """The page: :data:`TEMPLATE` with ``data`` embedded as JSON (``<`` escaped, so no ``</script>``)."""
    text = json.dumps(data, separators=(",", ":"), allow_nan=False).replace("<", "\\u003c")
    head, sep, tail = TEMPLATE.read_text(encoding="utf-8").partition("__ANIMAT_DATA__")
    if not sep:
        raise RuntimeError(f"{TEMPLATE}: no __ANIMAT_DATA__ placeholder")
    return head.replace("__ANIMAT_TITLE__", html.escape(str(data.get("title", "animat")))) + text + tail


def write_page(paths: Sequence[PathLike], out: PathLike, **kwargs: Any) -> Path:
    """Build the page for ``paths`` (:func:`build_data` keywords) and write it to ``out``."""
    out = Path(out)
    page = render_html(build_data(paths, **kwargs))
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(page, encoding="utf-8")
    return out


# --- serving ----------------------------------------------------------------------------------------------


def make_server(
    paths: Sequence[PathLike],
    *,
    port: int = 8765,
    live: bool = False,
    poll: float = 2.0,
    max_polls: int = 20000,
    page: Optional[str] = None,
    **kwargs: Any,
):
    """A :class:`http.server.ThreadingHTTPServer` on 127.0.0.1:``port`` (0: any free port) serving the
    page at ``/``, the swim of any individual at ``/swim.json?run=K&key=KEY`` (:func:`individual_swim`;
    the page asks for those it does not embed) and, with ``live``, the runs' current curves at
    ``/live.json`` (:func:`live_data`;
    ``?since=VERSION`` answers ``{"changed": false}`` while nothing changed). The page polls every
    ``poll`` seconds (backing off to 30 s while nothing changes; at most ``max_polls`` times); a live
    page is built again when it is loaded after the runs changed, so a reload shows the newest best's
    swim and genealogy. ``page`` is the page already built (``kwargs`` are :func:`build_data`'s, for
    building it). ``server.url`` is its address; call ``serve_forever()`` (or run it in a thread) and
    ``shutdown()``.
    """
    from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
    from urllib.parse import parse_qs, urlparse

    from .run import Run

    refs = find_runs(paths)
    max_points = int(kwargs.get("max_points", 500))
    frames = int(kwargs.get("frames") or (STUDY_FRAMES if len(refs) > STUDY_RUNS else 200))
    swims: Dict[Tuple[int, str], dict] = {}  # the individuals replayed on request
    liveinfo = {"poll": float(poll), "max_polls": int(max_polls)} if live else None
    built = {"version": _live_version(refs), "body": b""}
    if page is None:
        page = render_html(build_data(paths, live=liveinfo, refs=refs, **kwargs))
    built["body"] = page.encode("utf-8")
    lock = threading.Lock()

    def current_page() -> bytes:
        with lock:
            version = _live_version(refs)
            if live and version != built["version"]:  # the runs grew since it was built: build it again
                built["body"] = render_html(build_data(paths, live=liveinfo, refs=refs, **kwargs)).encode("utf-8")
                built["version"] = version
            return built["body"]

    class Handler(BaseHTTPRequestHandler):
        def _send(self, status: int, payload: bytes, kind: str) -> None:
            self.send_response(status)
            self.send_header("Content-Type", kind)
            self.send_header("Content-Length", str(len(payload)))
            self.send_header("Cache-Control", "no-store")
            self.end_headers()
            self.wfile.write(payload)

        def do_GET(self) -> None:  # noqa: N802 - the http.server API
            url = urlparse(self.path)
            if url.path in ("/", "/index.html", "/explore.html"):
                self._send(200, current_page(), "text/html; charset=utf-8")
            elif url.path == "/swim.json":
                query = parse_qs(url.query)
                try:
                    k = int(query.get("run", ["-1"])[0])
                    key = query.get("key", [""])[0]
                    if not 0 <= k < len(refs):
                        raise ValueError(f"no run {k} (0..{len(refs) - 1})")
                    with lock:
                        cached = swims.get((k, key))
                    if cached is None:
                        cached = individual_swim(Run(refs[k].path), key, frames)
                        with lock:
                            swims[(k, key)] = cached
                    answer = cached
                except (OSError, ValueError) as e:
                    answer = {"error": str(e)}
                self._send(200, json.dumps(answer, allow_nan=False).encode("utf-8"), "application/json")
            elif url.path == "/live.json" and live:
                since = parse_qs(url.query).get("since", [""])[0]
                with lock:
                    version = _live_version(refs)
                    answer = {"changed": False, "version": version} if since == version else live_data(refs, max_points)
                self._send(200, json.dumps(answer, allow_nan=False).encode("utf-8"), "application/json")
            else:
                self._send(404, b"not found\n", "text/plain; charset=utf-8")

        def log_message(self, format: str, *args: Any) -> None:  # noqa: A002 - quiet
            pass

    server = ThreadingHTTPServer(("127.0.0.1", int(port)), Handler)
    server.daemon_threads = True
    server.url = f"http://127.0.0.1:{server.server_address[1]}/"  # type: ignore[attr-defined]
    return server


def serve(paths: Sequence[PathLike], *, port: int = 8765, live: bool = False, log=print, **kwargs: Any) -> None:
    """Serve the page of ``paths`` on 127.0.0.1 until Ctrl-C (:func:`make_server`)."""
    server = make_server(paths, port=port, live=live, **kwargs)
    log(f"serving {server.url}{' (live)' if live else ''}; Ctrl-C stops")  # type: ignore[attr-defined]
    try:
        server.serve_forever(poll_interval=0.5)
    finally:
        server.server_close()
