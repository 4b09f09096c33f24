"""Hand-built swimmers of known locomotion mode (animat.known_swimmers, issue 19) are classified as built."""
import math

import numpy as np
import pytest

import animat
from animat import known_swimmers as K
from animat import locomotion as L


def swim(s, drag=2.0, steps=2000):
    c = animat.Config()
    c["scene.drag_normal"] = drag
    c["evaluation.steps"] = steps
    tr = animat.replay(s.body(c), c)
    assert tr.stable
    return L.classify_locomotion(tr)


@pytest.mark.parametrize("swimmer,drag", [
    (K.undulator("contraction"), 2.0),
    (K.synchronous_contractor(), 0.5),
    (K.protrusion_swimmer(length=1), 0.5),
    (K.protrusion_swimmer(length=3, wide=True), 2.0),
    (K.tail_swimmer(), 0.5),
], ids=lambda v: getattr(v, "name", str(v)))
def test_known_swimmer_is_classified_as_built(swimmer, drag):
    m = swim(swimmer, drag)
    assert m.mode == swimmer.expected, m.reason
    if swimmer.expected == "protrusions":
        assert m.groups >= 2 and m.contrast >= L.LOCAL_CONTRAST
        # the most strained fifth of the cells are mostly actuated ones (appendages and their anchors)
        actuated = set(np.flatnonzero(swimmer.amplitude > 0).tolist())
        strained = set(np.argsort(-m.amplitudes)[:int(math.ceil(0.2 * swimmer.cells))].tolist())
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
