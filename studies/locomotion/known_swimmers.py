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
:func:`paper_held_out_set` do the same for every class with protrusion swimmers of the paper's kind.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, List, Optional, Sequence, Tuple

import numpy as np

import animat
from animat.locomotion import classify_locomotion, paddling, procrustes_frames
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
    "AMPLITUDE",
    "APPENDAGE_KINDS",
    "appendage_swimmer",
    "standing_swimmer",
    "paper_calibration_set",
    "paper_held_out_set",
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
    """

    name: str
    expected: str
    positions: np.ndarray
    amplitude: np.ndarray
    frequency: np.ndarray
    phase: np.ndarray
    description: str
    mixed: str = ""

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
) -> KnownSwimmer:
    """A tear-drop body (wide and round at the back, -x; pointed at the front, +x), every cell in phase.

    ``lag`` > 0 adds a phase ramp of ``lag`` rad along the body (a mixture: mostly synchronous with a
    short wave); expected "synchronous contraction" either way, mixed "undulation" when ``lag`` >= π/2.
    """
    r = width / 2

    def inside(x: float, y: float) -> bool:
        back = x <= -length / 2 + r
        if back:
            return (x - (-length / 2 + r)) ** 2 + y**2 <= r * r
        half = r * (length / 2 - x) / (length - r)  # straight flanks narrowing to the tip at x = length/2
        return x <= length / 2 and abs(y) <= half + 0.05

    pos = hex_region(inside, spacing, seed=seed)
    x = pos[:, 0]
    phase = -lag * (x - x.min()) / np.ptp(x)
    mixed = "undulation" if lag >= math.pi / 2 else ""
    return _swimmer(
        name or ("synchronous_teardrop" if lag == 0 else f"synchronous_lag{lag:.1f}"),
        "synchronous contraction",
        pos,
        np.full(len(pos), AMPLITUDE),
        frequency,
        phase,
        f"{len(pos)} cells, tear-drop {length:g} x {width:g}, all in phase"
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

    @property
    def found(self) -> str:
        return self.mode.mode if self.mode is not None else "unstable"

    @property
    def correct(self) -> bool:
        return self.found == self.swimmer.expected


def classify_known(
    swimmers: Sequence[KnownSwimmer],
    drags: Sequence[float] = (0.5, 2.0),
    steps: int = 2000,
    config: Optional[Any] = None,
    stroke_rule: bool = False,
) -> List[KnownResult]:
    """Swim every swimmer ``steps`` steps at every normal drag (d_T = d_N / 200, the paper's ratio, via the
    config default) and classify the recorded swim with :func:`animat.classify_locomotion`
    (``stroke_rule``: with the paper's stroke rule, its ``stroke`` argument)."""
    out = []
    for dn in drags:
        cfg = config.copy() if config is not None else animat.Config()
        cfg["scene.drag_normal"] = float(dn)
        cfg["evaluation.steps"] = int(steps)
        for s in swimmers:
            tr = replay(s.body(cfg), cfg)
            mode = classify_locomotion(tr, stroke=stroke_rule) if tr.stable else None
            stroke = appendage_stroke(s, tr, mode) if mode is not None else None
            paddle = paddling(tr, mode) if mode is not None else None
            out.append(KnownResult(s, float(dn), int(steps), mode, float(tr.distance), bool(tr.stable), stroke, paddle))
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
    for xa in at:
        for s in (+1, -1):
            near = [(i, j) for (i, j) in core_sites if abs(_lattice(i, j, spacing)[0] - xa) <= 1.0 * spacing]
            j_top = max(s * j for (_, j) in near) * s
            for k in range(1, rows + 1):
                j = j_top + s * k
                cand = sorted(range(-ext, ext + 1), key=lambda i: (abs(_lattice(i, j, spacing)[0] - xa), i))
                app_sites += [(i, j) for i in cand[:width]]
    sites = sorted(core_sites) + [st for st in dict.fromkeys(app_sites) if st not in core_sites]
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


def paper_calibration_set() -> List[KnownSwimmer]:
    """Swimmers of every class, the protrusion ones of the paper's kind (:func:`appendage_swimmer`, every
    cell actuated); the stroke thresholds of :mod:`animat.protrusion` were set on this set only."""
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
    ]


def paper_held_out_set() -> List[KnownSwimmer]:
    """Other core sizes, appendage lengths, positions, phases and frequencies; not used to set anything."""
    pi = math.pi
    return [
        appendage_swimmer(
            "single",
            core_length=8.0,
            core_width=4.0,
            at=(-1.0,),
            frequency=6.0,
            appendage_phase=pi / 2,
            anchor_shift=pi,
            seed=21,
            name="ho_paper_single_small",
        ),
        appendage_swimmer(
            "single",
            core_length=10.0,
            core_width=5.0,
            at=(-2.0,),
            frequency=10.0,
            appendage_phase=pi / 4,
            anchor_shift=pi,
            seed=22,
            name="ho_paper_single_fast",
        ),
        appendage_swimmer(
            "chain2",
            core_length=10.0,
            core_width=5.0,
            at=(-1.5,),
            frequency=6.0,
            appendage_phase=3 * pi / 8,
            anchor_shift=pi,
            seed=23,
            name="ho_paper_chain2_big",
        ),
        appendage_swimmer(
            "chain3",
            at=(-1.5,),
            frequency=8.0,
            appendage_phase=pi / 4,
            anchor_shift=pi,
            seed=24,
            name="ho_paper_chain3",
        ),
        appendage_swimmer(
            "single",
            at=(-1.5,),
            frequency=8.0,
            appendage_phase=pi / 4,
            anchor_shift=pi,
            back_shift=pi / 2,
            seed=25,
            name="ho_paper_single_backline",
        ),
        *_held_out_whole_body(),
        tail_swimmer(length=6, core_radius=2.0, frequency=6.0, wavelengths=0.75, seed=13, name="ho_tail6"),
        tail_swimmer(length=3, core_radius=2.8, frequency=10.0, wavelengths=0.25, seed=14, name="ho_tail3_fast"),
        standing_swimmer("halves", length=10.0, width=3.5, frequency=5.0, seed=26, name="ho_standing_halves"),
        standing_swimmer("random", length=7.0, width=5.0, frequency=11.0, seed=27, name="ho_standing_random"),
    ]
