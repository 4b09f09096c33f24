"""Swimmers built by hand with a known locomotion mode, to check :func:`animat.classify_locomotion`
and the stroke rule of :mod:`animat.protrusion`. Study code, not part of the installed package: the
replication report, confusion.py beside it and the tests import it from this folder.

Nothing here is evolved: each builder places cell centres on a jittered triangular lattice (spacing
``spacing``; the body is their Gabriel graph, as ``animat.build_body`` makes it) and sets every cell's
amplitude, frequency and phase of eq. 2 of the paper, ``L = (1 + a_i sin(f_i t + φ_i) + a_j sin(f_j t +
φ_j)) L0``. The mode each was built to show is :attr:`KnownSwimmer.expected`:

- :func:`undulator`: an elongated body with a travelling wave of contraction; ``kind="contraction"``
  ramps the phase along the long axis (the direction it swims), ``kind="bending"`` adds a half period
  between the two sides, so the body bends from side to side as the wave runs along it,
  ``kind="across"`` ramps the phase across the body (perpendicular to the long axis).
- :func:`synchronous_contractor`: every cell in phase, on an asymmetric (tear-drop) outline, so
  contraction and expansion meet different drag (paper §6, Fig. 5).
- :func:`protrusion_swimmer`: a round core with two symmetric appendages (``length`` cells long, one
  cell or a two-cell-wide strip) whose actuation is set to sweep them backwards extended and forwards
  contracted (paper Fig. 6; :func:`appendage_stroke` measures how far a swim follows);
  only the appendages and the core cells they are anchored to oscillate strongly.
- :func:`tail_swimmer`: a round core with one two-cell-wide tail at the back that beats with a
  bending wave; the core is passive.
- :func:`appendage_swimmer`: the paper's kind of protrusion swimmer: an elliptic body with a
  symmetric pair of flank appendages (one cell beyond the outline, a chain, or a block), **every cell
  actuated** at 0.18–0.2, the core mostly synchronous; the appendages are extended on the backward
  stroke and contracted on the return where their phase and the core cells just behind them (shifted
  by ``anchor_shift``) make them row (:mod:`animat.protrusion` measures whether they do).
- :func:`standing_swimmer`: an ellipse whose halves are in antiphase, or with random phases ("other").
- mixtures: ``protrusion_swimmer(core_wave=...)`` (appendages on a core carrying a wave) and
  ``synchronous_contractor(lag=...)`` (in phase but for a short lag along the body).

:func:`calibration_set` and :func:`held_out_set` give the two sets of the calibration table (the held-
out one uses other shapes, sizes, appendage lengths and frequencies; it was not used to choose any
threshold), :func:`classify_known` swims and classifies them. :func:`paper_calibration_set` and
:func:`paper_held_out_set` do the same for every class with protrusion swimmers of the paper's kind,
each of which performs the stroke by :func:`stroke_truth` (measured from its appendage cells, known by
construction, not by the classifier); :func:`rowing_phase` actuates a geometry so that it does. Both have
been seen and are now calibration, as are :func:`paper_third_set` and :func:`paper_fourth_set` (seen).
Every whole-body swimmer of these sets is labelled by :func:`undulation_truth` (whether the realised
contraction of its cells travels as a wave along the lattice it was built on, the paper's undulation:
:func:`truth_label`); bodies on which a truth disagrees between drags are in no set.
:func:`paper_fifth_set`, :func:`paper_sixth_set` and :func:`paper_seventh_set` were held out (run once)
and are calibration now; :func:`paper_eighth_set`, the held-out set of the undulation truth on the
realised contraction and of the pair at rest, was run once (docs/locomotion.md) and is calibration now.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Callable, List, Optional, Sequence, Tuple

import numpy as np

import animat
from animat.locomotion import classify_locomotion, harmonic_amplitudes, paddling, procrustes_frames
from animat.trajectory import replay

__all__ = [
    "KnownSwimmer",
    "hex_region",
    "undulator",
    "synchronous_contractor",
    "protrusion_swimmer",
    "tail_swimmer",
    "calibration_set",
    "held_out_set",
    "KnownResult",
    "classify_known",
    "confusion_matrix",
    "Stroke",
    "appendage_stroke",
    "StrokeTruth",
    "stroke_truth",
    "TRUTH_ROWING",
    "TRUTH_STROKE",
    "TRUTH_DISTANCE",
    "TRUTH_AXIS_ANGLE",
    "UndulationTruth",
    "undulation_truth",
    "cell_contraction",
    "TRUTH_WAVE_LAG",
    "TRUTH_WAVE_COHERENCE",
    "truth_label",
    "label_by_truth",
    "AMPLITUDE",
    "APPENDAGE_KINDS",
    "appendage_swimmer",
    "standing_swimmer",
    "paper_calibration_set",
    "paper_held_out_set",
    "paper_third_set",
    "paper_fourth_set",
    "paper_fifth_set",
    "paper_sixth_set",
    "paper_seventh_set",
    "eighth_set_candidates",
    "paper_eighth_set",
]

#: The paper's largest amplitude (development.amplitude_max): a cell changes its springs by ±20 %.
AMPLITUDE = 0.2


@dataclass(frozen=True, eq=False)
class KnownSwimmer:
    """A hand-built swimmer.

    Attributes:
        name: short unique name. expected: the mode it was built to show (one of
            ``animat.locomotion.MODES``); mixed: a second mode built in (mixtures), else "".
        positions: (n, 2) cell centres; +x is the intended direction of swimming.
        amplitude, frequency, phase: (n,) per-cell actuation of eq. 2 (frequency in rad per time unit).
        description: how it was built.
        appendages: the cell indices of each appendage, by construction (:func:`appendage_swimmer`;
            empty for the other builders); :func:`stroke_truth` measures their stroke.
    """

    name: str
    expected: str
    positions: np.ndarray
    amplitude: np.ndarray
    frequency: np.ndarray
    phase: np.ndarray
    description: str
    mixed: str = ""
    appendages: Tuple[Tuple[int, ...], ...] = ()

    @property
    def cells(self) -> int:
        return len(self.positions)

    def body(self, config: Optional[Any] = None) -> Any:
        """The :class:`animat.Body` (springs: the Gabriel graph of the cell centres)."""
        return animat.build_body(self.positions, self.amplitude, self.frequency, self.phase, config=config)


def hex_region(
    inside: Callable[[float, float], bool], spacing: float = 1.0, extent: int = 12, jitter: float = 0.02, seed: int = 0
) -> np.ndarray:
    """Points of a triangular lattice (rows along x, ``spacing`` apart) with ``inside(x, y)`` true,
    jittered by up to ``jitter`` × spacing (no four points on a circle, so the Gabriel graph is unique)."""
    h = spacing * math.sqrt(3) / 2
    pts = []
    for j in range(-extent, extent + 1):
        for i in range(-extent, extent + 1):
            x, y = (i + 0.5 * (j % 2)) * spacing, j * h
            if inside(x, y):
                pts.append((x, y))
    p = np.array(pts, dtype=np.float64)
    p += np.random.default_rng(seed).uniform(-jitter, jitter, p.shape) * spacing
    return p


def _swimmer(
    name: str,
    expected: str,
    positions: np.ndarray,
    amplitude: np.ndarray,
    frequency: float,
    phase: np.ndarray,
    description: str,
    mixed: str = "",
    appendages: Sequence[Sequence[int]] = (),
) -> KnownSwimmer:
    n = len(positions)
    return KnownSwimmer(
        name,
        expected,
        positions,
        np.asarray(amplitude, dtype=np.float64),
        np.full(n, float(frequency)),
        np.mod(np.asarray(phase, dtype=np.float64), 2 * math.pi),
        description,
        mixed,
        tuple(tuple(int(i) for i in g) for g in appendages),
    )


def undulator(
    kind: str = "contraction",
    length: float = 9.0,
    width: float = 2.6,
    frequency: float = 8.0,
    wavelengths: float = 1.0,
    spacing: float = 1.0,
    seed: int = 0,
    name: Optional[str] = None,
) -> KnownSwimmer:
    """An elongated (rectangular, rounded) body with a travelling wave of contraction.

    Args:
        kind: "contraction" (phase ramp -2π·wavelengths·x/length along the long axis x),
            "bending" (the same plus π on the +y side: the sides alternate, the body bends) or
            "across" (the ramp along y, across the body, over its width).
        length, width: extent of the body (along x, y). frequency: rad per time unit.
        wavelengths: phase lag across the ramp in periods (1 = 2π).
    """
    pos = hex_region(lambda x, y: abs(x) <= length / 2 and abs(y) <= width / 2, spacing, seed=seed)
    x, y = pos[:, 0], pos[:, 1]
    k = 2 * math.pi * wavelengths
    if kind == "contraction":
        phase = -k * (x - x.min()) / np.ptp(x)
    elif kind == "bending":
        phase = -k * (x - x.min()) / np.ptp(x) + np.where(y > 0, math.pi, 0.0)
    elif kind == "across":
        phase = -k * (y - y.min()) / np.ptp(y)
    else:
        raise ValueError(f"undulator: kind must be contraction, bending or across, got {kind!r}")
    return _swimmer(
        name or f"undulator_{kind}",
        "undulation",
        pos,
        np.full(len(pos), AMPLITUDE),
        frequency,
        phase,
        f"{len(pos)} cells, {length:g} x {width:g}, wave of {wavelengths:g} period(s) ({kind}), f = {frequency:g}",
    )


def synchronous_contractor(
    length: float = 8.0,
    width: float = 5.0,
    frequency: float = 8.0,
    lag: float = 0.0,
    spacing: float = 1.0,
    seed: int = 0,
    name: Optional[str] = None,
    shape: str = "teardrop",
) -> KnownSwimmer:
    """A body with every cell in phase: by default a tear-drop (wide and round at the back, -x; pointed at
    the front, +x), so that contraction and expansion meet different drag (paper §6, Fig. 5).

    ``shape``: "teardrop"; "wedge" (straight flanks from a flat back of the full width to a front of a
    third of it) or "ellipse" (symmetric front to back: it may barely swim). ``lag`` > 0 adds a phase ramp
    of ``lag`` rad along the body (a mixture: mostly synchronous with a short wave); expected "synchronous
    contraction" either way, mixed "undulation" when ``lag`` >= π/2.
    """
    r = width / 2

    def teardrop(x: float, y: float) -> bool:
        back = x <= -length / 2 + r
        if back:
            return (x - (-length / 2 + r)) ** 2 + y**2 <= r * r
        half = r * (length / 2 - x) / (length - r)  # straight flanks narrowing to the tip at x = length/2
        return x <= length / 2 and abs(y) <= half + 0.05

    def wedge(x: float, y: float) -> bool:
        return abs(x) <= length / 2 and abs(y) <= r * (1.0 - (2.0 / 3.0) * (x + length / 2) / length) + 0.05

    def ellipse(x: float, y: float) -> bool:
        return (x / (length / 2)) ** 2 + (y / r) ** 2 <= 1.0

    shapes = {"teardrop": teardrop, "wedge": wedge, "ellipse": ellipse}
    if shape not in shapes:
        raise ValueError(f"synchronous_contractor: shape must be one of {sorted(shapes)}, got {shape!r}")
    pos = hex_region(shapes[shape], spacing, seed=seed)
    x = pos[:, 0]
    phase = -lag * (x - x.min()) / np.ptp(x)
    mixed = "undulation" if lag >= math.pi / 2 else ""
    outline = {"teardrop": "tear-drop", "wedge": "wedge", "ellipse": "ellipse"}[shape]
    return _swimmer(
        name or ("synchronous_teardrop" if lag == 0 else f"synchronous_lag{lag:.1f}"),
        "synchronous contraction",
        pos,
        np.full(len(pos), AMPLITUDE),
        frequency,
        phase,
        f"{len(pos)} cells, {outline} {length:g} x {width:g}, all in phase"
        + (f" but a lag of {lag:.2f} rad along the body" if lag else "")
        + f", f = {frequency:g}",
        mixed,
    )


def _appendage(
    base: np.ndarray, direction: np.ndarray, along: np.ndarray, length: int, wide: bool, spacing: float
) -> List[np.ndarray]:
    """Cells of an appendage growing from ``base`` along ``direction``: one per row, or two (offset
    along ``along`` by ±spacing/2) per row when ``wide``. Rows are spacing·√3/2 apart."""
    h = spacing * math.sqrt(3) / 2
    out = []
    for k in range(1, length + 1):
        c = base + direction * h * k
        if wide:
            out += [c + along * spacing / 2, c - along * spacing / 2]
        else:
            out.append(c + along * (spacing / 2 if k % 2 else 0.0))
    return out


def protrusion_swimmer(
    length: int = 1,
    wide: bool = False,
    core_radius: float = 2.3,
    frequency: float = 8.0,
    core_amplitude: float = 0.0,
    anchor_amplitude: float = 0.1,
    core_wave: float = 0.0,
    spacing: float = 1.0,
    seed: int = 0,
    name: Optional[str] = None,
) -> KnownSwimmer:
    """A round core with two symmetric appendages (at ±y) actuated to row: extended while they sweep
    backwards (-x), contracted on the way forward (paper §6, Fig. 6). The swims follow this only loosely
    (:func:`appendage_stroke`: the extension correlates weakly with the backward velocity).

    The appendage cells oscillate at full amplitude with phase π/2 (their springs are longest when the
    sweep moves backwards fastest); the core cells they are anchored to oscillate with
    ``anchor_amplitude``, the front ones (+x) at phase 0 and the back ones at π, which swings the
    appendage back and forth; every other core cell has ``core_amplitude`` (0: passive).

    Args:
        length: appendage length in cells (1: one cell beyond the outline, as the paper's 32-cell bests).
        wide: two-cell-wide appendages (multi-cell, as the paper's 64-cell bests, Fig. 6b).
        core_wave: a phase ramp of this many rad along x on the core cells (with ``core_amplitude`` > 0
            this is a mixture: protrusions plus undulation when it is at least π/2).
    """
    core = hex_region(lambda x, y: x * x + y * y <= core_radius**2, spacing, seed=seed)
    extra: List[np.ndarray] = []
    for s in (+1.0, -1.0):
        top = core[np.argmax(s * core[:, 1] - 0.3 * np.abs(core[:, 0]))]
        extra += _appendage(top, np.array([0.0, s]), np.array([1.0, 0.0]), length, wide, spacing)
    app = np.array(extra)
    app += np.random.default_rng(seed + 1).uniform(-0.02, 0.02, app.shape) * spacing
    pos = np.vstack([core, app])
    n_core = len(core)
    amp = np.full(len(pos), float(core_amplitude))
    x = core[:, 0]
    phase = np.zeros(len(pos))
    if core_wave:
        phase[:n_core] = -core_wave * (x - x.min()) / np.ptp(x)
    # anchors: core cells within 1.2 spacing of an appendage's first row
    for k in range(n_core):
        d = np.linalg.norm(app - core[k], axis=1).min()
        if d <= 1.2 * spacing:
            amp[k] = max(amp[k], anchor_amplitude)
            phase[k] = 0.0 if core[k, 0] >= 0 else math.pi
    amp[n_core:] = AMPLITUDE
    phase[n_core:] = math.pi / 2
    mixed = "undulation" if core_wave >= math.pi / 2 and core_amplitude > 0 else ""
    shape = f"{'two-cell-wide ' if wide else ''}{length}-cell"
    return _swimmer(
        name or f"protrusions_{'wide' if wide else 'single'}{length}" + ("_wave" if core_wave else ""),
        "protrusions",
        pos,
        amp,
        frequency,
        phase,
        f"{len(pos)} cells: core radius {core_radius:g} ({n_core} cells, amplitude {core_amplitude:g}"
        + (f", wave {core_wave:.2f} rad" if core_wave else "")
        + f"), two {shape} appendages at full amplitude, anchors {anchor_amplitude:g}, f = {frequency:g}",
        mixed,
    )


def tail_swimmer(
    length: int = 4,
    core_radius: float = 2.3,
    frequency: float = 8.0,
    wavelengths: float = 0.5,
    spacing: float = 1.0,
    seed: int = 0,
    name: Optional[str] = None,
) -> KnownSwimmer:
    """A passive round core with one two-cell-wide tail at the back (-x) beating with a bending wave
    (the two rows of the tail in antiphase, a phase ramp of ``wavelengths`` periods from base to tip)."""
    core = hex_region(lambda x, y: x * x + y * y <= core_radius**2, spacing, seed=seed)
    back = core[np.argmin(core[:, 0] - 0.3 * np.abs(core[:, 1]))]
    # the tail grows along -x: its two rows lie at ±spacing/2 in y
    h = spacing * math.sqrt(3) / 2
    cells, rows, sides = [], [], []
    for k in range(1, length + 1):
        c = back + np.array([-h * k, 0.0])
        for side in (+1.0, -1.0):
            cells.append(c + np.array([0.0, side * spacing / 2]))
            rows.append(k)
            sides.append(side)
    tail = np.array(cells) + np.random.default_rng(seed + 1).uniform(-0.02, 0.02, (len(cells), 2)) * spacing
    pos = np.vstack([core, tail])
    amp = np.zeros(len(pos))
    amp[len(core) :] = AMPLITUDE
    phase = np.zeros(len(pos))
    k = 2 * math.pi * wavelengths
    phase[len(core) :] = -k * (np.array(rows) - 1) / max(1, length - 1) + np.where(np.array(sides) > 0, math.pi, 0.0)
    return _swimmer(
        name or f"tail{length}",
        "tail",
        pos,
        amp,
        frequency,
        phase,
        f"{len(pos)} cells: passive core radius {core_radius:g}, a {length}-row two-cell-wide tail "
        f"with a bending wave of {wavelengths:g} period, f = {frequency:g}",
    )


def calibration_set() -> List[KnownSwimmer]:
    """The swimmers the classifier was checked on; its strain-contrast threshold
    (``animat.locomotion.LOCAL_CONTRAST``) was set between this set's whole-body and appendage swimmers."""
    return [
        undulator("contraction"),
        undulator("bending"),
        undulator("across", length=6.0, width=5.0, name="undulator_across"),
        synchronous_contractor(),
        synchronous_contractor(lag=1.0),
        protrusion_swimmer(length=1),
        protrusion_swimmer(length=3, wide=True),
        protrusion_swimmer(length=1, core_amplitude=0.05, core_wave=2 * math.pi),
        tail_swimmer(),
    ]


def _held_out_whole_body() -> List[KnownSwimmer]:
    """The held-out undulators and synchronous contractors (both held-out sets use them)."""
    return [
        undulator(
            "contraction", length=12.0, width=1.8, frequency=5.0, wavelengths=1.5, seed=3, name="ho_undulator_long"
        ),
        undulator(
            "bending", length=7.0, width=2.6, frequency=11.0, wavelengths=0.75, seed=4, name="ho_undulator_bend_fast"
        ),
        undulator(
            "contraction", length=8.0, width=3.5, frequency=3.0, wavelengths=0.5, seed=5, name="ho_undulator_slow"
        ),
        synchronous_contractor(length=10.0, width=4.0, frequency=5.0, seed=6, name="ho_sync_slender"),
        synchronous_contractor(length=6.0, width=5.5, frequency=11.0, seed=7, name="ho_sync_stubby_fast"),
        synchronous_contractor(length=7.0, width=4.5, frequency=3.0, lag=0.6, seed=8, name="ho_sync_lag_slow"),
    ]


def held_out_set() -> List[KnownSwimmer]:
    """Other shapes, sizes, appendage lengths and frequencies; not used to set any threshold."""
    return _held_out_whole_body() + [
        protrusion_swimmer(length=2, core_radius=2.0, frequency=5.0, seed=9, name="ho_protrusions_single2"),
        protrusion_swimmer(length=4, wide=True, core_radius=3.2, frequency=6.0, seed=10, name="ho_protrusions_wide4"),
        protrusion_swimmer(
            length=2,
            wide=True,
            core_radius=2.6,
            frequency=11.0,
            anchor_amplitude=0.15,
            seed=11,
            name="ho_protrusions_wide2_fast",
        ),
        protrusion_swimmer(
            length=1,
            core_radius=2.8,
            frequency=4.0,
            core_amplitude=0.03,
            core_wave=math.pi,
            seed=12,
            name="ho_protrusions_wave",
        ),
        tail_swimmer(length=6, core_radius=2.0, frequency=6.0, wavelengths=0.75, seed=13, name="ho_tail6"),
        tail_swimmer(length=3, core_radius=2.8, frequency=10.0, wavelengths=0.25, seed=14, name="ho_tail3_fast"),
    ]


@dataclass(frozen=True)
class Stroke:
    """How the appendage cells (those at full amplitude) of a protrusion or tail swimmer move in the body
    frame, over the classifier's window.

    Attributes:
        sweep: mean peak-to-peak displacement along the direction of motion (length units).
        extension: mean peak-to-peak distance from the body's centre.
        rowing: mean correlation of the extension with the backward velocity: +1 when an appendage is
            farthest out exactly while it moves backwards (the paper's Fig. 6 stroke), 0 when unrelated.
    """

    sweep: float
    extension: float
    rowing: float


def appendage_stroke(swimmer: KnownSwimmer, trajectory: Any, mode: Any) -> Optional[Stroke]:
    """:class:`Stroke` of ``swimmer``'s full-amplitude cells in a recorded ``trajectory``, using the window
    (last ``mode.cycles`` periods), body frame and direction of motion of the classifier's ``mode``.
    None when the swimmer has no appendage cells or the mode has no frequency."""
    app = np.flatnonzero(swimmer.amplitude >= AMPLITUDE)
    if swimmer.expected not in ("protrusions", "tail") or len(app) == 0 or not mode.omega > 0:
        return None
    # the classifier's own window (a suffix of mode.frames frames), as paddling() takes it
    Q, _, _ = procrustes_frames(np.asarray(trajectory.positions)[-max(int(mode.frames), 2) :])
    along = Q[:, app] @ np.asarray(mode.direction)
    radius = np.linalg.norm(Q[:, app], axis=2)
    backward = -np.gradient(along, axis=0)
    corr = [
        float(np.corrcoef(radius[:, k], backward[:, k])[0, 1])
        for k in range(len(app))
        if np.ptp(radius[:, k]) > 0 and np.ptp(backward[:, k]) > 0
    ]
    return Stroke(
        float(np.ptp(along, axis=0).mean()),
        float(np.ptp(radius, axis=0).mean()),
        float(np.mean(corr)) if corr else float("nan"),
    )


#: Ground truth of the paper's stroke (:func:`stroke_truth`), fixed from the paper's words before any
#: swim was classified: every appendage's extension correlates with its backward velocity at least this
#: much (the extension leads the backward sweep by at most 60°) ...
TRUTH_ROWING = 0.5
#: ... each appendage's loop is a stroke, not a tremor: peak-to-peak sweep and extension at least this
#: (spacings) ...
TRUTH_STROKE = 0.1
#: ... the body swims at least this far (spacings) over the analysed periods ...
TRUTH_DISTANCE = 0.25
#: ... within this angle (degrees) of its long (symmetry) axis, away from its appendages.
TRUTH_AXIS_ANGLE = 30.0
#: Periods analysed (the last ones, as the classifier's window).
TRUTH_PERIODS = 4


@dataclass(frozen=True)
class StrokeTruth:
    """Whether a swim of a hand-built appendage swimmer performs the paper's stroke, measured from its
    appendage cells known by construction (:attr:`KnownSwimmer.appendages`), not by the classifier.

    Attributes:
        rowing: per appendage, ``Σ −Im(E X̄) / Σ |E||X|`` over its cells (``X`` sweep along the direction
            of motion, ``E`` extension from its anchors along its outward direction, complex amplitudes
            at the actuation frequency): +1 when it is farthest out while it moves backwards fastest.
        sweep, extension: per appendage, mean peak-to-peak sweep and extension of its cells (spacings).
        distance: net distance swum over the analysed periods (spacings).
        axis_angle: angle between the direction of motion and the body's long axis at rest (degrees).
        away: whether the body moves away from its appendages (they trail behind its centre).
    """

    rowing: Tuple[float, ...]
    sweep: Tuple[float, ...]
    extension: Tuple[float, ...]
    distance: float
    axis_angle: float
    away: bool

    @property
    def strokes(self) -> bool:
        """Every appendage rows (:data:`TRUTH_ROWING`, :data:`TRUTH_STROKE`) and the body swims
        (:data:`TRUTH_DISTANCE`) along its axis (:data:`TRUTH_AXIS_ANGLE`), away from them."""
        return bool(
            len(self.rowing) >= 2
            and all(r >= TRUTH_ROWING for r in self.rowing)
            and all(v >= TRUTH_STROKE for v in self.sweep + self.extension)
            and self.distance >= TRUTH_DISTANCE
            and self.axis_angle <= TRUTH_AXIS_ANGLE
            and self.away
        )

    def why_not(self) -> str:
        """What fails (empty when it strokes)."""
        out = []
        if min(self.rowing, default=float("nan")) < TRUTH_ROWING:
            out.append(f"rowing {min(self.rowing):+.2f} < {TRUTH_ROWING}")
        if min(self.sweep + self.extension, default=0.0) < TRUTH_STROKE:
            out.append(f"stroke {min(self.sweep + self.extension):.2f} < {TRUTH_STROKE}")
        if self.distance < TRUTH_DISTANCE:
            out.append(f"distance {self.distance:.2f} < {TRUTH_DISTANCE}")
        if self.axis_angle > TRUTH_AXIS_ANGLE:
            out.append(f"off axis by {self.axis_angle:.0f} deg")
        if not self.away:
            out.append("moves towards its appendages")
        return "; ".join(out)


def _rest_frame(
    swimmer: KnownSwimmer, trajectory: Any, periods: int
) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float, np.ndarray]:
    """The last ``periods`` actuation periods of a swim (at most its second half) in the rest frame: every
    frame rotated onto the centred body at rest (Kabsch). Returns (Q, times, rest, rotations, omega,
    centres of mass): ``X[f] @ R[f] ~ rest``."""
    P = np.asarray(trajectory.positions, dtype=np.float64)
    t = np.asarray(trajectory.times, dtype=np.float64)
    rest = np.asarray(trajectory.body.positions, dtype=np.float64)
    omega = float(np.median(swimmer.frequency))
    start = max(t[-1] - periods * 2 * math.pi / omega, 0.5 * (t[0] + t[-1]))
    sel = t >= start
    P, t = P[sel], t[sel]
    rest = rest - rest.mean(axis=0)
    X = P - P.mean(axis=1, keepdims=True)
    H = np.einsum("fni,nj->fij", X, rest)
    U, _, Vt = np.linalg.svd(H)
    det = np.sign(np.linalg.det(U @ Vt))
    D = np.zeros((len(X), 2, 2))
    D[:, 0, 0] = 1.0
    D[:, 1, 1] = np.where(det == 0, 1.0, det)
    R = U @ D @ Vt  # X[f] @ R[f] ~ rest
    Q = np.einsum("fni,fij->fnj", X, R)
    return Q, t, rest, R, omega, P.mean(axis=1)


def stroke_truth(swimmer: KnownSwimmer, trajectory: Any, periods: int = TRUTH_PERIODS) -> Optional[StrokeTruth]:
    """:class:`StrokeTruth` of a swim of ``swimmer`` over its last ``periods`` actuation periods (at most
    the second half of the swim), or None when the swimmer has no known appendages.

    Independent of the classifier: the appendages and their anchors (the other cells joined to them by
    springs) are known by construction, the frequency is the actuation's, and the body frame is the rest
    shape's (each frame rotated onto the body at rest, Kabsch), so the long axis is the rest shape's
    principal axis."""
    if not swimmer.appendages:
        return None
    Q, t, rest, R, omega, com = _rest_frame(swimmer, trajectory, periods)
    springs = np.asarray(trajectory.body.springs, dtype=np.int64).reshape(-1, 2)
    drift = np.einsum("fi,fij->j", np.diff(com, axis=0), R[:-1])
    distance = float(np.linalg.norm(com[-1] - com[0]))
    d = drift / np.linalg.norm(drift) if np.linalg.norm(drift) > 0 else np.array([1.0, 0.0])
    axis = np.linalg.eigh(rest.T @ rest)[1][:, -1]
    angle = float(np.degrees(np.arccos(min(1.0, abs(float(d @ axis))))))
    cells = sorted({i for g in swimmer.appendages for i in g})
    away = bool(float(rest[cells].mean(axis=0) @ d) < 0)
    rows, sweeps, exts = [], [], []
    for g in swimmer.appendages:
        gs = set(g)
        anchors = sorted({int(v) for i, j in springs for v in (i, j) if (int(i) in gs) != (int(j) in gs)} - set(cells))
        u = rest[list(g)].mean(axis=0) - rest[anchors].mean(axis=0)
        u /= np.linalg.norm(u)
        sweep = harmonic_amplitudes(Q[:, list(g)] @ d, t, omega)
        ext = harmonic_amplitudes((Q[:, list(g)] - Q[:, anchors].mean(axis=1)[:, None, :]) @ u, t, omega)
        den = float(np.sum(np.abs(sweep) * np.abs(ext)))
        rows.append(float(np.sum(-np.imag(ext * np.conj(sweep))) / den) if den > 0 else float("nan"))
        sweeps.append(float(2 * np.mean(np.abs(sweep))))
        exts.append(float(2 * np.mean(np.abs(ext))))
    return StrokeTruth(tuple(rows), tuple(sweeps), tuple(exts), distance, angle, away)


#: Ground truth of undulation (:func:`undulation_truth`), from the paper's definition (§6): undulation
#: "results from waves of contractions propagating through the body", while in synchronous contraction
#: "the cells oscillate synchronously" (its Fig. 4 and 5 colour each cell by whether it contracts or
#: expands its springs). The realised contraction of the cells travels along the axis the body swims along
#: by at least a quarter period over the body (the phase lag of a travelling wave; π/2) ...
TRUTH_WAVE_LAG = math.pi / 2
#: ... and coherently: the contraction of a cell predicts its lattice neighbour's (one site further along the
#: axis) at least this much (a resultant: 1 for a wave of constant amplitude, 0 for unrelated cells); the
#: body swims as for the stroke (:data:`TRUTH_DISTANCE`, :data:`TRUTH_AXIS_ANGLE`).
TRUTH_WAVE_COHERENCE = 0.4
#: The two lattice axes of the builders (rows along x one spacing apart; the same column two rows apart).
LATTICE_STEPS = {"x": (1.0, 0.0), "y": (0.0, math.sqrt(3))}


def cell_contraction(Q: np.ndarray, rest: np.ndarray, springs: np.ndarray) -> np.ndarray:
    """(F, n): each cell's realised contraction, the mean relative length change of its springs against
    their length in the body at rest, ``L(t) / L_rest − 1`` (negative: contracted), frame by frame (``Q``:
    (F, n, 2) positions, ``rest``: (n, 2), ``springs``: (m, 2) cell indices). It is measured on the motion,
    not read from the actuation: what the paper's Fig. 4 and 5 colour blue (contracting) and red
    (expanding)."""
    n = len(rest)
    if len(springs) == 0:
        return np.zeros(Q.shape[:2])
    i, j = springs[:, 0], springs[:, 1]
    strain = np.linalg.norm(Q[:, i] - Q[:, j], axis=2) / np.linalg.norm(rest[i] - rest[j], axis=1) - 1.0
    acc = np.zeros((len(Q), n))
    np.add.at(acc.T, i, strain.T)
    np.add.at(acc.T, j, strain.T)
    deg = np.bincount(np.concatenate([i, j]), minlength=n).astype(float)
    return acc / np.maximum(deg, 1.0)


@dataclass(frozen=True)
class UndulationTruth:
    """Whether a swim of a hand-built whole-body swimmer undulates by the paper's definition (a wave of
    contraction travelling through the body), measured from its motion on the lattice it was built on
    (:func:`undulation_truth`), not by the classifier.

    Attributes:
        axis: the lattice axis ("x" or "y") nearest the direction of motion; the wave is measured along it.
        lag: phase lag of the cells' contraction over the body along that axis (rad; from one site to the
            next, times the body's extent in sites).
        coherence: ``|Σ C_j conj(C_i)| / Σ |C_j||C_i|`` over the pairs of cells ``j`` one lattice site
            beyond ``i`` along the axis (``C``: the cells' realised contraction, :func:`cell_contraction`,
            at the actuation frequency, complex).
        travel: +1 when the contraction travels with the motion, −1 against it (0 without a lag).
        distance: net distance swum over the analysed periods (spacings).
        axis_angle: angle between the direction of motion and the axis (degrees).
    """

    axis: str
    lag: float
    coherence: float
    travel: int
    distance: float
    axis_angle: float

    @property
    def undulates(self) -> bool:
        """A coherent wave of contraction (:data:`TRUTH_WAVE_COHERENCE`) of at least :data:`TRUTH_WAVE_LAG`
        along the axis the body swims along (:data:`TRUTH_DISTANCE`, :data:`TRUTH_AXIS_ANGLE`)."""
        return bool(
            self.lag >= TRUTH_WAVE_LAG
            and self.coherence >= TRUTH_WAVE_COHERENCE
            and self.distance >= TRUTH_DISTANCE
            and self.axis_angle <= TRUTH_AXIS_ANGLE
        )

    def why_not(self) -> str:
        """What fails (empty when it undulates)."""
        out = []
        if self.lag < TRUTH_WAVE_LAG:
            out.append(f"lag {self.lag:.2f} < pi/2")
        if self.coherence < TRUTH_WAVE_COHERENCE:
            out.append(f"coherence {self.coherence:.2f} < {TRUTH_WAVE_COHERENCE}")
        if self.distance < TRUTH_DISTANCE:
            out.append(f"distance {self.distance:.2f} < {TRUTH_DISTANCE}")
        if self.axis_angle > TRUTH_AXIS_ANGLE:
            out.append(f"off axis by {self.axis_angle:.0f} deg")
        return "; ".join(out)


def undulation_truth(swimmer: KnownSwimmer, trajectory: Any, periods: int = TRUTH_PERIODS) -> UndulationTruth:
    """:class:`UndulationTruth` of a swim of ``swimmer`` over its last ``periods`` actuation periods (the
    frame, window and frequency of :func:`stroke_truth`).

    The paper's undulation is a wave of contraction travelling through the body; its synchronous
    contraction has every cell oscillating in phase, however the body's displacement then moves. So the
    truth looks at the **realised contraction** of each cell (:func:`cell_contraction`: how its springs
    change length over the swim, measured on the motion, not the commanded actuation), and asks that it
    travel along the axis the body swims along, coherently, and that the body swim. Independent of the
    classifier: it uses the lattice the builder placed the cells on (its two axes, and which cell is the
    next site along each, :data:`LATTICE_STEPS`), the actuation frequency and the body at rest. A travelling
    wave makes the contraction of each cell repeat at the next site along the axis a fixed phase later (the
    step's phase, times the body's extent in sites, is the lag over the body); a synchronous or standing
    pattern has no such lag, unrelated cells no coherence. Pairs of neighbours along a row lie on the same
    side of the body, so a bending wave (the two sides in antiphase) is measured as the wave along each
    side."""
    Q, t, rest, R, omega, com = _rest_frame(swimmer, trajectory, periods)
    drift = np.einsum("fi,fij->j", np.diff(com, axis=0), R[:-1])
    distance = float(np.linalg.norm(com[-1] - com[0]))
    d = drift / np.linalg.norm(drift) if np.linalg.norm(drift) > 0 else np.array([1.0, 0.0])
    springs = np.asarray(trajectory.body.springs, dtype=np.int64).reshape(-1, 2)
    C = harmonic_amplitudes(cell_contraction(Q, rest, springs), t, omega)  # (n,) complex contraction
    built = np.asarray(swimmer.positions, dtype=np.float64)
    spacing = float(np.min(np.linalg.norm(built[:, None] - built[None], axis=2) + np.eye(len(built)) * 1e9))
    best: Optional[UndulationTruth] = None
    for name, step in LATTICE_STEPS.items():
        e = np.asarray(step) * spacing
        u = e / np.linalg.norm(e)
        angle = float(np.degrees(np.arccos(min(1.0, abs(float(d @ u))))))
        gap = np.linalg.norm(built[None, :, :] - built[:, None, :] - e[None, None, :], axis=2)
        i, j = np.nonzero(gap < 0.15 * spacing)  # j is one site beyond i along the axis
        if len(i) == 0:
            continue
        c = complex(np.sum(C[j] * np.conj(C[i])))
        den = float(np.sum(np.abs(C[j]) * np.abs(C[i])))
        coherence = abs(c) / den if den > 0 else 0.0
        phase = -float(np.angle(c))  # > 0: the pattern moves towards +e
        lag = abs(phase) * float(np.ptp(built @ u)) / float(np.linalg.norm(e))
        travel = int(np.sign(phase) * np.sign(float(d @ u))) if phase != 0 else 0
        truth = UndulationTruth(name, lag, coherence, travel, distance, angle)
        if best is None or angle < best.axis_angle:
            best = truth
    assert best is not None
    return best


#: Classes whose label the undulation truth checks: the whole-body builders (the appendage swimmers
#: have :func:`stroke_truth`; a tail's class is where its motion is, which the truth does not look at).
WHOLE_BODY = ("undulation", "synchronous contraction", "other")


def truth_label(swimmer: KnownSwimmer, truths: Sequence[Optional[UndulationTruth]]) -> Optional[str]:
    """The label of a whole-body swimmer by :func:`undulation_truth` at every drag swum (``truths``), as the
    stroke truth decides for the appendage swimmers: "undulation" when it undulates at every drag; its
    built label when it undulates at none and was not built as an undulator; None (rejected: in no set)
    when the drags disagree, a built undulator undulates at none, or a swim was unstable. Other classes
    keep their built label."""
    if swimmer.expected not in WHOLE_BODY:
        return swimmer.expected
    if not truths or any(t is None for t in truths):
        return None
    und = [t.undulates for t in truths if t is not None]
    if all(und):
        return "undulation"
    if not any(und) and swimmer.expected != "undulation":
        return swimmer.expected
    return None


def label_by_truth(
    swimmers: Sequence[KnownSwimmer], drags: Sequence[float] = (0.5, 2.0), steps: int = 2000
) -> List[Tuple[KnownSwimmer, Optional[str], List[Optional[UndulationTruth]]]]:
    """Swim each swimmer at every drag and label it by :func:`truth_label` (the classifier plays no part).
    Returns (swimmer, label or None when rejected, truths) per swimmer."""
    out = []
    for s in swimmers:
        truths: List[Optional[UndulationTruth]] = []
        for dn in drags:
            cfg = animat.Config()
            cfg["scene.drag_normal"] = float(dn)
            cfg["evaluation.steps"] = int(steps)
            tr = replay(s.body(cfg), cfg)
            truths.append(undulation_truth(s, tr) if tr.stable else None)
        out.append((s, truth_label(s, truths), truths))
    return out


def _by_truth(swimmers: Sequence[KnownSwimmer], relabelled: dict, rejected: dict) -> List[KnownSwimmer]:
    """``swimmers`` without the ``rejected`` ones and with the ``relabelled`` ones' labels (name -> label),
    as :func:`label_by_truth` found them (recorded, so that a set is the same without swimming it)."""
    out = []
    for s in swimmers:
        if s.name in rejected:
            continue
        if s.name in relabelled:
            s = replace(
                s,
                expected=relabelled[s.name],
                description=s.description + f" (label by the undulation truth; built as {s.expected})",
            )
        out.append(s)
    return out


@dataclass(frozen=True, eq=False)
class KnownResult:
    """One swim of a known swimmer: its name, expected and found modes, drag and the classifier's numbers."""

    swimmer: KnownSwimmer
    drag_normal: float
    steps: int
    mode: Any  # animat.locomotion.LocomotionMode
    distance: float
    stable: bool
    stroke: Optional[Stroke] = None
    paddling: Any = None  # animat.locomotion.Paddling of the swim (None when unstable)
    truth: Optional[StrokeTruth] = None  # the ground truth of the stroke (appendage swimmers only)
    undulation: Optional[UndulationTruth] = None  # the ground truth of undulation (whole-body swimmers only)

    @property
    def found(self) -> str:
        return self.mode.mode if self.mode is not None else "unstable"

    @property
    def correct(self) -> bool:
        return self.found == self.swimmer.expected


def swim_known(swimmer: KnownSwimmer, drag: float, steps: int = 2000, config: Optional[Any] = None) -> Any:
    """The recorded swim (:func:`animat.replay`) of a hand-built swimmer, ``steps`` steps at normal drag
    ``drag`` (d_T = d_N / 200 via the config default), under ``config`` (default: the defaults)."""
    cfg = config.copy() if config is not None else animat.Config()
    cfg["scene.drag_normal"] = float(drag)
    cfg["evaluation.steps"] = int(steps)
    return replay(swimmer.body(cfg), cfg)


def classify_known(
    swimmers: Sequence[KnownSwimmer],
    drags: Sequence[float] = (0.5, 2.0),
    steps: int = 2000,
    config: Optional[Any] = None,
    stroke_rule: bool = True,
) -> List[KnownResult]:
    """Swim every swimmer ``steps`` steps at every normal drag (d_T = d_N / 200, the paper's ratio, via the
    config default) and classify the recorded swim with :func:`animat.classify_locomotion`
    (``stroke_rule``, its ``stroke`` argument: the stroke path by default, as there; False: the earlier
    rules)."""
    out = []
    for dn in drags:
        for s in swimmers:
            tr = swim_known(s, dn, steps, config)
            mode = classify_locomotion(tr, stroke=stroke_rule) if tr.stable else None
            stroke = appendage_stroke(s, tr, mode) if mode is not None else None
            paddle = paddling(tr, mode) if mode is not None else None
            truth = stroke_truth(s, tr) if tr.stable else None
            whole = tr.stable and not s.appendages and s.expected in WHOLE_BODY
            und = undulation_truth(s, tr) if whole else None
            out.append(
                KnownResult(
                    s, float(dn), int(steps), mode, float(tr.distance), bool(tr.stable), stroke, paddle, truth, und
                )
            )
    return out


def confusion_matrix(results: Sequence[KnownResult], expected: Sequence[str], found: Sequence[str]) -> np.ndarray:
    """counts[i, j]: swims built as ``expected[i]`` classified as ``found[j]``."""
    m = np.zeros((len(expected), len(found)), dtype=np.int64)
    for r in results:
        m[expected.index(r.swimmer.expected), found.index(r.found)] += 1
    return m


# --- swimmers of the paper's protrusion kind (every cell actuated) -------------------------------------

#: Appendage kinds of :func:`appendage_swimmer`: (rows out of the body, cells per row).
APPENDAGE_KINDS = {"single": (1, 1), "chain2": (2, 1), "chain3": (3, 1), "block2x2": (2, 2), "block3x2": (3, 2)}


def _lattice(i: int, j: int, spacing: float) -> Tuple[float, float]:
    return ((i + 0.5 * (j % 2)) * spacing, j * spacing * math.sqrt(3) / 2)


def appendage_swimmer(
    kind: str = "single",
    core_length: float = 9.0,
    core_width: float = 4.6,
    at: Sequence[float] = (1.5,),
    frequency: float = 8.0,
    appendage_phase: float = math.pi,
    core_jitter: float = 0.3,
    back_shift: float = 0.0,
    anchor_shift: float = 0.0,
    appendage_bend: float = 0.0,
    spacing: float = 1.0,
    seed: int = 0,
    name: Optional[str] = None,
) -> KnownSwimmer:
    """An elliptic body (long axis x) with symmetric pairs of appendages on its flanks (±y), every cell
    actuated as the paper describes its protrusion swimmers (§6, Fig. 6, 7b).

    Every cell oscillates at near-maximal amplitude (``AMPLITUDE`` × uniform 0.9–1.0). The core cells are
    mostly synchronous (phase 0 ± ``core_jitter``/2, uniform; ``back_shift`` adds a phase shift to the
    hindmost line of cells, −x, as in the paper's Fig. 7b); the appendage cells have ``appendage_phase``
    (± the same jitter), chosen so that they are extended on the backward stroke and contracted on the
    return (measured by :func:`animat.protrusion.protrusion_stroke`).

    Args:
        kind: a key of :data:`APPENDAGE_KINDS`: "single" (one cell beyond the outline, the paper's 32-cell
            bests), "chain2"/"chain3" (a chain of cells), "block2x2"/"block3x2" (rows out × cells per row).
        core_length, core_width: the ellipse's axes (spacings).
        at: x positions (along the body) of the appendage pairs; one pair per entry.
    """
    if kind not in APPENDAGE_KINDS:
        raise ValueError(f"appendage_swimmer: kind must be one of {sorted(APPENDAGE_KINDS)}, got {kind!r}")
    rows, width = APPENDAGE_KINDS[kind]
    a, b = core_length / 2, core_width / 2
    ext = int(core_length / spacing) + 4
    core_sites = {
        (i, j)
        for j in range(-ext, ext + 1)
        for i in range(-ext, ext + 1)
        if (_lattice(i, j, spacing)[0] / a) ** 2 + (_lattice(i, j, spacing)[1] / b) ** 2 <= 1.0
    }
    app_sites: List[Tuple[int, int]] = []
    app_of: dict = {}  # site -> (pair, side): which appendage it belongs to
    for p_i, xa in enumerate(at):
        for s in (+1, -1):
            near = [(i, j) for (i, j) in core_sites if abs(_lattice(i, j, spacing)[0] - xa) <= 1.0 * spacing]
            j_top = max(s * j for (_, j) in near) * s
            for k in range(1, rows + 1):
                j = j_top + s * k
                cand = sorted(range(-ext, ext + 1), key=lambda i: (abs(_lattice(i, j, spacing)[0] - xa), i))
                app_sites += [(i, j) for i in cand[:width]]
                for i in cand[:width]:
                    app_of.setdefault((i, j), (p_i, s))
    sites = sorted(core_sites) + [st for st in dict.fromkeys(app_sites) if st not in core_sites]
    groups: dict = {}
    for k, st in enumerate(sites[len(core_sites) :]):
        groups.setdefault(app_of[st], []).append(len(core_sites) + k)
    pos = np.array([_lattice(i, j, spacing) for i, j in sites], dtype=np.float64)
    rng = np.random.default_rng(seed)
    pos += rng.uniform(-0.02, 0.02, pos.shape) * spacing
    n_core = len(core_sites)
    # amplitude and phase jitter drawn per mirror pair of sites ((i, j) and (i, -j)): the actuation is
    # symmetric about the long axis, as the body is
    mirror = {st: k for k, st in enumerate(sorted({(i, abs(j)) for i, j in sites}))}
    draw_amp = AMPLITUDE * rng.uniform(0.9, 1.0, len(mirror))
    draw_phase = rng.uniform(-core_jitter / 2, core_jitter / 2, len(mirror))
    key = np.array([mirror[(i, abs(j))] for i, j in sites])
    amp, phase = draw_amp[key], draw_phase[key].copy()
    if back_shift:
        x = pos[:n_core, 0]
        phase[:n_core][x <= x.min() + 0.6 * spacing] += back_shift
    phase[n_core:] += appendage_phase
    if appendage_bend:  # the hind cells of each appendage row (-x of the row's middle): they bend it back
        rows_of = {}
        for k, (_i, j) in enumerate(sites[n_core:]):
            rows_of.setdefault(j, []).append(n_core + k)
        for members in rows_of.values():
            mid = np.mean(pos[members, 0])
            for k in members:
                if pos[k, 0] < mid - 0.2 * spacing:
                    phase[k] += appendage_bend
    if anchor_shift:  # core cells touching an appendage's first row from behind (-x): they pull it back
        app = pos[n_core:]
        for k in range(n_core):
            d = np.linalg.norm(app - pos[k], axis=1)
            near = np.argmin(d)
            if d[near] <= 1.2 * spacing and pos[k, 0] < app[near, 0] - 0.2 * spacing:
                phase[k] += anchor_shift
    label = name or f"appendages_{kind}_x{len(at)}"
    return _swimmer(
        label,
        "protrusions",
        pos,
        amp,
        frequency,
        phase,
        f"{len(pos)} cells: elliptic core {core_length:g} x {core_width:g} ({n_core} cells, phase 0 "
        f"± {core_jitter / 2:g}"
        + (f", back line +{back_shift:.2f}" if back_shift else "")
        + f"), {len(at)} pair(s) of {kind} appendages at x = {', '.join(f'{v:g}' for v in at)} "
        f"(phase {appendage_phase:.2f}), every cell at amplitude 0.18-0.2, f = {frequency:g}",
        appendages=[groups[key] for key in sorted(groups)],
    )


def standing_swimmer(
    kind: str = "halves",
    length: float = 8.0,
    width: float = 4.0,
    frequency: float = 8.0,
    spacing: float = 1.0,
    seed: int = 0,
    name: Optional[str] = None,
) -> KnownSwimmer:
    """An elliptic body, every cell at full amplitude, with a phase pattern that is neither a travelling
    wave nor synchronous: ``kind="halves"`` (front and back halves in antiphase, a standing pattern) or
    ``kind="random"`` (independent uniform phases). Expected "other"."""
    pos = hex_region(lambda x, y: (x / (length / 2)) ** 2 + (y / (width / 2)) ** 2 <= 1.0, spacing, seed=seed)
    if kind == "halves":
        phase = np.where(pos[:, 0] >= 0, 0.0, math.pi)
    elif kind == "random":
        phase = np.random.default_rng(seed + 100).uniform(0, 2 * math.pi, len(pos))
    else:
        raise ValueError(f"standing_swimmer: kind must be halves or random, got {kind!r}")
    return _swimmer(
        name or f"standing_{kind}",
        "other",
        pos,
        np.full(len(pos), AMPLITUDE),
        frequency,
        phase,
        f"{len(pos)} cells, ellipse {length:g} x {width:g}, phases: {kind}, f = {frequency:g}",
    )


def rowing_phase(
    drags: Sequence[float] = (0.5, 2.0), steps: int = 2000, phases: int = 8, **geometry: Any
) -> Tuple[float, List[Optional[StrokeTruth]]]:
    """The appendage phase (of ``phases`` evenly spaced in [0, 2π)) with which :func:`appendage_swimmer`
    of ``geometry`` (its keyword arguments but the phase; ``anchor_shift`` π unless given) rows best by
    the ground truth (:func:`stroke_truth`): the most drags at which it strokes, then the highest
    worst-appendage rowing. Returns the phase and the truths at ``drags``. The classifier plays no part:
    this is how the held-out protrusion swimmers of :func:`paper_held_out_set` were actuated (the
    phase at which a body rows depends on its size, appendages and frequency through the dynamics, so
    no one phase rows on every geometry)."""
    geometry.setdefault("anchor_shift", math.pi)
    best: Optional[Tuple[Tuple[int, float], float, List[Optional[StrokeTruth]]]] = None
    for k in range(phases):
        phase = 2 * math.pi * k / phases
        s = appendage_swimmer(appendage_phase=phase, **geometry)
        truths: List[Optional[StrokeTruth]] = []
        for dn in drags:
            cfg = animat.Config()
            cfg["scene.drag_normal"] = float(dn)
            cfg["evaluation.steps"] = int(steps)
            tr = replay(s.body(cfg), cfg)
            truths.append(stroke_truth(s, tr) if tr.stable else None)
        ok = [t for t in truths if t is not None]
        key = (
            sum(t.strokes for t in ok),
            min((min(t.rowing) for t in ok), default=-2.0) if len(ok) == len(truths) else -2.0,
        )
        if best is None or key > best[0]:
            best = (key, phase, truths)
    assert best is not None
    return best[1], best[2]


#: The first four sets' whole-body candidates that the undulation truth (:func:`label_by_truth`, at d_N = 0.5
#: and 2; the realised contraction) rejects (in no set), with what fails (d_N = 0.5 / 2) ...
TRUTH_REJECTED = {
    "undulator_contraction": "built undulator that swims 0.18 / 0.09 spacings in 4 periods (< 0.25)",
    "undulator_bend_fast": "built undulator: its contraction lags 0.61 / 0.68 < pi/2 over the body",
}
#: ... and relabels (name -> label by the truth): none.
TRUTH_RELABELLED: dict = {}


def paper_calibration_set() -> List[KnownSwimmer]:
    """Swimmers of every class, the protrusion ones of the paper's kind (:func:`appendage_swimmer`, every
    cell actuated, each performing the stroke by :func:`stroke_truth` at d_N = 0.5 and 2); the stroke
    thresholds of :mod:`animat.protrusion` were set on this set only.

    The second half (from ``paper_single_small`` on) was the first held-out set: its results were seen
    (docs/locomotion.md), so it joined the calibration set and :func:`paper_held_out_set` was built anew.
    Three of its protrusion bodies were dropped, as they do not perform the stroke by the ground truth:
    a single-cell pair on a 10 × 5 core at f = 10 (rows backwards, barely moves), a two-cell chain on a
    10 × 5 core at f = 6 (one chain does not row, the body swims 15–17° off its axis) and a three-cell
    chain on the 9 × 4.6 core (rowing 0.21)."""
    return _by_truth(calibration_candidates(), TRUTH_RELABELLED, TRUTH_REJECTED)


def calibration_candidates() -> List[KnownSwimmer]:
    """Every candidate of :func:`paper_calibration_set` with its built label, before the undulation truth."""
    pi = math.pi
    return [
        appendage_swimmer("single", at=(-1.5,), appendage_phase=pi / 4, anchor_shift=pi, name="paper_single"),
        appendage_swimmer("single", at=(-1.5,), appendage_phase=0.0, anchor_shift=pi, name="paper_single_ph0"),
        appendage_swimmer("chain2", at=(-1.5,), appendage_phase=pi / 4, anchor_shift=pi, name="paper_chain2"),
        appendage_swimmer("chain2", at=(-1.5,), appendage_phase=pi / 2, anchor_shift=pi, name="paper_chain2_ph2"),
        undulator("contraction"),
        undulator("bending"),
        undulator("across", length=6.0, width=5.0, name="undulator_across"),
        synchronous_contractor(),
        synchronous_contractor(lag=1.0),
        tail_swimmer(),
        standing_swimmer("halves"),
        standing_swimmer("random"),
        # the first held-out set, seen
        appendage_swimmer(
            "single",
            core_length=8.0,
            core_width=4.0,
            at=(-1.0,),
            frequency=6.0,
            appendage_phase=pi / 2,
            anchor_shift=pi,
            seed=21,
            name="paper_single_small",
        ),
        appendage_swimmer(
            "single",
            at=(-1.5,),
            frequency=8.0,
            appendage_phase=pi / 4,
            anchor_shift=pi,
            back_shift=pi / 2,
            seed=25,
            name="paper_single_backline",
        ),
        undulator("contraction", length=12.0, width=1.8, frequency=5.0, wavelengths=1.5, seed=3, name="undulator_long"),
        undulator(
            "bending", length=7.0, width=2.6, frequency=11.0, wavelengths=0.75, seed=4, name="undulator_bend_fast"
        ),
        undulator("contraction", length=8.0, width=3.5, frequency=3.0, wavelengths=0.5, seed=5, name="undulator_slow"),
        synchronous_contractor(length=10.0, width=4.0, frequency=5.0, seed=6, name="sync_slender"),
        synchronous_contractor(length=6.0, width=5.5, frequency=11.0, seed=7, name="sync_stubby_fast"),
        synchronous_contractor(length=7.0, width=4.5, frequency=3.0, lag=0.6, seed=8, name="sync_lag_slow"),
        tail_swimmer(length=6, core_radius=2.0, frequency=6.0, wavelengths=0.75, seed=13, name="tail6"),
        tail_swimmer(length=3, core_radius=2.8, frequency=10.0, wavelengths=0.25, seed=14, name="tail3_fast"),
        standing_swimmer("halves", length=10.0, width=3.5, frequency=5.0, seed=26, name="standing_halves_long"),
        standing_swimmer("random", length=7.0, width=5.0, frequency=11.0, seed=27, name="standing_random_fast"),
    ]


#: The held-out protrusion swimmers: geometry chosen before any was swum, appendage phase by
#: :func:`rowing_phase` (the ground truth, not the classifier). Of 12 candidates these 6 stroke at both
#: drags; the other 6 did not at any of 8 phases and are in no set (docs/locomotion.md).
HELD_OUT_APPENDAGES = {
    "ho_single_a": dict(kind="single", core_length=7.0, core_width=3.6, at=(-1.0,), frequency=5.0, seed=41),
    "ho_single_b": dict(kind="single", core_length=11.0, core_width=5.4, at=(-2.5,), frequency=7.0, seed=42),
    "ho_single_e": dict(kind="single", core_length=10.0, core_width=4.4, at=(-2.0,), frequency=9.0, seed=45),
    "ho_chain2_a": dict(kind="chain2", core_length=8.0, core_width=4.0, at=(-1.0,), frequency=5.0, seed=46),
    "ho_chain3_a": dict(kind="chain3", core_length=10.0, core_width=4.4, at=(-1.5,), frequency=6.0, seed=49),
    "ho_block2x2_b": dict(kind="block2x2", core_length=11.0, core_width=5.0, at=(-2.0,), frequency=4.0, seed=52),
}
#: Their phases (in units of π/4) as :func:`rowing_phase` chose them.
HELD_OUT_PHASES = {
    "ho_single_a": 2,
    "ho_single_b": 7,
    "ho_single_e": 2,
    "ho_chain2_a": 2,
    "ho_chain3_a": 2,
    "ho_block2x2_b": 1,
}
#: The candidates that did not stroke at both drags at any phase (rejected by the ground truth).
HELD_OUT_REJECTED = {
    "ho_single_c": dict(kind="single", core_length=9.0, core_width=4.2, at=(-0.5,), frequency=11.0, seed=43),
    "ho_single_d": dict(kind="single", core_length=8.5, core_width=4.8, at=(1.5,), frequency=4.0, seed=44),
    "ho_chain2_b": dict(kind="chain2", core_length=10.0, core_width=4.6, at=(-2.0,), frequency=9.0, seed=47),
    "ho_chain2_c": dict(kind="chain2", core_length=9.0, core_width=5.0, at=(1.0,), frequency=3.0, seed=48),
    "ho_chain3_b": dict(kind="chain3", core_length=8.0, core_width=4.0, at=(-1.0,), frequency=10.0, seed=50),
    "ho_block2x2_a": dict(kind="block2x2", core_length=9.0, core_width=4.6, at=(-1.5,), frequency=7.0, seed=51),
}


def paper_held_out_set() -> List[KnownSwimmer]:
    """A second held-out set, built after the first was seen (which then joined the calibration set):
    other core sizes, appendage lengths (1 to 3 cells, a 2 × 2 block), positions and frequencies 3–11,
    every body chosen before the classifier was run on any of them; not used to set anything."""
    return _by_truth(held_out_candidates(), TRUTH_RELABELLED, TRUTH_REJECTED)


def held_out_candidates() -> List[KnownSwimmer]:
    """Every candidate of :func:`paper_held_out_set` with its built label, before the undulation truth."""
    pi = math.pi
    prot = [
        appendage_swimmer(**g, appendage_phase=HELD_OUT_PHASES[name] * pi / 4, anchor_shift=pi, name=name)
        for name, g in HELD_OUT_APPENDAGES.items()
    ]
    return prot + [
        undulator("contraction", length=10.0, width=2.2, frequency=7.0, wavelengths=1.0, seed=61, name="ho_und_a"),
        undulator("bending", length=8.0, width=3.0, frequency=4.0, wavelengths=1.0, seed=62, name="ho_und_bend"),
        undulator("across", length=5.0, width=6.0, frequency=9.0, seed=63, name="ho_und_across"),
        undulator("contraction", length=9.0, width=3.0, frequency=4.0, wavelengths=0.75, seed=64, name="ho_und_slow"),
        synchronous_contractor(length=9.0, width=4.5, frequency=4.0, seed=65, name="ho_sync_a"),
        synchronous_contractor(length=7.0, width=6.0, frequency=9.0, seed=66, name="ho_sync_b"),
        synchronous_contractor(length=8.0, width=5.0, frequency=6.0, lag=0.8, seed=67, name="ho_sync_lag"),
        tail_swimmer(length=5, core_radius=2.5, frequency=7.0, wavelengths=0.5, seed=68, name="ho_tail5"),
        tail_swimmer(length=4, core_radius=2.2, frequency=4.0, wavelengths=0.6, seed=69, name="ho_tail4_slow"),
        tail_swimmer(length=3, core_radius=2.0, frequency=9.0, wavelengths=0.4, seed=70, name="ho_tail3"),
        standing_swimmer("halves", length=9.0, width=4.5, frequency=7.0, seed=71, name="ho_standing_halves"),
        standing_swimmer("random", length=8.0, width=4.0, frequency=4.0, seed=72, name="ho_standing_random"),
        standing_swimmer("random", length=10.0, width=5.0, frequency=9.0, seed=73, name="ho_standing_random_big"),
        standing_swimmer("halves", length=7.0, width=3.8, frequency=10.0, seed=74, name="ho_standing_halves_fast"),
    ]


#: The third held-out set's protrusion swimmers: 12 candidate geometries chosen before any was swum (cores
#: 7.5 × 4.4 to 11 × 5.2, one-cell appendages, one with two pairs, two- and three-cell chains and 2 × 2
#: blocks, at x = −2.5 to −0.5, f = 4–10), each actuated by :func:`rowing_phase` (the ground truth, not
#: the classifier). These 7 stroke at both drags; the other 5 are in no set (:data:`THIRD_REJECTED`).
THIRD_APPENDAGES = {
    "h3_single_a": dict(kind="single", core_length=8.0, core_width=4.2, at=(-1.5,), frequency=6.0, seed=101),
    "h3_single_b": dict(kind="single", core_length=10.5, core_width=5.0, at=(-2.0,), frequency=8.0, seed=102),
    "h3_single_c": dict(kind="single", core_length=9.5, core_width=4.0, at=(-1.0,), frequency=4.0, seed=103),
    "h3_single_2pairs": dict(kind="single", core_length=11.0, core_width=5.0, at=(-2.5, 0.5), frequency=6.0, seed=112),
    "h3_chain2_a": dict(kind="chain2", core_length=9.0, core_width=4.4, at=(-1.5,), frequency=7.0, seed=105),
    "h3_chain3_a": dict(kind="chain3", core_length=9.5, core_width=4.8, at=(-2.0,), frequency=5.0, seed=108),
    "h3_chain3_b": dict(kind="chain3", core_length=11.0, core_width=5.0, at=(-1.5,), frequency=7.0, seed=109),
}
#: Their phases (in units of π/4) as :func:`rowing_phase` chose them.
THIRD_PHASES = {
    "h3_single_a": 7,
    "h3_single_b": 7,
    "h3_single_c": 1,
    "h3_single_2pairs": 7,
    "h3_chain2_a": 3,
    "h3_chain3_a": 2,
    "h3_chain3_b": 7,
}
#: The candidates that did not stroke at both drags at any phase (rejected by the ground truth): at their
#: best phase a one-cell pair near the middle at f = 10 rows backwards at d_N = 0.5 (−0.86); a two-cell
#: chain pair at f = 4.5 rows 0.39 at d_N = 2; a two-cell chain pair at f = 9 rows backwards and swims
#: 44° off its axis at d_N = 0.5; the two 2 × 2 blocks row at most 0.07.
THIRD_REJECTED = {
    "h3_single_d": dict(kind="single", core_length=7.5, core_width=4.4, at=(-0.5,), frequency=10.0, seed=104),
    "h3_chain2_b": dict(kind="chain2", core_length=11.0, core_width=5.2, at=(-2.5,), frequency=4.5, seed=106),
    "h3_chain2_c": dict(kind="chain2", core_length=8.5, core_width=4.0, at=(-1.0,), frequency=9.0, seed=107),
    "h3_block2x2_a": dict(kind="block2x2", core_length=10.0, core_width=4.8, at=(-1.5,), frequency=5.0, seed=110),
    "h3_block2x2_b": dict(kind="block2x2", core_length=9.0, core_width=5.2, at=(-2.0,), frequency=8.0, seed=111),
}


def paper_third_set() -> List[KnownSwimmer]:
    """The third held-out set, built after the bending-wave rule (``animat.locomotion.bending_wave``) was
    fixed on the two earlier sets: undulators of four kinds (three bending ones), synchronous
    contractors, protrusion swimmers of the paper's kind that stroke by the ground truth, tails and
    standing swimmers, all of other sizes, seeds and frequencies 3–11; every body chosen before the
    classifier was run on any of them, which was done once (docs/locomotion.md). Sets nothing."""
    return _by_truth(third_set_candidates(), TRUTH_RELABELLED, TRUTH_REJECTED)


def third_set_candidates() -> List[KnownSwimmer]:
    """Every candidate of :func:`paper_third_set` with its built label, before the undulation truth."""
    pi = math.pi
    prot = [
        appendage_swimmer(**g, appendage_phase=THIRD_PHASES[name] * pi / 4, anchor_shift=pi, name=name)
        for name, g in THIRD_APPENDAGES.items()
    ]
    return prot + [
        undulator("contraction", length=11.0, width=2.6, frequency=6.0, wavelengths=1.25, seed=81, name="h3_und_a"),
        undulator("bending", length=9.0, width=2.2, frequency=6.0, wavelengths=1.0, seed=82, name="h3_und_bend_a"),
        undulator("bending", length=10.0, width=3.4, frequency=9.0, wavelengths=0.75, seed=83, name="h3_und_bend_b"),
        undulator("bending", length=12.0, width=2.6, frequency=3.5, wavelengths=1.5, seed=84, name="h3_und_bend_c"),
        undulator("across", length=6.0, width=7.0, frequency=5.0, seed=85, name="h3_und_across"),
        undulator("contraction", length=7.0, width=3.0, frequency=3.0, wavelengths=0.6, seed=86, name="h3_und_slow"),
        synchronous_contractor(length=11.0, width=4.2, frequency=7.0, seed=87, name="h3_sync_a"),
        synchronous_contractor(length=6.5, width=5.0, frequency=4.0, seed=88, name="h3_sync_b"),
        synchronous_contractor(length=9.0, width=5.5, frequency=10.0, lag=0.7, seed=89, name="h3_sync_lag"),
        tail_swimmer(length=4, core_radius=2.6, frequency=5.0, wavelengths=0.5, seed=90, name="h3_tail4"),
        tail_swimmer(length=5, core_radius=2.2, frequency=10.0, wavelengths=0.4, seed=91, name="h3_tail5_fast"),
        tail_swimmer(length=3, core_radius=2.4, frequency=6.0, wavelengths=0.6, seed=92, name="h3_tail3"),
        standing_swimmer("halves", length=11.0, width=4.0, frequency=6.0, seed=93, name="h3_standing_halves"),
        standing_swimmer("random", length=9.0, width=4.5, frequency=6.0, seed=94, name="h3_standing_random"),
        standing_swimmer("random", length=6.0, width=4.5, frequency=3.5, seed=95, name="h3_standing_random_slow"),
        standing_swimmer("halves", length=8.0, width=5.0, frequency=11.0, seed=96, name="h3_standing_halves_fast"),
    ]


#: The fourth held-out set's protrusion swimmers, built after the permutation test of the bending fit
#: (``animat.locomotion.BEND_P``) was fixed: 18 candidate geometries chosen before any was swum, in two
#: batches of 12 and 6 (the first gave only 4 bodies that stroke; cores 7 × 3.8 to 12 × 5.6, one-cell
#: appendages, two bodies with two pairs, two- and three-cell chains, 2 × 2 blocks, at x = −3 to −1,
#: f = 3.5–10), each actuated by :func:`rowing_phase` (the ground truth, not the classifier). These 7
#: stroke at both drags; the other 11 are in no set (:data:`FOURTH_REJECTED`).
FOURTH_APPENDAGES = {
    "h4_single_d": dict(kind="single", core_length=10.0, core_width=4.6, at=(-1.5,), frequency=3.5, seed=204),
    "h4_single_e": dict(kind="single", core_length=8.5, core_width=4.4, at=(-1.5,), frequency=6.5, seed=213),
    "h4_single_f": dict(kind="single", core_length=11.0, core_width=4.8, at=(-2.0,), frequency=4.5, seed=214),
    "h4_single_2pairs": dict(kind="single", core_length=12.0, core_width=5.2, at=(-3.0, 0.0), frequency=7.0, seed=205),
    "h4_single_2pairs_b": dict(
        kind="single", core_length=10.0, core_width=4.6, at=(-2.5, 0.5), frequency=5.0, seed=218
    ),
    "h4_chain2_b": dict(kind="chain2", core_length=8.0, core_width=4.2, at=(-1.5,), frequency=5.0, seed=207),
    "h4_chain3_a": dict(kind="chain3", core_length=10.0, core_width=4.6, at=(-2.5,), frequency=6.0, seed=209),
}
#: Their phases (in units of π/4) as :func:`rowing_phase` chose them.
FOURTH_PHASES = {
    "h4_single_d": 2,
    "h4_single_e": 7,
    "h4_single_f": 0,
    "h4_single_2pairs": 7,
    "h4_single_2pairs_b": 1,
    "h4_chain2_b": 3,
    "h4_chain3_a": 2,
}
#: The candidates that did not stroke at both drags at any phase (rejected by the ground truth), with what
#: fails at their best phase (d_N = 0.5; d_N = 2): a one-cell pair on 9 × 4 at f = 5.5 (swims 0.20 < 0.25 at
#: d_N = 2), a one-cell pair on 12 × 5.6 at f = 7.5 (rowing 0.47, 30–34° off its axis), a one-cell pair on
#: 7 × 3.8 at f = 8.5 (moves towards its appendages), two-cell chains at f = 6.5 (rowing 0.39 at d_N = 2),
#: f = 10 (rowing 0.01 at d_N = 0.5), f = 4 (rowing 0.31–0.33, towards its appendages) and f = 7 (rowing
#: 0.04–0.06), three-cell chains at f = 8 (rowing ≈ 0) and f = 4.5 (swims 0.19 at d_N = 0.5), and both
#: 2 × 2 blocks (rowing −0.33 to 0.13).
FOURTH_REJECTED = {
    "h4_single_a": dict(kind="single", core_length=9.0, core_width=4.0, at=(-2.0,), frequency=5.5, seed=201),
    "h4_single_b": dict(kind="single", core_length=12.0, core_width=5.6, at=(-3.0,), frequency=7.5, seed=202),
    "h4_single_c": dict(kind="single", core_length=7.0, core_width=3.8, at=(-1.0,), frequency=8.5, seed=203),
    "h4_chain2_a": dict(kind="chain2", core_length=10.5, core_width=4.8, at=(-2.0,), frequency=6.5, seed=206),
    "h4_chain2_c": dict(kind="chain2", core_length=11.5, core_width=5.0, at=(-2.5,), frequency=10.0, seed=208),
    "h4_chain2_d": dict(kind="chain2", core_length=9.5, core_width=4.2, at=(-2.0,), frequency=4.0, seed=215),
    "h4_chain2_e": dict(kind="chain2", core_length=12.0, core_width=5.0, at=(-2.5,), frequency=7.0, seed=216),
    "h4_chain3_b": dict(kind="chain3", core_length=12.0, core_width=5.4, at=(-2.0,), frequency=8.0, seed=210),
    "h4_chain3_c": dict(kind="chain3", core_length=9.0, core_width=4.4, at=(-1.5,), frequency=4.5, seed=217),
    "h4_block2x2_a": dict(kind="block2x2", core_length=11.0, core_width=5.0, at=(-2.5,), frequency=6.0, seed=211),
    "h4_block2x2_b": dict(kind="block2x2", core_length=9.5, core_width=4.4, at=(-1.5,), frequency=9.0, seed=212),
}


def paper_fourth_set() -> List[KnownSwimmer]:
    """The fourth held-out set, built after the permutation test of the bending fit was fixed on the three
    earlier sets (all calibration now): undulators (two contraction waves, three bending undulators, one
    of them short with few springs, a wave across), synchronous contractors, protrusion swimmers of the
    paper's kind that stroke by the ground truth, tails, and standing swimmers, five of them with random
    phases (the bending wave's weak spot), all of new sizes, seeds and frequencies 3–11; every body chosen
    before the classifier was run on any of them, which was done once (docs/locomotion.md). Sets nothing."""
    return _by_truth(fourth_set_candidates(), TRUTH_RELABELLED, TRUTH_REJECTED)


def fourth_set_candidates() -> List[KnownSwimmer]:
    """Every candidate of :func:`paper_fourth_set` with its built label, before the undulation truth."""
    pi = math.pi
    prot = [
        appendage_swimmer(**g, appendage_phase=FOURTH_PHASES[name] * pi / 4, anchor_shift=pi, name=name)
        for name, g in FOURTH_APPENDAGES.items()
    ]
    return prot + [
        undulator("contraction", length=10.0, width=2.4, frequency=8.0, wavelengths=1.0, seed=121, name="h4_und_a"),
        undulator("contraction", length=13.0, width=2.0, frequency=4.5, wavelengths=2.0, seed=122, name="h4_und_b"),
        undulator("bending", length=8.5, width=2.4, frequency=7.0, wavelengths=1.0, seed=123, name="h4_und_bend_a"),
        undulator("bending", length=11.0, width=3.0, frequency=5.0, wavelengths=1.25, seed=124, name="h4_und_bend_b"),
        undulator("bending", length=7.5, width=2.8, frequency=10.0, wavelengths=0.8, seed=125, name="h4_und_bend_c"),
        undulator("across", length=5.5, width=6.5, frequency=7.0, seed=126, name="h4_und_across"),
        synchronous_contractor(length=10.0, width=4.8, frequency=5.0, seed=127, name="h4_sync_a"),
        synchronous_contractor(length=7.5, width=5.5, frequency=9.0, seed=128, name="h4_sync_b"),
        synchronous_contractor(length=8.5, width=4.4, frequency=3.5, lag=0.5, seed=129, name="h4_sync_lag"),
        tail_swimmer(length=4, core_radius=2.4, frequency=8.0, wavelengths=0.5, seed=130, name="h4_tail4"),
        tail_swimmer(length=5, core_radius=2.6, frequency=4.0, wavelengths=0.7, seed=131, name="h4_tail5_slow"),
        tail_swimmer(length=3, core_radius=2.2, frequency=11.0, wavelengths=0.3, seed=132, name="h4_tail3_fast"),
        standing_swimmer("random", length=8.0, width=4.0, frequency=5.0, seed=133, name="h4_standing_random_a"),
        standing_swimmer("random", length=10.0, width=4.4, frequency=8.0, seed=134, name="h4_standing_random_b"),
        standing_swimmer("random", length=7.0, width=3.6, frequency=4.0, seed=135, name="h4_standing_random_c"),
        standing_swimmer("random", length=11.0, width=5.0, frequency=10.0, seed=136, name="h4_standing_random_d"),
        standing_swimmer("random", length=9.0, width=3.6, frequency=3.0, seed=137, name="h4_standing_random_e"),
        standing_swimmer("halves", length=9.5, width=4.2, frequency=7.0, seed=138, name="h4_standing_halves"),
        standing_swimmer("halves", length=7.5, width=4.6, frequency=4.5, seed=139, name="h4_standing_halves_b"),
    ]


#: The fifth held-out set's protrusion swimmers, built after the extension along the protrusion's axis
#: (``animat.protrusion.cell_strokes``), the backward bending wave (``animat.locomotion.BEND_BACKWARD``)
#: and the undulation truth were fixed on the four seen sets: 12 candidate geometries chosen before any was
#: swum (cores 8 × 4 to 11.5 × 5.2; one-cell appendages, one body with two pairs, four two-cell and four
#: three-cell chains (the weak spot), a 2 × 2 block; at x = −2.5 to −1, f = 4–7.5), each actuated by
#: :func:`rowing_phase` (the ground truth, not the classifier). These 9 stroke at both drags; the other 3
#: are in no set (:data:`FIFTH_REJECTED`).
FIFTH_APPENDAGES = {
    "h5_single_a": dict(kind="single", core_length=9.0, core_width=4.4, at=(-1.5,), frequency=5.5, seed=301),
    "h5_single_b": dict(kind="single", core_length=11.5, core_width=5.2, at=(-2.5,), frequency=6.0, seed=302),
    "h5_single_2pairs": dict(kind="single", core_length=11.0, core_width=5.0, at=(-2.5, 0.5), frequency=4.5, seed=303),
    "h5_chain2_a": dict(kind="chain2", core_length=8.5, core_width=4.2, at=(-1.5,), frequency=6.0, seed=304),
    "h5_chain2_b": dict(kind="chain2", core_length=9.5, core_width=4.6, at=(-2.0,), frequency=4.5, seed=305),
    "h5_chain3_a": dict(kind="chain3", core_length=10.5, core_width=4.8, at=(-2.0,), frequency=5.5, seed=308),
    "h5_chain3_b": dict(kind="chain3", core_length=9.0, core_width=4.2, at=(-1.5,), frequency=6.5, seed=309),
    "h5_chain3_d": dict(kind="chain3", core_length=10.0, core_width=4.4, at=(-2.0,), frequency=7.0, seed=311),
    "h5_block2x2_a": dict(kind="block2x2", core_length=10.5, core_width=5.0, at=(-2.0,), frequency=5.0, seed=312),
}
#: Their phases (in units of π/4) as :func:`rowing_phase` chose them.
FIFTH_PHASES = {
    "h5_single_a": 0,
    "h5_single_b": 1,
    "h5_single_2pairs": 0,
    "h5_chain2_a": 2,
    "h5_chain2_b": 7,
    "h5_chain3_a": 1,
    "h5_chain3_b": 2,
    "h5_chain3_d": 3,
    "h5_block2x2_a": 3,
}
#: The candidates that did not stroke at both drags at any phase, with what fails at their best phase
#: (d_N = 0.5 / 2): a two-cell chain pair at f = 5.5 (rowing 0.29 / 0.26), a two-cell chain pair at f = 7.5
#: (swims 0.23 < 0.25 at d_N = 2) and a three-cell chain pair at f = 4 (rowing 0.45 at d_N = 0.5).
FIFTH_REJECTED = {
    "h5_chain2_c": dict(kind="chain2", core_length=10.5, core_width=4.8, at=(-2.0,), frequency=5.5, seed=306),
    "h5_chain2_d": dict(kind="chain2", core_length=8.0, core_width=4.0, at=(-1.0,), frequency=7.5, seed=307),
    "h5_chain3_c": dict(kind="chain3", core_length=11.0, core_width=5.0, at=(-2.5,), frequency=4.0, seed=310),
}
#: The fifth set's whole-body candidates that the undulation truth (:func:`label_by_truth`) rejects, with
#: what fails (d_N = 0.5 / 2) ...
FIFTH_TRUTH_REJECTED = {
    "h5_und_bend_a": "built undulator: contraction lag 0.84 < pi/2 at d_N = 0.5 (undulates at d_N = 2)",
    "h5_und_across": "built undulator: swims 0.09 spacings at d_N = 2",
    "h5_standing_random_d": "random phases: undulates at d_N = 0.5 (lag 1.89, coherence 0.51), not at d_N = 2 (lag 1.54)",
}
#: ... and relabels (name -> label by the truth): none.
FIFTH_RELABELLED: dict = {}


def fifth_set_candidates() -> List[KnownSwimmer]:
    """Every candidate of the fifth set with its built label, before the truths (the protrusion candidates at
    their :data:`FIFTH_PHASES` phase; the rejected ones of :data:`FIFTH_REJECTED` are not built)."""
    pi = math.pi
    prot = [
        appendage_swimmer(**g, appendage_phase=FIFTH_PHASES[name] * pi / 4, anchor_shift=pi, name=name)
        for name, g in FIFTH_APPENDAGES.items()
    ]
    return prot + [
        undulator("contraction", length=11.0, width=2.2, frequency=6.5, wavelengths=1.0, seed=321, name="h5_und_a"),
        undulator("contraction", length=9.5, width=2.6, frequency=9.0, wavelengths=1.5, seed=322, name="h5_und_b"),
        undulator("contraction", length=12.0, width=2.4, frequency=5.0, wavelengths=1.25, seed=344, name="h5_und_c"),
        undulator("bending", length=10.0, width=2.6, frequency=4.0, wavelengths=1.0, seed=323, name="h5_und_bend_a"),
        undulator("bending", length=9.0, width=2.4, frequency=8.5, wavelengths=1.25, seed=324, name="h5_und_bend_b"),
        undulator("bending", length=12.0, width=3.2, frequency=6.0, wavelengths=1.0, seed=325, name="h5_und_bend_c"),
        undulator("bending", length=8.0, width=2.2, frequency=5.5, wavelengths=1.0, seed=343, name="h5_und_bend_d"),
        undulator("across", length=6.5, width=7.5, frequency=4.5, seed=326, name="h5_und_across"),
        synchronous_contractor(length=9.5, width=5.0, frequency=6.5, seed=327, name="h5_sync_a"),
        synchronous_contractor(length=8.0, width=6.0, frequency=3.0, seed=328, name="h5_sync_b"),
        synchronous_contractor(length=7.0, width=5.2, frequency=8.0, seed=345, name="h5_sync_c"),
        synchronous_contractor(length=11.0, width=4.6, frequency=10.5, lag=0.3, seed=329, name="h5_sync_lag"),
        tail_swimmer(length=4, core_radius=2.3, frequency=6.5, wavelengths=0.55, seed=330, name="h5_tail4"),
        tail_swimmer(length=5, core_radius=2.0, frequency=9.5, wavelengths=0.45, seed=331, name="h5_tail5"),
        tail_swimmer(length=3, core_radius=2.7, frequency=3.5, wavelengths=0.65, seed=332, name="h5_tail3_slow"),
        standing_swimmer("random", length=8.5, width=3.8, frequency=6.5, seed=333, name="h5_standing_random_a"),
        standing_swimmer("random", length=10.5, width=4.2, frequency=3.5, seed=334, name="h5_standing_random_b"),
        standing_swimmer("random", length=7.5, width=4.0, frequency=9.0, seed=335, name="h5_standing_random_c"),
        standing_swimmer("random", length=12.0, width=4.8, frequency=5.5, seed=336, name="h5_standing_random_d"),
        standing_swimmer("random", length=9.5, width=3.4, frequency=4.5, seed=337, name="h5_standing_random_e"),
        standing_swimmer("random", length=8.0, width=3.4, frequency=5.0, seed=340, name="h5_standing_random_f"),
        standing_swimmer("random", length=11.0, width=4.4, frequency=7.5, seed=341, name="h5_standing_random_g"),
        standing_swimmer("random", length=9.0, width=4.0, frequency=10.0, seed=342, name="h5_standing_random_h"),
        standing_swimmer("halves", length=10.0, width=4.6, frequency=8.5, seed=338, name="h5_standing_halves"),
        standing_swimmer("halves", length=8.0, width=3.6, frequency=3.5, seed=339, name="h5_standing_halves_b"),
    ]


def paper_fifth_set() -> List[KnownSwimmer]:
    """The fifth held-out set: :func:`fifth_set_candidates` labelled by the ground truths (the protrusion
    bodies stroke at both drags by :func:`stroke_truth`; the whole-body ones are labelled by
    :func:`undulation_truth`, :data:`FIFTH_TRUTH_REJECTED` dropped, :data:`FIFTH_RELABELLED` relabelled),
    all of new sizes, seeds and frequencies 3–10.5, six of them random-phase bodies and six chain or
    block appendage pairs (the weak spots); fixed before the classifier was run on any of them, which is
    done once (docs/locomotion.md). Sets nothing."""
    return _by_truth(fifth_set_candidates(), FIFTH_RELABELLED, FIFTH_TRUTH_REJECTED)


#: The sixth held-out set's appendage candidates that stroke at both drags by :func:`stroke_truth` (with
#: :data:`SIXTH_PHASES`), weighted toward multi-cell appendages: two one-cell pairs, three two-cell and four
#: three-cell chain pairs, two 2 × 2 block pairs; new cores, seeds and frequencies.
SIXTH_APPENDAGES = {
    "h6_single_a": dict(kind="single", core_length=9.5, core_width=4.6, at=(-2.0,), frequency=6.5, seed=401),
    "h6_single_b": dict(kind="single", core_length=10.5, core_width=5.0, at=(-1.0,), frequency=4.0, seed=402),
    "h6_chain2_b": dict(kind="chain2", core_length=10.0, core_width=4.8, at=(-1.5,), frequency=7.0, seed=404),
    "h6_chain2_d": dict(kind="chain2", core_length=8.5, core_width=4.0, at=(-1.0,), frequency=6.0, seed=406),
    "h6_chain2_e": dict(kind="chain2", core_length=12.0, core_width=5.0, at=(-3.0,), frequency=5.5, seed=407),
    "h6_chain3_a": dict(kind="chain3", core_length=9.5, core_width=4.4, at=(-1.5,), frequency=5.0, seed=408),
    "h6_chain3_b": dict(kind="chain3", core_length=11.0, core_width=4.6, at=(-2.5,), frequency=6.0, seed=409),
    "h6_chain3_c": dict(kind="chain3", core_length=10.0, core_width=5.0, at=(-2.0,), frequency=4.0, seed=410),
    "h6_chain3_g": dict(kind="chain3", core_length=11.5, core_width=5.0, at=(-2.5,), frequency=4.5, seed=422),
    "h6_block2x2_a": dict(kind="block2x2", core_length=10.0, core_width=4.8, at=(-2.0,), frequency=4.5, seed=413),
    "h6_block2x2_f": dict(kind="block2x2", core_length=11.0, core_width=5.4, at=(-2.0,), frequency=3.5, seed=418),
}
#: Their appendage phases (× π/4) by :func:`rowing_phase` (the ground truth; the classifier plays no part).
SIXTH_PHASES = {
    "h6_single_a": 7,
    "h6_single_b": 1,
    "h6_chain2_b": 2,
    "h6_chain2_d": 1,
    "h6_chain2_e": 2,
    "h6_chain3_a": 2,
    "h6_chain3_b": 2,
    "h6_chain3_c": 2,
    "h6_chain3_g": 3,
    "h6_block2x2_a": 3,
    "h6_block2x2_f": 1,
}
#: Candidates that do not stroke at both drags with any of the 8 phases (best phase's truth): in no set.
SIXTH_REJECTED = {
    "h6_chain2_a": "rowing 0.07 / 0.24, moves towards its appendages",
    "h6_chain2_c": "rowing 0.50 / 0.48 < 0.5 at d_N = 2",
    "h6_chain3_d": "rowing -0.11 / -0.22",
    "h6_chain3_e": "rowing 0.09 < 0.5 at d_N = 0.5",
    "h6_chain3_f": "swims 0.24 < 0.25 spacings",
    "h6_block2x2_b": "moves towards its appendages; swims 0.22 spacings",
    "h6_block2x2_c": "rowing -0.16 / -0.37",
    "h6_block2x2_d": "rowing 0.11 / 0.02",
    "h6_block2x2_e": "rowing 0.19 / -0.16, swims 0.06 spacings",
    "h6_block2x2_g": "rowing 0.30 / 0.46, moves towards its appendages",
    "h6_block2x2_h": "rowing -0.05 / -0.12, 45-67 deg off its axis",
}
#: Whole-body candidates the undulation truth rejects (:func:`label_by_truth`, d_N = 0.5 and 2).
SIXTH_TRUTH_REJECTED = {
    "h6_und_c": "built undulator: swims 0.20 / 0.05 spacings",
    "h6_standing_random_e": "random phases: undulates at d_N = 2 (lag 9.66, coherence 0.53), not at d_N = 0.5",
}
#: ... and relabels: none.
SIXTH_RELABELLED: dict = {}


def sixth_set_candidates() -> List[KnownSwimmer]:
    """Every candidate of the sixth set with its built label, before the truths (the protrusion candidates at
    their :data:`SIXTH_PHASES` phase; the rejected ones of :data:`SIXTH_REJECTED` are not built)."""
    pi = math.pi
    prot = [
        appendage_swimmer(**g, appendage_phase=SIXTH_PHASES[name] * pi / 4, anchor_shift=pi, name=name)
        for name, g in SIXTH_APPENDAGES.items()
    ]
    return prot + [
        undulator("contraction", length=10.5, width=2.4, frequency=7.5, wavelengths=1.25, seed=431, name="h6_und_a"),
        undulator("contraction", length=12.5, width=2.6, frequency=4.5, wavelengths=1.5, seed=432, name="h6_und_b"),
        undulator("contraction", length=9.0, width=2.2, frequency=8.0, wavelengths=1.0, seed=433, name="h6_und_c"),
        undulator("bending", length=11.0, width=2.8, frequency=5.0, wavelengths=1.0, seed=434, name="h6_und_bend_a"),
        undulator("bending", length=9.5, width=2.4, frequency=7.0, wavelengths=1.25, seed=435, name="h6_und_bend_b"),
        undulator("bending", length=12.5, width=3.0, frequency=4.5, wavelengths=1.0, seed=436, name="h6_und_bend_c"),
        synchronous_contractor(length=9.0, width=5.4, frequency=5.0, seed=437, name="h6_sync_a"),
        synchronous_contractor(length=7.5, width=5.6, frequency=9.5, seed=438, name="h6_sync_b"),
        synchronous_contractor(length=10.5, width=4.8, frequency=4.0, seed=439, name="h6_sync_c"),
        tail_swimmer(length=4, core_radius=2.5, frequency=5.0, wavelengths=0.5, seed=440, name="h6_tail4"),
        tail_swimmer(length=5, core_radius=2.2, frequency=7.5, wavelengths=0.6, seed=441, name="h6_tail5"),
        tail_swimmer(length=3, core_radius=2.4, frequency=10.0, wavelengths=0.4, seed=442, name="h6_tail3_fast"),
        standing_swimmer("random", length=9.0, width=4.2, frequency=5.0, seed=443, name="h6_standing_random_a"),
        standing_swimmer("random", length=11.5, width=4.6, frequency=4.0, seed=444, name="h6_standing_random_b"),
        standing_swimmer("random", length=8.0, width=3.6, frequency=8.5, seed=445, name="h6_standing_random_c"),
        standing_swimmer("random", length=10.0, width=3.8, frequency=6.0, seed=446, name="h6_standing_random_d"),
        standing_swimmer("random", length=12.5, width=5.0, frequency=3.0, seed=447, name="h6_standing_random_e"),
        standing_swimmer("random", length=8.5, width=4.4, frequency=7.0, seed=448, name="h6_standing_random_f"),
        standing_swimmer("random", length=10.5, width=4.0, frequency=9.5, seed=449, name="h6_standing_random_g"),
        standing_swimmer("halves", length=9.5, width=4.2, frequency=6.0, seed=450, name="h6_standing_halves"),
    ]


def paper_sixth_set() -> List[KnownSwimmer]:
    """The sixth held-out set: :func:`sixth_set_candidates` labelled by the ground truths (the protrusion
    bodies stroke at both drags by :func:`stroke_truth`; the whole-body ones are labelled by
    :func:`undulation_truth`, :data:`SIXTH_TRUTH_REJECTED` dropped, :data:`SIXTH_RELABELLED` relabelled), all
    of new sizes, seeds and frequencies 3–10, weighted toward multi-cell appendages (nine of the eleven
    protrusion bodies are chains or blocks) and random-phase bodies (seven candidates); fixed before the
    classifier was run on any of them, which is done once (docs/locomotion.md). Sets nothing."""
    return _by_truth(sixth_set_candidates(), SIXTH_RELABELLED, SIXTH_TRUTH_REJECTED)


#: The seventh held-out set's appendage candidates that stroke at both drags by :func:`stroke_truth` (with
#: :data:`SEVENTH_PHASES`): built after the extension across the motion and the growth of protrusions by
#: their loops (``animat.protrusion.grow_protrusions``) were fixed on the six sets above, weighted toward
#: three-cell chains and 2 × 2 blocks (12 and 11 of the 28 candidates; seeds 501-560, reused only for other
#: geometries); two one-cell pairs, three two-cell chain pairs, one three-cell chain pair and four block
#: pairs stroke at both drags.
SEVENTH_APPENDAGES = {
    "h7_single_a": dict(kind="single", core_length=9.0, core_width=4.8, at=(-1.5,), frequency=5.0, seed=501),
    "h7_single_b": dict(kind="single", core_length=10.0, core_width=4.4, at=(-2.0,), frequency=7.0, seed=502),
    "h7_chain2_a": dict(kind="chain2", core_length=9.5, core_width=4.4, at=(-1.5,), frequency=5.0, seed=503),
    "h7_chain2_b": dict(kind="chain2", core_length=11.0, core_width=5.2, at=(-2.5,), frequency=6.5, seed=504),
    "h7_chain2_c": dict(kind="chain2", core_length=8.5, core_width=4.2, at=(-1.0,), frequency=4.0, seed=505),
    "h7_chain3_f": dict(kind="chain3", core_length=9.5, core_width=4.8, at=(-2.0,), frequency=7.5, seed=511),
    "h7_block2x2_a": dict(kind="block2x2", core_length=10.5, core_width=5.2, at=(-2.0,), frequency=4.0, seed=513),
    "h7_block2x2_g": dict(kind="block2x2", core_length=12.5, core_width=5.2, at=(-3.0,), frequency=5.5, seed=519),
    "h7_block2x2_h": dict(kind="block2x2", core_length=10.5, core_width=4.4, at=(-2.0,), frequency=5.0, seed=520),
    "h7_block2x2_j": dict(kind="block2x2", core_length=13.0, core_width=5.4, at=(-3.0,), frequency=4.0, seed=549),
}
#: Their appendage phases (× π/4) by :func:`rowing_phase` (the ground truth; the classifier plays no part).
SEVENTH_PHASES = {
    "h7_single_a": 1,
    "h7_single_b": 7,
    "h7_chain2_a": 2,
    "h7_chain2_b": 1,
    "h7_chain2_c": 1,
    "h7_chain3_f": 2,
    "h7_block2x2_a": 7,
    "h7_block2x2_g": 2,
    "h7_block2x2_h": 1,
    "h7_block2x2_j": 1,
}
#: Candidates that do not stroke at both drags with any of the 8 phases: their geometry and what fails at
#: their best phase (d_N = 0.5 / 2). In no set.
SEVENTH_REJECTED = {
    "h7_chain3_a": (
        dict(kind="chain3", core_length=10.5, core_width=4.6, at=(-2.0,), frequency=4.5, seed=506),
        "rowing 0.49 < 0.5 / strokes",
    ),
    "h7_chain3_b": (
        dict(kind="chain3", core_length=9.0, core_width=4.0, at=(-1.5,), frequency=5.5, seed=507),
        "strokes / rowing 0.41",
    ),
    "h7_chain3_c": (
        dict(kind="chain3", core_length=11.5, core_width=5.4, at=(-2.5,), frequency=6.5, seed=508),
        "rowing 0.08, swims 0.11 spacings / rowing 0.15, moves towards its appendages",
    ),
    "h7_chain3_d": (
        dict(kind="chain3", core_length=10.0, core_width=4.2, at=(-1.5,), frequency=3.5, seed=509),
        "strokes / rowing 0.29",
    ),
    "h7_chain3_e": (
        dict(kind="chain3", core_length=12.0, core_width=5.0, at=(-3.0,), frequency=5.0, seed=510),
        "rowing 0.02 / strokes",
    ),
    "h7_chain3_g": (
        dict(kind="chain3", core_length=11.0, core_width=4.4, at=(-2.0,), frequency=6.0, seed=512),
        "strokes / rowing 0.13",
    ),
    "h7_chain3_h": (
        dict(kind="chain3", core_length=12.5, core_width=5.6, at=(-2.5,), frequency=4.0, seed=547),
        "strokes / rowing 0.00, swims 0.06 spacings",
    ),
    "h7_chain3_i": (
        dict(kind="chain3", core_length=10.0, core_width=4.6, at=(-1.5,), frequency=5.0, seed=560),
        "strokes / rowing 0.36",
    ),
    "h7_chain3_j": (
        dict(kind="chain3", core_length=11.0, core_width=5.0, at=(-2.0,), frequency=4.0, seed=507),
        "strokes / rowing -0.49, moves towards its appendages",
    ),
    "h7_chain3_k": (
        dict(kind="chain3", core_length=9.5, core_width=4.4, at=(-1.0,), frequency=6.5, seed=509),
        "rowing 0.19 / strokes",
    ),
    "h7_chain3_l": (
        dict(kind="chain3", core_length=12.0, core_width=5.4, at=(-2.5,), frequency=5.5, seed=512),
        "rowing 0.13 / rowing 0.11, swims 0.14 spacings",
    ),
    "h7_block2x2_b": (
        dict(kind="block2x2", core_length=11.5, core_width=5.0, at=(-2.5,), frequency=5.0, seed=514),
        "rowing 0.45, 39 deg off its axis / rowing 0.47, swims 0.17 spacings",
    ),
    "h7_block2x2_c": (
        dict(kind="block2x2", core_length=9.5, core_width=4.6, at=(-1.5,), frequency=3.5, seed=515),
        "moves towards its appendages at both drags",
    ),
    "h7_block2x2_d": (
        dict(kind="block2x2", core_length=12.0, core_width=5.6, at=(-2.5,), frequency=4.5, seed=516),
        "rowing -0.47 / strokes",
    ),
    "h7_block2x2_e": (
        dict(kind="block2x2", core_length=10.0, core_width=5.4, at=(-2.0,), frequency=6.0, seed=517),
        "rowing 0.29 / 0.26",
    ),
    "h7_block2x2_f": (
        dict(kind="block2x2", core_length=11.0, core_width=4.8, at=(-1.5,), frequency=3.0, seed=518),
        "moves towards its appendages at both drags",
    ),
    "h7_block2x2_i": (
        dict(kind="block2x2", core_length=11.5, core_width=5.6, at=(-2.0,), frequency=3.5, seed=548),
        "rowing -0.08 / -0.16, 59-62 deg off its axis",
    ),
    "h7_block2x2_k": (
        dict(kind="block2x2", core_length=9.0, core_width=5.0, at=(-1.5,), frequency=4.5, seed=550),
        "rowing 0.01 / 0.01, 46-62 deg off its axis",
    ),
}
#: Whole-body candidates the undulation truth rejects (:func:`label_by_truth`, d_N = 0.5 and 2) and relabels:
#: none (every built synchronous body's contraction lags at most 0.61 rad over the body; no random-phase
#: body's contraction travels coherently along the axis it swims along at both drags).
SEVENTH_TRUTH_REJECTED: dict = {}
SEVENTH_RELABELLED: dict = {}


def seventh_set_candidates() -> List[KnownSwimmer]:
    """Every candidate of the seventh set with its built label, before the truths (the protrusion candidates
    at their :data:`SEVENTH_PHASES` phase; the rejected ones of :data:`SEVENTH_REJECTED` are not built)."""
    pi = math.pi
    prot = [
        appendage_swimmer(**g, appendage_phase=SEVENTH_PHASES[name] * pi / 4, anchor_shift=pi, name=name)
        for name, g in SEVENTH_APPENDAGES.items()
    ]
    U, S, T, W = undulator, synchronous_contractor, tail_swimmer, standing_swimmer
    return prot + [
        U("contraction", length=10.0, width=2.4, frequency=6.0, wavelengths=1.25, seed=521, name="h7_und_a"),
        U("contraction", length=11.5, width=2.2, frequency=8.5, wavelengths=1.0, seed=522, name="h7_und_b"),
        U("contraction", length=13.0, width=2.8, frequency=5.5, wavelengths=1.5, seed=523, name="h7_und_c"),
        U("bending", length=10.5, width=2.6, frequency=6.5, wavelengths=1.0, seed=524, name="h7_und_bend_a"),
        U("bending", length=12.0, width=2.8, frequency=4.0, wavelengths=1.25, seed=525, name="h7_und_bend_b"),
        U("bending", length=9.0, width=2.2, frequency=8.0, wavelengths=1.0, seed=526, name="h7_und_bend_c"),
        U("across", length=7.0, width=7.0, frequency=5.0, seed=546, name="h7_und_across"),
        S(length=8.5, width=5.0, frequency=6.0, seed=527, name="h7_sync_a"),
        S(length=9.5, width=5.2, frequency=3.5, seed=528, name="h7_sync_b"),
        S(length=11.5, width=4.6, frequency=5.5, seed=529, name="h7_sync_c"),
        S(length=10.0, width=4.4, frequency=8.5, seed=530, name="h7_sync_d"),
        S(length=12.5, width=5.0, frequency=4.5, seed=551, name="h7_sync_e"),
        S(length=11.0, width=4.2, frequency=9.5, seed=552, name="h7_sync_f"),
        S(length=10.5, width=5.0, frequency=7.0, lag=0.2, seed=531, name="h7_sync_lag_a"),
        S(length=12.0, width=4.8, frequency=4.5, lag=0.4, seed=532, name="h7_sync_lag_b"),
        S(length=9.0, width=4.4, frequency=6.5, lag=0.3, seed=553, name="h7_sync_lag_c"),
        S(length=11.5, width=4.8, frequency=10.0, lag=0.3, seed=554, name="h7_sync_lag_d"),
        S(length=10.0, width=4.6, frequency=4.5, seed=555, name="h7_sync_g"),
        S(length=12.0, width=5.2, frequency=3.5, seed=556, name="h7_sync_h"),
        S(length=9.5, width=4.8, frequency=9.0, lag=0.2, seed=557, name="h7_sync_lag_e"),
        T(length=4, core_radius=2.6, frequency=6.0, wavelengths=0.5, seed=533, name="h7_tail4"),
        T(length=5, core_radius=2.1, frequency=8.5, wavelengths=0.55, seed=534, name="h7_tail5"),
        T(length=3, core_radius=2.5, frequency=4.5, wavelengths=0.6, seed=535, name="h7_tail3"),
        W("random", length=9.5, width=4.0, frequency=4.5, seed=536, name="h7_standing_random_a"),
        W("random", length=11.0, width=4.8, frequency=6.5, seed=537, name="h7_standing_random_b"),
        W("random", length=8.5, width=3.8, frequency=8.0, seed=538, name="h7_standing_random_c"),
        W("random", length=12.0, width=4.4, frequency=3.5, seed=539, name="h7_standing_random_d"),
        W("random", length=10.0, width=4.6, frequency=5.5, seed=540, name="h7_standing_random_e"),
        W("random", length=13.0, width=5.2, frequency=4.0, seed=541, name="h7_standing_random_f"),
        W("random", length=9.0, width=3.6, frequency=7.0, seed=542, name="h7_standing_random_g"),
        W("random", length=11.5, width=4.2, frequency=9.0, seed=543, name="h7_standing_random_h"),
        W("random", length=10.5, width=4.4, frequency=3.0, seed=558, name="h7_standing_random_i"),
        W("random", length=12.5, width=4.6, frequency=5.0, seed=559, name="h7_standing_random_j"),
        W("halves", length=10.5, width=4.4, frequency=5.0, seed=544, name="h7_standing_halves_a"),
        W("halves", length=9.0, width=4.0, frequency=7.5, seed=545, name="h7_standing_halves_b"),
    ]


def paper_seventh_set() -> List[KnownSwimmer]:
    """The seventh held-out set: :func:`seventh_set_candidates` labelled by the ground truths (the protrusion
    bodies stroke at both drags by :func:`stroke_truth`; the whole-body ones are labelled by
    :func:`undulation_truth`, :data:`SEVENTH_TRUTH_REJECTED` dropped, :data:`SEVENTH_RELABELLED` relabelled),
    all of new sizes, seeds (501-560) and frequencies 3-10, weighted toward multi-cell appendages (eight of
    the ten protrusion bodies), bodies actuated synchronously (13 candidates, whose displacement may travel
    while their contraction does not) and random-phase bodies; fixed before the classifier was run on any of
    them, which was done once (docs/locomotion.md); calibration now."""
    return _by_truth(seventh_set_candidates(), SEVENTH_RELABELLED, SEVENTH_TRUTH_REJECTED)


#: The eighth held-out set's appendage candidates that stroke at both drags by :func:`stroke_truth` (with
#: :data:`EIGHTH_PHASES`): built after the undulation truth was grounded on the realised contraction, with
#: new cores (8.75-12.25 long), seeds (601-620) and frequencies (quarter values, 3.25-7.25, used by no
#: earlier set). Of 20 candidates (six one-cell, five two-cell chain, four three-cell chain and five 2 × 2
#: block pairs) six one-cell, two two-cell chain, three three-cell chain and three block pairs stroke.
EIGHTH_APPENDAGES = {
    "h8_single_a": dict(kind="single", core_length=9.25, core_width=4.5, at=(-1.75,), frequency=5.25, seed=601),
    "h8_single_b": dict(kind="single", core_length=10.75, core_width=4.9, at=(-2.25,), frequency=6.75, seed=602),
    "h8_single_c": dict(kind="single", core_length=8.75, core_width=4.3, at=(-1.25,), frequency=4.25, seed=603),
    "h8_single_d": dict(kind="single", core_length=11.25, core_width=5.1, at=(-2.5,), frequency=7.25, seed=604),
    "h8_single_e": dict(kind="single", core_length=12.25, core_width=5.3, at=(-3.0,), frequency=5.75, seed=617),
    "h8_single_f": dict(kind="single", core_length=9.75, core_width=4.7, at=(-1.5,), frequency=3.75, seed=618),
    "h8_chain2_a": dict(kind="chain2", core_length=9.75, core_width=4.5, at=(-1.75,), frequency=5.75, seed=605),
    "h8_chain2_b": dict(kind="chain2", core_length=10.25, core_width=4.7, at=(-2.0,), frequency=4.75, seed=606),
    "h8_chain3_a": dict(kind="chain3", core_length=10.25, core_width=4.7, at=(-2.0,), frequency=5.25, seed=609),
    "h8_chain3_b": dict(kind="chain3", core_length=9.25, core_width=4.3, at=(-1.5,), frequency=6.25, seed=610),
    "h8_chain3_c": dict(kind="chain3", core_length=11.25, core_width=4.9, at=(-2.25,), frequency=4.25, seed=611),
    "h8_block2x2_a": dict(kind="block2x2", core_length=10.75, core_width=5.1, at=(-2.0,), frequency=4.25, seed=613),
    "h8_block2x2_b": dict(kind="block2x2", core_length=11.25, core_width=4.7, at=(-2.25,), frequency=4.75, seed=614),
    "h8_block2x2_c": dict(kind="block2x2", core_length=12.25, core_width=5.5, at=(-2.75,), frequency=3.75, seed=615),
}
#: Their appendage phases (× π/4) by :func:`rowing_phase` (the ground truth; the classifier plays no part).
EIGHTH_PHASES = {
    "h8_single_a": 0,
    "h8_single_b": 7,
    "h8_single_c": 1,
    "h8_single_d": 7,
    "h8_single_e": 7,
    "h8_single_f": 0,
    "h8_chain2_a": 2,
    "h8_chain2_b": 7,
    "h8_chain3_a": 2,
    "h8_chain3_b": 2,
    "h8_chain3_c": 2,
    "h8_block2x2_a": 3,
    "h8_block2x2_b": 0,
    "h8_block2x2_c": 1,
}
#: Candidates that do not stroke at both drags with any of the 8 phases: their geometry and what fails at
#: their best phase (d_N = 0.5 / 2). In no set.
EIGHTH_REJECTED = {
    "h8_chain2_c": (
        dict(kind="chain2", core_length=8.75, core_width=4.1, at=(-1.25,), frequency=6.25, seed=607),
        "rowing 0.28 / rowing 0.22, 30 deg off its axis",
    ),
    "h8_chain2_d": (
        dict(kind="chain2", core_length=11.75, core_width=5.3, at=(-2.75,), frequency=5.25, seed=608),
        "moves towards its appendages at both drags",
    ),
    "h8_chain2_e": (
        dict(kind="chain2", core_length=10.75, core_width=4.9, at=(-2.25,), frequency=3.25, seed=619),
        "38 deg off its axis / strokes",
    ),
    "h8_chain3_d": (
        dict(kind="chain3", core_length=12.25, core_width=5.3, at=(-2.75,), frequency=5.75, seed=612),
        "rowing 0.24 / 0.23",
    ),
    "h8_block2x2_d": (
        dict(kind="block2x2", core_length=9.75, core_width=4.9, at=(-1.75,), frequency=5.25, seed=616),
        "rowing -0.41 / -0.13, moves towards its appendages",
    ),
    "h8_block2x2_e": (
        dict(kind="block2x2", core_length=11.75, core_width=5.1, at=(-2.5,), frequency=4.25, seed=620),
        "rowing 0.20, swims 0.20 spacings / rowing 0.13; moves towards its appendages",
    ),
}
#: Whole-body candidates the undulation truth rejects (:func:`label_by_truth`, d_N = 0.5 and 2) ...
EIGHTH_TRUTH_REJECTED: dict = {}
#: ... and relabels.
EIGHTH_RELABELLED: dict = {}


def eighth_set_candidates() -> List[KnownSwimmer]:
    """Every candidate of the eighth set with its built label, before the truths (the protrusion candidates
    at their :data:`EIGHTH_PHASES` phase; the rejected ones of :data:`EIGHTH_REJECTED` are not built)."""
    pi = math.pi
    prot = [
        appendage_swimmer(**g, appendage_phase=EIGHTH_PHASES[name] * pi / 4, anchor_shift=pi, name=name)
        for name, g in EIGHTH_APPENDAGES.items()
    ]
    U, S, T, W = undulator, synchronous_contractor, tail_swimmer, standing_swimmer
    return prot + [
        U("contraction", length=10.25, width=2.3, frequency=6.25, wavelengths=1.0, seed=621, name="h8_und_a"),
        U("contraction", length=11.75, width=2.5, frequency=5.25, wavelengths=1.25, seed=622, name="h8_und_b"),
        U("contraction", length=12.75, width=2.7, frequency=4.75, wavelengths=1.5, seed=623, name="h8_und_c"),
        U("contraction", length=9.75, width=2.5, frequency=7.25, wavelengths=1.0, seed=624, name="h8_und_d"),
        U("contraction", length=13.25, width=2.3, frequency=3.75, wavelengths=1.75, seed=625, name="h8_und_e"),
        U("bending", length=10.25, width=2.5, frequency=5.75, wavelengths=1.0, seed=626, name="h8_und_bend_a"),
        U("bending", length=11.25, width=2.7, frequency=4.25, wavelengths=1.25, seed=627, name="h8_und_bend_b"),
        U("bending", length=9.25, width=2.3, frequency=6.75, wavelengths=1.0, seed=628, name="h8_und_bend_c"),
        U("bending", length=12.75, width=2.9, frequency=5.25, wavelengths=1.0, seed=629, name="h8_und_bend_d"),
        U("bending", length=10.75, width=2.3, frequency=7.75, wavelengths=1.25, seed=630, name="h8_und_bend_e"),
        U("across", length=6.75, width=7.25, frequency=5.75, seed=631, name="h8_und_across"),
        S(length=9.25, width=5.1, frequency=5.75, seed=632, name="h8_sync_a"),
        S(length=11.25, width=4.5, frequency=4.25, seed=633, name="h8_sync_b"),
        S(length=8.25, width=5.3, frequency=8.75, seed=634, name="h8_sync_c"),
        S(length=10.75, width=4.7, frequency=6.25, lag=0.3, seed=635, name="h8_sync_lag_a"),
        S(length=12.25, width=4.9, frequency=3.75, lag=0.5, seed=636, name="h8_sync_lag_b"),
        S(length=10.25, width=4.7, frequency=5.25, seed=637, shape="wedge", name="h8_sync_wedge_a"),
        S(length=9.25, width=5.3, frequency=7.75, seed=638, shape="wedge", name="h8_sync_wedge_b"),
        S(length=11.75, width=4.3, frequency=4.75, seed=639, shape="wedge", name="h8_sync_wedge_c"),
        S(length=10.75, width=4.5, frequency=6.75, seed=640, shape="ellipse", name="h8_sync_ellipse_a"),
        S(length=8.75, width=4.9, frequency=4.25, seed=641, shape="ellipse", name="h8_sync_ellipse_b"),
        T(length=4, core_radius=2.35, frequency=6.25, wavelengths=0.5, seed=642, name="h8_tail4"),
        T(length=5, core_radius=2.45, frequency=4.75, wavelengths=0.6, seed=643, name="h8_tail5"),
        T(length=3, core_radius=2.55, frequency=8.25, wavelengths=0.45, seed=644, name="h8_tail3"),
        W("random", length=9.25, width=3.9, frequency=5.25, seed=645, name="h8_standing_random_a"),
        W("random", length=10.75, width=4.3, frequency=3.75, seed=646, name="h8_standing_random_b"),
        W("random", length=12.25, width=4.7, frequency=6.75, seed=647, name="h8_standing_random_c"),
        W("random", length=8.75, width=3.7, frequency=7.75, seed=648, name="h8_standing_random_d"),
        W("random", length=11.25, width=4.9, frequency=4.25, seed=649, name="h8_standing_random_e"),
        W("random", length=13.25, width=5.1, frequency=5.75, seed=650, name="h8_standing_random_f"),
        W("random", length=9.75, width=4.1, frequency=8.75, seed=651, name="h8_standing_random_g"),
        W("random", length=10.25, width=4.5, frequency=3.25, seed=652, name="h8_standing_random_h"),
        W("halves", length=10.25, width=4.3, frequency=5.75, seed=653, name="h8_standing_halves_a"),
        W("halves", length=9.25, width=3.9, frequency=6.75, seed=654, name="h8_standing_halves_b"),
    ]


def paper_eighth_set() -> List[KnownSwimmer]:
    """The eighth held-out set: :func:`eighth_set_candidates` labelled by the ground truths (the protrusion
    bodies stroke at both drags by :func:`stroke_truth`; the whole-body ones are labelled by
    :func:`undulation_truth` on their realised contraction, :data:`EIGHTH_TRUTH_REJECTED` dropped,
    :data:`EIGHTH_RELABELLED` relabelled), all of new sizes, seeds (601-654) and frequencies (quarter
    values, 3.25-8.75), with ten wave undulators (five contraction, five bending) and one across, ten
    synchronous bodies of three shapes (tear-drops, two with a lag, wedges, ellipses), eight random-phase
    bodies and protrusion bodies of every appendage kind; fixed before the classifier was run on any of
    them, which was done once (docs/locomotion.md); calibration now."""
    return _by_truth(eighth_set_candidates(), EIGHTH_RELABELLED, EIGHTH_TRUTH_REJECTED)
