"""The paper's protrusion stroke (animat.protrusion) and its place in the classifier."""

import math

import numpy as np
import pytest

import animat
from animat import locomotion as L
from animat import protrusion as P

import known_swimmers as K  # studies/locomotion (conftest.py)

OMEGA = 2 * math.pi


def _frames(swimmer, sweep, extension, periods=4, per_period=40):
    """Body-frame frames of ``swimmer`` at rest but for its non-core cells (the appendages), which move
    at x_rest + sweep·sin(ωt) and y_rest ± extension·cos(ωt) (outwards on each flank)."""
    body = swimmer.body()
    rest = np.asarray(body.positions) - np.asarray(body.positions).mean(axis=0)
    t = np.arange(periods * per_period) / per_period
    Q = np.repeat(rest[None], len(t), axis=0)
    core = int(swimmer.description.split("(")[1].split()[0])
    for i in range(core, swimmer.cells):
        Q[:, i, 0] += sweep * np.sin(OMEGA * t)
        Q[:, i, 1] += np.sign(rest[i, 1]) * extension * np.cos(OMEGA * t)
    return Q, t, body, rest


def test_a_paddling_pair_scores_one_and_its_reverse_minus_one():
    s = K.appendage_swimmer("single", at=(-1.5,))
    Q, t, body, rest = _frames(s, sweep=-0.3, extension=0.2)  # out, back, in, forward for motion along +x
    st = P.stroke_motion(Q, t, OMEGA, (1.0, 0.0), body.skin_loops[0], body.springs, rest)
    assert st.pair != () and st.strokes
    a, b = st.pair
    assert set(st.protrusions[a]) | set(st.protrusions[b]) == {s.cells - 2, s.cells - 1}
    assert st.score == pytest.approx(1.0, abs=2e-3)  # the outward direction is off y by the lattice jitter
    # loop area per cell: pi * 0.3 * 0.2 (the anchors do not move), in spacings^2 (spacing ~1)
    assert st.area == pytest.approx(math.pi * 0.06, rel=0.05)
    back = P.stroke_motion(
        *_frames(s, sweep=+0.3, extension=0.2)[:2], OMEGA, (1.0, 0.0), body.skin_loops[0], body.springs, rest
    )
    assert back.score == pytest.approx(-1.0, abs=2e-3) and not back.strokes
    # the same stroke seen against a motion along -x is the reverse loop
    other_way = P.stroke_motion(Q, t, OMEGA, (-1.0, 0.0), body.skin_loops[0], body.springs, rest)
    assert other_way.score == pytest.approx(-1.0, abs=2e-3)


def test_the_area_is_the_whole_appendage_loop():
    # every cell of a three-cell chain makes the same loop: the appendage's area is their sum, so a chain
    # whose cells each make a small loop is not judged by one cell's loop
    s = K.appendage_swimmer("chain3", at=(-1.5,))
    Q, t, body, rest = _frames(s, sweep=-0.3, extension=0.2)
    st = P.stroke_motion(Q, t, OMEGA, (1.0, 0.0), body.skin_loops[0], body.springs, rest)
    assert st.pair != () and st.strokes
    a, b = st.pair
    assert len(st.protrusions[a]) == len(st.protrusions[b]) == 3
    assert st.score > 0.95  # a chain's axis is off y by the lattice offset of its cells
    assert st.areas[a] == pytest.approx(3 * math.pi * 0.06, rel=0.1)


def test_a_sweep_or_an_extension_alone_does_not_row():
    s = K.appendage_swimmer("single", at=(-1.5,))
    for sweep, ext in ((-0.3, 0.0), (0.0, 0.2)):
        Q, t, body, rest = _frames(s, sweep, ext)
        st = P.stroke_motion(Q, t, OMEGA, (1.0, 0.0), body.skin_loops[0], body.springs, rest)
        assert not st.strokes
        assert not st.score > 1e-6  # 0 up to rounding, or nan when one of them does not move


def test_a_body_without_protrusions_has_no_pair():
    s = K.protrusion_swimmer(length=1)  # its round core alone: cut the appendages off
    core = int(s.description.split("(")[1].split()[0])
    disc = K.KnownSwimmer(
        "disc", "other", s.positions[:core], s.amplitude[:core], s.frequency[:core], s.phase[:core], "the core"
    )
    body = disc.body()
    rest = np.asarray(body.positions) - np.asarray(body.positions).mean(axis=0)
    t = np.arange(160) / 40
    Q = np.repeat(rest[None], len(t), axis=0)
    Q[:, :, 0] += 0.05 * np.sin(OMEGA * t)[:, None] * rest[:, 0][None]  # a gentle breathing
    st = P.stroke_motion(Q, t, OMEGA, (1.0, 0.0), body.skin_loops[0], body.springs, rest)
    assert st.protrusions == () and st.pair == () and math.isnan(st.score) and not st.strokes


def test_rowing_weights_cells_by_their_loop():
    X = np.array([1.0, 1.0]) * -1.0
    E = np.array([1j, -1j])  # one cell rows, one rows backwards
    assert P.rowing(X, E) == pytest.approx(0.0)
    assert P.rowing(X, np.array([1j, 0.1j])) == pytest.approx(1.0)
    assert math.isnan(P.rowing(np.zeros(2), np.zeros(2)))


def test_appendage_swimmer_actuates_every_cell_symmetrically():
    s = K.appendage_swimmer("chain2", at=(-1.5,), appendage_phase=math.pi / 4, anchor_shift=math.pi)
    assert np.all(s.amplitude >= 0.9 * K.AMPLITUDE - 1e-12) and np.all(s.amplitude <= K.AMPLITUDE)
    core = int(s.description.split("(")[1].split()[0])
    assert s.cells - core == 4  # two chains of two cells
    ys = s.positions[core:, 1]
    assert (ys > 0).sum() == (ys < 0).sum() == 2
    # mirror-symmetric actuation: every cell has a partner across the long axis with the same a and phase
    for i in range(s.cells):
        j = int(np.argmin(np.linalg.norm(s.positions - s.positions[i] * [1, -1], axis=1)))
        assert s.amplitude[j] == s.amplitude[i] and s.phase[j] == s.phase[i]
    with pytest.raises(ValueError):
        K.appendage_swimmer("fin")


def _classify(swimmer, drag):
    tr = K.swim_known(swimmer, drag)
    assert tr.stable
    return tr, L.classify_locomotion(tr, stroke=True)


# The calibration set at d_N = 0.5 (docs/locomotion.md): the paper's protrusion swimmers swim and are
# found by the stroke rule; every whole-body, tail and "other" swimmer keeps its class, and the bending
# undulators are undulation by the bending wave of the stroke path (test_locomotion_bending.py).
CAL = {s.name: s for s in K.paper_calibration_set()}
HELD = {s.name: s for s in K.paper_held_out_set()}


@pytest.mark.parametrize("name", ["paper_single_ph0", "paper_chain2", "paper_chain2_ph2"])
def test_paper_protrusion_swimmers_swim_and_stroke(name):
    tr, m = _classify(CAL[name], 0.5)
    assert tr.distance > 1.0
    assert m.mode == "protrusions" and m.stroke.strokes, m.reason
    assert m.stroke.score >= P.STROKE_SCORE and m.stroke.area >= P.STROKE_AREA


@pytest.mark.parametrize(
    "name,expected",
    [
        ("undulator_long", "undulation"),
        ("undulator_bending", "undulation"),
        ("synchronous_teardrop", "synchronous contraction"),
        ("synchronous_lag1.0", "synchronous contraction"),
        ("tail4", "tail"),
        ("standing_halves", "other"),
        ("standing_random", "other"),
    ],
)
def test_other_classes_do_not_stroke(name, expected):
    _, m = _classify(CAL[name], 0.5)
    assert m.mode == expected, m.reason
    assert not m.stroke.strokes


def test_paper_single_strokes_at_moderate_drag():
    tr, m = _classify(CAL["paper_single"], 2.0)
    assert tr.distance > 1.0 and m.mode == "protrusions" and m.stroke.score > 0.8


def test_classify_motion_without_an_outline_has_no_stroke():
    tr, m = _classify(CAL["paper_chain2"], 0.5)
    bare = L.classify_motion(tr.positions, tr.times, springs=tr.body.springs, omega=m.omega)
    assert bare.stroke is None and m.stroke is not None
    assert P.protrusion_stroke(tr, m) is m.stroke
    default = P.protrusion_stroke(tr)  # by the default classifier, the stroke path: the same stroke
    assert (default.score, default.area, default.pair) == (m.stroke.score, m.stroke.area, m.stroke.pair)


def test_the_ground_truth_is_measured_on_the_built_appendages():
    s = CAL["paper_single"]
    assert s.appendages and all(len(g) == 1 for g in s.appendages) and len(s.appendages) == 2
    assert K.undulator("contraction").appendages == ()
    c = animat.Config()
    c["scene.drag_normal"] = 0.5
    c["evaluation.steps"] = 2000
    tr = animat.replay(s.body(c), c)
    t = K.stroke_truth(s, tr)
    assert t.strokes and t.why_not() == ""
    assert min(t.rowing) > 0.9 and t.away and t.axis_angle < 10
    assert K.stroke_truth(K.undulator("contraction"), tr) is None


def test_a_body_that_rows_backwards_fails_the_ground_truth():
    # the first held-out set's single-cell pair on a 10 x 5 core at f = 10: dropped, it rows backwards
    s = K.appendage_swimmer(
        "single",
        core_length=10.0,
        core_width=5.0,
        at=(-2.0,),
        frequency=10.0,
        appendage_phase=math.pi / 4,
        anchor_shift=math.pi,
        seed=22,
    )
    c = animat.Config()
    c["scene.drag_normal"] = 2.0
    c["evaluation.steps"] = 2000
    t = K.stroke_truth(s, animat.replay(s.body(c), c))
    assert not t.strokes and max(t.rowing) < 0 and "rowing" in t.why_not()


def test_rowing_phase_gives_the_held_out_phase():
    phase, truths = K.rowing_phase(**K.HELD_OUT_APPENDAGES["ho_single_b"])
    assert phase == pytest.approx(K.HELD_OUT_PHASES["ho_single_b"] * math.pi / 4)
    assert all(t.strokes for t in truths)


def test_a_slow_undulator_whose_corners_row_is_an_undulator():
    # its corners row with the wave (pair score ~1): the wave decides, the stroke is a mixture
    _, m = _classify(CAL["undulator_slow"], 0.5)
    assert m.stroke.strokes and m.mode == "undulation" and m.mixed == ("protrusions",), m.reason


@pytest.mark.parametrize("name,expected", [("tail6", "tail"), ("standing_halves_long", "other")])
def test_strain_contrast_without_a_stroke_is_not_protrusions(name, expected):
    _, m = _classify(CAL[name], 2.0)
    assert not m.stroke.strokes and m.mode == expected, m.reason


@pytest.mark.parametrize(
    "name,drag,expected",
    [
        ("ho_single_b", 0.5, "protrusions"),
        ("ho_block2x2_b", 2.0, "protrusions"),
        ("ho_und_across", 2.0, "undulation"),
        ("ho_tail5", 0.5, "tail"),
        ("ho_standing_halves", 0.5, "other"),
    ],
)
def test_held_out_swimmers(name, drag, expected):
    tr, m = _classify(HELD[name], drag)
    assert m.mode == expected, m.reason
    if HELD[name].appendages:
        assert K.stroke_truth(HELD[name], tr).strokes


def test_cell_strokes_can_measure_along_the_protrusions_own_axis():
    # (outward None; the stroke rule measures across the motion) a two-cell chain on anchors at the origin:
    # swinging it rigidly about them is sweep, not extension; stretching it along its axis is extension
    t = np.arange(160) / 40
    swing = 0.4 * np.sin(OMEGA * t)
    Q = np.zeros((len(t), 4, 2))
    Q[:, 0] = (-0.5, 0.0)
    Q[:, 1] = (0.5, 0.0)  # the anchors, mean at the origin
    for k, r in ((2, 1.0), (3, 2.0)):
        Q[:, k, 0] = r * np.sin(swing)
        Q[:, k, 1] = r * np.cos(swing)
    X, E = P.cell_strokes(Q, t, OMEGA, (1.0, 0.0), [2, 3], Q[:, :2].mean(axis=1), None)
    assert np.all(np.abs(X) > 0.3) and np.all(np.abs(E) < 1e-3)
    Q[:, 2:, 1] *= 1 + 0.2 * np.cos(OMEGA * t)[:, None]  # and now it also stretches
    _, E = P.cell_strokes(Q, t, OMEGA, (1.0, 0.0), [2, 3], Q[:, :2].mean(axis=1), None)
    assert np.abs(E[1]) == pytest.approx(2 * np.abs(E[0]), rel=0.1) and np.abs(E[0]) > 0.15


def test_cell_loops_are_signed_by_the_side():
    t = np.arange(160) / 40
    Q = np.zeros((len(t), 2, 2))
    Q[:, 0, 0] = -0.3 * np.sin(OMEGA * t)  # out (+y) while it moves back (-x): the stroke's loop
    Q[:, 0, 1] = 1.0 + 0.2 * np.cos(OMEGA * t)
    Q[:, 1, 0] = 0.3 * np.sin(OMEGA * t)  # along a line: no loop
    left = P.cell_loops(Q, t, OMEGA, (1.0, 0.0), 1.0)
    assert left[0] == pytest.approx(math.pi * 0.06, rel=1e-6) and abs(left[1]) < 1e-12
    assert P.cell_loops(Q, t, OMEGA, (1.0, 0.0), -1.0)[0] == pytest.approx(-math.pi * 0.06, rel=1e-6)


def test_a_protrusion_found_in_part_grows_to_the_whole_appendage():
    # every cell of each 2 x 2 block makes the stroke's loop, the core stands still: from its outer row
    # alone each block grows to its four cells and no further; a reverse loop does not grow
    s = K.appendage_swimmer("block2x2", at=(-1.5,))
    Q, t, body, rest = _frames(s, sweep=-0.3, extension=0.2)
    outer = [sorted(g)[2:] for g in s.appendages]  # the row farthest out (cells are listed row by row)
    grown = P.grow_protrusions(Q, t, OMEGA, (1.0, 0.0), outer, body.springs, 1.0)
    assert [tuple(g) for g in grown] == [tuple(sorted(g)) for g in s.appendages]
    Qb, *_ = _frames(s, sweep=+0.3, extension=0.2)
    assert P.grow_protrusions(Qb, t, OMEGA, (1.0, 0.0), outer, body.springs, 1.0) == outer
    st = P.stroke_motion(Q, t, OMEGA, (1.0, 0.0), body.skin_loops[0], body.springs, rest)
    a, b = st.pair
    assert {st.protrusions[a], st.protrusions[b]} == {tuple(sorted(g)) for g in s.appendages} and st.strokes
