"""replication_stats (studies/replication): Fisher's exact test against hand-computed tables, the bootstrap."""

import math

import numpy as np
import pytest

import replication_stats as S  # studies/replication (conftest.py)


def test_fisher_2x2_by_hand():
    # margins 4/4 and 4/4: P(a) = C(4,a) C(4,4-a) / C(8,4) = (1, 16, 36, 16, 1) / 70 for a = 0..4;
    # observed a = 3 (P = 16/70): the tables at most as probable are a = 0, 1, 3, 4: (1+16+16+1)/70.
    r = S.fisher_exact([[3, 1], [1, 3]])
    assert r.method == "exact" and r.tables == 5
    assert r.p_value == pytest.approx(34 / 70, rel=1e-12)
    # [[2,0],[0,2]]: P(a) = (1, 4, 1) / 6; observed a = 2 -> p = 2/6
    assert S.fisher_exact([[2, 0], [0, 2]]).p_value == pytest.approx(1 / 3, rel=1e-12)
    # a lopsided table: [[1,9],[11,3]] has p = 0.0027594561852200 (R: fisher.test)
    assert S.fisher_exact([[1, 9], [11, 3]]).p_value == pytest.approx(0.00275945618522, rel=1e-9)


def test_fisher_rxc_exact_agrees_with_monte_carlo_and_drops_empty_margins():
    t = [[5, 0, 0, 1], [0, 4, 2, 0], [0, 1, 3, 4], [0, 0, 0, 0]]
    exact = S.fisher_exact(t)
    assert exact.method == "exact" and exact.shape == (3, 4)
    mc = S.fisher_exact(t, max_tables=10, samples=100_000, seed=1)
    assert mc.method == "monte carlo"
    assert mc.p_value == pytest.approx(exact.p_value, abs=0.002 + 3 * math.sqrt(exact.p_value / 1e5))
    assert S.fisher_exact([[3, 4]]).p_value == 1.0  # one row: nothing to test
    with pytest.raises(ValueError):
        S.fisher_exact([[1, -1], [0, 2]])


def test_table_probability_sums_to_one_over_all_tables():
    # all 2x2 tables with margins (3, 2) x (2, 3): a = 0..2
    total = sum(math.exp(S.table_log_probability([[a, 3 - a], [2 - a, a]])) for a in range(0, 3))
    assert total == pytest.approx(1.0, rel=1e-12)


def test_bootstrap_interval():
    ci = S.bootstrap_ci([1.0, 2.0, 3.0, 4.0, 5.0], resamples=5000, seed=3)
    assert ci.estimate == 3.0 and ci.n == 5
    assert 1.0 <= ci.low < 3.0 < ci.high <= 5.0
    assert S.bootstrap_ci([1.0, 2.0, 3.0, 4.0, 5.0], resamples=5000, seed=3) == ci  # seeded: reproducible
    const = S.bootstrap_ci([2.5] * 4)
    assert (const.low, const.estimate, const.high) == (2.5, 2.5, 2.5)
    med = S.bootstrap_ci([1.0, 2.0, 9.0], statistic=lambda a: np.median(a, axis=1))
    assert med.estimate == 2.0
    one = S.bootstrap_ci([7.0, float("nan")])
    assert (one.low, one.high, one.n) == (7.0, 7.0, 1)


def test_mode_table():
    modes, groups, counts = S.mode_table({"a": ["x", "y", "x"], "b": ["z"]}, modes=["y", "x"])
    assert modes == ["y", "x", "z"] and groups == ["a", "b"]
    assert counts.tolist() == [[1, 0], [2, 0], [0, 1]]
