"""Hand-built swimmers of known locomotion mode (studies/locomotion/known_swimmers.py) are classified as built."""

import math

import numpy as np
import pytest

import animat
from animat import locomotion as L

import known_swimmers as K  # studies/locomotion (conftest.py)


def swim(s, drag=2.0, steps=2000):
    c = animat.Config()
    c["scene.drag_normal"] = drag
    c["evaluation.steps"] = steps
    tr = animat.replay(s.body(c), c)
    assert tr.stable
    # The earlier rules (stroke=False): these builders' protrusion swimmers have a passive core and
    # are found by the strain-contrast rule, which the stroke path does not use for protrusions.
    return L.classify_locomotion(tr, stroke=False)


@pytest.mark.parametrize(
    "swimmer,drag",
    [
        (K.undulator("contraction"), 2.0),
        (K.synchronous_contractor(), 0.5),
        (K.protrusion_swimmer(length=1), 0.5),
        (K.protrusion_swimmer(length=3, wide=True), 2.0),
        (K.tail_swimmer(), 0.5),
    ],
    ids=lambda v: getattr(v, "name", str(v)),
)
def test_known_swimmer_is_classified_as_built(swimmer, drag):
    m = swim(swimmer, drag)
    assert m.mode == swimmer.expected, m.reason
    if swimmer.expected == "protrusions":
        assert m.groups >= 2 and m.contrast >= L.LOCAL_CONTRAST
        # the most strained fifth of the cells are mostly actuated ones (appendages and their anchors)
        actuated = set(np.flatnonzero(swimmer.amplitude > 0).tolist())
        strained = set(np.argsort(-m.amplitudes)[: int(math.ceil(0.2 * swimmer.cells))].tolist())
        assert len(strained & actuated) >= 0.75 * len(strained)
    if swimmer.expected == "tail":
        assert m.groups == 1
    if swimmer.expected == "synchronous contraction":
        assert m.coherence > 0.95 and m.contrast < L.LOCAL_CONTRAST


def test_builders_set_the_actuation_they_describe():
    s = K.protrusion_swimmer(length=2, wide=True, anchor_amplitude=0.0)
    assert s.cells == len(s.amplitude) == len(s.phase) == len(s.frequency)
    active = s.amplitude > 0
    assert active.sum() == 8 and np.allclose(s.phase[active], math.pi / 2)  # 2 appendages x 2 rows x 2 cells
    ys = s.positions[active, 1]
    assert (ys > 0).sum() == (ys < 0).sum() == 4  # symmetric
    u = K.undulator("contraction", wavelengths=1.0)
    order = np.argsort(u.positions[:, 0])
    assert np.ptp(np.unwrap(u.phase[order])) > 1.5 * math.pi  # a full period along the body
    assert np.all(K.synchronous_contractor().phase == 0.0)
    with pytest.raises(ValueError):
        K.undulator("sideways")


def test_confusion_matrix_counts():
    fake = [K.KnownResult(K.tail_swimmer(), 0.5, 10, None, 0.0, False)]
    m = K.confusion_matrix(fake, ["tail"], ["tail", "unstable"])
    assert m.tolist() == [[0, 1]]


def test_appendage_stroke_is_measured_for_appendage_swimmers_only():
    res = K.classify_known([K.protrusion_swimmer(length=1), K.undulator("contraction")], drags=(0.5,), steps=1500)
    prot, und = res
    assert und.stroke is None
    s = prot.stroke
    assert s is not None and s.sweep > 0.05 and s.extension > 0.1 and -1.0 <= s.rowing <= 1.0


# --- the paper's stroke (animat.locomotion.paddling) ------------------------------------------------------


def _paddler_frames(sweep: float, extension: float, base: float = 2.0, frames: int = 200, periods: float = 4.0):
    """A rigid 4 × 2 block of cells with one paddle cell above and one below its middle (the skin walks
    around both, CCW). Each paddle sits `base` from the axis ± `extension`·cos(ωt) and at x = `sweep`·sin(ωt)
    (mirrored: the two are symmetric). sweep < 0: farthest out while moving backwards (−x), the paper's
    stroke for motion along +x."""
    block = [(-2, -1), (-1, -1), (0, -1), (1, -1), (2, -1), (2, 1), (1, 1), (0, 1), (-1, 1), (-2, 1)]
    t = np.linspace(0.0, periods * 2 * math.pi, frames, endpoint=False)
    P = np.zeros((frames, len(block) + 2, 2))
    P[:, : len(block)] = np.array(block, dtype=float)
    for k, sgn in ((10, 1.0), (11, -1.0)):
        P[:, k, 0] = sweep * np.sin(t)
        P[:, k, 1] = sgn * (base + extension * np.cos(t))
    loop = [0, 1, 11, 3, 4, 5, 6, 10, 8, 9]  # cells 2 and 7 are inside; body on the left
    return P, loop


def test_paddling_scores_the_papers_stroke_and_its_reverse():
    P, loop = _paddler_frames(sweep=-0.3, extension=0.2)
    p = L.paddling_motion(P, loop, 1.0, (1.0, 0.0))
    assert p.pair == (10, 11) and p.score > 0.95 and p.paddles
    # height of the paddles above the chord of their neighbours (x = ±1, y = ±1): 1 ± 0.2, at most ~1.2
    assert p.spike[list(p.cells).index(10)] == pytest.approx(1.2, abs=0.02)
    assert set(p.protruding.tolist()) == {10, 11}
    # the block's corner (2, -1) stands 2/√5 above the chord from (1, -1) to (2, 1); the cell beside a
    # paddle lies below the chord to the paddle (a concave corner)
    assert p.spike[list(p.cells).index(4)] == pytest.approx(2 / math.sqrt(5), abs=1e-6)
    assert p.spike[list(p.cells).index(1)] < 0
    back = L.paddling_motion(*_paddler_frames(sweep=0.3, extension=0.2), 1.0, (1.0, 0.0))
    assert back.score < -0.95 and not back.paddles


def test_paddling_is_zero_for_a_sweep_or_an_extension_alone_and_needs_a_protrusion():
    sweep_only = L.paddling_motion(*_paddler_frames(sweep=-0.3, extension=0.0), 1.0, (1.0, 0.0))
    assert abs(sweep_only.score) < 0.15 and not sweep_only.paddles
    # pulled into the outline (height 0.3 ± 0.2 above the chord): nothing protrudes, no pair
    inside = L.paddling_motion(*_paddler_frames(sweep=-0.3, extension=0.2, base=1.3), 1.0, (1.0, 0.0))
    assert inside.pair == () and math.isnan(inside.score) and not inside.paddles
    # the length unit scales the spike: at rest length 2 the paddles stand 0.6 high, under PADDLE_SPIKE
    halved = L.paddling_motion(*_paddler_frames(sweep=-0.3, extension=0.2), 2.0, (1.0, 0.0))
    assert halved.pair == ()


def test_paddling_rejects_a_bad_loop():
    P, _ = _paddler_frames(sweep=-0.3, extension=0.2)
    with pytest.raises(ValueError, match="skin loop"):
        L.paddling_motion(P, [0, 1], 1.0, (1.0, 0.0))


@pytest.mark.parametrize(
    "swimmer",
    [
        K.undulator("contraction"),
        K.undulator("across", length=6.0, width=5.0),
        K.synchronous_contractor(),
        K.synchronous_contractor(lag=1.0),
    ],
    ids=lambda s: s.name,
)
def test_whole_body_swimmers_do_not_paddle(swimmer):
    c = animat.Config()
    c["scene.drag_normal"] = 2.0
    c["evaluation.steps"] = 2000
    tr = animat.replay(swimmer.body(c), c)
    p = L.paddling(tr)
    assert not p.paddles, (p.pair, p.score)
