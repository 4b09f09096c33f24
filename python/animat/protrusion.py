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
   or consecutive on the outline form one protrusion. Its **anchors** are the non-protruding cells
   joined to it by springs.
2. *Stroke of a protrusion.* In the body frame (Procrustes, as the classifier), with ``d`` the
   direction of motion: per protruding cell, its **sweep** ``x(t)`` = position along ``d`` (relative
   to the body's centre: body deformation counts) and its **extension** ``e(t)`` = its offset from the
   mean of its protrusion's anchors along the protrusion's own axis, the line from the anchors' mean to
   the protrusion's centroid in the same frame (for a one-cell protrusion: its distance from the anchors'
   mean; a projection on a fixed outward direction mixed the large sweep of a swept-back appendage into its
   extension, and the distance of a chain's outer cells from the anchors also changes as the chain bends
   sideways, which is not extension: measured that way, chains that row by the ground truth scored
   0.28-0.41). Both are fitted at the analysed frequency ω (complex
   amplitudes ``X``, ``E``, the convention of :func:`animat.locomotion.harmonic_amplitudes`). The
   correlation of ``e`` with the backward velocity ``−dx/dt`` is ``−Im(E X̄) / (|E||X|)``: +1 for the
   loop out → back → in → forward (extended while it moves backwards fastest), −1 for the reverse loop,
   0 for a purely radial or a purely sweeping motion. The protrusion's **score** is this correlation
   weighted by ``|E||X|`` over its cells, ``Σ −Im(E X̄) / Σ |E||X|``; its **area** is the signed area of
   its cells' loops in the (sweep, extension) plane, ``−π Im(E X̄)``, summed over its cells, in
   spacings²: how large the stroke of the whole appendage is (for a one-cell protrusion, its one loop;
   the inner cells of a chain make small loops, so that a mean per cell put three-cell chains that row
   by the ground truth under :data:`STROKE_AREA`).
3. *Symmetric pairs.* Two protrusions mirrored about a principal axis of the mean shape
   (:func:`animat.shape.describe`'s test, ``pair_tolerance`` 1 spacing). The **pair score** is the
   smaller score of the two, the swim's **score** the best pair score (nan without a pair), and the
   swim **strokes** when that score reaches :data:`STROKE_SCORE` and the pair's smaller area reaches
   :data:`STROKE_AREA`.

The thresholds were set on the hand-built swimmers of ``paper_calibration_set`` in
studies/locomotion/known_swimmers.py (swum 2000 steps at d_N = 0.5 and 2), see :data:`STROKE_SCORE`; :func:`animat.locomotion.classify_motion`
uses the rule as its first test for "protrusions" (docs/locomotion.md).
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
        X, E = cell_strokes(Q, t, omega, d, g, base, None)
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
    best: Tuple[int, ...] = ()
    score = area = float("nan")
    if len(pairs) and np.isfinite(pair_scores).any():
        k = int(np.nanargmax(pair_scores))
        best = tuple(pairs[k])
        score = float(pair_scores[k])
        area = float(min(ar[best[0]], ar[best[1]]))
    return ProtrusionStroke(
        tuple(tuple(g) for g in groups),
        tuple(bool(set(g) & rest_set) for g in groups),
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
