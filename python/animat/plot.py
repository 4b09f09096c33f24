"""The paper's figures (Joachimczak & Wróbel, GECCO 2012) with matplotlib.

Every function returns a :class:`matplotlib.figure.Figure` (made with ``pyplot.figure``, so
``plt.show()`` and notebooks display it) and never calls ``show``; all of them work with the
headless Agg backend. Save with ``fig.savefig("x.png")`` and free with ``plt.close(fig)``.

=====================  ===========  ==========================================================
function               paper        shows
=====================  ===========  ==========================================================
:func:`development`    Fig. 2       cells (circles + orientation ticks) at chosen steps
:func:`construction`   Fig. 3       centres → Delaunay → body graph (regions, skin)
:func:`motion_cycle`   Figs. 4–6    snapshots of one motion cycle, nodes red / blue / green
:func:`phase_map`      Fig. 7       nodes coloured by phase shift, maximum indicated
:func:`stiffness_map`  (Fig. 7)     nodes and springs coloured by evolved stiffness
:func:`fitness_history` Figs. 8–9   best fitness per generation, morphology changes marked
:func:`energy_split`   (§4)         where the actuation work went: fluid, dampers, collisions...
=====================  ===========  ==========================================================

:func:`draw_body` draws one body into an existing Axes (used by all of the above and by
:func:`animat.animate`); :func:`draw_world` the floor and the chemical source of the world a body
swims in. Every figure names the world as it is (:func:`world_text`: the fluid only with effect
``drag``, gravity and the floor only with theirs), the run's objective (:func:`objective_info`) and
the body graph used (:func:`graph_name`).

A swim in which no cell moves (:func:`motionless`: a run's best can be such a body when nothing that
moves scored better yet) draws its figures with a warning (:func:`motion_cycle`,
:func:`animat.animate`). Under GRN control with ``control.actuation = "direct"`` the developed
phases drive nothing (:func:`oscillator_phases_used`), so :func:`phase_map` draws a note instead.
"""

from __future__ import annotations

import math
import warnings
from typing import Any, Dict, List, Optional, Sequence, Tuple

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import EllipseCollection, LineCollection, PatchCollection, PolyCollection
from matplotlib.colors import Normalize
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, ConnectionPatch, Polygon
from matplotlib.ticker import MaxNLocator
from numpy.typing import ArrayLike

from . import _core
from .run import MORPHOLOGY_TOLERANCE, Run
from .trajectory import CONTRACTING, EXPANDING, NEUTRAL, STATE_NAMES, Trajectory, _swims_per_source, body_of

__all__ = [
    "development",
    "construction",
    "motion_cycle",
    "phase_map",
    "stiffness_map",
    "fitness_history",
    "draw_body",
    "STATE_COLORS",
    "PHASE_CMAP",
    "STIFFNESS_CMAP",
    "rotation_to",
    "development_steps",
    "energy_split",
    "ENERGY_SINKS",
    "world_text",
    "objective_info",
    "graph_name",
    "draw_world",
    "chemical_source_of",
    "motionless",
    "oscillator_phases_used",
    "FLOOR_COLOR",
    "GROUND_COLOR",
    "SOURCE_COLOR",
]

#: The sinks of :class:`animat.EnergyAccount` that :func:`energy_split` draws, with their labels and colours.
ENERGY_SINKS = (
    ("drag_normal", "fluid drag, normal", "#1f77b4"),
    ("drag_tangential", "fluid drag, tangential", "#9ecae1"),
    ("spring_damping", "spring damping", "#d62728"),
    ("collisions", "collisions", "#9467bd"),
    ("ground", "ground", "#8c564b"),
    ("other", "other forces", "#7f7f7f"),
    ("stored_change", "stored (kinetic + potential)", "#2ca02c"),
    ("residual", "residual (integration)", "#000000"),
)

#: Node colours of the motion figures (paper Figs. 4–6): red expanding, blue contracting, green neutral.
STATE_COLORS = {EXPANDING: "#d62728", CONTRACTING: "#1f77b4", NEUTRAL: "#2ca02c"}
#: Colour map of :func:`phase_map` (low phase blue, maximum red, as in paper Fig. 7).
PHASE_CMAP = "jet"
#: Colour map of :func:`stiffness_map` (soft light, stiff dark).
STIFFNESS_CMAP = "viridis_r"

SPRING_COLOR = "#8c8c8c"
SKIN_COLOR = "#111111"
FILL_COLOR = "#e9eef3"
#: The floor line (effect ``ground``), the ground below it, and the chemical source (star, arrow).
FLOOR_COLOR = "#8c564b"
GROUND_COLOR = "#eee4da"
SOURCE_COLOR = "#ff7f0e"


# --- the world, the objective and the body graph, as the figures name them --------------------------------


def _scene_of(config: Any = None, scene: Any = None) -> Any:
    if scene is not None:
        return scene
    return _core.Scene.from_config(config if config is not None else _core.Config())


def world_text(config: Any = None, scene: Any = None, *, source_trial: Optional[int] = None) -> str:
    """One line naming the world a swim happens in, as it is: the fluid (``d_N``, ``d_T``) only when
    effect ``drag`` is in the scene ("no fluid drag" otherwise), gravity and the floor only when
    effects ``gravity`` / ``ground`` are, the GRN controller under ``control.mode = "grn"`` and the
    chemical source when there is one (see :func:`chemical_source_of`).

    Under objective ``chemotaxis`` an evaluation swims toward ``evaluation.source_directions``
    sources (:func:`animat.trajectory.chemotaxis_source`), none of them at ``scene.chemical_source``
    itself: without ``source_trial`` the text says how far and how many ("point source 20 from the
    start, 4 directions"); with it (a replayed swim: ``trajectory.meta["source_trial"]``, whose
    config holds that swim's source) where that swim's source is and which swim it is ("point source
    at (-5.83, -19.1) from the start (swim 1 of 4)").

    ``scene`` (an :class:`animat.Scene`) overrides ``config``'s scene (default: animat defaults)."""
    cfg = config if config is not None else _core.Config()
    sc = _scene_of(cfg, scene)
    effects = list(sc.effects)
    parts = []
    if "drag" in effects:
        d_t = sc.drag_tangential if sc.drag_tangential >= 0 else sc.drag_normal / 200.0
        parts.append(f"fluid d_N = {sc.drag_normal:g}, d_T = {d_t:g}")
    else:
        parts.append("no fluid drag")
    if "gravity" in effects:
        parts.append(f"gravity g = {sc.gravity:g}")
    if "ground" in effects:
        parts.append(
            f"floor at y = {sc.ground_height:g} (μ_s = {sc.ground_friction_static:g}, "
            f"μ_k = {sc.ground_friction_kinetic:g})"
        )
    if str(cfg["control.mode"]) == "grn":
        parts.append(f"GRN control ({cfg['control.actuation']})")
    source = chemical_source_of(cfg, sc)
    if source is not None:
        kind = sc.chemical if sc.chemical != "none" else "chemotaxis"
        trials = _swims_per_source(cfg)
        at = f"{kind} source at ({source[0]:.3g}, {source[1]:.3g}) from the start"
        if not trials:
            parts.append(at)
        elif source_trial is None:
            parts.append(f"{kind} source {float(np.hypot(*source)):g} from the start, {trials} directions")
        else:
            parts.append(f"{at} (swim {source_trial + 1} of {trials})")
    return "; ".join(parts)


def chemical_source_of(config: Any = None, scene: Any = None) -> Optional[np.ndarray]:
    """The chemical source ``scene.chemical_source`` (relative to the body's centre at the start of
    the swim) when the world has one: a GRN-controlled swim (``control.mode = "grn"``) sensing a
    ``point`` or ``plane`` field, or the objective ``chemotaxis`` (which scores progress toward it).
    None otherwise."""
    cfg = config if config is not None else _core.Config()
    sc = _scene_of(cfg, scene)
    sensed = str(cfg["control.mode"]) == "grn" and sc.chemical != "none"
    if not sensed and str(cfg["evaluation.objective"]) != "chemotaxis":
        return None
    return np.asarray(sc.chemical_source, dtype=float)


def objective_info(config: Any = None) -> Tuple[str, str, Optional[bool]]:
    """(name, meaning, nonnegative) of ``config``'s ``evaluation.objective``, from its row of
    :func:`animat.objectives`; a Python objective ``"python:NAME"`` gives ``NAME``, its meaning
    "Python objective NAME" and ``None`` for the sign (unknown)."""
    cfg = config if config is not None else _core.Config()
    name = str(cfg["evaluation.objective"])
    if name.startswith("python:"):
        short = name[len("python:") :]
        return short, f"Python objective {short}", None
    for spec in _core.objectives():
        if spec.name == name:
            return spec.name, spec.meaning, bool(spec.nonnegative)
    return name, name, None


def graph_name(config: Any = None, body: Any = None) -> str:
    """The body graph, as titles name it, from ``config``'s ``body.graph`` (default: animat
    defaults): "Gabriel graph", "distance graph (≤ t × neighbour distance)" (t =
    ``body.distance_threshold``) or "alpha-shape graph (α = a)" (a = ``body.alpha``). Without a
    config, a ``body`` whose springs are the Gabriel graph of its cells is "Gabriel graph" and any
    other "body graph"."""
    if config is None and body is not None:
        pos = np.asarray(body.positions)
        try:
            gabriel = np.asarray(_core.gabriel_graph(pos)).reshape(-1, 2)
        except ValueError:  # cells the Gabriel graph rejects (duplicates): not a Gabriel body
            return "body graph"
        same = np.array_equal(gabriel, np.asarray(body.springs).reshape(-1, 2))  # both sorted, i < j
        return "Gabriel graph" if same else "body graph"
    cfg = config if config is not None else _core.Config()
    graph = str(cfg["body.graph"])
    if graph == "gabriel":
        return "Gabriel graph"
    if graph == "distance":
        return f"distance graph (≤ {cfg['body.distance_threshold']:g} × neighbour distance)"
    if graph == "alpha_shape":
        return f"alpha-shape graph (α = {cfg['body.alpha']:g})"
    return f"{graph} graph"


def draw_world(
    ax: Axes,
    config: Any = None,
    *,
    scene: Any = None,
    start: ArrayLike = (0.0, 0.0),
    transform: Optional[Any] = None,
    extent: float = 1e4,
) -> Dict[str, Any]:
    """Draw the world around a body into ``ax``: the floor (effect ``ground``: a line at
    ``scene.ground_height``, label ``"floor"``, the ground below it shaded, label ``"ground"``) and
    the chemical source (a star at ``start + scene.chemical_source``, label ``"chemical source"``;
    see :func:`chemical_source_of`).

    Args:
        start: the body's centre of mass at the start of the swim (the source is relative to it).
        transform: a function mapping (k, 2) world points to the drawing's coordinates (default: none;
            :func:`animat.animate` and :func:`motion_cycle` rotate and shift the world with it).
        extent: half-length of the floor line along x.
    Returns:
        dict ``"floor"``, ``"ground"``, ``"source"``: the artists drawn (None where the world has none)
        and ``"source_xy"``, the source in drawing coordinates (or None).
    """
    cfg = config if config is not None else _core.Config()
    sc = _scene_of(cfg, scene)
    tf = transform if transform is not None else (lambda p: p)
    out: Dict[str, Any] = {"floor": None, "ground": None, "source": None, "source_xy": None}
    if "ground" in list(sc.effects):
        h = float(sc.ground_height)
        x0 = float(np.asarray(start, dtype=float)[0])
        line = tf(np.array([[x0 - extent, h], [x0 + extent, h]]))
        below = tf(np.array([[x0 - extent, h], [x0 + extent, h], [x0 + extent, h - extent], [x0 - extent, h - extent]]))
        out["ground"] = ax.add_patch(
            Polygon(below, closed=True, facecolor=GROUND_COLOR, edgecolor="none", zorder=0.5, label="ground")
        )
        (out["floor"],) = ax.plot(
            line[:, 0], line[:, 1], color=FLOOR_COLOR, lw=2.0, zorder=0.6, label="floor", scalex=False, scaley=False
        )
    source = chemical_source_of(cfg, sc)
    if source is not None:
        xy = tf((np.asarray(start, dtype=float) + source)[None, :])[0]
        out["source_xy"] = xy
        (out["source"],) = ax.plot(
            [xy[0]],
            [xy[1]],
            marker="*",
            ms=16,
            ls="",
            color=SOURCE_COLOR,
            mec="#7f3f00",
            mew=0.8,
            zorder=6,
            label="chemical source",
            scalex=False,
            scaley=False,
        )
    return out


def oscillator_phases_used(config: Any = None) -> bool:
    """Whether the developed oscillators' phases shape the swim: always in open loop (the paper's
    eq. 2) and under ``control.mode = "grn"`` with ``control.actuation = "amplitude"`` (the GRN sets
    the amplitudes of those oscillators); not with ``"direct"``, where the GRN writes every term u_i
    itself and no oscillator runs (docs/control.md)."""
    cfg = config if config is not None else _core.Config()
    return str(cfg["control.mode"]) != "grn" or str(cfg["control.actuation"]) != "direct"


#: :func:`motionless`: no cell moves farther than this fraction of the body length from its start.
MOTIONLESS_TOLERANCE = 1e-6


def motionless(trajectory: Trajectory, tolerance: float = MOTIONLESS_TOLERANCE) -> bool:
    """True when no cell of the swim moves farther from where it started than ``tolerance`` body
    lengths (``animat.body_length``): a body at rest for the whole swim."""
    pos = np.asarray(trajectory.positions)
    if len(pos) < 2:
        return True
    moved = float(np.linalg.norm(pos - pos[0], axis=2).max())
    return moved <= tolerance * float(_core.body_length(trajectory.body))


def _warn_if_motionless(trajectory: Trajectory, caller: str) -> None:
    """Warn that a figure of ``trajectory`` shows a body at rest (see :func:`motionless`)."""
    if motionless(trajectory):
        steps = int(trajectory.steps[-1] - trajectory.steps[0]) if len(trajectory.steps) else 0
        warnings.warn(
            f"{caller}: the body does not move (no cell moves in the {steps} steps of the swim). A run's best is "
            "such a body while nothing that moves has scored better: a short run, or an objective that "
            "standing still does not lose (chemotaxis)",
            UserWarning,
            stacklevel=3,
        )


# --- helpers ------------------------------------------------------------------------------------------


def rotation_to(direction: ArrayLike, target: ArrayLike = (1.0, 0.0)) -> np.ndarray:
    """The 2×2 rotation matrix R with ``R @ direction`` parallel to ``target`` (default +x).

    Use it as ``positions @ R.T`` on (…, 2) arrays."""
    d = np.asarray(direction, dtype=float)
    t = np.asarray(target, dtype=float)
    angle = math.atan2(t[1], t[0]) - math.atan2(d[1], d[0])
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


def _segments(positions: np.ndarray, pairs: np.ndarray) -> List[np.ndarray]:
    """Line segments of index pairs, as LineCollection takes them."""
    return [positions[pair] for pair in np.asarray(pairs).reshape(-1, 2)]


def _node_radius(body) -> float:
    L0 = np.asarray(body.rest_lengths)
    return 0.22 * float(np.median(L0)) if len(L0) else 0.25


def _loops_closed(positions, loops):
    return [positions[np.append(loop, loop[0])] for loop in loops if len(loop)]


def draw_body(
    ax: Axes,
    body: Any,
    positions: Optional[np.ndarray] = None,
    node_colors: Any = "#444444",
    *,
    node_radius: Optional[float] = None,
    fill: bool = True,
    springs: bool = True,
    spring_colors: Any = SPRING_COLOR,
    skin_width: float = 2.2,
    spring_width: float = 0.8,
    node_edge: str = "#222222",
    zorder: float = 2.0,
    label: str = "nodes",
) -> Dict[str, Any]:
    """Draw one body into ``ax``: light region fill, springs (thin), skin (thick) and nodes.

    Args:
        ax: a matplotlib Axes (its aspect is not changed).
        body: an :class:`animat.Body` (springs, skin loops, regions).
        positions: (n, 2) node positions (default: ``body.positions``, the rest state).
        node_colors: one colour or a sequence of n colours.
        node_radius: node disc radius in data units (default 0.22 × median spring rest length).
        fill, springs: draw the region fill / the springs.
        spring_colors: one colour or m colours.

    Returns:
        dict of the artists: ``"fill"`` (PolyCollection or None), ``"springs"`` and ``"skin"``
        (LineCollection), ``"nodes"`` (EllipseCollection with label ``label``, facecolors in node
        order) — update them for animation.
    """
    pos = np.asarray(body.positions if positions is None else positions, dtype=float)
    r = _node_radius(body) if node_radius is None else node_radius
    out: Dict[str, Any] = {"fill": None}
    if fill and len(body.regions):
        out["fill"] = PolyCollection(
            [pos[reg] for reg in body.regions], facecolors=FILL_COLOR, edgecolors="none", zorder=zorder - 0.3
        )
        ax.add_collection(out["fill"])
    sp = np.asarray(body.springs)
    out["springs"] = LineCollection(
        _segments(pos, sp if springs else sp[:0]), colors=spring_colors, linewidths=spring_width, zorder=zorder - 0.2
    )
    ax.add_collection(out["springs"])
    out["skin"] = LineCollection(
        _loops_closed(pos, body.skin_loops),
        colors=SKIN_COLOR,
        linewidths=skin_width,
        capstyle="round",
        joinstyle="round",
        zorder=zorder - 0.1,
    )
    ax.add_collection(out["skin"])
    n = len(pos)
    out["nodes"] = EllipseCollection(
        np.full(n, 2 * r),
        np.full(n, 2 * r),
        np.zeros(n),
        units="xy",
        offsets=pos,
        offset_transform=ax.transData,
        facecolors=node_colors,
        edgecolors=node_edge,
        linewidths=0.5,
        zorder=zorder,
        label=label,
    )
    ax.add_collection(out["nodes"])
    return out


def _frame_axes(ax, lo, hi, pad):
    ax.set_aspect("equal")
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_xticks([])
    ax.set_yticks([])
    for s in ax.spines.values():
        s.set_color("#bbbbbb")


# --- Fig. 2: development --------------------------------------------------------------------------------


def development_steps(embryo_or_trace) -> list:
    """Default steps for :func:`development`: the first cell, every division round (daughters still
    overlapping), 30 steps after the last division (pushed apart, paper Fig. 2e) and the end."""
    trace = getattr(embryo_or_trace, "trace", None) or embryo_or_trace
    steps = list(trace.steps)
    if hasattr(embryo_or_trace, "division_steps"):
        divisions = sorted(set(embryo_or_trace.division_steps))
    else:
        counts = [len(p) for p in trace.positions]
        divisions = [steps[k] for k in range(1, len(steps)) if counts[k] != counts[k - 1]]
    end = steps[-1]
    picks = [steps[0]] + divisions + ([divisions[-1] + 30] if divisions else []) + [end]
    available = set(steps)
    chosen = []
    for s in sorted(set(picks)):
        if s not in available:  # trace recorded every k steps: nearest snapshot at or after s
            later = [x for x in steps if x >= s]
            s = later[0] if later else end
        if s not in chosen:
            chosen.append(s)
    if len(chosen) > 12:  # many division rounds: keep the first, the last three and an even spread
        keep = np.unique(np.linspace(0, len(chosen) - 4, 8).round().astype(int)).tolist() + list(
            range(len(chosen) - 3, len(chosen))
        )
        chosen = [chosen[k] for k in sorted(set(keep))]
    return chosen


def development(
    embryo_or_trace: Any,
    steps: Optional[Sequence[int]] = None,
    *,
    config: Optional[Any] = None,
    cols: int = 4,
    title: Optional[str] = None,
) -> Figure:
    """Paper Fig. 2: the embryo at chosen development steps, cells as circles with a short line
    along each cell's orientation vector, all panels at the same scale.

    Args:
        embryo_or_trace: an :class:`animat.DevelopmentTrace`, an :class:`animat.Embryo` developed
            with ``config.development.trace_every > 0``, or an :class:`animat.Genome` /
            LineageEntry (developed here with ``config`` and ``trace_every = 1``).
        steps: development steps to draw (must be recorded in the trace; default
            :func:`development_steps`).
        config: config for developing a genome (default: animat defaults).
        cols: panels per row.
    Returns:
        The Figure, one Axes per step, titled "step s (k cells)".
    Raises:
        ValueError: an embryo without a trace, or a step that is not in the trace.
    """
    embryo = None
    if hasattr(embryo_or_trace, "genome") and not isinstance(embryo_or_trace, _core.Genome):
        embryo_or_trace = embryo_or_trace.genome
    if isinstance(embryo_or_trace, _core.Genome):
        cfg = (config if config is not None else _core.Config()).copy()
        cfg["development.trace_every"] = 1
        embryo_or_trace = _core.develop(embryo_or_trace, cfg)
    if isinstance(embryo_or_trace, _core.Embryo):
        embryo = embryo_or_trace
        if embryo.trace is None:
            raise ValueError(
                "development: this Embryo has no trace; develop it with "
                "config['development.trace_every'] = 1 (or pass the genome)"
            )
        trace = embryo.trace
    else:
        trace = embryo_or_trace
    steps = list(steps) if steps is not None else development_steps(embryo if embryo is not None else trace)
    index = {s: k for k, s in enumerate(trace.steps)}
    missing = [s for s in steps if s not in index]
    if missing:
        raise ValueError(
            f"development: steps {missing} are not in the trace (recorded: {trace.steps[0]}.."
            f"{trace.steps[-1]} every {trace.steps[1] - trace.steps[0] if len(trace.steps) > 1 else 1})"
        )
    if not steps:
        raise ValueError("development: no steps to draw")
    last = index[max(steps)]
    centre = trace.positions[last].mean(axis=0)
    half = (
        np.max(
            [np.abs(trace.positions[index[s]] - centre).max(axis=0) + np.max(trace.radii[index[s]]) for s in steps],
            axis=0,
        )
        * 1.08
    )  # (2,) half-extent of the common frame
    half = np.maximum(half, 0.35 * half.max())
    cols = max(1, min(cols, len(steps)))
    rows = (len(steps) + cols - 1) // cols
    panel_w = 2.1
    panel_h = float(np.clip(panel_w * half[1] / half[0], 0.9, 2.6))
    fig = plt.figure(figsize=(panel_w * cols, (panel_h + 0.35) * rows + 0.45))
    axes = fig.subplots(rows, cols, squeeze=False)
    for ax in axes.flat[len(steps) :]:
        ax.set_visible(False)
    for ax, s, letter in zip(axes.flat, steps, "abcdefghijklmnopqrstuvwxyz"):
        k = index[s]
        pos, radii, orient = trace.positions[k], trace.radii[k], trace.orientations[k]
        ax.add_collection(
            PatchCollection(
                [Circle(p, r) for p, r in zip(pos, radii)], facecolor="#cfe3f7", edgecolor="#1f4e79", linewidth=0.8
            )
        )
        ax.add_collection(
            LineCollection([(p, p + r * o) for p, r, o in zip(pos, radii, orient)], colors="#b22222", linewidths=1.2)
        )
        _frame_axes(ax, centre - half, centre + half, 0.0)
        ax.set_title(f"step {s} ({len(radii)} cell{'s' if len(radii) != 1 else ''})", fontsize=9)
        ax.text(0.03, 0.97, f"({letter})", transform=ax.transAxes, va="top", fontsize=8)
    fig.suptitle(title or "Development (paper Fig. 2): cells and their orientation vectors", fontsize=10)
    fig.tight_layout(h_pad=1.0)
    return fig


# --- Fig. 3: construction -------------------------------------------------------------------------------


def construction(
    embryo_or_points: Any,
    radii: Optional[np.ndarray] = None,
    *,
    config: Optional[Any] = None,
    title: Optional[str] = None,
) -> Figure:
    """Paper Fig. 3: (a) cell centres at the end of development, (b) their Delaunay
    triangulation, (c) the body graph (the paper's Gabriel graph, or ``config``'s ``body.graph``,
    named in the title by :func:`graph_name`), the final structure, with its regions shaded (one
    colour each) and the skin (the only edges that feel drag) drawn thick.

    Args:
        embryo_or_points: an :class:`animat.Embryo`, a Genome / LineageEntry (developed with
            ``config``), a :class:`animat.Body`, or an (n, 2) array of cell centres.
        radii: (n,) cell radii for panel (a) (default: the embryo's, else 0.5).
        config: config for developing / building (default: animat defaults).
    Returns:
        The Figure with three Axes.
    """
    thing = embryo_or_points
    if hasattr(thing, "genome") and not isinstance(thing, _core.Genome):
        thing = thing.genome
    if isinstance(thing, _core.Genome):
        thing = _core.develop(thing, config)
    if isinstance(thing, _core.Embryo):
        pos = np.asarray(thing.positions)
        radii = np.asarray(thing.radii) if radii is None else np.asarray(radii)
        body = _core.build_body(thing, config)
    elif isinstance(thing, _core.Body):
        pos = np.asarray(thing.positions)
        body = thing
    else:
        pos = np.asarray(thing, dtype=float)
        body = _core.build_body(pos, config=config)
    if radii is None:
        radii = np.full(len(pos), 0.5)
    delaunay = np.asarray(_core.delaunay_edges(pos, config))
    graph = graph_name(config, body if config is None and isinstance(thing, _core.Body) else None)

    pad = float(np.max(radii)) + 0.3
    lo, hi = pos.min(axis=0), pos.max(axis=0)
    ext = hi - lo + 2 * pad
    panel_h = float(np.clip(3.8 * ext[1] / max(ext[0], 1e-9), 1.6, 5.0))
    fig = plt.figure(figsize=(12, panel_h + 1.1))
    axes = fig.subplots(1, 3)
    for ax in axes:
        _frame_axes(ax, lo, hi, pad)

    ax = axes[0]
    ax.add_collection(
        PatchCollection(
            [Circle(p, r) for p, r in zip(pos, radii)], facecolor="#dde8f3", edgecolor="#8aa6c1", linewidth=0.6
        )
    )
    ax.plot(pos[:, 0], pos[:, 1], "o", color="k", ms=3.5)
    ax.set_title(f"(a) cell centres ({len(pos)} cells)", fontsize=10)

    ax = axes[1]
    ax.add_collection(LineCollection(_segments(pos, delaunay), colors="#555555", linewidths=0.9))
    ax.plot(pos[:, 0], pos[:, 1], "o", color="k", ms=3.5)
    ax.set_title(f"(b) Delaunay triangulation ({len(delaunay)} edges)", fontsize=10)

    ax = axes[2]
    cmap = plt.get_cmap("Pastel1")
    if body.region_count:
        ax.add_collection(
            PatchCollection(
                [Polygon(pos[r]) for r in body.regions],
                facecolor=[cmap(k % 9) for k in range(body.region_count)],
                edgecolor="none",
            )
        )
    springs = np.asarray(body.springs)
    ax.add_collection(LineCollection(_segments(pos, springs), colors="#555555", linewidths=0.9))
    skin = np.asarray(body.skin)
    ax.add_collection(LineCollection(_segments(pos, skin), colors="#b2182b", linewidths=2.8, capstyle="round"))
    ax.plot(pos[:, 0], pos[:, 1], "o", color="k", ms=3.5, zorder=3)
    ax.set_title(
        f"(c) {graph}: {body.spring_count} springs,\n{body.region_count} regions (shaded), "
        f"{len(skin)} skin edges (thick)",
        fontsize=10,
    )
    fig.suptitle(title or "From embryo to body (paper Fig. 3)", fontsize=11)
    fig.tight_layout()
    return fig


# --- Figs. 4-6: motion cycle ----------------------------------------------------------------------------


def _has_down(trajectory: Trajectory) -> bool:
    """True when the trajectory's world has a fixed "down" (effect ``gravity`` or ``ground``)."""
    effects = list(_scene_of(trajectory.config, trajectory.meta.get("scene")).effects)
    return "gravity" in effects or "ground" in effects


def motion_cycle(
    trajectory: Trajectory,
    frames: Optional[Sequence[int]] = None,
    *,
    count: int = 6,
    align: Optional[bool] = None,
    cols: Optional[int] = None,
    color_springs: bool = False,
    title: Optional[str] = None,
) -> Figure:
    """Paper Figs. 4–6: snapshots of one motion cycle. Node colour is the cell's actuation state
    from eq. 2 (``trajectory.node_state``): red expanding, blue contracting, green neutral
    (:data:`STATE_COLORS`). The skin is drawn thick, springs thin, and an arrow in each panel
    marks the overall direction of motion.

    Args:
        trajectory: from :func:`animat.replay` (record with ``every`` small enough to resolve the
            cycle; the default ``every=1`` does).
        frames: frame indices (into the trajectory) to draw; default
            ``trajectory.cycle_frames(count)``, ``count`` frames spread over the last dominant
            oscillation period.
        align: rotate every snapshot so that the overall direction of motion points right, as in
            the paper (the same rotation for all panels). Default: True, but False in a world with
            gravity or a floor (down stays down; the floor, effect ``ground``, is drawn at its height).
        cols: panels per row (default: all in one row up to 6).
        color_springs: colour the springs by ``trajectory.spring_state`` instead of grey.
    Returns:
        The Figure; panel k shows ``frames[k]``, titled with its control step, and its node
        collection (label ``"nodes"``) has node i's facecolour ``STATE_COLORS[node_state[frame, i]]``.
    """
    tr = trajectory
    frames = list(tr.cycle_frames(count) if frames is None else frames)
    if not frames:
        raise ValueError("motion_cycle: no frames to draw")
    _warn_if_motionless(tr, "motion_cycle")
    for f in frames:
        if not -tr.frame_count <= f < tr.frame_count:
            raise ValueError(f"motion_cycle: frame {f} out of range (trajectory has {tr.frame_count} frames)")
    if align is None:
        align = not _has_down(tr)
    rot = rotation_to(tr.direction) if align else np.eye(2)
    direction = rot @ tr.direction
    origin = tr.com[frames[0]] if align else np.zeros(2)  # unrotated: world coordinates (the floor's height)
    snaps = [(tr.positions[f] - origin) @ rot.T for f in frames]
    allpts = np.concatenate(snaps)
    r = _node_radius(tr.body)
    lo, hi = allpts.min(axis=0), allpts.max(axis=0)
    ext = hi - lo + 2 * (r + 0.4)
    cols = cols or min(len(frames), 6)
    rows = (len(frames) + cols - 1) // cols
    panel_w = 2.2 if cols > 3 else 3.0
    panel_h = float(np.clip(panel_w * ext[1] / ext[0], 1.2, 4.0))
    fig = plt.figure(figsize=(panel_w * cols, panel_h * rows + 1.0))
    axes = fig.subplots(rows, cols, squeeze=False)
    for ax in axes.flat[len(frames) :]:
        ax.set_visible(False)
    steps0 = int(tr.steps[frames[0]])
    world: Dict[str, Any] = {"floor": None}
    for ax, f, pos in zip(axes.flat, frames, snaps):
        colors = [STATE_COLORS[int(s)] for s in tr.node_state[f]]
        scol = [STATE_COLORS[int(s)] for s in tr.spring_state[f]] if color_springs else SPRING_COLOR
        draw_body(ax, tr.body, pos, colors, node_radius=r, spring_colors=scol)
        world = draw_world(
            ax, tr.config, scene=tr.meta.get("scene"), start=tr.com[0], transform=lambda p: (p - origin) @ rot.T
        )
        _frame_axes(ax, lo, hi, r + 0.4)
        ax.set_title(f"step {int(tr.steps[f])}", fontsize=9)
        ax.text(0.02, 0.03, f"+{int(tr.steps[f]) - steps0}", transform=ax.transAxes, fontsize=7, color="#666666")
        ax.annotate(
            "",
            xy=(0.93 + 0.05 * direction[0], 0.12 + 0.05 * direction[1] * panel_w / panel_h),
            xytext=(0.93 - 0.05 * direction[0], 0.12 - 0.05 * direction[1] * panel_w / panel_h),
            xycoords="axes fraction",
            arrowprops=dict(arrowstyle="-|>", color="#555555", lw=1.2),
        )
    handles = [
        Line2D(
            [],
            [],
            marker="o",
            ls="",
            markerfacecolor=STATE_COLORS[s],
            markeredgecolor="#222222",
            markersize=8,
            label=STATE_NAMES[s],
        )
        for s in (EXPANDING, CONTRACTING, NEUTRAL)
    ]
    handles.append(Line2D([], [], color=SKIN_COLOR, lw=2.2, label="skin"))
    handles.append(
        Line2D(
            [],
            [],
            marker=r"$\rightarrow$",
            ls="",
            color="#555555",
            markersize=12,
            label="direction of motion" + (" (rotated to point right)" if align else ""),
        )
    )
    if world["floor"] is not None:
        handles.append(Line2D([], [], color=FLOOR_COLOR, lw=2.0, label="floor"))
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8, frameon=False)
    period = tr.period()
    cycle = f"dominant period {period / tr.dt:.0f} steps" if math.isfinite(period) else "no oscillation"
    source = chemical_source_of(tr.config, tr.meta.get("scene"))
    toward = ""
    if source is not None and tr.meta.get("source_trial") is not None:  # one swim of a chemotaxis evaluation
        gain = float(np.linalg.norm(source) - np.linalg.norm(source - tr.displacement))
        toward = f" ({gain:.3g} toward the source)"
    fig.suptitle(
        title
        or f"Motion cycle (paper Figs. 4-6): steps {int(tr.steps[frames[0]])}-"
        f"{int(tr.steps[frames[-1]])}, {cycle}; distance {tr.distance:.3g}{toward} in "
        f"{int(tr.steps[-1] - tr.steps[0])} steps\n"
        f"{world_text(tr.config, tr.meta.get('scene'), source_trial=tr.meta.get('source_trial'))}",
        fontsize=9.5,
    )
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    return fig


# --- Fig. 7: phase map ----------------------------------------------------------------------------------


def _map_axes(ax: Optional[Axes], extent: np.ndarray, colorbar: bool) -> Tuple[Figure, Axes]:
    """The figure and axes of a body map (phase_map, stiffness_map): ``ax`` and its figure, or a new
    figure sized to the body's ``extent`` (width, height incl. padding) with room for a colour bar."""
    if ax is None:
        h = 3.6
        w = float(np.clip(h * extent[0] / max(extent[1], 1e-9), 2.5, 8.0)) + (1.1 if colorbar else 0.2)
        fig = plt.figure(figsize=(w, h + 0.5))
        return fig, fig.add_subplot()
    fig = ax.get_figure(root=True) if matplotlib.__version_info__ >= (3, 10) else ax.figure  # type: ignore[call-arg]
    assert isinstance(fig, Figure)
    return fig, ax


def _label_max(ax: Axes, pos: np.ndarray, k: int, lo: np.ndarray, hi: np.ndarray, value: float) -> None:
    """Label node k of a body map "max <value>", the label pushed outward from the body's centre."""
    toward = (lo + hi) / 2 - pos[k]
    toward = toward / (np.linalg.norm(toward) or 1.0)
    ax.annotate(
        f"max {value:.2f}",
        xy=pos[k],
        xytext=tuple(22 * toward),
        textcoords="offset points",
        fontsize=8,
        ha="left" if toward[0] > 0.3 else ("right" if toward[0] < -0.3 else "center"),
        va="bottom" if toward[1] > 0.3 else ("top" if toward[1] < -0.3 else "center"),
        arrowprops=dict(arrowstyle="-", color="#444444", lw=0.8),
        bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="#999999", lw=0.5, alpha=0.9),
        zorder=5,
    )


def phase_map(
    body: Any,
    *,
    config: Optional[Any] = None,
    ax: Optional[Axes] = None,
    cmap: str = PHASE_CMAP,
    colorbar: bool = True,
    title: Optional[str] = None,
) -> Figure:
    """Paper Fig. 7: the body at rest (its initial, equilibrium state) with every node coloured by
    its oscillation phase shift. The colour range is normalised to the body's phases
    (``vmin = phase.min()``, ``vmax = phase.max()``) and the maximum (the red node) is written
    next to it and in the title. When all phases are equal every node is red and the range is
    ``[max - 1, max]``; the title says "all equal".

    Under ``control.mode = "grn"`` with ``control.actuation = "direct"`` (``config``) no oscillator
    runs, so no phase drives the swim (:func:`oscillator_phases_used`): the figure has no phase map,
    only a text saying so (a figure with no Axes; with ``ax``, that Axes turned off with the text).

    Args:
        body: an :class:`animat.Body`, Embryo, Genome / LineageEntry (developed with ``config``)
            or a Trajectory.
        ax: draw into this Axes (default: a new Figure).
        cmap: matplotlib colour map name (default ``"jet"``: blue low, red maximum).
        colorbar: add a colour bar (radians).
    Returns:
        The Figure. The node collection (label ``"nodes"``) carries the phases as its array and
        the Normalize as its ``norm``.
    """
    if not oscillator_phases_used(config if config is not None else getattr(body, "config", None)):
        note = (
            "No phase map: under GRN control with control.actuation = 'direct'\nthe GRN writes every "
            "cell's term u_i while swimming;\nno oscillator runs, so no phase drives the swim"
        )
        if ax is None:
            fig = plt.figure(figsize=(5.0, 1.6))
            fig.text(0.5, 0.5, note, ha="center", va="center", fontsize=9, label="no phase map")
            return fig
        ax.set_axis_off()
        ax.text(0.5, 0.5, note, ha="center", va="center", fontsize=8, transform=ax.transAxes, label="no phase map")
        return _map_axes(ax, np.ones(2), False)[0]
    body = body_of(body, config)
    phase = np.asarray(body.phase, dtype=float)
    pos = np.asarray(body.positions)
    standalone = ax is None
    r = _node_radius(body)
    pad = r + 0.5
    lo, hi = pos.min(axis=0), pos.max(axis=0)
    fig, ax = _map_axes(ax, hi - lo + 2 * pad, colorbar)
    vmin, vmax = (float(phase.min()), float(phase.max())) if len(phase) else (0.0, 1.0)
    # all phases equal: every node is the maximum (red); the colour range is then [max - 1, max]
    norm = Normalize(vmin=vmin if vmax > vmin else vmax - 1.0, vmax=vmax)
    artists = draw_body(ax, body, pos, "#ffffff")
    nodes = artists["nodes"]
    nodes.set_array(phase)
    nodes.set_cmap(cmap)
    nodes.set_norm(norm)
    nodes.update_scalarmappable()  # facecolours now, not only at draw time
    _frame_axes(ax, lo, hi, pad)
    if len(phase):
        k = int(np.argmax(phase))
        _label_max(ax, pos, k, lo, hi, vmax)
    if colorbar:
        cb = fig.colorbar(nodes, ax=ax, fraction=0.045, pad=0.03)
        cb.set_label("phase shift φ (rad)", fontsize=8)
        cb.ax.tick_params(labelsize=7)
    ax.set_title(
        title
        if title is not None
        else (
            f"Phase shifts (paper Fig. 7)\nmax φ = {vmax:.2f} rad"
            + (" (all equal)" if vmax == vmin else f", min {vmin:.2f} rad")
        ),
        fontsize=9,
    )
    if standalone:
        fig.tight_layout()
    return fig


# --- stiffness map, the phase map's sibling ---------------------------------------------------------------


def stiffness_map(
    body: Any,
    *,
    config: Optional[Any] = None,
    ax: Optional[Axes] = None,
    cmap: str = STIFFNESS_CMAP,
    colorbar: bool = True,
    title: Optional[str] = None,
) -> Figure:
    """The sibling of :func:`phase_map` (paper Fig. 7 style) for evolved stiffness: the body at rest
    with every node coloured by its stiffness factor f (GRN output ``stiffness``) and every spring by
    its own factor, the harmonic mean 2 f_i f_j / (f_i + f_j) of its two cells (its stiffness is
    ``scene.spring_stiffness`` times that). Colours are on a logarithmic scale over the body's
    factors; the stiffest node is annotated. A body without evolved stiffness (``body.stiffness``
    empty: the paper's uniform springs) is drawn with factor 1 everywhere and says so in the title.

    Args:
        body: an :class:`animat.Body`, Embryo, Genome / LineageEntry (developed with ``config``)
            or a Trajectory.
        ax: draw into this Axes (default: a new Figure).
        cmap: matplotlib colour map name (default ``"viridis_r"``: soft light, stiff dark).
        colorbar: add a colour bar (factor, log scale).
    Returns:
        The Figure. The node collection (label ``"nodes"``) carries the node factors as its array,
        the spring collection the spring factors; both share one LogNorm.
    """
    from matplotlib.colors import LogNorm

    body = body_of(body, config)
    pos = np.asarray(body.positions)
    n = len(pos)
    f = np.asarray(getattr(body, "stiffness", np.empty(0)), dtype=float)
    uniform = len(f) != n
    if uniform:
        f = np.ones(n)
    sp = np.asarray(body.springs, dtype=np.int64).reshape(-1, 2)
    fs = 2.0 * f[sp[:, 0]] * f[sp[:, 1]] / (f[sp[:, 0]] + f[sp[:, 1]]) if len(sp) else np.empty(0)
    standalone = ax is None
    r = _node_radius(body)
    pad = r + 0.5
    lo, hi = pos.min(axis=0), pos.max(axis=0)
    fig, ax = _map_axes(ax, hi - lo + 2 * pad, colorbar)
    vmin, vmax = (float(f.min()), float(f.max())) if n else (1.0, 1.0)
    norm = LogNorm(vmin=vmin if vmax > vmin else vmax / 2.0, vmax=vmax)
    artists = draw_body(ax, body, pos, "#ffffff", spring_width=2.0)
    springs = artists["springs"]
    springs.set_array(fs)
    springs.set_cmap(cmap)
    springs.set_norm(norm)
    # draw_body gave the springs an explicit colour, which matplotlib keeps over the mapping: set the
    # mapped colours explicitly.
    springs.set_edgecolor(plt.get_cmap(cmap)(norm(fs)) if len(fs) else "none")
    nodes = artists["nodes"]
    nodes.set_array(f)
    nodes.set_cmap(cmap)
    nodes.set_norm(norm)
    nodes.update_scalarmappable()
    _frame_axes(ax, lo, hi, pad)
    if n and not uniform:
        k = int(np.argmax(f))
        _label_max(ax, pos, k, lo, hi, vmax)
    if colorbar:
        cb = fig.colorbar(nodes, ax=ax, fraction=0.045, pad=0.03)
        cb.set_label("stiffness factor f (× k)", fontsize=8)
        cb.ax.tick_params(labelsize=7)
    if title is None:
        title = (
            "Stiffness (uniform: no evolved stiffness)"
            if uniform
            else f"Evolved stiffness\nfactor {vmin:.2f} to {vmax:.2f} (× spring_stiffness)"
        )
    ax.set_title(title, fontsize=9)
    if standalone:
        fig.tight_layout()
    return fig


# --- Figs. 8-9: fitness history ------------------------------------------------------------------------


def fitness_history(
    run: Any,
    *,
    max_thumbnails: int = 6,
    tolerance: float = MORPHOLOGY_TOLERANCE,
    show_mean: bool = True,
    title: Optional[str] = None,
) -> Figure:
    """Paper Figs. 8–9: the best fitness over generations, with the generations at which the best
    individual's morphology changed marked, and thumbnails of those bodies (at rest, nodes
    coloured by phase shift, each thumbnail normalised like :func:`phase_map`; plain nodes when
    all cells have the same phase) joined to their point on the curve. The y axis is labelled with
    the run's objective (``evaluation.objective``, :func:`objective_info`) and starts at 0 only when
    no value drawn is negative: a signed objective (speed_toward, distance_minus_energy,
    chemotaxis, a Python one) is drawn whole, with 0 marked.

    Under GRN control with ``control.actuation = "direct"`` the thumbnails are plain (no phase drives
    those swims, :func:`oscillator_phases_used`). The layout is matplotlib's constrained one: the axis
    labels and the two-line title stay inside the figure whatever the width of the tick labels.

    Args:
        run: an :class:`animat.Run` or a run directory path.
        max_thumbnails: at most this many thumbnails (always the first and the last morphology;
            the others evenly spread over the changes). Every change is still marked on the curve.
        tolerance: morphology-change tolerance, see :meth:`animat.Run.morphology_changes`.
        show_mean: also draw the population's mean fitness (thin grey).
    Returns:
        The Figure: the main Axes (label ``"fitness"``) and one small Axes per thumbnail.
    """
    run = run if isinstance(run, Run) else Run(run)
    cfg = run.config
    hist = run.history
    lineage = run.best_genomes
    changes = run.morphology_changes(tolerance, cfg) if lineage else []

    k = min(len(changes), max(0, max_thumbnails))
    if k and len(changes) > k:
        idx = np.unique(np.linspace(0, len(changes) - 1, k).round().astype(int))
        shown = [changes[i] for i in idx]
    else:
        shown = changes[:k]

    fig = plt.figure(figsize=(10, 6.2 if shown else 4.2), layout="constrained")
    gs: Any = None
    if shown:
        gs = fig.add_gridspec(2, max(len(shown), 1), height_ratios=[1.0, 1.5])
        main = fig.add_subplot(gs[1, :])
    else:
        main = fig.add_subplot()
    main.set_label("fitness")
    gens = hist["generation"] if len(hist) else np.array([e.generation for e in lineage])
    best = hist["best"] if len(hist) else np.array([e.fitness for e in lineage])
    if len(gens):
        main.plot(gens, best, drawstyle="steps-post", color="#1f4e79", lw=1.6, label="best fitness")
        if show_mean and len(hist):
            main.plot(gens, hist["mean"], color="#999999", lw=0.9, label="mean fitness (viable)")
    lg = [e.generation for e in lineage]
    lf = [e.fitness for e in lineage]
    if lineage:
        main.plot(lg, lf, "o", ms=3.5, color="#1f4e79", label="new best individual")
    cg = [e.generation for e in changes]
    cf = [e.fitness for e in changes]
    for g in cg:
        main.axvline(g, color="#d62728", lw=0.6, ls=":", zorder=0)
    if changes:
        main.plot(cg, cf, "D", ms=6, mfc="#d62728", mec="k", mew=0.6, label="morphology changed", zorder=4)
    main.set_xlabel("generation")
    objective, meaning, nonnegative = objective_info(cfg)
    main.set_ylabel(f"fitness: {objective}")
    main.set_title(f"objective {objective}: {meaning}", fontsize=8, loc="left", color="#444444")
    main.grid(alpha=0.25)
    main.legend(fontsize=8, loc="upper left")
    main.xaxis.set_major_locator(MaxNLocator(integer=True))
    if len(gens):
        span = max(float(gens[-1] - gens[0]), 1.0)
        main.set_xlim(float(gens[0]) - 0.02 * span, float(gens[-1]) + 0.02 * span)
    shown_values = [np.asarray(ln.get_ydata(), dtype=float) for ln in main.get_lines()]
    lowest = min((float(np.nanmin(v)) for v in shown_values if v.size and np.isfinite(v).any()), default=0.0)
    if lowest >= 0.0 and nonnegative is not False:
        main.set_ylim(bottom=0)  # a non-negative objective (or values): the axis starts at 0
    else:  # a signed objective can go below 0: nothing clipped, 0 marked
        main.axhline(0.0, color="#777777", lw=0.7, zorder=0)

    for col, entry in enumerate(shown):
        ax = fig.add_subplot(gs[0, col])
        try:
            body = body_of(entry, cfg)
        except ValueError:
            ax.set_axis_off()
            continue
        ph = np.asarray(body.phase)
        if len(ph) and np.ptp(ph) > 0 and oscillator_phases_used(cfg):
            phase_map(body, ax=ax, colorbar=False, title="")
            for t in list(ax.texts):
                t.remove()
            note = f"φ {ph.min():.2f}-{ph.max():.2f}"
        else:  # no phase shift among the cells (paper Fig. 8: such bodies are not coloured), or none used
            pos = np.asarray(body.positions)
            draw_body(ax, body, pos, "#f2f2f2")
            _frame_axes(ax, pos.min(axis=0), pos.max(axis=0), _node_radius(body) + 0.5)
            note = "no phase shift" if oscillator_phases_used(cfg) else "GRN control (direct)"
        ax.set_title(f"gen {entry.generation}: {entry.fitness:.3g}\n{note}", fontsize=8)
        con = ConnectionPatch(
            xyA=(0.5, 0.0),
            coordsA=ax.transAxes,
            xyB=(entry.generation, entry.fitness),
            coordsB=main.transData,
            color="#d62728",
            lw=0.7,
            alpha=0.7,
        )
        fig.add_artist(con)
    n_changes = len(changes)
    coloured = "nodes coloured by phase" if oscillator_phases_used(cfg) else "plain nodes"
    fig.suptitle(
        title
        or f"Fitness history (paper Figs. 8-9): {run.path.name}\n{len(hist)} generations, "
        f"{len(lineage)} improvement{'' if len(lineage) == 1 else 's'}, "
        f"{n_changes} morpholog{'y' if n_changes == 1 else 'ies'}"
        f"{f' ({len(shown)} shown, {coloured})' if shown else ''}",
        fontsize=10,
    )
    return fig


def genealogy(run: Any, id: Optional[int] = None, *, title: Optional[str] = None) -> Figure:
    """The family tree of the best (or of individual ``id``): every ancestor recorded in the run's
    ``genealogy.csv`` (:meth:`animat.Run.ancestry`) at its generation of birth and fitness, joined to
    its parents (solid: the first parent, dashed: the second of a crossover); the line of first
    parents back to generation 0 is drawn bold, over the run's best fitness per generation (grey).

    Returns:
        The Figure; its Axes is labelled ``"genealogy"``. Raises ValueError for a run without a
        genealogy (made before it was recorded).
    """
    run = run if isinstance(run, Run) else Run(run)
    tree = run.ancestry(id)
    by_id = {int(r["id"]): r for r in tree}
    fig, ax = plt.subplots(figsize=(9, 4.6))
    ax.set_label("genealogy")
    hist = run.history
    if len(hist):
        ax.plot(hist["generation"], hist["best"], drawstyle="steps-post", color="0.75", lw=1.0, label="best fitness")
    solid, dashed = [], []
    for r in tree:
        child = (float(r["generation"]), float(r["fitness"]))
        for parent, segments in ((int(r["parent_a"]), solid), (int(r["parent_b"]), dashed)):
            if parent in by_id:
                p = by_id[parent]
                segments.append([(float(p["generation"]), float(p["fitness"])), child])
    ax.add_collection(LineCollection(solid, colors="#7f9fbf", linewidths=0.8))
    ax.add_collection(LineCollection(dashed, colors="#bf9f7f", linewidths=0.8, linestyles="dashed"))
    line, current = [], tree[0]
    while True:
        line.append((float(current["generation"]), float(current["fitness"])))
        parent = int(current["parent_a"])
        if parent not in by_id:
            break
        current = by_id[parent]
    line_arr = np.array(line)
    ax.plot(line_arr[:, 0], line_arr[:, 1], color="#1f4e79", lw=1.8, label="first parents")
    ax.scatter(tree["generation"], tree["fitness"], s=8, color="#1f4e79", zorder=3, label="ancestors")
    ax.scatter([line[0][0]], [line[0][1]], s=40, color="#c0392b", zorder=4, label=f"individual {int(tree[0]['id'])}")
    name, _, _ = objective_info(run.config)
    ax.set_xlabel("generation of birth")
    ax.set_ylabel(f"fitness: {name}")
    crossovers = int(np.sum(tree["parent_b"] >= 0))
    ax.set_title(
        title
        or f"{run.path.name}: {len(tree)} ancestors over {int(tree[0]['generation'])} generations, {crossovers} by crossover",
        fontsize=10,
    )
    ax.legend(fontsize=8, loc="lower right")
    ax.autoscale_view()
    fig.tight_layout()
    return fig


def energy_split(
    accounts: Any,
    labels: Optional[Sequence[str]] = None,
    *,
    ax: Optional[Axes] = None,
    title: str = "Where the actuation work goes",
) -> Figure:
    """One horizontal bar per swim: the share of the energy that came in (actuation plus pushes)
    taken by each sink of its :class:`animat.EnergyAccount` (``evaluation.energy_accounting``), in
    the order of :data:`ENERGY_SINKS`; the fluid's share is printed at the end of each bar.

    ``accounts``: one EnergyAccount, an EvaluationResult or SwimResult (its ``.energy``), or a
    sequence of them; ``labels``: one per bar (default ``swim 1``, ``swim 2``...). Raises
    ``ValueError`` for an account that was not measured or that took in no energy.
    """
    items = list(accounts) if isinstance(accounts, (list, tuple)) else [accounts]
    books = [getattr(a, "energy", a) for a in items]
    for k, b in enumerate(books):
        if not getattr(b, "measured", False):
            raise ValueError(
                f"energy_split: swim {k + 1} has no energy books (set evaluation.energy_accounting = true)"
            )
        if not b.actuation + b.external > 0.0:
            raise ValueError(
                f"energy_split: swim {k + 1} took in no energy (actuation {b.actuation}, pushes {b.external})"
            )
    names = list(labels) if labels is not None else [f"swim {k + 1}" for k in range(len(books))]
    if len(names) != len(books):
        raise ValueError(f"energy_split: {len(names)} labels for {len(books)} swims")
    if ax is None:
        fig = plt.figure(figsize=(8.0, 1.2 + 0.45 * len(books)))
        ax = fig.add_subplot(1, 1, 1)
    else:
        fig = ax.get_figure(root=True) if matplotlib.__version_info__ >= (3, 10) else ax.figure  # type: ignore[call-arg]
        assert isinstance(fig, Figure)
    y = np.arange(len(books))[::-1]
    left = np.zeros(len(books))
    for key, label, color in ENERGY_SINKS:
        share = np.array([getattr(b, key) / (b.actuation + b.external) for b in books])
        ax.barh(y, share, left=left, color=color, label=label, height=0.7)
        left += share
    for yy, b in zip(y, books):
        ax.text(
            1.01,
            yy,
            f"fluid {100.0 * b.fluid / (b.actuation + b.external):.0f} %",
            va="center",
            fontsize=8,
            transform=ax.get_yaxis_transform(),
        )
    ax.set_yticks(y, names)
    ax.set_xlim(min(0.0, float(left.min()) - 0.02), max(1.0, float(left.max())) + 0.02)
    ax.set_xlabel("share of the energy that came in (actuation + pushes)")
    ax.set_title(title)
    ax.legend(
        loc="upper center", bbox_to_anchor=(0.5, -0.35 if len(books) < 4 else -0.12), ncol=4, fontsize=7, frameon=False
    )
    fig.tight_layout()
    return fig
