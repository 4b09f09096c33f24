"""The paper's protrusion stroke, measured on a swim (paper §6, Fig. 6).

The paper says of its protrusion swimmers: they "propel themselves by extending them and generating
thrust while the protrusions are pulled backwards"; "the protrusions are fully extended when moving
backwards (generating thrust) but are contracted during their return"; "a clear tendency to place the
protrusions symmetrically"; and "in 32-cell structures protrusions are often built from one cell
extending beyond the main outline of the body and become more pronounced only due to dynamic changes
in shape during motion". :func:`stroke_motion` asks exactly that of a window of a swim:

1. *Protrusions.* The cells that stand out of the body's core by :func:`animat.shape.describe` (cell
   height above the core ≥ ``ShapeParams.min_height``, 0.5 spacings) **at rest** (the body's rest
   positions) **or in any of** ``samples`` (8) frames spread over the last period of the window (the
   body-frame shapes: protrusions that appear only during motion). Protruding cells joined by a spring
   or consecutive on the outline form one protrusion. Each is then **grown to the whole appendage**
   (:func:`grow_protrusions`): a cell joined to it by a spring joins it when its own loop in the body
   frame (:func:`cell_loops`: the signed area of its trajectory in the plane of the direction of motion
   and the protrusion's side) is at least half (:data:`GROW_SHARE`) of the largest loop of the
   protrusion's cells and at least :data:`STROKE_AREA`. The shape sees only what stands out of the core:
   of a 2 × 2 block often only the outer row or three cells, while the base row, inside the core's
   outline, makes the block's largest loops (measured on the part alone, its extension is taken from the
   moving base row and the block pairs scored −0.86 to 0.37 though they row by the ground truth). Its
   **anchors** are the cells joined to it by springs that are in no protrusion.
2. *Stroke of a protrusion.* In the body frame (Procrustes, as the classifier), with ``d`` the
   direction of motion: per cell of the protrusion, its **sweep** ``x(t)`` = position along ``d``
   (relative to the body's centre: body deformation counts) and its **extension** ``e(t)`` = its offset
   from the mean of the protrusion's anchors **across the motion**, along the normal of ``d`` on the
   protrusion's side (the side to which it sticks out of its anchors in the mean shape). Sweep and
   extension are then the two components of the cell's motion, and the stroke is its loop in that
   plane: how far the appendage reaches out sideways while it moves back. An extension along the
   protrusion's own axis (anchors' mean to centroid, frame by frame) turned with the appendage's swing,
   so that a swept-back three-cell chain that rows by the ground truth (0.64-0.85) scored −0.02 to 0.36;
   along a fixed outward direction of the mean shape, the sweep of a swept-back appendage leaked into
   the extension. Both are fitted at the analysed frequency ω (complex
   amplitudes ``X``, ``E``, the convention of :func:`animat.locomotion.harmonic_amplitudes`). The
   correlation of ``e`` with the backward velocity ``−dx/dt`` is ``−Im(E X̄) / (|E||X|)``: +1 for the
   loop out → back → in → forward (extended while it moves backwards fastest), −1 for the reverse loop,
   0 for a purely radial or a purely sweeping motion. The protrusion's **score** is this correlation
   weighted by ``|E||X|`` over its cells, ``Σ −Im(E X̄) / Σ |E||X|``; its **area** is the signed area of
   its cells' loops in the (sweep, extension) plane, ``−π Im(E X̄)``, summed over its cells, in
   spacings²: how large the stroke of the whole appendage is (for a one-cell protrusion, its one loop;
   the inner cells of a chain make small loops, so that a mean per cell put three-cell chains that row
   by the ground truth under :data:`STROKE_AREA`).
3. *Symmetric pairs.* Two (grown) protrusions mirrored about a principal axis of the mean shape
   (:func:`animat.shape.describe`'s test, ``pair_tolerance`` 1 spacing). The **pair score** is the
   smaller score of the two, the swim's **score** the best pair score (nan without a pair), and the
   swim **strokes** when that score reaches :data:`STROKE_SCORE` and the pair's smaller area reaches
   :data:`STROKE_AREA`. When the body at rest is given, only pairs whose two protrusions both stand out
   of the core **at rest** count: the paper's protrusions are cells "extending beyond the main outline of
   the body" that "become more pronounced" in motion, part of the body's shape. A pair of which one
   protrusion or both appear only in motion is the swing of a whole body's corners: on the seven
   calibration sets such pairs rowed on three synchronous tear-drops (pair scores 0.42-0.65, areas
   0.16-0.68), while the pair of each of the 110 protrusion swims that stroke stands out at rest.

The thresholds were set on the hand-built swimmers of ``paper_calibration_set`` in
studies/locomotion/known_swimmers.py (swum 2000 steps at d_N = 0.5 and 2), see :data:`STROKE_SCORE`; given the
body's outline, :func:`animat.locomotion.classify_motion` uses the rule as its first test for "protrusions":
the stroke path, which :func:`animat.locomotion.classify_locomotion` takes by default (docs/locomotion.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, List, Optional, Sequence, Tuple

import numpy as np

from .shape import Protrusion, ShapeParams, cell_heights, cell_spacing, connected_groups, symmetric_pairs

__all__ = [
    "ProtrusionStroke",
    "stroke_motion",
    "protrusion_stroke",
    "cell_strokes",
    "rowing",
    "STROKE_SCORE",
    "STROKE_AREA",
    "STROKE_SAMPLES",
    "GROW_SHARE",
    "cell_loops",
    "grow_protrusions",
]

#: Pair score (the smaller of the two protrusions' weighted rowing correlations) from which a swim
#: strokes as the paper's protrusion swimmers do. Set between the calibration set's groups (see
#: docs/locomotion.md).
STROKE_SCORE = 0.4
#: Smallest signed loop area (spacings², summed over the protrusion's cells) of the weaker protrusion of
#: the pair: a stroke, not a tremor.
STROKE_AREA = 0.1
#: Frames over the last period in which dynamic protrusions are looked for.
STROKE_SAMPLES = 8
#: A cell joins a protrusion (:func:`grow_protrusions`) when its own loop is at least this share of the
#: largest loop of the protrusion's cells (half the peak: the appendage is where the stroke is) ...
GROW_SHARE = 0.5
#: ... and at least :data:`STROKE_AREA` spacings² itself (a stroke, not a tremor).


def cell_strokes(
    Q: np.ndarray, times: np.ndarray, omega: float, direction: Any, cells: Sequence[int], base: np.ndarray, outward: Any
) -> Tuple[np.ndarray, np.ndarray]:
    """Complex amplitudes at ``omega`` of the sweep ``X`` (position along ``direction``) and the
    extension ``E`` of ``cells``: their offset from ``base`` along ``outward``, or, when ``outward`` is
    None, along the protrusion's own axis, the line from ``base`` to the cells' centroid in each frame
    (for one cell: its distance from ``base``).

    Args:
        Q: (F, n, 2) body-frame positions. times: (F,). omega: rad per time unit.
        direction: (2,) direction of motion (body frame). cells: (k,) cell indices.
        base: (F, 2) the reference point of the extension (the anchors' mean), or (2,) a fixed point.
        outward: (2,) a fixed direction in which the cells extend, or None (the protrusion's axis).
    """
    from .locomotion import harmonic_amplitudes  # noqa: PLC0415 - locomotion imports this module

    d = np.asarray(direction, dtype=np.float64)
    d = d / np.linalg.norm(d)
    c = np.asarray(cells, dtype=np.int64)
    b = np.asarray(base, dtype=np.float64)
    b = np.broadcast_to(b if b.ndim == 2 else b[None, :], (len(Q), 2))
    sweep = Q[:, c] @ d
    offset = Q[:, c] - b[:, None, :]
    if outward is None:  # along the protrusion's axis: base -> centroid, frame by frame
        axis = offset.mean(axis=1)
        norm = np.linalg.norm(axis, axis=1, keepdims=True)
        axis = np.divide(axis, norm, out=np.zeros_like(axis), where=norm > 0)
        ext = np.einsum("fki,fi->fk", offset, axis)
    else:
        u = np.asarray(outward, dtype=np.float64)
        u = u / np.linalg.norm(u)
        ext = offset @ u
    return np.atleast_1d(harmonic_amplitudes(sweep, times, omega)), np.atleast_1d(
        harmonic_amplitudes(ext, times, omega)
    )


def rowing(X: np.ndarray, E: np.ndarray) -> float:
    """``Σ −Im(E X̄) / Σ |E||X|`` in [−1, 1]: +1 when every cell is farthest out while it moves backwards
    fastest; nan when nothing moves."""
    den = float(np.sum(np.abs(X) * np.abs(E)))
    return float(np.sum(-np.imag(E * np.conj(X))) / den) if den > 0 else float("nan")


@dataclass(frozen=True, eq=False)
class ProtrusionStroke:
    """The stroke of a swim's protrusions (module docstring).

    Attributes:
        protrusions: cell groups (sorted tuples), at rest ones first.
        at_rest: per protrusion, whether any of its cells protrudes at rest (else only during motion).
        scores: (p,) weighted rowing correlation per protrusion (nan when it does not move).
        areas: (p,) signed loop area of each protrusion (summed over its cells), spacings².
        pairs: symmetric pairs (indices into ``protrusions``).
        pair_scores: (len(pairs),) the smaller score of each pair.
        pair: the best pair (by pair score), or ().
        score: its pair score (nan without a pair). area: the smaller area of that pair.
    """

    protrusions: Tuple[Tuple[int, ...], ...]
    at_rest: Tuple[bool, ...]
    scores: np.ndarray
    areas: np.ndarray
    pairs: Tuple[Tuple[int, int], ...]
    pair_scores: np.ndarray
    pair: Tuple[int, ...]
    score: float
    area: float

    @property
    def strokes(self) -> bool:
        """The best symmetric pair rows as the paper describes (score ≥ STROKE_SCORE, area ≥ STROKE_AREA)."""
        return bool(self.score >= STROKE_SCORE and self.area >= STROKE_AREA)

    @property
    def rowing_protrusions(self) -> int:
        """Protrusions whose own score and area reach the thresholds."""
        return int(np.sum((self.scores >= STROKE_SCORE) & (self.areas >= STROKE_AREA)))


def _empty() -> ProtrusionStroke:
    return ProtrusionStroke((), (), np.zeros(0), np.zeros(0), (), np.zeros(0), (), float("nan"), float("nan"))


def _protruding(
    positions: np.ndarray, outline: Sequence[int], springs: np.ndarray, params: ShapeParams, spacing: float
) -> List[int]:
    h = cell_heights(positions, outline, params, spacing)
    if h is None:
        return []
    return [int(i) for i in np.flatnonzero(h >= params.min_height)]


def _side(mean: np.ndarray, group: Sequence[int], anchors: Sequence[int], normal: np.ndarray) -> float:
    """+1 or −1: the side of the direction of motion (``normal`` its left) to which ``group`` sticks out
    of its ``anchors`` in the mean shape (from the body's centre when that is 0 or there are no anchors)."""
    c = mean[list(group)].mean(axis=0)
    v = float((c - mean[list(anchors)].mean(axis=0)) @ normal) if len(anchors) else 0.0
    if v == 0:
        v = float(c @ normal)
    return 1.0 if v >= 0 else -1.0


def cell_loops(Q: np.ndarray, times: np.ndarray, omega: float, direction: Any, side: float = 1.0) -> np.ndarray:
    """(n,) the signed area of each cell's loop in the body frame at ``omega``, in the plane of the
    direction of motion ``d`` and the normal ``side`` × (its left): ``−π Im(Y X̄)`` with ``X``, ``Y`` the
    complex amplitudes of its position along ``d`` and along that normal. Positive when the cell is
    farthest out on that side while it moves backwards (the stroke's loop), negative for the reverse
    loop, 0 for a motion along a line (a breathing or a purely sweeping cell)."""
    from .locomotion import harmonic_amplitudes  # noqa: PLC0415 - locomotion imports this module

    d = np.asarray(direction, dtype=np.float64)
    d = d / np.linalg.norm(d)
    D = harmonic_amplitudes(np.asarray(Q, dtype=np.float64), np.asarray(times, dtype=np.float64), omega)
    X, Y = D @ d, side * (D @ np.array([-d[1], d[0]]))
    return -math.pi * np.imag(Y * np.conj(X))


def grow_protrusions(
    Q: np.ndarray,
    times: np.ndarray,
    omega: float,
    direction: Any,
    groups: Sequence[Sequence[int]],
    springs: Any,
    spacing: float,
) -> List[List[int]]:
    """The protrusions found by the shape (``groups``), each grown to the whole appendage that strokes
    with it: a cell joined by a spring to the protrusion, in no other protrusion, joins it when its own
    loop (:func:`cell_loops`, on the protrusion's side, :func:`_side`) is at least :data:`GROW_SHARE` of
    the largest loop of the protrusion's cells and at least :data:`STROKE_AREA` spacings², repeated until
    no cell joins (a protrusion none of whose cells makes a positive loop does not grow). The shape finds only the cells that stand out of the core: the base row of a 2 × 2
    block lies inside the core's outline, but it makes the block's largest loops. Cells are only added:
    the shape-found cells stay, whatever their loops."""
    sp = np.asarray(springs, dtype=np.int64).reshape(-1, 2)
    d = np.asarray(direction, dtype=np.float64)
    d = d / np.linalg.norm(d)
    normal = np.array([-d[1], d[0]])
    mean = np.asarray(Q, dtype=np.float64).mean(axis=0)
    nb: dict = {}
    for i, j in sp:
        nb.setdefault(int(i), set()).add(int(j))
        nb.setdefault(int(j), set()).add(int(i))
    taken = {int(c) for g in groups for c in g}
    right, left = cell_loops(Q, times, omega, d, -1.0), cell_loops(Q, times, omega, d, 1.0)
    floor = STROKE_AREA * spacing**2
    out: List[List[int]] = []
    for g in groups:
        gs = {int(c) for c in g}
        anchors = sorted({v for c in gs for v in nb.get(c, ())} - gs)
        lp = left if _side(mean, sorted(gs), anchors, normal) > 0 else right
        while True:
            top = max(lp[c] for c in gs)
            if not top > 0:  # the protrusion makes no stroke's loop: nothing strokes with it
                break
            add = {v for c in gs for v in nb.get(c, ()) if v not in taken and lp[v] >= max(floor, GROW_SHARE * top)}
            if not add:
                break
            gs |= add
            taken |= add
        out.append(sorted(gs))
    return out


def stroke_motion(
    Q: np.ndarray,
    times: np.ndarray,
    omega: float,
    direction: Any,
    outline: Sequence[int],
    springs: Any,
    rest_positions: Optional[Any] = None,
    samples: int = STROKE_SAMPLES,
    params: ShapeParams = ShapeParams(),
) -> ProtrusionStroke:
    """:class:`ProtrusionStroke` of a window of body-frame frames.

    Args:
        Q: (F, n, 2) body-frame positions (:func:`animat.locomotion.procrustes_frames`).
        times: (F,) their times. omega: the analysed angular frequency (> 0).
        direction: (2,) direction of motion in that frame.
        outline: the outer skin loop (``Body.skin_loops[0]``). springs: (m, 2).
        rest_positions: (n, 2) the body at rest (None: only the frames are searched).
        samples: frames over the last period searched for protrusions that appear during motion.
    """
    Q = np.asarray(Q, dtype=np.float64)
    t = np.asarray(times, dtype=np.float64)
    loop = [int(v) for v in outline]
    sp = np.asarray(springs, dtype=np.int64).reshape(-1, 2)
    F, n, _ = Q.shape
    if len(loop) < 3 or n < 3 or not omega > 0 or F < 4:
        return _empty()
    mean = Q.mean(axis=0)
    s = cell_spacing(mean if rest_positions is None else np.asarray(rest_positions, dtype=np.float64))
    rest: List[int] = []
    if rest_positions is not None:
        rest = _protruding(np.asarray(rest_positions, dtype=np.float64), loop, sp, params, s)
    period = 2 * math.pi / omega
    in_last = np.flatnonzero(t >= t[-1] - period)
    picks = np.unique(in_last[np.linspace(0, len(in_last) - 1, max(1, samples)).round().astype(int)])
    moving: set = set()
    for f in picks:
        moving.update(_protruding(Q[f], loop, sp, params, s))
    cells = sorted(set(rest) | moving)
    if not cells:
        return _empty()
    links = [(int(loop[k]), int(loop[(k + 1) % len(loop)])) for k in range(len(loop))] + [
        (int(e[0]), int(e[1])) for e in sp
    ]
    groups = connected_groups(cells, links)
    rest_set = set(rest)
    groups.sort(key=lambda g: (not (set(g) & rest_set), -len(g), g))
    member = {c: k for k, g in enumerate(groups) for c in g}
    d = np.asarray(direction, dtype=np.float64)
    d = d / np.linalg.norm(d)
    normal = np.array([-d[1], d[0]])
    groups = grow_protrusions(Q, t, omega, d, groups, sp, s)
    member = {c: k for k, g in enumerate(groups) for c in g}
    scores, areas, found = [], [], []
    for g in groups:
        gs = set(g)
        anchors = sorted({int(v) for i, j in sp for v in (i, j) if (int(i) in gs) != (int(j) in gs)} - set(member))
        if not anchors:  # joined only to other protrusions: measure from the body's centre
            base = np.zeros((F, 2))
            origin = np.zeros(2)
        else:
            base = Q[:, anchors].mean(axis=1)
            origin = mean[anchors].mean(axis=0)
        outward = mean[list(g)].mean(axis=0) - origin
        if not np.linalg.norm(outward) > 0:
            scores.append(float("nan"))
            areas.append(float("nan"))
            found.append(Protrusion(tuple(g), 0.0, tuple(mean[list(g)].mean(axis=0))))
            continue
        side = _side(mean, g, anchors, normal)
        X, E = cell_strokes(Q, t, omega, d, g, base, side * normal)  # extension across the motion
        scores.append(rowing(X, E))
        areas.append(float(np.sum(-math.pi * np.imag(E * np.conj(X)))) / s**2)  # the whole appendage's
        cx, cy = mean[list(g)].mean(axis=0)
        found.append(Protrusion(tuple(g), 0.0, (float(cx), float(cy))))
    pairs = tuple(symmetric_pairs(mean, found, params, s))
    sc = np.array(scores, dtype=np.float64)
    ar = np.array(areas, dtype=np.float64)
    pair_scores = np.array(
        [np.fmin(sc[a], sc[b]) if np.isfinite(sc[a]) and np.isfinite(sc[b]) else np.nan for a, b in pairs],
        dtype=np.float64,
    )
    at_rest = [bool(set(g) & rest_set) for g in groups]
    # the paper's protrusions are part of the body's shape (cells "extending beyond the main outline of the
    # body" that "become more pronounced ... during motion"): with the body at rest known, a pair counts only
    # when both of its protrusions stand out at rest
    eligible = np.array(
        [
            np.isfinite(v) and (rest_positions is None or (at_rest[a] and at_rest[b]))
            for (a, b), v in zip(pairs, pair_scores)
        ],
        dtype=bool,
    )
    best: Tuple[int, ...] = ()
    score = area = float("nan")
    if eligible.any():
        k = int(np.flatnonzero(eligible)[np.argmax(pair_scores[eligible])])
        best = tuple(pairs[k])
        score = float(pair_scores[k])
        area = float(min(ar[best[0]], ar[best[1]]))
    return ProtrusionStroke(
        tuple(tuple(g) for g in groups),
        tuple(at_rest),
        sc,
        ar,
        pairs,
        pair_scores,
        best,
        score,
        area,
    )


def protrusion_stroke(trajectory: Any, mode: Optional[Any] = None) -> ProtrusionStroke:
    """:class:`ProtrusionStroke` of a recorded swim over the classifier's window (``mode``: a
    :class:`animat.locomotion.LocomotionMode`; default :func:`animat.classify_locomotion` of it)."""
    from .locomotion import classify_locomotion, procrustes_frames  # noqa: PLC0415

    if mode is None:
        mode = classify_locomotion(trajectory)
    if getattr(mode, "stroke", None) is not None:
        return mode.stroke
    frames = max(int(mode.frames), 4)
    Q, _, _ = procrustes_frames(np.asarray(trajectory.positions)[-frames:])
    body = trajectory.body
    loops = body.skin_loops
    if not len(loops):
        return _empty()
    return stroke_motion(
        Q, np.asarray(trajectory.times)[-frames:], mode.omega, mode.direction, loops[0], body.springs, body.positions
    )
