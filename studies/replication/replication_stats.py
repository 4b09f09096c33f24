"""Small-sample statistics for the replication report (replication_report.py): pure functions on plain numbers.

- :func:`fisher_exact`: Fisher's exact test of independence for an r x c contingency table (the
  Freeman–Halton extension beyond 2 x 2): does the locomotion mode depend on the environment? Exact
  enumeration of every table with the observed margins; above ``max_tables`` tables a seeded Monte
  Carlo estimate (random tables with the same margins, as R's ``fisher.test(simulate.p.value=TRUE)``),
  and the result says which.
- :func:`bootstrap_ci`: percentile bootstrap confidence interval of a statistic (seeded, so the
  report is reproducible).
- :func:`mode_table`: counts of labels per group, as the table :func:`fisher_exact` takes.

Only ``numpy`` and ``math``; no scipy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

__all__ = ["FisherResult", "fisher_exact", "table_log_probability", "BootstrapCI", "bootstrap_ci", "mode_table"]


@dataclass(frozen=True)
class FisherResult:
    """Result of :func:`fisher_exact`.

    Attributes:
        p_value: probability, under independence with the margins fixed, of a table at most as probable
            as the observed one (two-sided in the 2 x 2 case).
        method: "exact" (every table enumerated) or "monte carlo" (``samples`` random tables).
        tables: number of tables enumerated (exact) or drawn (Monte Carlo).
        shape: (rows, columns) of the table after dropping empty rows and columns.
    """

    p_value: float
    method: str
    tables: int
    shape: Tuple[int, int]


def _log_factorial(n: int) -> float:
    return math.lgamma(n + 1)


def table_log_probability(table: Union[np.ndarray, Sequence[Sequence[int]]]) -> float:
    """log P of a table under the multivariate hypergeometric law with its own margins:
    ``P = Π R_i! Π C_j! / (N! Π n_ij!)``."""
    t = np.asarray(table, dtype=np.int64)
    rows, cols, n = t.sum(axis=1), t.sum(axis=0), int(t.sum())
    return (
        sum(_log_factorial(int(r)) for r in rows)
        + sum(_log_factorial(int(c)) for c in cols)
        - _log_factorial(n)
        - sum(_log_factorial(int(x)) for x in t.ravel())
    )


def _compositions(total: int, caps: Sequence[int]):
    """All vectors v with 0 <= v_i <= caps_i and sum v = total."""
    if len(caps) == 1:
        if total <= caps[0]:
            yield (total,)
        return
    rest = sum(caps[1:])
    for v in range(max(0, total - rest), min(caps[0], total) + 1):
        for tail in _compositions(total - v, caps[1:]):
            yield (v,) + tail


def fisher_exact(
    table: Union[np.ndarray, Sequence[Sequence[int]]],
    *,
    max_tables: int = 2_000_000,
    samples: int = 200_000,
    seed: int = 0,
) -> FisherResult:
    """Fisher's exact test of independence of an r x c table of counts (rows x columns).

    The p-value sums the probabilities of every table with the observed row and column totals whose
    probability is at most the observed table's (relative tolerance 1e-7, as R's ``fisher.test``).
    Rows and columns that are all zero are dropped first; a table with fewer than two non-empty rows or
    columns gives p = 1.

    Args:
        table: counts (non-negative integers), e.g. modes x environments.
        max_tables: enumerate exactly up to this many tables, else estimate by Monte Carlo.
        samples: random tables drawn for the Monte Carlo estimate.
        seed: seed of the Monte Carlo draws.
    """
    t = np.asarray(table, dtype=np.int64)
    if t.ndim != 2 or (t < 0).any():
        raise ValueError("fisher_exact: table must be a 2-D array of non-negative counts")
    t = t[t.sum(axis=1) > 0][:, t.sum(axis=0) > 0]
    shape = (int(t.shape[0]), int(t.shape[1])) if t.size else (0, 0)
    if t.size == 0 or min(t.shape) < 2:
        return FisherResult(1.0, "exact", 1, shape)
    rows = [int(x) for x in t.sum(axis=1)]
    cols = [int(x) for x in t.sum(axis=0)]
    observed = table_log_probability(t)
    const = sum(_log_factorial(r) for r in rows) + sum(_log_factorial(c) for c in cols) - _log_factorial(int(t.sum()))
    threshold = observed + math.log1p(1e-7)

    # Exact: fill column by column; the column's cells are compositions of its total under the rows'
    # remaining totals. Accumulate Σ exp(logP) over tables with logP <= threshold.
    total = [0.0]
    count = [0]
    too_many = [False]

    def fill(j: int, remaining: List[int], partial: float) -> None:
        if too_many[0]:
            return
        if j == len(cols) - 1:  # the last column is forced
            lp = partial - sum(_log_factorial(r) for r in remaining)
            count[0] += 1
            if count[0] > max_tables:
                too_many[0] = True
                return
            if const + lp <= threshold:
                total[0] += math.exp(const + lp)
            return
        for col in _compositions(cols[j], remaining):
            fill(j + 1, [r - v for r, v in zip(remaining, col)], partial - sum(_log_factorial(v) for v in col))

    fill(0, list(rows), 0.0)
    if not too_many[0]:
        return FisherResult(min(1.0, total[0]), "exact", count[0], shape)

    # Monte Carlo: random tables with the same margins are random pairings of row labels and column labels.
    rng = np.random.default_rng(seed)
    row_labels = np.repeat(np.arange(len(rows)), rows)
    col_labels = np.repeat(np.arange(len(cols)), cols)
    lf = np.array([_log_factorial(k) for k in range(int(t.sum()) + 1)])
    hits = 0
    batch = 10_000
    done = 0
    while done < samples:
        m = min(batch, samples - done)
        perm = np.argsort(rng.random((m, len(row_labels))), axis=1)
        cells = row_labels[perm] * len(cols) + col_labels[None, :]
        counts = np.zeros((m, len(rows) * len(cols)), dtype=np.int64)
        np.add.at(counts, (np.repeat(np.arange(m), len(row_labels)), cells.ravel()), 1)
        lp = const - lf[counts].sum(axis=1)
        hits += int((lp <= threshold).sum())
        done += m
    return FisherResult((hits + 1) / (samples + 1), "monte carlo", samples, shape)


@dataclass(frozen=True)
class BootstrapCI:
    """A statistic of a sample with its percentile bootstrap interval.

    Attributes:
        estimate: the statistic of the sample itself.
        low, high: the (1 - level)/2 and (1 + level)/2 quantiles of the statistic over the resamples.
        level: e.g. 0.95. resamples: how many. n: sample size.
    """

    estimate: float
    low: float
    high: float
    level: float
    resamples: int
    n: int


def bootstrap_ci(
    values: Sequence[float],
    statistic: Optional[Callable[[np.ndarray], Any]] = None,
    *,
    level: float = 0.95,
    resamples: int = 10_000,
    seed: int = 0,
) -> BootstrapCI:
    """Percentile bootstrap interval of ``statistic`` (default: the mean) of ``values``.

    ``statistic`` maps a (resamples, n) array to (resamples,) (e.g. ``lambda a: a.mean(axis=1)``) and is
    applied to the sample as a (1, n) array for the estimate. NaNs are dropped. With fewer than two
    values the interval is (estimate, estimate). With few values (our 5 runs) the interval is narrow
    for its nominal level: the bootstrap cannot see beyond the sample's range.
    """
    x = np.asarray([v for v in values if v == v], dtype=np.float64)
    stat = statistic if statistic is not None else (lambda a: a.mean(axis=1))
    if not 0 < level < 1:
        raise ValueError("bootstrap_ci: level must be in (0, 1)")
    if len(x) == 0:
        return BootstrapCI(float("nan"), float("nan"), float("nan"), level, 0, 0)
    est = float(np.asarray(stat(x[None, :]))[0])
    if len(x) < 2:
        return BootstrapCI(est, est, est, level, 0, len(x))
    rng = np.random.default_rng(seed)
    idx = rng.integers(0, len(x), size=(resamples, len(x)))
    boot = np.asarray(stat(x[idx]), dtype=np.float64)
    lo, hi = np.quantile(boot, [(1 - level) / 2, (1 + level) / 2])
    return BootstrapCI(est, float(lo), float(hi), level, resamples, len(x))


def mode_table(
    labels_by_group: Dict[str, Sequence[str]], modes: Optional[Sequence[str]] = None
) -> Tuple[List[str], List[str], np.ndarray]:
    """Counts of each label per group: ``(modes, groups, counts)`` with counts[i, j] the number of
    group j's items labelled modes[i]. ``modes`` fixes the row order (labels not in it are added at the end)."""
    groups = list(labels_by_group)
    rows = list(modes) if modes is not None else []
    for g in groups:
        for lab in labels_by_group[g]:
            if lab not in rows:
                rows.append(lab)
    counts = np.zeros((len(rows), len(groups)), dtype=np.int64)
    for j, g in enumerate(groups):
        for lab in labels_by_group[g]:
            counts[rows.index(lab), j] += 1
    return rows, groups, counts
