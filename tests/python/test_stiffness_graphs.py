"""Evolvable stiffness and the other body graphs from Python: evolved stiffness reaches the body
(genome.extra_outputs = "stiffness"), the stiffness map renders (the phase map's sibling), old
genomes still develop, and body.graph selects the distance / alpha-shape bodies."""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import animat  # noqa: E402
from animat import plot  # noqa: E402


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def stiffness_config():
    c = animat.Config()
    c["genome.extra_outputs"] = "stiffness"
    return c


@pytest.fixture(scope="module")
def stiff_embryo():
    c = stiffness_config()
    genome, _ = animat.Genome.random_viable(3, c)
    return animat.develop(genome, c), c


def test_stiffness_output_sets_per_cell_factors(stiff_embryo):
    embryo, c = stiff_embryo
    f = np.asarray(embryo.stiffness)
    assert f.shape == (embryo.cell_count,)
    lo, hi = c["development.stiffness_min"], c["development.stiffness_max"]
    assert np.all(f >= lo) and np.all(f <= hi)
    body = animat.build_body(embryo, config=c)
    assert np.array_equal(np.asarray(body.stiffness), f)


def test_default_config_has_no_stiffness():
    c = animat.Config()
    genome, _ = animat.Genome.random_viable(3, c)
    embryo = animat.develop(genome, c)
    assert len(embryo.stiffness) == 0
    assert len(animat.build_body(embryo, config=c).stiffness) == 0
    # An old (paper) genome under a config that enables the output: it has no stiffness element, so
    # level 0 everywhere, i.e. stiffness_min; it develops exactly as before otherwise.
    e2 = animat.develop(genome, stiffness_config())
    assert np.array_equal(np.asarray(e2.positions), np.asarray(embryo.positions))
    assert np.allclose(e2.stiffness, stiffness_config()["development.stiffness_min"])


def test_stiffness_map_renders(stiff_embryo, tmp_path):
    embryo, c = stiff_embryo
    body = animat.build_body(embryo, config=c)
    fig = plot.stiffness_map(body)
    ax = fig.axes[0]
    nodes = [col for col in ax.collections if col.get_label() == "nodes"][0]
    f = np.asarray(body.stiffness)
    assert np.allclose(nodes.get_array(), f)
    assert nodes.norm.vmax == pytest.approx(f.max())
    fig.savefig(tmp_path / "stiffness_map.png")
    assert (tmp_path / "stiffness_map.png").stat().st_size > 1000
    # Beside the phase map, into given axes; and a body without evolved stiffness.
    fig, (a, b) = plt.subplots(1, 2)
    plot.phase_map(body, ax=a, colorbar=False)
    plot.stiffness_map(body, ax=b, colorbar=False)
    plain = animat.build_body(np.asarray(body.positions))
    fig = plot.stiffness_map(plain)
    assert "uniform" in fig.axes[0].get_title()


@pytest.mark.parametrize("graph", ["distance", "alpha_shape"])
def test_body_graph_from_config(graph):
    rng = np.random.default_rng(2)
    pts = rng.uniform(0, 6, size=(40, 2))
    c = animat.Config()
    c["body.graph"] = graph
    body = animat.build_body(pts, config=c)
    gabriel = animat.build_body(pts)
    assert not np.array_equal(np.asarray(body.springs), np.asarray(gabriel.springs))
    assert np.all(np.asarray(body.rest_areas) > 0)
    with pytest.raises(ValueError, match="body.graph"):
        c["body.graph"] = "voronoi"


def test_stiffness_map_colours_springs_by_their_harmonic_mean():
    pos = np.array([[0, 0], [1, 0], [0.5, 0.9], [1.5, 0.9]], dtype=float)
    plain = animat.build_body(pos)
    kind, version, state = plain.__getstate__()  # a Body with evolved factors, through its pickled state
    f = np.array([0.5, 1.0, 2.0, 4.0])
    body = animat.Body.__new__(animat.Body)
    body.__setstate__((kind, version, tuple(state[:10]) + (f,)))
    assert np.array_equal(body.stiffness, f)
    old = animat.Body.__new__(animat.Body)  # pickled before evolvable stiffness (10 fields): still loads
    old.__setstate__((kind, version, tuple(state[:10])))
    assert len(old.stiffness) == 0 and np.array_equal(old.springs, plain.springs)
    fig = plot.stiffness_map(body)
    ax = fig.axes[0]
    springs = [c for c in ax.collections if c.get_array() is not None and c.get_label() != "nodes"][0]
    sp = np.asarray(body.springs)
    expected = 2 * f[sp[:, 0]] * f[sp[:, 1]] / (f[sp[:, 0]] + f[sp[:, 1]])
    assert np.allclose(springs.get_array(), expected)
    cmap = plt.get_cmap(plot.STIFFNESS_CMAP)
    assert np.allclose(springs.get_edgecolor(), cmap(springs.norm(expected)))
