"""The bending wave of the classifier's stroke path (animat.locomotion.bending_wave, docs/locomotion.md)."""

import math

import numpy as np
import pytest

import animat
from animat import locomotion as L

import known_swimmers as K  # studies/locomotion (conftest.py)

OMEGA = 2 * math.pi


def _strip(length=12, rows=3):
    pts = [(i + 0.5 * (j % 2), (j - (rows - 1) / 2) * math.sqrt(3) / 2) for j in range(rows) for i in range(length)]
    X = np.array(pts)
    X += np.random.default_rng(0).uniform(-0.02, 0.02, X.shape)
    return X - X.mean(axis=0)


def _frames(kind, k=0.6, amplitude=0.3):
    """A 3-row strip with a bending wave (lateral w = A sin(kx - ωt), travels towards +x), a longitudinal
    contraction wave, or all in phase (breathing along x)."""
    X = _strip()
    t = np.arange(160) / 40
    x, y = X[None, :, 0], X[None, :, 1]
    arg = k * x - OMEGA * t[:, None]
    P = np.repeat(X[None], len(t), axis=0)
    if kind == "bending":
        P[:, :, 0] = x - y * amplitude * k * np.cos(arg)
        P[:, :, 1] = y + amplitude * np.sin(arg)
    elif kind == "contraction":
        P[:, :, 0] = x - (0.15 / k) * np.cos(arg)
    else:
        P[:, :, 0] = x * (1 + 0.1 * np.sin(OMEGA * t[:, None]))
    return P, t


def test_a_bending_wave_is_a_clean_ramp_of_the_side_signed_strain():
    P, t = _frames("bending")
    Q, _, _ = L.procrustes_frames(P)
    springs = animat.gabriel_graph(P[0])
    b = L.bending_wave(Q, t, OMEGA, springs, np.array([1.0, 0.0]))
    assert b.is_wave and b.fit > 0.95 and b.lag > math.pi
    assert b.gradient[0] == pytest.approx(-0.6, abs=0.05) and abs(b.gradient[1]) < 0.05  # -k along the axis
    assert b.travel == "forward"  # it runs towards +x, as built
    for kind in ("contraction", "breathing"):  # both sides in phase: no bending wave
        P, t = _frames(kind)
        Q, _, _ = L.procrustes_frames(P)
        b = L.bending_wave(Q, t, OMEGA, springs)
        assert not b.is_wave and b.fit < 0.3, kind


def test_the_bending_wave_is_looked_for_only_on_the_stroke_path():
    P, t = _frames("bending")
    assert L.classify_motion(P, t, omega=OMEGA).bend is None
    assert L.classify_motion(P, t, omega=OMEGA, bending=True).bend.is_wave


def _swim(swimmer, drag):
    c = animat.Config()
    c["scene.drag_normal"] = drag
    c["evaluation.steps"] = 2000
    tr = animat.replay(swimmer.body(c), c)
    assert tr.stable
    return tr


CAL = {s.name: s for s in K.paper_calibration_set()}
THIRD = {s.name: s for s in K.paper_third_set()}


def test_a_calibration_bending_undulator_is_undulation_with_the_stroke_rule_only():
    tr = _swim(CAL["undulator_bend_fast"], 0.5)
    default = L.classify_locomotion(tr)
    assert default.mode == "other" and default.bend is None  # the default classifier as before (docs/replication.md)
    m = L.classify_locomotion(tr, stroke=True)
    assert m.mode == "undulation" and m.bend.is_wave and m.bend.fit >= L.BEND_FIT, m.reason
    assert not m.wave.is_wave  # the cells' contraction alone misses it


@pytest.mark.parametrize(
    "name,drag,expected",
    [
        ("h3_und_bend_a", 0.5, "undulation"),
        ("h3_und_bend_c", 2.0, "undulation"),
        ("h3_single_2pairs", 0.5, "protrusions"),
        ("h3_tail5_fast", 2.0, "tail"),
        ("h3_standing_halves", 0.5, "other"),
    ],
)
def test_third_held_out_swimmers(name, drag, expected):
    tr = _swim(THIRD[name], drag)
    m = L.classify_locomotion(tr, stroke=True)
    assert m.mode == expected, m.reason
    if THIRD[name].appendages:
        assert K.stroke_truth(THIRD[name], tr).strokes


@pytest.mark.xfail(strict=True, reason="known miss of the third held-out set: random phases fit a bending wave")
def test_third_held_out_random_phases_are_other():
    m = L.classify_locomotion(_swim(THIRD["h3_standing_random"], 0.5), stroke=True)
    assert m.mode == "other", m.reason


def test_the_bending_fit_is_tested_against_shuffled_positions():
    P, t = _frames("bending")
    Q, _, _ = L.procrustes_frames(P)
    b = L.bending_wave(Q, t, OMEGA, animat.gabriel_graph(P[0]))
    assert b.p_value == pytest.approx(1 / (1 + L.BEND_PERMUTATIONS))  # no shuffle fits as well
    rng = np.random.default_rng(5)  # unrelated phases on 14 positions: the free gradient still fits ~0.5
    phases, weights, x = rng.uniform(0, 2 * math.pi, 14), rng.rayleigh(1.0, 14), np.linspace(0, 9, 14)
    _, fit = L.circular_linear_fit(phases, weights, x)
    null = L.shuffled_fits(phases, weights, x, 199, seed=1)
    assert 0.3 < np.median(null) < 0.7 and np.mean(null >= fit) > L.BEND_P
    assert np.array_equal(null, L.shuffled_fits(phases, weights, x, 199, seed=1))  # deterministic
    assert L.shuffled_fits(phases, weights, x, 0).shape == (0,)


def test_a_chance_bending_fit_of_random_phases_is_not_a_wave():
    m = L.classify_locomotion(_swim(THIRD["h3_standing_random_slow"], 0.5), stroke=True)
    assert m.bend.fit >= L.BEND_FIT and m.bend.p_value > L.BEND_P  # fits 0.70, but so do 5 % of the shuffles
    assert m.mode == "other", m.reason


FOURTH = {s.name: s for s in K.paper_fourth_set()}


@pytest.mark.parametrize(
    "name,drag,expected",
    [
        ("h4_und_bend_b", 0.5, "undulation"),
        ("h4_single_2pairs_b", 2.0, "protrusions"),
        ("h4_tail5_slow", 0.5, "tail"),
        ("h4_standing_random_a", 2.0, "other"),
        ("h4_sync_lag", 0.5, "synchronous contraction"),
    ],
)
def test_fourth_held_out_swimmers(name, drag, expected):
    tr = _swim(FOURTH[name], drag)
    m = L.classify_locomotion(tr, stroke=True)
    assert m.mode == expected, m.reason
    if FOURTH[name].appendages:
        assert K.stroke_truth(FOURTH[name], tr).strokes


@pytest.mark.xfail(strict=True, reason="known miss of the fourth held-out set: random phases bend as a wave (p 0.001)")
def test_fourth_held_out_random_phases_are_other():
    m = L.classify_locomotion(_swim(FOURTH["h4_standing_random_e"], 0.5), stroke=True)
    assert m.mode == "other", m.reason


@pytest.mark.xfail(strict=True, reason="known miss of the fourth held-out set: a two-cell chain pair scores 0.30")
def test_fourth_held_out_chain_pair_strokes():
    tr = _swim(FOURTH["h4_chain2_b"], 0.5)
    assert K.stroke_truth(FOURTH["h4_chain2_b"], tr).strokes  # rows by the ground truth ...
    m = L.classify_locomotion(tr, stroke=True)
    assert m.mode == "protrusions", m.reason  # ... but not by the classifier's pair score
