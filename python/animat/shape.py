"""Shape descriptors of a body: elongation, concavity and protrusions (paper §6, Fig. 6).

The paper says that at low drag the best animats "often evolved protrusions ("appendages")", placed
symmetrically, and that "in 32-cell structures protrusions are often built from one cell extending
beyond the main outline of the body", while at high drag "bodies elongated in the direction of motion"
undulate. This module measures those shapes on a body at rest (the output of the body stage), so
that one can ask which shapes development makes and which ones evolution selects. Every length is
in **cell spacings** ``s``: the median distance from a cell centre to its nearest neighbour (1 for
cells of radius 0.5 that touch).

Input: cell centres ``positions`` (n, 2), the **outline** (the outer skin loop, ``Body.skin_loops[0]``:
cell indices counter-clockwise around the body, a dangling edge walked twice) and optionally the
springs ``(m, 2)`` (for grouping cells into protrusions). :func:`body_shape` takes an
:class:`animat.Body`, :func:`genome_shape` a genome and a config (develop, build the body, describe).

The engine computes the measures (``include/animat/shape.hpp``; this module calls it): every
evaluation carries its body's ``elongation``, ``protrusions``, ``symmetric_pair`` and ``concavity``
(:class:`animat.EvaluationResult`, the searches' Fitness), with the defaults of :class:`ShapeParams`.

Elongation
    ``sqrt(λ1 / λ2)``, λ1 ≥ λ2 the principal second moments (eigenvalues of the covariance matrix)
    of the cells about their centroid, each cell counted as a uniform disc of diameter
    ``cell_diameter`` spacings (default 1), which adds ``(cell_diameter·s)² / 16`` to both moments.
    1 for a disc (any body with a 3-fold or higher rotational symmetry); for a straight line of k
    cells ``sqrt(1 + 4 (k² − 1) / 3)`` (k = 10: 11.53); finite for every body, also for a line.
    ``cell_diameter = 0`` gives the bare cell centres (then a straight line is ``inf``).

Concavity
    ``1 − A_outline / A_hull``: A_outline the area enclosed by the outline polygon (shoelace; a
    dangling edge is walked there and back and encloses nothing, so a one-cell-wide tail or a chain
    adds no area), A_hull the area of the convex hull of the cell centres. 0 for a convex body, up to
    1 for a body that is all chains (a bent chain or a cross encloses nothing). Degenerate bodies
    with a hull smaller than the smallest region a body can have, one triangle of touching cells
    (``sqrt(3)/4 s²``), have concavity 0: fewer than three cells, or cells (nearly) on a line.

Protrusions
    A protrusion is a part of the body that sticks out of the body's **core**. The core is the
    morphological opening of the outline polygon P (through the centres of the skin cells) by a disc
    of radius ``core_radius`` ρ (default 0.75 spacings): the union of all discs of radius ρ that fit
    inside P, i.e. the points within ρ of a point of P at depth ≥ ρ (depth: distance to the nearest
    outline edge), computed exactly (:func:`cell_heights`). A cell's **height** is the
    distance of its centre from the core (0 inside it); a cell **protrudes** when its height is at
    least ``min_height`` (default 0.5 spacings). Protruding cells joined by a spring (without
    springs: closer than 1.5 spacings) or consecutive on the outline form one protrusion; its
    **size** is its number of cells, its height the largest of its cells'.

    What this counts, with the defaults (analytic values, tested):

    - one cell sitting in the notch between two touching skin cells of a flat or round side (the
      paper's "one cell extending beyond the main outline"): height ``sqrt(3)/2 + sqrt(ρ² − 1/4) − ρ``
      = 0.675, a protrusion of size 1;
    - a skin cell of a round body: height 0; a corner of a convex body with interior angle θ:
      ``ρ (1/sin(θ/2) − 1)``: 0.12 at 120°, 0.31 at 90° (not protrusions), 0.75 at 60° (a sharp tip,
      such as a corner of a triangle of cells, is one); the threshold lies at θ ≈ 74°;
    - a chain of k cells sticking out of the body: one protrusion of size k;
    - a body with no point at depth ≥ ρ inside its outline (nowhere three hexagonally packed rows
      wide: a line, a cross of chains, a two-row strip) has **no core** and, by definition, **no
      protrusions**: all of it is thin, which elongation and concavity describe.

Symmetric pair
    Two protrusions whose centroids p, q (relative to the centroid of all cells) are mirror images
    of each other about one of the body's principal axes (the eigenvectors of the elongation's
    moment matrix, through the centroid), within ``pair_tolerance`` spacings (default 1): the mirror
    image of p lies within the tolerance of q, and p and q lie on opposite sides of that axis. Two
    fins on the two flanks of an elongated body at the same height along it are a pair (mirrored
    about the long axis), and so are two bumps on opposite sides of a round body (about the axis
    perpendicular to the line joining them). On a body that is round apart from its protrusions the
    principal axes are set by the protrusions themselves, so two protrusions of the same size at the
    same distance from the centre are always a pair; the test discriminates on elongated bodies.

Example::

    shape = animat.shape.genome_shape(genome, config)     # None for a non-viable genome
    print(shape.elongation, shape.concavity, shape.protrusion_count, shape.symmetric_pair)
    row = shape.as_dict()                                  # flat scalars, for a CSV row
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from . import _core

__all__ = [
    "ShapeParams",
    "Protrusion",
    "Shape",
    "describe",
    "body_shape",
    "genome_shape",
    "cell_spacing",
    "principal_axes",
    "elongation",
    "concavity",
    "cell_heights",
    "connected_groups",
    "symmetric_pairs",
]


@dataclass(frozen=True)
class ShapeParams:
    """Parameters of the descriptors, every length in cell spacings (see the module docstring)."""

    cell_diameter: float = 1.0  #: each cell is a disc of this diameter in the second moments (elongation)
    core_radius: float = 0.75  #: ρ: radius of the disc that defines the core (the opening of the outline)
    min_height: float = 0.5  #: a cell protrudes when its centre is at least this far from the core
    pair_tolerance: float = 1.0  #: largest distance between a protrusion's mirror image and its partner

    def __post_init__(self) -> None:
        for name in ("cell_diameter", "min_height", "pair_tolerance"):
            if not getattr(self, name) >= 0:
                raise ValueError(f"ShapeParams.{name} must be >= 0, got {getattr(self, name)}")
        if not self.core_radius > 0:
            raise ValueError(f"ShapeParams.core_radius must be > 0, got {self.core_radius}")


@dataclass(frozen=True)
class Protrusion:
    """Protruding cells joined into one protrusion: ``cells`` (indices, sorted), ``height`` (the
    largest height of its cells, spacings) and ``centroid`` (mean position of its cells)."""

    cells: Tuple[int, ...]
    height: float
    centroid: Tuple[float, float]

    @property
    def size(self) -> int:
        """Number of cells."""
        return len(self.cells)


@dataclass(frozen=True)
class Shape:
    """The descriptors of one body (see the module docstring for the definitions)."""

    cell_count: int
    spacing: float  #: s, the median nearest-neighbour distance (length units)
    elongation: float
    concavity: float
    outline_area: float  #: in s²
    hull_area: float  #: in s²
    core_cells: int  #: cells that do not protrude (0 when the body has no core)
    heights: Tuple[float, ...]  #: per cell, spacings (all 0 when the body has no core)
    protrusions: Tuple[Protrusion, ...]  #: largest first (size, then height)
    symmetric_pairs: Tuple[Tuple[int, int], ...] = field(default=())  #: indices into protrusions

    @property
    def has_core(self) -> bool:
        return self.core_cells > 0

    @property
    def protrusion_count(self) -> int:
        return len(self.protrusions)

    @property
    def symmetric_pair(self) -> bool:
        """At least one symmetric pair of protrusions."""
        return len(self.symmetric_pairs) > 0

    @property
    def protruding_cells(self) -> int:
        return sum(p.size for p in self.protrusions)

    def as_dict(self) -> Dict[str, Any]:
        """Flat scalars (for a CSV row or JSON)."""
        sizes = [p.size for p in self.protrusions]
        return {
            "cells": self.cell_count,
            "spacing": self.spacing,
            "elongation": self.elongation,
            "concavity": self.concavity,
            "outline_area": self.outline_area,
            "hull_area": self.hull_area,
            "core_cells": self.core_cells,
            "protrusions": self.protrusion_count,
            "protruding_cells": self.protruding_cells,
            "largest_protrusion": max(sizes, default=0),
            "max_height": max((p.height for p in self.protrusions), default=0.0),
            "single_cell_protrusions": sum(1 for s in sizes if s == 1),
            "symmetric_pairs": len(self.symmetric_pairs),
        }


# --- geometry -------------------------------------------------------------------------------------


def cell_spacing(positions: np.ndarray) -> float:
    """s: the median distance from a cell centre to its nearest neighbour (1.0 for fewer than 2 cells)."""
    p = np.asarray(positions, dtype=float)
    if len(p) < 2:
        return 1.0
    dx, dy = p[:, None, 0] - p[None, :, 0], p[:, None, 1] - p[None, :, 1]
    d2 = dx * dx + dy * dy  # the squares np.linalg.norm sums; the root of the least is the least norm
    np.fill_diagonal(d2, np.inf)
    s = float(np.median(np.sqrt(d2.min(axis=1))))
    return s if s > 0 else 1.0


def principal_axes(
    positions: np.ndarray, params: ShapeParams = ShapeParams(), spacing: Optional[float] = None
) -> Tuple[np.ndarray, np.ndarray]:
    """The cells' principal second moments about their centroid and the principal axes (module
    docstring, "Elongation"): the eigenvalues λ2 ≤ λ1 (ascending, squared length units) and the unit
    eigenvectors (the columns of a 2 × 2 array, in the same order) of the covariance matrix of the
    cell centres plus ``(cell_diameter·s)² / 16`` on the diagonal, each cell counted as a uniform disc.
    ``spacing`` is s (default :func:`cell_spacing` of ``positions``). Needs at least one cell."""
    p = np.asarray(positions, dtype=float).reshape(-1, 2)
    if len(p) == 0:
        raise ValueError("principal_axes: no cells")
    s = cell_spacing(p) if spacing is None else spacing
    c = p - p.mean(axis=0)
    m = c.T @ c / len(p) + (params.cell_diameter * s) ** 2 / 16.0 * np.eye(2)
    return np.linalg.eigh(m)


def elongation(positions: np.ndarray, params: ShapeParams = ShapeParams(), spacing: Optional[float] = None) -> float:
    """sqrt(λ1/λ2) of the cells' principal second moments (module docstring); 1.0 for one cell.
    Computed by the engine (``shape.hpp``), which also bands it for ``morphology_kind``."""
    p = np.asarray(positions, dtype=float).reshape(-1, 2)
    return float(_core.shape_elongation(p, params.cell_diameter, spacing))


def concavity(positions: np.ndarray, outline: Sequence[int], spacing: Optional[float] = None) -> float:
    """1 − A_outline / A_hull (module docstring); 0 for a body whose hull is smaller than one
    triangle of touching cells."""
    return float(_engine_shape(positions, outline, None, ShapeParams(), spacing)["concavity"])


def _engine_shape(
    positions: Any, outline: Optional[Sequence[int]], springs: Any, params: ShapeParams, spacing: Optional[float] = None
) -> Dict[str, Any]:
    """The engine's descriptors (``shape.hpp``, the one definition of this module's measures) as a
    dict of :class:`Shape`'s fields and ``has_core``."""
    p = np.asarray(positions, dtype=float).reshape(-1, 2)
    loop = [] if outline is None else [int(i) for i in outline]
    flat = None if springs is None else [int(k) for k in np.asarray(springs, dtype=np.int64).reshape(-1)]
    return _core.describe_shape(
        p, loop, flat, params.cell_diameter, params.core_radius, params.min_height, params.pair_tolerance, spacing
    )


# The pieces of the exact construction of the core, in numpy: the reference that
# tests/python/test_qd_descriptors.py rebuilds the engine's cell heights from.


def _inside(q: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Even-odd rule: (N,) bool, q inside the closed polygon with edges a→b (an edge walked twice cancels)."""
    ay, by = a[None, :, 1], b[None, :, 1]
    y = q[:, 1:2]
    straddles = (ay > y) != (by > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        x_cross = a[None, :, 0] + (y - ay) * (b[None, :, 0] - a[None, :, 0]) / (by - ay)
    hits = straddles & (q[:, 0:1] < x_cross)
    return (hits.sum(axis=1) % 2) == 1


def _core_candidates(a: np.ndarray, b: np.ndarray, rho: float) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The pieces of {depth = ρ} of the polygon with edges a→b (body on the left): the offset lines
    (points o, unit directions t) and the vertex circles (centres v), and their pairwise
    intersections (the corners of the core's erosion)."""
    d = b - a
    t = d / np.linalg.norm(d, axis=1)[:, None]
    o = a + rho * np.column_stack([-t[:, 1], t[:, 0]])
    v = np.unique(a, axis=0)
    points = []
    # line-line
    k, l = np.triu_indices(len(o), 1)
    cross = t[k, 0] * t[l, 1] - t[k, 1] * t[l, 0]
    ok = np.abs(cross) > 1e-12
    k, l, cross = k[ok], l[ok], cross[ok]
    w = o[l] - o[k]
    s = (w[:, 0] * t[l, 1] - w[:, 1] * t[l, 0]) / cross
    points.append(o[k] + s[:, None] * t[k])
    # line-circle
    w = o[:, None, :] - v[None, :, :]
    wt = np.einsum("kvj,kj->kv", w, t)
    disc = wt**2 - np.einsum("kvj,kvj->kv", w, w) + rho**2
    kk, vv = np.nonzero(disc >= 0)
    root = np.sqrt(disc[kk, vv])
    for sign in (-1.0, 1.0):
        points.append(o[kk] + (-wt[kk, vv] + sign * root)[:, None] * t[kk])
    # circle-circle
    i, j = np.triu_indices(len(v), 1)
    gap = v[j] - v[i]
    dist = np.linalg.norm(gap, axis=1)
    ok = (dist > 0) & (dist <= 2 * rho)
    i, j, gap, dist = i[ok], j[ok], gap[ok], dist[ok]
    half = np.sqrt(np.maximum(0.0, rho**2 - dist**2 / 4))
    perp = np.column_stack([-gap[:, 1], gap[:, 0]]) / dist[:, None]
    mid = (v[i] + v[j]) / 2
    points += [mid + half[:, None] * perp, mid - half[:, None] * perp]
    return np.concatenate(points), o, t, v


def cell_heights(
    positions: np.ndarray, outline: Sequence[int], params: ShapeParams = ShapeParams(), spacing: Optional[float] = None
) -> Optional[np.ndarray]:
    """Each cell's distance from the body's core, in spacings (module docstring); None when the body
    has no core (no disc of radius ``core_radius`` fits in its outline: with the defaults, it is
    nowhere three hexagonally packed rows wide).

    Exact up to rounding: the nearest point of the eroded outline {depth >= ρ} to a cell is either
    the cell itself, its projection on an edge's offset line, its radial projection on a vertex's
    circle of radius ρ, or a corner where two of those meet; every candidate at depth >= ρ counts.
    Computed by the engine (``shape.hpp``)."""
    d = _engine_shape(positions, outline, None, params, spacing)
    return np.array(d["heights"], dtype=float) if d["has_core"] else None


def connected_groups(members: Sequence[int], links: Sequence[Tuple[int, int]]) -> List[List[int]]:
    """The connected components of the graph on ``members`` (distinct cell indices) whose edges are
    the ``links`` (index pairs; a link with an end outside ``members`` is ignored), by union-find: one
    sorted list per component, the components in the order in which their first member appears in
    ``members`` (by smallest index when ``members`` is sorted). Protruding cells joined this way form
    one protrusion (:func:`describe`, :mod:`animat.protrusion`)."""
    parent = {m: m for m in members}

    def find(x: int) -> int:
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for i, j in links:
        if i in parent and j in parent:
            ri, rj = find(i), find(j)
            if ri != rj:
                parent[max(ri, rj)] = min(ri, rj)
    out: Dict[int, List[int]] = {}
    for m in members:
        out.setdefault(find(m), []).append(m)
    return [sorted(g) for g in out.values()]


def symmetric_pairs(
    positions: np.ndarray,
    protrusions: Sequence[Protrusion],
    params: ShapeParams = ShapeParams(),
    spacing: Optional[float] = None,
) -> List[Tuple[int, int]]:
    """The symmetric pairs among ``protrusions`` (module docstring, "Symmetric pair"): index pairs
    ``(i, j)``, i < j, of protrusions whose centroids, taken relative to the centroid of the cells at
    ``positions``, are mirror images of each other about one of the principal axes of those cells
    (:func:`principal_axes`) within ``params.pair_tolerance`` spacings, on opposite sides of that axis.
    ``spacing`` is s (default :func:`cell_spacing` of ``positions``)."""
    p = np.asarray(positions, dtype=float).reshape(-1, 2)
    s = cell_spacing(p) if spacing is None else spacing
    _, axes = principal_axes(p, params, s)
    centre = p.mean(axis=0)
    pairs: List[Tuple[int, int]] = []
    for i in range(len(protrusions)):
        for j in range(i + 1, len(protrusions)):
            a = (np.asarray(protrusions[i].centroid) - centre) / s
            b = (np.asarray(protrusions[j].centroid) - centre) / s
            for k in range(2):  # mirror about axis k: the component along the other axis changes sign
                normal = axes[:, 1 - k]
                mirrored = a - 2.0 * np.dot(a, normal) * normal
                opposite = np.dot(a, normal) * np.dot(b, normal) < 0
                if opposite and np.linalg.norm(mirrored - b) <= params.pair_tolerance:
                    pairs.append((i, j))
                    break
    return pairs


def describe(
    positions: Any, outline: Optional[Sequence[int]], springs: Any = None, params: ShapeParams = ShapeParams()
) -> Shape:
    """The descriptors of cells at ``positions`` (n, 2) with the outer ``outline`` (cell indices,
    counter-clockwise; ``Body.skin_loops[0]``; None or empty for fewer than two cells) and optional
    ``springs`` (m, 2) used to group protruding cells. Computed by the engine (``shape.hpp``), which
    also gives every evaluation's elongation, protrusions, symmetric_pair and concavity."""
    d = _engine_shape(positions, outline, springs, params)
    found = tuple(Protrusion(tuple(cells), float(h), (float(c[0]), float(c[1]))) for cells, h, c in d["protrusions"])
    return Shape(
        int(d["cell_count"]),
        float(d["spacing"]),
        float(d["elongation"]),
        float(d["concavity"]),
        float(d["outline_area"]),
        float(d["hull_area"]),
        int(d["core_cells"]),
        tuple(float(h) for h in d["heights"]),
        found,
        tuple((int(i), int(j)) for i, j in d["symmetric_pairs"]),
    )


def body_shape(body: Any, params: ShapeParams = ShapeParams()) -> Shape:
    """The descriptors of an :class:`animat.Body` (its rest positions, outer skin loop and springs)."""
    loops = body.skin_loops
    return describe(body.positions, loops[0] if len(loops) else None, body.springs, params)


def genome_shape(genome: Any, config: Any = None, params: ShapeParams = ShapeParams()) -> Optional[Shape]:
    """Develop ``genome`` under ``config`` (an :class:`animat.Config`, None = defaults), build its
    body and describe it; None when the embryo is not viable (no body)."""
    from . import pipeline

    embryo = pipeline.develop(genome, config)
    if not embryo.viable:
        return None
    return body_shape(pipeline.build_body(embryo, config=config), params)
