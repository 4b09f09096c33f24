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
    b = L.bending_wave(Q, t, OMEGA, springs, np.array([-1.0, 0.0]))  # a body swimming towards -x
    assert b.is_wave and b.fit > 0.95 and b.lag > math.pi
    assert b.gradient[0] == pytest.approx(-0.6, abs=0.05) and abs(b.gradient[1]) < 0.05  # -k along the axis
    assert b.travel == "backward"  # it runs towards +x, as built: backward along a body swimming to -x
    for kind in ("contraction", "breathing"):  # both sides in phase: no bending wave
        P, t = _frames(kind)
        Q, _, _ = L.procrustes_frames(P)
        b = L.bending_wave(Q, t, OMEGA, springs, np.array([-1.0, 0.0]))
        assert not b.is_wave and b.fit < 0.3, kind


def test_a_bending_wave_that_runs_forward_or_across_does_not_count():
    # the same clean bend, but the body swims the way it runs (or across it, or the motion is unknown):
    # a bend drives a body with d_T < d_N only when it runs backward (BEND_BACKWARD)
    P, t = _frames("bending")
    Q, _, _ = L.procrustes_frames(P)
    springs = animat.gabriel_graph(P[0])
    for motion in ((1.0, 0.0), (0.0, 1.0), None):
        b = L.bending_wave(Q, t, OMEGA, springs, None if motion is None else np.array(motion))
        assert b.fit > 0.95 and b.p_value <= L.BEND_P and not b.is_wave, motion
    assert L.bending_wave(Q, t, OMEGA, springs, np.array([1.0, 0.0])).travel == "forward"


def test_the_bending_wave_is_looked_for_only_on_the_stroke_path():
    P, t = _frames("bending")
    P[:, :, 0] -= 0.2 * t[:, None]  # it swims towards -x, against its wave
    assert L.classify_motion(P, t, omega=OMEGA).bend is None
    assert L.classify_motion(P, t, omega=OMEGA, bending=True).bend.is_wave


def _swim(swimmer, drag):
    tr = K.swim_known(swimmer, drag)
    assert tr.stable
    return tr


CAL = {s.name: s for s in K.paper_calibration_set()}
THIRD = {s.name: s for s in K.paper_third_set()}


def test_a_calibration_bending_undulator_is_undulation_with_the_stroke_rule_only():
    # a candidate of the calibration set that the undulation truth rejects (its cells' contraction lags
    # 0.61-0.68 rad over the body); the classifier's bending wave, on the side-signed strain, finds the bend
    s = next(s for s in K.calibration_candidates() if s.name == "undulator_bend_fast")
    assert s.name in K.TRUTH_REJECTED and s.name not in CAL
    tr = _swim(s, 0.5)
    earlier = L.classify_locomotion(tr, stroke=False)
    assert earlier.mode == "other" and earlier.bend is None  # the earlier rules look for no bending wave
    m = L.classify_locomotion(tr, stroke=True)
    assert m.mode == "undulation" and m.bend.is_wave and m.bend.fit >= L.BEND_FIT, m.reason
    assert not m.wave.is_wave  # the cells' contraction alone misses it
    default = L.classify_locomotion(tr)  # the default classifier is the stroke path
    assert (default.label, default.reason) == (m.label, m.reason)


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


def test_random_phases_that_bend_across_the_motion_are_other():
    # h3_standing_random at d_N = 0.5: its low bending modes fit a wave (p 0.003) that runs 130 deg from its
    # (slight) motion, not backward; the undulation truth finds it does not swim (0.07 spacings)
    s = THIRD["h3_standing_random"]
    tr = _swim(s, 0.5)
    m = L.classify_locomotion(tr, stroke=True)
    assert m.bend.fit >= L.BEND_FIT and m.bend.p_value <= L.BEND_P and m.bend.angle < L.BEND_BACKWARD
    assert m.mode == "other", m.reason
    assert not K.undulation_truth(s, tr).undulates


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
    # its displacement travels along its axis (0.27 spacings swum), but its cells' contraction lags 1.39-1.46
    # rad over the body: "other" by the undulation truth, as the classifier finds
    s = THIRD["h3_standing_random_slow"]
    assert s.expected == "other"
    m = L.classify_locomotion(_swim(s, 0.5), stroke=True)
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
        ("h4_sync_b", 0.5, "synchronous contraction"),
    ],
)
def test_fourth_held_out_swimmers(name, drag, expected):
    tr = _swim(FOURTH[name], drag)
    m = L.classify_locomotion(tr, stroke=True)
    assert m.mode == expected, m.reason
    if FOURTH[name].appendages:
        assert K.stroke_truth(FOURTH[name], tr).strokes


def test_a_random_phase_bend_running_forward_is_not_undulation():
    # h4_standing_random_e at d_N = 0.5 (a miss of the fourth set): fit 0.80, p 0.001, but the bend runs
    # 63 deg from the motion of a body that swims 0.01 spacings in 4 periods
    s = FOURTH["h4_standing_random_e"]
    tr = _swim(s, 0.5)
    m = L.classify_locomotion(tr, stroke=True)
    assert m.bend.p_value <= L.BEND_P and m.bend.angle < L.BEND_BACKWARD
    assert m.mode == "other", m.reason
    u = K.undulation_truth(s, tr)
    assert not u.undulates and u.distance < K.TRUTH_DISTANCE


def test_a_two_cell_chain_pair_that_rows_is_protrusions():
    # h4_chain2_b at d_N = 0.5 (a miss of the fourth set): measured along the chain's axis its pair scores 0.83
    tr = _swim(FOURTH["h4_chain2_b"], 0.5)
    assert K.stroke_truth(FOURTH["h4_chain2_b"], tr).strokes
    m = L.classify_locomotion(tr, stroke=True)
    assert m.mode == "protrusions" and m.stroke.score > 0.8, m.reason


def test_the_undulation_truth_on_the_lattice():
    und = _swim(FOURTH["h4_und_bend_a"], 2.0)
    u = K.undulation_truth(FOURTH["h4_und_bend_a"], und)
    assert u.undulates and u.axis == "x" and u.lag > math.pi and u.travel == -1  # the contraction runs backward
    sync = FOURTH["h4_sync_b"]
    u = K.undulation_truth(sync, _swim(sync, 0.5))
    assert not u.undulates and u.lag < K.TRUTH_WAVE_LAG
    assert K.truth_label(sync, [u, u]) == "synchronous contraction"
    assert K.truth_label(sync, [u, None]) is None
    assert K.truth_label(FOURTH["h4_tail4"], []) == "tail"  # not a whole-body swimmer: its built label
