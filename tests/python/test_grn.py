"""animat.Grn through Python: eq. 1 relaxation against its closed form, levels in [0, 1),
maternal and sensed-morphogen inputs, edges, reachability (viability criterion 1) and DOT export."""

import math

import numpy as np
import pytest

import animat

P, G, M, I, O = 0, 1, 2, 3, 4
BIAS, MAT0, MAT1, MAT2 = 0, 1, 2, 3
DIVIDE, ROTATE, GROW, AMPLITUDE, FREQUENCY, PHASE = range(6)


def genome(elements):
    """elements: list of (type, channel, x, y, sign)."""
    n = len(elements)
    types = np.array([e[0] for e in elements], dtype=np.int64).reshape(n)
    channels = np.array([e[1] for e in elements], dtype=np.int64).reshape(n)
    coords = np.array([[e[2], e[3]] for e in elements], dtype=np.float64).reshape(n, 2)
    signs = np.array([e[4] if len(e) > 4 else 1 for e in elements], dtype=np.int64).reshape(n)
    return animat.Genome.from_arrays(types, signs, channels, coords)


def closed_form(T, steps, dt=0.05):
    k = np.arange(steps + 1, dtype=float)
    return T * (1.0 - (1.0 - dt) ** k)


def required_outputs(x, y):
    return [(O, c, x, y) for c in (DIVIDE, AMPLITUDE, FREQUENCY, PHASE)]


def test_unit_relaxes_along_closed_form():
    grn = animat.Grn(genome([(I, BIAS, 0, 0), (P, 0, 0, 0), (G, 0, 9, 9)]))
    assert grn.unit_count == 1 and grn.node_count == 7
    L = grn.run(200)
    assert L.shape == (201, 7) and L.dtype == np.float64
    np.testing.assert_allclose(L[:, 0], closed_form(math.tanh(5.0), 200), rtol=0, atol=1e-12)
    # The discrete recurrence, step by step.
    l = 0.0
    for k in range(1, 201):
        l += (math.tanh(5.0) - l) * 0.05
        assert abs(L[k, 0] - l) < 1e-12


@pytest.mark.parametrize(
    "x, s_in, s_p", [(0.0, 1, 1), (0.0, -1, -1), (0.5, 1, 1), (1.7, 1, 1), (0.0, -1, 1), (1.0, 1, -1)]
)
def test_closed_form_for_several_activations(x, s_in, s_p):
    grn = animat.Grn(genome([(I, BIAS, 0, 0, s_in), (P, 0, x, 0, s_p), (G, 0, 9, 9)]))
    A = s_in * s_p * animat.affinity(x)
    L = grn.run(100)
    np.testing.assert_allclose(L[:, 0], closed_form(math.tanh(max(A, 0.0) / 2), 100), rtol=0, atol=1e-12)


def test_dt_from_config():
    grn = animat.Grn(genome([(I, BIAS, 0, 0), (P, 0, 0, 0), (G, 0, 9, 9)]))
    c = animat.Config({"grn": {"dt": 0.1}})
    np.testing.assert_allclose(grn.run(50, config=c)[:, 0], closed_form(math.tanh(5.0), 50, 0.1), rtol=0, atol=1e-12)


def test_output_node_relaxes_along_closed_form():
    grn = animat.Grn(genome([(I, BIAS, 0, 0), (O, DIVIDE, 0, 0), (O, PHASE, 0.8, 0)]))
    assert grn.unit_count == 0 and grn.node_count == 6
    L = grn.run(100)
    d, p = grn.output_index(animat.OutputChannel.divide), grn.output_index(animat.OutputChannel.phase)
    assert (d, p) == (0, 5)
    np.testing.assert_allclose(L[:, d], closed_form(math.tanh(5.0), 100), rtol=0, atol=1e-12)
    np.testing.assert_allclose(L[:, p], closed_form(math.tanh(animat.affinity(0.8) / 2), 100), rtol=0, atol=1e-12)
    assert np.all(L[:, grn.output_index(animat.OutputChannel.rotate)] == 0.0)


def test_synchronous_chain_and_initial_levels():
    grn = animat.Grn(genome([(I, BIAS, 0, 0), (P, 0, 0, 0), (G, 0, 5, 5), (O, DIVIDE, 5, 5)]))
    L = grn.run(100)
    d = grn.output_index(animat.OutputChannel.divide)
    u = o = 0.0
    for k in range(1, 101):
        u, o = u + (math.tanh(5.0) - u) * 0.05, o + (math.tanh(10.0 * u / 2) - o) * 0.05
        assert abs(L[k, 0] - u) < 1e-12 and abs(L[k, d] - o) < 1e-12
    # A self-inhibiting unit started at 0.8 decays as 0.8 * 0.95^k.
    inhib = animat.Grn(genome([(P, 0, 0, 0, -1), (G, 0, 0, 0)]))
    init = [0.8] + [0.0] * 6
    np.testing.assert_allclose(inhib.run(60, initial=init)[:, 0], 0.8 * 0.95 ** np.arange(61), rtol=0, atol=1e-12)
    with pytest.raises(ValueError, match="initial has 2 levels, expected 7"):
        inhib.run(3, initial=[0.0, 0.0])
    with pytest.raises(ValueError, match="steps"):
        inhib.run(-1)


def test_maternal_inputs():
    grn = animat.Grn(genome([(I, MAT1, 0, 0), (P, 0, 0, 0), (G, 0, 9, 9), (I, MAT2, 20, 20), (O, GROW, 20, 20.5)]))
    L = grn.run(80, maternal=[0.9, 0.3, 0.6])
    np.testing.assert_allclose(L[:, 0], closed_form(math.tanh(10 * 0.3 / 2), 80), rtol=0, atol=1e-12)
    g = grn.output_index(animat.OutputChannel.grow)
    np.testing.assert_allclose(L[:, g], closed_form(math.tanh(animat.affinity(0.5) * 0.6 / 2), 80), rtol=0, atol=1e-12)
    assert np.all(grn.run(20)[:, 0] == 0.0)  # maternal inputs default to 0


def test_sensed_morphogens_replace_own_level():
    grn = animat.Grn(genome([(I, BIAS, 0, 0), (P, 0, 0, 0), (M, 0, 5, 5), (P, 0, 5, 5), (G, 0, 9, 0)]))
    assert grn.unit_count == 2
    assert list(grn.morphogen_units) == [0]
    L = grn.run(100, morphogens=[0.4])
    np.testing.assert_allclose(L[:, 1], closed_form(math.tanh(2.0), 100), rtol=0, atol=1e-12)
    # Without sensed values: the cell's own level of unit 0.
    L2 = grn.run(100)
    u0 = u1 = 0.0
    for k in range(1, 101):
        u0, u1 = u0 + (math.tanh(5.0) - u0) * 0.05, u1 + (math.tanh(10 * u0 / 2) - u1) * 0.05
        assert abs(L2[k, 1] - u1) < 1e-12
    with pytest.raises(ValueError, match="morphogens has 2 entries, expected 1"):
        grn.run(5, morphogens=[0.1, 0.2])


def test_edges_arrays():
    grn = animat.Grn(
        genome(
            [
                (I, BIAS, 0, 0),
                (I, MAT0, 20, 0.5, -1),
                (P, 0, 0, 0),
                (P, 0, 1, 0),
                (G, 0, 10, 10),
                (P, 0, 20, 0),
                (G, 0, 30, 30),
                (O, DIVIDE, 10, 11.5),
                (O, ROTATE, 30, 30, -1),
            ]
        )
    )
    src, dst, w = grn.edges()
    assert src.dtype == np.int64 and dst.dtype == np.int64 and w.dtype == np.float64
    edges = {(int(s), int(t)): float(x) for s, t, x in zip(src, dst, w)}
    U = grn.unit_count
    assert U == 2 and len(edges) == 4
    assert edges[(0, 0)] == pytest.approx(10 + animat.affinity(1.0), abs=1e-12)
    assert edges[(1, 1)] == pytest.approx(-animat.affinity(0.5), abs=1e-12)
    assert edges[(4 + 0, U + DIVIDE)] == pytest.approx(animat.affinity(1.5), abs=1e-12)
    assert edges[(4 + 1, U + ROTATE)] == -10.0


def test_levels_stay_in_unit_interval_under_extreme_weights_for_long_runs():
    for sign in (1, -1):
        els = [(I, BIAS, 0, 0, sign)] * 40 + [(P, 0, 0, 0)] * 40 + [(G, 0, 0, 0, sign), (M, 0, 0, 0, sign)]
        els += [(O, c, 0, 0) for c in range(6)]
        grn = animat.Grn(genome(els))
        L = grn.run(100_000)
        assert L.min() >= 0.0 and L.max() < 1.0
    c = animat.Config({"genome": {"coord_range": 0.3, "initial_units": 30}})
    g = animat.Genome.random(5, c)
    grn = animat.Grn(g, c)
    rng = np.random.default_rng(0)
    L = grn.run(
        100_000,
        maternal=list(rng.uniform(size=3)),
        morphogens=list(rng.uniform(size=len(grn.morphogen_units))),
        config=c,
    )
    assert L.min() >= 0.0 and L.max() < 1.0


@pytest.mark.parametrize("dt", [0.05, 0.25, 0.5, 0.9, 1.0])
def test_levels_stay_below_one_for_every_allowed_dt(dt):
    # grn.dt may be anything in (0, 1]; tanh(A/2) rounds to 1.0 for large A.
    els = [(I, BIAS, 0, 0)] * 40 + [(P, 0, 0, 0)] * 40 + [(G, 0, 0, 0)] + [(O, c, 0, 0) for c in range(6)]
    grn = animat.Grn(genome(els))
    L = grn.run(2000, config=animat.Config({"grn": {"dt": dt}}))
    assert L.max() < 1.0, f"dt = {dt}: a level reached {L.max()!r}"


def test_has_required_paths():
    direct = animat.Grn(genome([(I, BIAS, 0, 0)] + required_outputs(0, 0)))
    assert direct.has_required_paths()
    assert direct.reaches(animat.OutputChannel.divide)
    assert not direct.reaches(animat.OutputChannel.rotate)
    for missing in (DIVIDE, AMPLITUDE, FREQUENCY, PHASE):
        els = [(I, MAT0, 0, 0)] + [
            (O, c, *((50, 50) if c == missing else (0, 0))) for c in (DIVIDE, AMPLITUDE, FREQUENCY, PHASE)
        ]
        g = animat.Grn(genome(els))
        assert not g.has_required_paths()
        assert not g.reaches(animat.OutputChannel(missing))


def test_path_through_intermediate_unit():
    chain = [(I, BIAS, 0, 0), (P, 0, 0, 0), (G, 0, 5, 5), (P, 0, 5, 5), (G, 0, 10, 10)] + required_outputs(10, 10)
    grn = animat.Grn(genome(chain))
    assert grn.unit_count == 2 and grn.has_required_paths()
    src, dst, _ = grn.edges()
    assert not any(s == 0 and t >= grn.unit_count for s, t in zip(src, dst)), "no direct input->output edge"
    broken = list(chain)
    broken[3] = (P, 0, 30, 30)
    assert not animat.Grn(genome(broken)).has_required_paths()
    # A unit that drives the outputs but is reached by no input does not count.
    orphan = [(I, BIAS, 40, 40), (P, 0, 0, 0), (G, 0, 0, 0)] + required_outputs(0, 0)
    assert not animat.Grn(genome(orphan)).has_required_paths()


def test_to_dot():
    grn = animat.Grn(
        genome([(I, BIAS, 0, 0), (P, 0, 0, 0), (M, 0, 5, 5), (P, 0, 5, 5, -1), (G, 0, 10, 10), (O, DIVIDE, 10, 10)])
    )
    dot = grn.to_dot()
    assert dot.startswith("digraph")
    for s in (
        'in0 [label="bias"',
        'u0 [label="unit 0 (morphogen)"]',
        'out0 [label="divide"',
        'in0 -> u0 [label="10", color=black]',
        'u0 -> u1 [label="-10", color=red, style=dashed]',
        'u1 -> out0 [label="10", color=black]',
    ):
        assert s in dot, dot
    assert dot.count("->") == len(grn.edges()[0]) == 3


def test_random_genome_grn_runs():
    g = animat.Genome.random(2)
    grn = animat.Grn(g)
    assert grn.unit_count == 10 and grn.node_count == 16
    L = grn.run(400, maternal=[0.2, 0.5, 0.8])
    assert L.shape == (401, 16)
    assert np.all(L[0] == 0.0)
    assert np.all((L >= 0) & (L < 1))


def test_network_key_ignores_elements_in_no_interaction_and_reads_every_weight():
    def network(gene_x, promoter_x):
        # bias -> unit 0 -> divide; the second unit's gene at (gene_x, 30) is beyond every cut-off
        return animat.Grn(
            genome(
                [(I, BIAS, 0, 0), (P, 0, promoter_x, 0), (G, 0, 10, 10), (P, 0, 20, 20), (G, 0, gene_x, 30)]
                + [(O, DIVIDE, 10, 11.5)]
            )
        )

    key = network(30, 1).network_key()
    assert isinstance(key, bytes) and len(key) > 0
    assert network(34, 1).network_key() == key  # a different genome, the same network
    assert network(30, 1.25).network_key() != key  # one weight changed
