"""The engine's shape measures (include/animat/shape.hpp, which animat.shape calls) against a numpy
implementation of the module docstring's definitions, on the bodies evolution made (the stored bests
under data/) and on random viable genomes: counts, cells and pairs exactly, numbers to rounding."""

from pathlib import Path

import numpy as np
import pytest

import animat
from animat import _core
from animat import shape as S

DATA = Path(__file__).resolve().parents[2] / "data"


def hull_area(p):
    """Area of the convex hull of the points (Andrew's monotone chain)."""
    pts = sorted(map(tuple, np.unique(p, axis=0)))
    if len(pts) < 3:
        return 0.0

    def turns_left(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]) > 0

    def chain(points):
        out = []
        for q in points:
            while len(out) >= 2 and not turns_left(out[-2], out[-1], q):
                out.pop()
            out.append(q)
        return out[:-1]

    return shoelace(np.array(chain(pts) + chain(pts[::-1])))


def shoelace(v):
    if len(v) < 3:
        return 0.0
    x, y = v[:, 0], v[:, 1]
    return abs(0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y)))


def heights(positions, outline, rho, s):
    """Each cell's distance from the core (the opening of the outline by a disc of radius rho), from
    the candidate points of the eroded outline (animat.shape._core_candidates) and every cell's own
    candidates; None when the erosion is empty."""
    u = positions / s
    a = u[np.asarray(outline, dtype=np.int64)]
    b = np.roll(a, -1, axis=0)
    keep = np.any(a != b, axis=1)
    a, b = a[keep], b[keep]
    if len(a) < 3:
        return None
    corners, o, t, v = S._core_candidates(a, b, rho)
    lo, hi = a.min(axis=0) - 1e-9, a.max(axis=0) + 1e-9
    pool = [corners[np.all((corners >= lo) & (corners <= hi), axis=1)], u]
    for x in u:
        pool.append(o + np.einsum("kj,kj->k", x - o, t)[:, None] * t)
        r = np.linalg.norm(x - v, axis=1)
        pool.append(v[r > 0] + rho * (x - v)[r > 0] / r[r > 0, None])
    q = np.concatenate(pool)
    ab = b - a
    t = np.clip(np.einsum("nej,ej->ne", q[:, None, :] - a[None], ab) / np.einsum("ij,ij->i", ab, ab), 0, 1)
    depth = np.linalg.norm(q[:, None, :] - (a[None] + t[..., None] * ab[None]), axis=2).min(axis=1)
    core = q[(depth >= rho * (1 - 1e-9) - 1e-12) & S._inside(q, a, b)]
    if len(core) == 0:
        return None
    return np.maximum(0.0, np.linalg.norm(u[:, None, :] - core[None], axis=2).min(axis=1) - rho)


def reference(body, params=S.ShapeParams()):
    """(cell_count, elongation, concavity, core_cells, heights, protrusions as (cells, height),
    symmetric pairs) by the definitions, in numpy (eigh for the moments)."""
    p = np.asarray(body.positions, dtype=float)
    outline = [int(i) for i in body.skin_loops[0]]
    n = len(p)
    s = S.cell_spacing(p)
    c = p - p.mean(axis=0)
    lam, _ = np.linalg.eigh(c.T @ c / n + (params.cell_diameter * s) ** 2 / 16 * np.eye(2))
    elongation = float(np.sqrt(lam[1] / lam[0]))
    a_hull = hull_area(p)
    concavity = 0.0 if a_hull < np.sqrt(3) / 4 * s * s else min(1.0, max(0.0, 1 - shoelace(p[outline]) / a_hull))
    h = heights(p, outline, params.core_radius, s)
    if h is None:
        return n, elongation, concavity, 0, np.zeros(n), [], []
    protruding = [i for i in range(n) if h[i] >= params.min_height]
    links = [(outline[k], outline[(k + 1) % len(outline)]) for k in range(len(outline))]
    links += [tuple(map(int, e)) for e in body.springs]
    groups = S.connected_groups(protruding, links)
    found = [S.Protrusion(tuple(g), float(h[g].max()), tuple(map(float, p[g].mean(axis=0)))) for g in groups]
    found.sort(key=lambda pr: (-pr.size, -pr.height, pr.cells))
    return n, elongation, concavity, n - len(protruding), h, found, S.symmetric_pairs(p, found, params, s)


def stored_bodies():
    """The bodies of the last best genome of each stored run of data/replication_regime."""
    bodies = []
    for run_dir in sorted(DATA.glob("replication_regime/*/run_*")):
        run = animat.Run(run_dir)
        config = run.config
        embryo = animat.develop(run.best_genomes[-1].genome, config)
        if embryo.viable:
            bodies.append(animat.build_body(embryo, config=config))
    return bodies


def random_bodies(n, seed):
    config = animat.Config()
    out = []
    for i in range(n):
        genome = animat.Genome.random_viable(animat.Rng.derive(seed, 0, i), config)[0]
        out.append(animat.build_body(animat.develop(genome, config), config=config))
    return out


@pytest.fixture(scope="module")
def bodies():
    return stored_bodies() + random_bodies(30, seed=56)


def test_engine_shape_equals_the_definitions_on_evolved_and_random_bodies(bodies):
    assert len(bodies) >= 50
    with_protrusions = with_pairs = 0
    for k, body in enumerate(bodies):
        got = S.body_shape(body)
        n, elongation, concavity, core_cells, h, found, pairs = reference(body)
        assert got.cell_count == n, k
        assert got.elongation == pytest.approx(elongation, rel=1e-12), k
        assert got.concavity == pytest.approx(concavity, rel=1e-12, abs=1e-15), k
        assert got.core_cells == core_cells, k
        assert np.allclose(got.heights, h, rtol=0, atol=1e-12), k
        assert [pr.cells for pr in got.protrusions] == [pr.cells for pr in found], k
        assert [pr.height for pr in got.protrusions] == pytest.approx([pr.height for pr in found], abs=1e-12), k
        assert list(got.symmetric_pairs) == list(pairs), k
        with_protrusions += got.protrusion_count > 0
        with_pairs += got.symmetric_pair
    # a real comparison: bodies with protrusions, and some with a symmetric pair
    assert with_protrusions >= 10
    assert with_pairs >= 2


def test_the_engine_elongation_is_the_one_morphology_kind_bands(bodies):
    for body in bodies:
        assert S.elongation(body.positions) == _core.shape_elongation(body.positions)
        assert S.body_shape(body).elongation == _core.shape_elongation(body.positions)


def test_an_outline_index_that_is_no_cell_is_refused_by_value():
    with pytest.raises(ValueError, match="outline index 7 is not a cell"):
        S.describe([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], [0, 1, 7])
