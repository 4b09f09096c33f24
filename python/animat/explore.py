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
- with ``modes=True``, the locomotion mode of every run's best (:func:`animat.classify_locomotion`).

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


def _history_payload(history: np.ndarray, config: Any, max_points: int) -> Tuple[dict, dict]:
    """The curves (downsampled) and the flagged generations (all of them) of one run's history."""
    n = len(history)
    if n == 0:
        empty: Dict[str, list] = {k: [] for k in ("generation", "best", "mean", "reference", "viable")}
        return {**empty, "total": 0, "changes_kept": True}, {"invalid": [], "drag_limited": [], "guard": []}
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
    if len(history):
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
    world: Dict[str, Any] = {"banner": aplot.world_text(config), "floor": None, "source": None, "chemical": None}
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


def run_data(ref: RunRef, *, frames: int = 200, max_points: int = 500, modes: bool = False, max_nodes: int = 1500):
    """The page's data for one run (a dict, JSON-ready): summary, curves, flags, lineage, genealogy,
    swim, config (an :class:`animat.Config`, under ``"_config"``, removed before embedding)."""
    from . import plot as aplot
    from .run import Run

    run = Run(ref.path)
    config = run.config
    history = run.history
    lineage_entries = run.best_genomes
    lineage = _lineage_payload(lineage_entries)
    curves, flags = _history_payload(history, config, max_points)
    name, meaning, nonnegative = aplot.objective_info(config)
    data: Dict[str, Any] = {
        "label": ref.label,
        "group": ref.group,
        "path": str(ref.path),
        "objective": {"name": name, "meaning": meaning, "nonnegative": nonnegative},
        "world": aplot.world_text(config),
        "history": curves,
        "flags": flags,
        "lineage": lineage,
        "genealogy": _genealogy_payload(ref.path, lineage, max_nodes),
        "swim": None,
        "swim_note": "",
        "mode": None,
        "_config": config,
    }
    data["summary"] = _summary(history, ref.path, run.status)
    if not lineage_entries:
        data["swim_note"] = "no best yet (best/ is empty)"
        return data
    best = lineage_entries[-1]
    try:
        data["swim"] = _swim_payload(best, config, frames)
    except (ValueError, RuntimeError) as e:
        data["swim_note"] = f"the best of generation {best.generation} could not be replayed: {e}"
    if modes:
        from .locomotion import classify_locomotion

        try:
            data["mode"] = classify_locomotion(best.genome, config).label
        except (ValueError, RuntimeError) as e:
            data["mode"] = f"(not classified: {e})"
    return data


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


def build_data(
    paths: Sequence[PathLike],
    *,
    frames: int = 200,
    max_points: int = 500,
    modes: bool = False,
    max_nodes: int = 1500,
    title: Optional[str] = None,
    live: Optional[dict] = None,
    refs: Optional[List[RunRef]] = None,
) -> dict:
    """The page's data (a dict, JSON-ready) for the runs of ``paths`` (see :func:`find_runs`).

    frames: at most this many frames of each best's swim (:func:`animat.animation.default_frames`:
    the end of the swim, at least 8 frames per oscillation period). max_points: generations per
    curve at most (downsampled beyond, every change of the best kept). modes: classify each best's
    locomotion (a few seconds per run). max_nodes: ancestors drawn at most in a genealogy (the
    primary line and the youngest others). live: ``{"poll": seconds, "max_polls": N}`` for a served
    live page.
    """
    from . import __version__

    refs = find_runs(paths) if refs is None else refs
    runs = [run_data(r, frames=frames, max_points=max_points, modes=modes, max_nodes=max_nodes) for r in refs]
    for r, color in zip(runs, _colors(refs)):
        r["color"] = color
    diff = _config_diff([r.pop("_config") for r in runs])
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
        "config_diff": diff,
        "modes": bool(modes),
        "limits": {"frames": frames, "max_points": max_points, "max_nodes": max_nodes},
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
    page at ``/`` and, with ``live``, the runs' current curves at ``/live.json`` (:func:`live_data`;
    ``?since=VERSION`` answers ``{"changed": false}`` while nothing changed). The page polls every
    ``poll`` seconds (backing off to 30 s while nothing changes; at most ``max_polls`` times); a live
    page is built again when it is loaded after the runs changed, so a reload shows the newest best's
    swim and genealogy. ``page`` is the page already built (``kwargs`` are :func:`build_data`'s, for
    building it). ``server.url`` is its address; call ``serve_forever()`` (or run it in a thread) and
    ``shutdown()``.
    """
    from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
    from urllib.parse import parse_qs, urlparse

    refs = find_runs(paths)
    max_points = int(kwargs.get("max_points", 500))
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
