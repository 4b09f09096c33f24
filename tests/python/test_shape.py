"""Shape descriptors (animat.shape) on hand-built bodies with known answers."""

import math

import numpy as np
import pytest

import animat
from animat import shape as S

SQ3 = math.sqrt(3.0)
RHO = S.ShapeParams().core_radius
BUMP_HEIGHT = SQ3 / 2 + math.sqrt(RHO**2 - 0.25) - RHO  # one cell in the notch of a flat side: 0.675
TOL = 1e-9


def hexagon(radius=2.0):
    """Hexagonally packed cells (spacing 1) within `radius` of the origin: 19 cells for 2.0."""
    pts = [(i + 0.5 * j, j * SQ3 / 2) for i in range(-8, 9) for j in range(-8, 9)]
    return np.array([p for p in pts if p[0] ** 2 + p[1] ** 2 <= radius**2 + 1e-9])


def strip(rows=5, length=8):
    """A hexagonally packed strip along x with flat top and bottom sides and 120° corners: rows of
    `length` cells (even rows, shifted by 1/2) and `length` + 1 cells (odd rows); `rows` is odd."""
    return np.array([(i + 0.5 * ((r + 1) % 2), r * SQ3 / 2) for r in range(rows) for i in range(length + r % 2)])


def shape_of(points):
    return S.body_shape(animat.build_body(np.asarray(points, dtype=float)))


def test_hexagon_is_a_round_convex_body_without_protrusions():
    sh = shape_of(hexagon())
    assert sh.cell_count == 19
    assert sh.spacing == pytest.approx(1.0)
    assert sh.elongation == pytest.approx(1.0, abs=1e-12)
    assert sh.concavity == pytest.approx(0.0, abs=1e-12)
    assert sh.outline_area == pytest.approx(6 * SQ3, rel=1e-12)  # hexagon of circumradius 2
    assert sh.protrusion_count == 0 and sh.core_cells == 19
    # the six 120° corners: ρ (1/sin 60° − 1); every other cell is in the core
    corner = RHO * (2 / SQ3 - 1)
    assert sorted(sh.heights)[-6:] == pytest.approx([corner] * 6, abs=TOL)
    assert sorted(sh.heights)[:-6] == pytest.approx([0.0] * 13, abs=TOL)


def test_one_cell_in_a_notch_is_one_protrusion_of_size_one():
    body = strip()
    top = body[:, 1].max()
    bump = np.array([[4.0, top + SQ3 / 2]])  # in the notch between the top cells at x = 3.5 and 4.5
    pts = np.vstack([body, bump])
    sh = shape_of(pts)
    assert sh.protrusion_count == 1
    (p,) = sh.protrusions
    assert p.cells == (len(body),) and p.size == 1
    assert p.height == pytest.approx(BUMP_HEIGHT, abs=TOL)
    assert sh.core_cells == len(body)
    assert not sh.symmetric_pair


def test_strip_alone_has_no_protrusions_and_its_elongation_follows_the_moments():
    pts = strip()
    sh = shape_of(pts)
    assert sh.protrusion_count == 0
    c = pts - pts.mean(axis=0)
    lam = np.linalg.eigvalsh(c.T @ c / len(pts) + np.eye(2) / 16)
    assert sh.elongation == pytest.approx(math.sqrt(lam[1] / lam[0]), rel=1e-12)
    # outline: a 7 x 2√3 rectangle and four half-cell triangles (√3/4 each) at the ends; its hull adds
    # the two notches of the middle row (√3/4 each)
    assert sh.outline_area == pytest.approx(15 * SQ3, rel=1e-12)
    assert sh.hull_area == pytest.approx(15.5 * SQ3, rel=1e-12)
    assert sh.concavity == pytest.approx(1 / 31, rel=1e-12)


def test_disc_with_two_opposite_bumps_is_a_symmetric_pair():
    bump = np.array([2.5, SQ3 / 2])
    sh = shape_of(np.vstack([hexagon(), bump, -bump]))
    assert sh.protrusion_count == 2
    assert sorted(p.cells for p in sh.protrusions) == [(19,), (20,)]
    assert all(p.size == 1 for p in sh.protrusions)
    assert sh.symmetric_pairs == ((0, 1),)
    one = shape_of(np.vstack([hexagon(), bump]))
    assert one.protrusion_count == 1 and not one.symmetric_pair


def test_fins_on_an_elongated_body_pair_only_when_mirrored_about_its_axis():
    body = strip()
    top, bottom = body[:, 1].max() + SQ3 / 2, body[:, 1].min() - SQ3 / 2
    # top and bottom rows hold cells at x = 0.5 ... 7.5: notches at x = 1 ... 7
    mirrored = shape_of(np.vstack([body, [[4.0, top], [4.0, bottom]]]))
    assert mirrored.protrusion_count == 2
    assert mirrored.symmetric_pairs == ((0, 1),)
    assert all(p.height == pytest.approx(BUMP_HEIGHT, abs=TOL) for p in mirrored.protrusions)
    staggered = shape_of(np.vstack([body, [[1.0, top], [5.0, bottom]]]))
    assert staggered.protrusion_count == 2
    assert staggered.symmetric_pairs == ()


def test_a_chain_sticking_out_is_one_protrusion_of_its_length():
    pts = np.vstack([hexagon(), [[3.0, 0.0], [4.0, 0.0]]])
    for springs in (True, False):
        body = animat.build_body(pts)
        sh = S.describe(body.positions, body.skin_loops[0], body.springs if springs else None)
        assert sh.protrusion_count == 1
        assert sh.protrusions[0].cells == (19, 20)
        # the tip's distance from the core: from the eroded hexagon's corner on the x axis, minus ρ
        eroded_corner = 2.0 - RHO / math.sin(math.pi / 3)
        assert sh.protrusions[0].height == pytest.approx(4.0 - eroded_corner - RHO, abs=TOL)
        assert sh.heights[19] == pytest.approx(3.0 - eroded_corner - RHO, abs=TOL)


def test_corners_sharper_than_74_degrees_protrude():
    # a triangle of hexagonally packed cells, 6 per side: three 60° tips at height ρ (1/sin 30° − 1) = ρ
    tri = np.array([(i + 0.5 * j, j * SQ3 / 2) for j in range(6) for i in range(6 - j)])
    sh = shape_of(tri)
    assert sh.protrusion_count == 3
    assert all(p.size == 1 for p in sh.protrusions)
    assert all(p.height == pytest.approx(RHO, abs=TOL) for p in sh.protrusions)
    tips = {0, 5, len(tri) - 1}
    assert {p.cells[0] for p in sh.protrusions} == tips
    # a square-packed square: 90° corners at ρ (√2 − 1) = 0.31 < 0.5
    square = np.array([(i, j) for i in range(5) for j in range(5)], dtype=float)
    sq = shape_of(square)
    assert sq.protrusion_count == 0
    assert max(sq.heights) == pytest.approx(RHO * (math.sqrt(2) - 1), abs=TOL)
    assert sq.elongation == pytest.approx(1.0, abs=1e-12)


def test_line_is_elongated_and_has_no_core():
    for k in (2, 10, 32):
        pts = np.column_stack([np.arange(k, dtype=float), np.zeros(k)])
        sh = shape_of(pts)
        assert sh.elongation == pytest.approx(math.sqrt(1 + 4 * (k * k - 1) / 3), rel=1e-12)
        assert sh.concavity == 0.0 and sh.outline_area == 0.0
        assert sh.protrusion_count == 0 and sh.core_cells == 0 and not sh.has_core
    bare = S.elongation(np.column_stack([np.arange(10.0), np.zeros(10)]), S.ShapeParams(cell_diameter=0.0))
    assert bare == math.inf


def test_cross_of_chains_is_round_and_fully_concave():
    arms = [(x, 0) for x in range(-3, 4)] + [(0, y) for y in (-3, -2, -1, 1, 2, 3)]
    sh = shape_of(np.array(arms, dtype=float))
    assert sh.elongation == pytest.approx(1.0, abs=1e-12)
    assert sh.outline_area == 0.0 and sh.hull_area == pytest.approx(18.0)
    assert sh.concavity == 1.0
    assert sh.protrusion_count == 0 and not sh.has_core


def test_concavity_of_a_notched_square_with_a_given_outline():
    # a 3 x 3 square grid without the middle of its top side; the outline dips to the centre cell
    pts = np.array([(0, 0), (1, 0), (2, 0), (0, 1), (1, 1), (2, 1), (0, 2), (2, 2)], dtype=float)
    outline = [0, 1, 2, 5, 7, 4, 6, 3]
    sh = S.describe(pts, outline)
    assert sh.hull_area == pytest.approx(4.0) and sh.outline_area == pytest.approx(3.0)
    assert sh.concavity == pytest.approx(0.25, abs=1e-12)
    dangling = S.describe(pts, outline[:3] + [5, 2, 1])  # an outline with edges walked twice encloses nothing
    assert dangling.outline_area == pytest.approx(0.0) and dangling.concavity == pytest.approx(1.0)


def test_descriptors_do_not_depend_on_position_rotation_or_scale():
    bump = np.array([2.5, SQ3 / 2])
    pts = np.vstack([hexagon(), bump, -bump, [[3.0, 0.0]]])
    ref = shape_of(pts)
    a = 0.7
    rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    moved = shape_of(1.3 * pts @ rot.T + np.array([5.0, -2.0]))
    assert moved.spacing == pytest.approx(1.3)
    assert moved.elongation == pytest.approx(ref.elongation, rel=1e-9)
    assert moved.concavity == pytest.approx(ref.concavity, rel=1e-9)
    assert [p.cells for p in moved.protrusions] == [p.cells for p in ref.protrusions]
    assert moved.symmetric_pairs == ref.symmetric_pairs
    assert np.allclose(moved.heights, ref.heights, atol=1e-9)


def test_as_dict_is_flat_and_consistent():
    bump = np.array([2.5, SQ3 / 2])
    chain = [[1.5, 1.5 * SQ3], [2.0, 2 * SQ3]]  # out of the corner at (1, √3)
    sh = shape_of(np.vstack([hexagon(), bump, -bump, chain]))
    d = sh.as_dict()
    assert all(isinstance(v, (int, float)) for v in d.values())
    assert d["protrusions"] == sh.protrusion_count
    assert d["protruding_cells"] == sum(p.size for p in sh.protrusions) == d["cells"] - d["core_cells"]
    assert d["largest_protrusion"] == 2 and d["single_cell_protrusions"] == 2


def test_small_and_empty_bodies():
    assert S.describe(np.zeros((0, 2)), None).cell_count == 0
    one = S.describe(np.zeros((1, 2)), None)
    assert one.elongation == 1.0 and one.protrusion_count == 0
    two = shape_of([[0.0, 0.0], [1.0, 0.0]])
    assert two.concavity == 0.0 and two.protrusion_count == 0


def test_genome_shape_develops_and_builds_the_body():
    config = animat.Config()
    genome, _ = animat.Genome.random_viable(3, config)
    body = animat.build_body(animat.develop(genome, config), config=config)
    assert S.genome_shape(genome, config) == S.body_shape(body)
    nonviable = next(
        g for g in (animat.Genome.random(k, config) for k in range(100)) if not animat.develop(g, config).viable
    )
    assert S.genome_shape(nonviable, config) is None


def test_params_are_checked():
    with pytest.raises(ValueError):
        S.ShapeParams(core_radius=0.0)
    with pytest.raises(ValueError):
        S.ShapeParams(min_height=-1.0)


def test_public_building_blocks_agree_with_describe():
    # principal_axes: the moments behind elongation; axes orthonormal, the long one along x for a strip
    body = strip()
    lam, axes = S.principal_axes(body)
    assert lam[0] <= lam[1]
    assert math.sqrt(lam[1] / lam[0]) == pytest.approx(S.elongation(body), rel=1e-12)
    assert axes.T @ axes == pytest.approx(np.eye(2), abs=1e-12)
    assert abs(axes[0, 1]) == pytest.approx(1.0, abs=1e-9)
    with pytest.raises(ValueError, match="no cells"):
        S.principal_axes(np.zeros((0, 2)))
    # connected_groups: components over the members only, each sorted, in order of first member
    assert S.connected_groups([5, 1, 2, 9], [(1, 2), (2, 7), (9, 5)]) == [[5, 9], [1, 2]]
    assert S.connected_groups([], [(0, 1)]) == []
    # symmetric_pairs: the pairs describe reports
    bump = np.array([2.5, SQ3 / 2])
    points = np.vstack([hexagon(), bump, -bump])
    sh = shape_of(points)
    assert tuple(S.symmetric_pairs(points, sh.protrusions)) == sh.symmetric_pairs == ((0, 1),)
    assert S.symmetric_pairs(points, sh.protrusions[:1]) == []
