"""The engine's locomotion classifier (``_core._classify_motion``, include/animat/locomotion.hpp) against
animat.locomotion.classify_motion, on stored bests and on synthetic swims, and the locomotion measure that
``animat.evaluate`` classifies during its own swim when the config's search reads it.

Every deterministic number agrees to RTOL: both sides solve the same least-squares fits and grid searches,
the C++ with a closed-form 2-D rotation (Python: an SVD) and a QR solve (Python: lstsq), which differ by
round-off only. The bending wave's p-value comes from 999 shuffles drawn by a different generator (the
project's Rng, not numpy's), so it agrees within the sampling error of the permutation test; the engine runs that test only when the
other bending criteria hold and stops once p > BEND_P is certain (it is most of its cost); its p-value is
nan then.
"""

import math
import pickle
from pathlib import Path

import numpy as np
import pytest

import animat
from animat import _core
from animat import locomotion as L
from animat.protrusion import STROKE_AREA, STROKE_SCORE

ROOT = Path(__file__).resolve().parents[2]
#: One stored best per replication condition and two of the 64-cell condition (a few seconds each).
BESTS = ["dn0.5/run_0", "dn0.5/run_1", "dn2/run_0", "dn2/run_1", "dn10/run_0", "dn10/run_1", "dn0.2_64cells/run_0"]
RTOL = 1e-6
#: Every stored best (10 runs of each of the 4 replication conditions).
ALL_BESTS = sorted(
    str(p.relative_to(ROOT / "data" / "replication")) for p in (ROOT / "data" / "replication").glob("*/run_*")
)


#: Travelling index of a standing pattern in round-off (0 in exact arithmetic; a travelling wave's
#: is orders of magnitude above it).
STANDING_TI = 1e-12


def _p_tolerance(p):
    """Four standard errors of a permutation p-value from 999 shuffles, plus one shuffle."""
    return 4 * math.sqrt(max(p, 1e-3) * (1 - p) / 999) + 1 / 1000


def _compare_wave(py, cc, bending):
    assert cc is not None
    assert cc["fit"] == pytest.approx(py.fit, rel=RTOL, abs=1e-9)
    assert cc["lag"] == pytest.approx(py.lag, rel=RTOL, abs=1e-9)
    assert cc["travelling_index"] == pytest.approx(py.travelling_index, rel=RTOL, abs=1e-9)
    assert cc["coherence"] == pytest.approx(py.coherence, rel=RTOL, abs=1e-9)
    gradient, angle = np.asarray(py.gradient), py.angle
    if py.travelling_index <= STANDING_TI and not np.allclose(cc["gradient"], gradient, rtol=RTOL, atol=1e-9):
        # A standing pattern (z = e^{iθ}·r, r real) fits g and -g exactly equally: which of the two
        # each grid search returns is round-off (numpy's sums against the engine's), so only the
        # line of the gradient is determined, and the angle up to its supplement.
        gradient, angle = -gradient, 180.0 - angle
    assert np.allclose(cc["gradient"], gradient, rtol=RTOL, atol=1e-9)
    if math.isfinite(angle):
        assert cc["angle"] == pytest.approx(angle, rel=RTOL, abs=1e-6)
    if bending and math.isfinite(cc["p_value"]):
        assert cc["p_value"] == pytest.approx(py.p_value, abs=_p_tolerance(py.p_value))
    elif bending:  # the engine shuffles only when every other criterion holds, and until p > BEND_P
        # it stopped at 10 shuffles that fit as well (p >= 11 / 1000): Python's p, from other
        # shuffles, lies above that or within its sampling error of it
        stopped = 11 / (1 + L.BEND_PERMUTATIONS)
        assert not py.is_wave or py.p_value + _p_tolerance(py.p_value) >= stopped
        assert py.p_value + _p_tolerance(py.p_value) >= stopped or not (
            py.fit >= L.BEND_FIT
            and py.lag >= L.WAVE_LAG
            and py.travelling_index >= L.WAVE_TI
            and py.angle >= L.BEND_BACKWARD
        )


def _compare(positions, times, springs, omega, bending):
    py = L.classify_motion(positions, times, springs=springs, omega=omega, bending=bending)
    cc = _core._classify_motion(positions, times, springs, omega, 4.0, bending)
    assert cc["mode"] == py.mode, (cc, py)
    assert cc["mixed"] == tuple(py.mixed)
    assert cc["frames"] == py.frames
    assert np.allclose(cc["direction"], py.direction, rtol=RTOL, atol=1e-9)
    for key in ("omega", "cycles", "speed"):
        assert cc[key] == pytest.approx(getattr(py, key), rel=RTOL, abs=1e-9), key
    assert cc["deformation"] == pytest.approx(py.deformation, rel=RTOL, abs=1e-9)
    if py.mode != "none":  # a rigid body's other measures are ratios of round-off
        for key in ("coherence", "concentration", "travelling_index"):
            assert cc[key] == pytest.approx(getattr(py, key), rel=RTOL, abs=1e-9), key
        assert list(cc["top_cells"]) == list(py.top_cells)
        assert np.allclose(cc["amplitudes"], py.amplitudes, rtol=RTOL, atol=1e-12)
        assert cc["contrast"] == pytest.approx(py.contrast, rel=RTOL)
        assert cc["groups"] == py.groups
        _compare_wave(py.wave, cc["wave"], False)
    if py.bend is not None:
        _compare_wave(py.bend, cc["bend"], True)
    return py, cc


@pytest.mark.parametrize("best", BESTS)
def test_engine_classifies_stored_bests_as_python(best):
    run = animat.Run(ROOT / "data" / "replication" / best)
    tr = animat.replay(run.best(), run.config)
    omega = _core._dominant_frequency(tr.body.amplitude, tr.body.frequency)
    assert omega == pytest.approx(2 * math.pi / tr.period(), rel=1e-12)
    for bending in (False, True):
        _, whole = _compare(tr.positions, tr.times, tr.body.springs, omega, bending)
    # What a recorder keeps during the swim (locomotion.hpp): the frames from the window's start on.
    steps = int(run.config["evaluation.steps"])
    first = _core._locomotion_window_start(steps, float(run.config["physics.dt"]), omega)
    assert len(tr.times) == steps + 1 and steps + 1 - first <= steps // 2 + 2
    end = _core._classify_motion(tr.positions[first:], tr.times[first:], tr.body.springs, omega, 4.0, True, 0.0)
    assert repr(end) == repr(whole)  # bit for bit (repr: nan equals nan)


def _compare_stroke(py, cc):
    """The paper's stroke (animat.protrusion.ProtrusionStroke) against the engine's."""
    assert cc is not None
    assert cc["protrusions"] == py.protrusions
    assert cc["at_rest"] == py.at_rest
    assert cc["pairs"] == tuple(tuple(p) for p in py.pairs)
    assert np.allclose(cc["scores"], py.scores, rtol=RTOL, atol=1e-9, equal_nan=True)
    assert np.allclose(cc["areas"], py.areas, rtol=RTOL, atol=1e-9, equal_nan=True)
    assert np.allclose(cc["pair_scores"], py.pair_scores, rtol=RTOL, atol=1e-9, equal_nan=True)
    assert cc["pair"] == tuple(py.pair)
    assert np.allclose([cc["score"], cc["area"]], [py.score, py.area], rtol=RTOL, atol=1e-9, equal_nan=True)
    assert cc["strokes"] == py.strokes


def _default_path(tr):
    """animat.classify_locomotion's default (stroke) path on a replay, and the engine on the same frames."""
    py = L.classify_locomotion(tr)
    loops = tr.body.skin_loops
    outline = [int(v) for v in loops[0]] if len(loops) else None
    omega = _core._dominant_frequency(tr.body.amplitude, tr.body.frequency)
    cc = _core._classify_motion(
        tr.positions,
        tr.times,
        tr.body.springs,
        omega,
        4.0,
        outline is not None and len(outline) >= 3,
        None,
        outline,
        tr.body.positions if outline is not None else None,
    )
    return py, cc


@pytest.mark.parametrize("best", ALL_BESTS)
def test_engine_default_path_classifies_every_stored_best_as_python(best):
    """The stroke path (outline, rest positions, bending wave): the mode animat.qd's locomotion descriptor
    reads, on every stored best."""
    run = animat.Run(ROOT / "data" / "replication" / best)
    py, cc = _default_path(animat.replay(run.best(), run.config))
    assert (cc["mode"], cc["mixed"], cc["groups"]) == (py.mode, tuple(py.mixed), py.groups), (cc, py)
    assert py.stroke is not None
    _compare_stroke(py.stroke, cc["stroke"])
    if py.bend is not None:
        _compare_wave(py.bend, cc["bend"], True)


def test_stored_bests_cover_the_stroke_rule():
    """The stored bests reach the stroke rule's both sides, so the test above decides it."""
    assert len(ALL_BESTS) == 40
    assert STROKE_SCORE == 0.4 and STROKE_AREA == 0.1  # the engine's kStrokeScore, kStrokeArea


#: One stored best of each condition, for the evaluation's own measure.
EVALUATED = ["dn0.5/run_0", "dn2/run_1", "dn10/run_2", "dn0.2_64cells/run_0"]


def _search_config(config, algorithm, **keys):
    c = config.copy()
    c["search.algorithm"] = algorithm
    for key, value in keys.items():
        c[f"search.{key}"] = value
    return c


@pytest.mark.parametrize("best", EVALUATED)
def test_evaluation_classifies_its_own_swim_when_the_search_reads_locomotion(best):
    run = animat.Run(ROOT / "data" / "replication" / best)
    genome = run.best().genome
    expected = L.MODES.index(L.classify_locomotion(genome, run.config).mode)
    plain = animat.evaluate(genome, run.config)
    assert plain.locomotion == -1  # the GA's config: nothing recorded, nothing classified
    for config in (
        _search_config(run.config, "map_elites", descriptors=["locomotion", "cells"], bins=[6.0, 16.0]),
        _search_config(run.config, "nsga2", objectives=["distance:max", "locomotion:min"]),
    ):
        measured = animat.evaluate(genome, config)
        assert measured.locomotion == expected
        fitness = animat.evolution.to_fitness(measured)
        assert fitness.locomotion == expected
        assert pickle.loads(pickle.dumps(fitness)).locomotion == expected
        # the recording changes nothing else
        for field in ("fitness", "displacement", "max_speed", "max_stretch", "elongation", "protrusions"):
            assert np.array_equal(getattr(measured, field), getattr(plain, field)), field
    other = _search_config(run.config, "map_elites", descriptors=["elongation", "protrusions"])
    assert animat.evaluate(genome, other).locomotion == -1


def _strip(length=12, rows=3):
    pts = [(i + 0.5 * (j % 2), (j - (rows - 1) / 2) * math.sqrt(3) / 2) for j in range(rows) for i in range(length)]
    X = np.array(pts)
    X += np.random.default_rng(0).uniform(-0.02, 0.02, X.shape)
    return X - X.mean(axis=0)


def _swim(kind, omega=2 * math.pi):
    """A 3-row strip (its Gabriel graph as springs) carried along and turned: a bending wave, a
    contraction wave, breathing, random phases per cell, or at rest."""
    X = _strip()
    t = np.arange(400) / 40
    x, y = X[None, :, 0], X[None, :, 1]
    arg = 0.6 * x - omega * t[:, None]
    P = np.repeat(X[None], len(t), axis=0)
    if kind == "bending":
        P[:, :, 0] = x - y * 0.18 * np.cos(arg)
        P[:, :, 1] = y + 0.3 * np.sin(arg)
    elif kind == "contraction":
        P[:, :, 0] = x - 0.25 * np.cos(arg)
    elif kind == "breathing":
        P = P * (1 + 0.1 * np.sin(omega * t))[:, None, None]
    elif kind == "random":
        phase = np.random.default_rng(1).uniform(0, 2 * math.pi, len(X))
        P = P + 0.15 * np.sin(omega * t[:, None, None] + phase[None, :, None]) * np.array([1.0, 0.5])
    turn = 0.1 * t
    c, s = np.cos(turn)[:, None], np.sin(turn)[:, None]
    Q = np.stack([c * P[:, :, 0] - s * P[:, :, 1] + 0.2 * t[:, None], s * P[:, :, 0] + c * P[:, :, 1]], axis=2)
    return Q, t, np.asarray(_core.gabriel_graph(X))


@pytest.mark.parametrize("kind", ["bending", "contraction", "breathing", "random", "rest"])
def test_engine_classifies_synthetic_swims_as_python(kind):
    P, t, springs = _swim(kind)
    for bending in (False, True):
        py, _ = _compare(P, t, springs, 2 * math.pi, bending)
    expected = {"contraction": "undulation", "breathing": "synchronous contraction", "rest": "none"}
    if kind in expected:
        assert py.mode == expected[kind]


def test_engine_refuses_bad_frames():
    P, t, springs = _swim("rest")
    with pytest.raises(ValueError, match="at least 8 frames"):
        _core._classify_motion(P[:7], t[:7], springs, 1.0)
    with pytest.raises(ValueError, match="times"):
        _core._classify_motion(P, t[:-1], springs, 1.0)
    with pytest.raises(ValueError, match="names cell 99"):
        _core._classify_motion(P, t, [[0, 99]], 1.0)
