"""Body stage through Python: Gabriel graph against its O(n^3) definition, Body shapes and dtypes,
and the documented errors."""

import re

import numpy as np
import pytest

import animat


def brute_gabriel(points):
    """(i, j) is an edge iff no other point p lies in the closed disc with diameter ij, i.e.
    iff dot(p_i - p, p_j - p) > 0 for every other p (Thales)."""
    p = np.asarray(points, dtype=float)
    n = len(p)
    edges = []
    for i in range(n):
        di = p[i] - p  # (n, 2)
        for j in range(i + 1, n):
            dot = np.einsum("kd,kd->k", di, p[j] - p)
            dot[[i, j]] = 1.0
            if np.all(dot > 0):
                edges.append((i, j))
    return np.array(edges, dtype=np.int64).reshape(-1, 2)


@pytest.mark.parametrize("n", [3, 4, 5, 7, 10, 16, 25, 40, 75, 150])
def test_gabriel_matches_brute_force_random(n):
    for seed in range(8 if n <= 40 else 2):
        p = np.random.default_rng(1000 * n + seed).uniform(-5, 5, size=(n, 2))
        got = animat.gabriel_graph(p)
        assert got.dtype == np.int64 and got.shape[1] == 2
        np.testing.assert_array_equal(got, brute_gabriel(p), err_msg=f"n={n} seed={seed}")


def test_gabriel_matches_brute_force_on_lattice_points():
    # Integer lattice points: cocircular quadruples everywhere, decided by the closed disc.
    rng = np.random.default_rng(7)
    for trial in range(30):
        side = int(rng.integers(3, 9))
        cells = rng.choice(side * side, size=int(rng.integers(3, side * side + 1)), replace=False)
        p = np.stack([cells % side, cells // side], axis=1).astype(float)
        np.testing.assert_array_equal(animat.gabriel_graph(p), brute_gabriel(p), err_msg=f"trial {trial}")


def test_square_grid_has_no_diagonals():
    k = 7
    x, y = np.meshgrid(np.arange(k, dtype=float), np.arange(k, dtype=float))
    p = np.stack([x.ravel(), y.ravel()], axis=1)
    edges = animat.gabriel_graph(p)
    assert len(edges) == 2 * k * (k - 1)
    lengths = np.linalg.norm(p[edges[:, 0]] - p[edges[:, 1]], axis=1)
    np.testing.assert_array_equal(lengths, 1.0)


def test_edges_are_sorted_and_a_delaunay_subset():
    p = np.random.default_rng(3).random((60, 2))
    g = animat.gabriel_graph(p)
    d = animat.delaunay_edges(p)
    assert d.dtype == np.int64 and d.shape[1] == 2
    for e in (g, d):
        assert np.all(e[:, 0] < e[:, 1])
        assert [tuple(r) for r in e] == sorted(tuple(r) for r in e)
    assert {tuple(r) for r in g} <= {tuple(r) for r in d}


def test_accepts_lists_and_other_dtypes():
    pts = [[0, 0], [1, 0], [0, 1]]
    np.testing.assert_array_equal(animat.gabriel_graph(pts), [[0, 1], [0, 2]])  # (1, 2): 0 on its circle
    np.testing.assert_array_equal(animat.gabriel_graph(np.array(pts, dtype=np.int32)), [[0, 1], [0, 2]])
    np.testing.assert_array_equal(animat.gabriel_graph(np.asfortranarray(np.array(pts, float))), [[0, 1], [0, 2]])


def test_body_fields_shapes_and_dtypes():
    rng = np.random.default_rng(11)
    n = 30
    p = rng.uniform(0, 10, size=(n, 2))
    amp, freq, phase = rng.uniform(0, 0.2, n), rng.uniform(1, 3, n), rng.uniform(0, 2 * np.pi, n)
    b = animat.build_body(p, amplitude=amp, frequency=freq, phase=phase)
    assert isinstance(b, animat.Body)
    assert b.node_count == n
    assert b.positions.shape == (n, 2) and b.positions.dtype == np.float64
    np.testing.assert_array_equal(b.positions, p)
    m = b.spring_count
    assert b.springs.shape == (m, 2) and b.springs.dtype == np.int64
    np.testing.assert_array_equal(b.springs, animat.gabriel_graph(p))
    assert b.rest_lengths.shape == (m,)
    np.testing.assert_allclose(b.rest_lengths, np.linalg.norm(p[b.springs[:, 0]] - p[b.springs[:, 1]], axis=1))
    assert isinstance(b.regions, list) and len(b.regions) == b.region_count
    assert all(r.dtype == np.int64 and r.ndim == 1 and len(r) >= 3 for r in b.regions)
    assert b.rest_areas.shape == (b.region_count,) and np.all(b.rest_areas > 0)
    assert b.skin.dtype == np.int64 and b.skin.shape[1] == 2
    assert len(b.skin_loops) == 1 and b.skin_loops[0].dtype == np.int64
    for name, want in [("amplitude", amp), ("frequency", freq), ("phase", phase)]:
        got = getattr(b, name)
        assert got.shape == (n,) and got.dtype == np.float64
        np.testing.assert_array_equal(got, want)
    # Euler for a connected planar graph, and the regions tile the area inside the skin.
    assert b.node_count - b.spring_count + b.region_count == 1
    skin_area = animat.polygon_area(p, b.skin_loops[0].tolist())
    assert np.isclose(b.rest_areas.sum(), skin_area, rtol=1e-12)
    for r, area in zip(b.regions, b.rest_areas):
        assert animat.polygon_area(p, r.tolist()) == area
    assert repr(b) == f"<animat.Body {n} nodes, {m} springs, {b.region_count} regions, {len(b.skin)} skin edges>"


def test_every_half_edge_in_exactly_one_face():
    p = np.random.default_rng(5).uniform(-1, 1, size=(80, 2))
    b = animat.build_body(p)
    halfedges = []
    for r in b.regions:  # CCW, face on the left
        halfedges += list(zip(r.tolist(), np.roll(r, -1).tolist()))
    s = b.skin_loops[0]  # CCW around the body: the outer face walks it backwards
    halfedges += list(zip(np.roll(s, -1).tolist(), s.tolist()))
    assert len(halfedges) == len(set(halfedges)) == 2 * b.spring_count
    skin_from_loop = sorted({(min(a, c), max(a, c)) for a, c in zip(s.tolist(), np.roll(s, -1).tolist())})
    assert skin_from_loop == [tuple(e) for e in b.skin.tolist()]


def test_oscillators_default_to_zero():
    b = animat.build_body([[0, 0], [1, 0], [0.5, 0.9]])
    for name in ("amplitude", "frequency", "phase"):
        np.testing.assert_array_equal(getattr(b, name), np.zeros(3))
    assert b.region_count == 1
    np.testing.assert_array_equal(b.regions[0], [0, 1, 2])
    assert b.rest_areas[0] == pytest.approx(0.45)


def test_degenerate_sizes():
    b0 = animat.build_body(np.zeros((0, 2)))
    assert b0.node_count == 0 and b0.springs.shape == (0, 2) and b0.regions == [] and b0.skin_loops == []
    assert animat.gabriel_graph(np.zeros((0, 2))).shape == (0, 2)
    assert animat.gabriel_graph([]).shape == (0, 2)
    b1 = animat.build_body([[1.0, 2.0]])
    assert b1.node_count == 1 and b1.spring_count == 0 and b1.skin.shape == (0, 2) and b1.skin_loops == []
    b2 = animat.build_body([[0.0, 0.0], [3.0, 4.0]])
    np.testing.assert_array_equal(b2.springs, [[0, 1]])
    np.testing.assert_array_equal(b2.rest_lengths, [5.0])
    np.testing.assert_array_equal(b2.skin, [[0, 1]])
    np.testing.assert_array_equal(b2.skin_loops[0], [0, 1])


def test_collinear_is_a_chain():
    order = np.random.default_rng(2).permutation(12)
    p = np.stack([order * 2.0 + 1, order * -3.0], axis=1)  # exactly collinear, shuffled
    b = animat.build_body(p)
    inv = np.argsort(order)  # inv[k] = index of the k-th point along the line
    chain = sorted(tuple(sorted((int(inv[k]), int(inv[k + 1])))) for k in range(11))
    assert [tuple(e) for e in b.springs.tolist()] == chain
    assert b.regions == [] and len(b.skin) == 11 and len(b.skin_loops[0]) == 22


@pytest.mark.parametrize(
    "points, message",
    [
        (np.zeros((3, 3)), "gabriel_graph: points must be an (n, 2) array, got shape (3, 3)"),
        (np.zeros(4), "gabriel_graph: points must be an (n, 2) array, got shape (4,)"),
        (np.zeros((3, 0)), "gabriel_graph: points must be an (n, 2) array, got shape (3, 0)"),
        ([[0, 0], [1, np.nan], [2, 5]], "gabriel_graph: point 1 has a non-finite coordinate y = nan"),
        ([[0, 0], [np.inf, 1]], "gabriel_graph: point 1 has a non-finite coordinate x = inf"),
        ([[0, 0], [1, 2e7]], "gabriel_graph: point 1 has coordinate y = 20000000, beyond max_coordinate = 1000000"),
        (
            [[0, 0], [1, 1], [0, 0]],
            "gabriel_graph: points 0 and 2 coincide at (0, 0) (distance 0); duplicate cell centres are rejected",
        ),
        (
            [[0, 0], [1, 1], [2.5e-7, 0]],
            "gabriel_graph: points 0 and 2 are 2.5e-07 apart, closer than merge_distance = 1e-06; "
            "near-coincident cell centres are rejected",
        ),
    ],
)
def test_bad_points_raise_value_error(points, message):
    with pytest.raises(ValueError) as info:
        animat.gabriel_graph(points)
    assert str(info.value) == message


def test_bad_oscillators_raise_value_error():
    p = [[0, 0], [1, 0], [0.5, 0.9]]
    with pytest.raises(ValueError, match=r"^build_body: amplitude has 2 entries, expected 3"):
        animat.build_body(p, amplitude=[0.1, 0.2])
    with pytest.raises(ValueError, match=r"^build_body: phase must be a 1-D array, got shape \(3, 1\)"):
        animat.build_body(p, phase=np.zeros((3, 1)))
    with pytest.raises(ValueError, match=r"^build_body: frequency\[2\] = nan is not finite"):
        animat.build_body(p, frequency=[1.0, 1.0, np.nan])


def test_config_body_section_is_used():
    p = [[0, 0], [1, 0], [0.5, 0.9], [0.5, 0.9 + 1e-3]]
    with pytest.raises(ValueError, match="closer than merge_distance = 0.01"):
        animat.build_body(p, config=animat.Config({"body": {"merge_distance": 0.01}}))
    assert animat.build_body(p).node_count == 4  # default merge_distance 1e-6


def test_build_body_from_embryo_matches_arrays():
    for seed in range(20):
        embryo = animat.develop(animat.Genome.random(seed))
        try:
            b = animat.build_body(embryo, allow_nonviable=True)  # any embryo: non-viable ones are refused by default
        except ValueError as e:  # development's business; the array overload must agree
            with pytest.raises(ValueError, match=re.escape(str(e))):
                animat.build_body(embryo.positions, embryo.amplitude, embryo.frequency, embryo.phase)
            continue
        ref = animat.build_body(embryo.positions, embryo.amplitude, embryo.frequency, embryo.phase)
        for name in ("positions", "springs", "rest_lengths", "rest_areas", "skin", "amplitude", "frequency", "phase"):
            np.testing.assert_array_equal(getattr(b, name), getattr(ref, name))
        assert [r.tolist() for r in b.regions] == [r.tolist() for r in ref.regions]
