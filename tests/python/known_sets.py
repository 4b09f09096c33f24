"""What the tests of the hand-built sets (test_locomotion_{fifth,sixth,seventh,eighth}.py) share: a swim
that must stay stable, and the check that a swim is classified as its ground truths label it."""

from animat import locomotion as L

import known_swimmers as K  # studies/locomotion (conftest.py)


def swim(swimmer, drag):
    """The swimmer's swim at normal drag ``drag`` (known_swimmers.swim_known), which must stay stable."""
    tr = K.swim_known(swimmer, drag)
    assert tr.stable
    return tr


def check_classified_as_labelled(swimmer, drag, expected):
    """The stroke path finds ``expected``, the swimmer's label, and the label's ground truth holds on this
    swim: an appendage swimmer's pair strokes, a whole-body swimmer undulates exactly when so labelled."""
    tr = swim(swimmer, drag)
    m = L.classify_locomotion(tr, stroke=True)
    assert m.mode == expected == swimmer.expected, m.reason
    if swimmer.appendages:
        assert K.stroke_truth(swimmer, tr).strokes
    else:
        u = K.undulation_truth(swimmer, tr) if swimmer.expected in K.WHOLE_BODY else None
        assert u is None or u.undulates == (expected == "undulation")
