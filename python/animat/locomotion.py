"""Locomotion modes and the paper's statistics of evolved swimmers (paper §6–§7).

Classification (:func:`classify_locomotion`)
-------------------------------------------
The paper names three modes of the best swimmers (§6): **undulation** ("waves of contractions
travelling through the body"), **synchronous contraction** ("the cells oscillate synchronously", the
body contracts and expands as a whole) and **protrusions** ("appendages" that are extended while
they move backwards and contracted on their return, while the rest of the body moves less); many
bests mix two. We decide automatically from the recorded swim, with numbers that can be checked:

1. *Window.* The last ``cycles`` whole periods (default 4, at most the second half of the swim) of
   the dominant actuation frequency ω (the amplitude-weighted median of the cells' frequencies; for
   raw positions without a body, the peak of the deformation spectrum).
2. *Body frame.* Every frame is aligned onto the window's mean shape by the best rotation and
   translation (generalised Procrustes / Kabsch, no reflection). What remains is deformation, so no
   measure below changes under a rigid motion of any frame.
3. *Per-cell signals at ω.* A least-squares fit ``s(t) = c + Re(z) sin ωt + Im(z) cos ωt`` gives a
   complex amplitude ``z = A e^{iφ}`` for ``s = A sin(ωt + φ)`` (the phase convention of eq. 2). Two
   signals: the cell's body-frame **displacement** (a 2-D complex vector) and its **contraction**,
   the mean relative length change of its springs: what the paper's figures colour red (expanding
   its springs) and blue (contracting), here measured from the motion rather than read from the
   commanded actuation, so it includes the body's elastic response.
4. *Measures.*

   - ``deformation``: RMS displacement amplitude at ω over the body's RMS radius.
   - ``coherence`` R = ``|Σ a_i e^{iφ_i}| / Σ a_i`` of the contraction (a_i, φ_i its amplitude and
     phase): 1 when every cell contracts at the same time.
   - *Phase gradient*: the circular–linear fit ``φ_i ≈ φ_0 + g · x_i`` of the contraction phases
     (x_i the cell's body-frame rest position, g a 2-D gradient in rad per length unit) that
     maximises ``fit = |Σ a_i e^{i(φ_i − g·x_i)}| / Σ a_i``; ``lag`` = |g| × the extent of the
     body along g (cells with at least 10 % of the largest amplitude): the total phase lag of the
     wave across the body. A wave ``sin(ωt − k·x)`` travels along +k, i.e. against g; its direction
     is reported against the direction of motion (forward, backward, across).
   - ``travelling_index`` TI = λ_min/λ_max of the Gram matrix of (Re z, Im z) of the contraction
     field: 0 for a standing pattern (cells in phase or in antiphase), 1 for a pure travelling wave.
     A linear fit can "explain" two halves in antiphase as a gradient (a 0/π jump); TI cannot.
   - ``concentration``: the share of the displacement energy Σ|z_i|² carried by the 20 % of the
     cells that move most.

5. *Decision*, in this order (the thresholds are module constants):

   - ``deformation < NONE_DEFORMATION`` (0.01): **none**: the body does not deform periodically
     (a rigid or resting body). Swimming bodies deform by 0.1–0.4 (amplitude up to 0.2 per cell,
     two cells per spring); a rigid body gives < 1e-9.
   - the paper's stroke (the *stroke path*: whenever the body's outline is known, i.e.
     :func:`classify_locomotion` of a trajectory or of anything it replays, unless ``stroke=False``;
     :func:`classify_motion` with ``outline``): a symmetric pair of protrusions (:mod:`animat.shape`, at
     rest or during the last cycle; both standing out at rest) that rows, extended while moving
     backwards and contracted on the return (:func:`animat.protrusion.stroke_motion`: pair score ``>=
     STROKE_SCORE`` 0.4 and loop area ``>= STROKE_AREA`` 0.1 spacings²): **protrusions**, but
     **undulation** mixed with protrusions when the wave criterion also holds (a slow wave makes an
     undulator's corners row). On the stroke path a strain contrast without a rowing pair is not
     protrusions (next item): it is a **tail** when the strained cells form one group or the outline has
     one protrusion, else the wave, synchrony and "other" rules decide. Calibrated on the hand-built
     swimmers of studies/locomotion/known_swimmers.py whose protrusion swimmers actuate every cell
     (``paper_calibration_set`` and the sets after it) and checked on a held-out set run once: every
     class ≥ 80 % (docs/locomotion.md, which gives the confusion matrices).
   - ``concentration >= PROTRUSION_CONCENTRATION`` (0.65), or a strain contrast (RMS contraction
     amplitude of the most strained 20 % of the cells over the median cell's) ``>= LOCAL_CONTRAST``
     (3.5): on the stroke path a **tail** under the condition above; without it (``stroke=False``, the
     earlier rules, or a positions array, which has no outline) **protrusions** when those cells (the
     most strained fifth if the contrast decided, else the most mobile fifth) form two or more groups
     joined by springs, **tail** when they form one. The contrast rule was added because hand-built protrusion swimmers
     (studies/locomotion/known_swimmers.py) put only 0.44–0.62 of the motion in their top fifth: the passive
     core of a soft body is pushed around by its appendages. For the old rule: the rest of the body
     moves with less than 37 % of the RMS amplitude of its most mobile fifth. Smooth whole-body
     deformations stay below: a breathing disc puts 0.36 of its energy in the top 20 % (amplitude
     ∝ radius), an elongated body contracting along its axis 0.49 (amplitude ∝ distance from the
     centre); synchronously driven real bodies measured 0.34–0.57 (calibration below).
   - a *wave*: ``fit >= WAVE_FIT`` (0.8), ``lag >= WAVE_LAG`` (π/2) and ``travelling_index >=
     WAVE_TI`` (0.15): **undulation** (listed as mixed with protrusions when both hold). π/2 is a
     quarter period across the body, the brief's and the paper's "wave travelling through the
     body"; the drag and inertia of synchronously driven bodies produce lags up to 0.74 rad. On the
     stroke path a *bending wave* also counts
     (:func:`bending_wave`: the same fit, lag and TI on the strain of the springs along the body,
     signed by the side they lie on, fit ``>= BEND_FIT`` 0.65 and significant against shuffled positions,
     p ``<= BEND_P`` 0.01, running backward against the motion, ``BEND_BACKWARD``): the two sides of a
     bending undulator contract in antiphase, which the cells' contraction mixes into a poor ramp (fit 0.75-0.80).
   - ``coherence >= SYNC_COHERENCE`` (0.8): **synchronous contraction**; also listed as mixed with an
     undulation whose lag is short enough to keep R ≥ 0.8 (a uniform lag of π/2 gives R = 0.90, of
     π 0.64): mostly synchronous with a visible wave.
   - otherwise **other**: no travelling wave and not in phase (e.g. two groups in antiphase).

*Calibration* (real physics: 6 bodies, the demo's best, a d_N = 0.5 best and 4 random viable 32-cell
embryos, each with every cell at amplitude 0.2 and f = 3, 8 or 11.7, swum 4000 steps at d_N = 0.5,
2 and 10, i.e. 54 swims per imposed phase pattern): all in phase gave R 0.94–1.00, lag ≤ 0.74,
TI ≤ 0.13, concentration 0.34–0.57 (all 54 "synchronous contraction"); a linear phase ramp of π
or 2π along the long axis or π across it gave fit ≥ 0.94, lag 2.2–6.3 and TI 0.32–0.95 (all 162
"undulation", 8 of them mixed with synchronous contraction); two halves in antiphase gave fit
0.75–0.85 but TI ≤ 0.11 and R ≤ 0.21, and the two ends in antiphase with the middle fit ≤ 0.78 (all
108 "other"); random phases gave fit 0.44–0.89 (median 0.60) and concentration up to 0.71 (202 of
216 "other", 5 "undulation", 9 "protrusions"). Commanded ramps of π/2 came out at lags 0.9–2.2
(37 "synchronous contraction", 17 mixed): a quarter-period command is at the threshold. The
concentration threshold could not be calibrated on real protrusion swimmers (none was at hand); it rests
on the smooth-deformation bounds above and on a synthetic swimmer (two 3-cell appendages on a 19-cell
blob that sweep and extend as the paper's Fig. 6 describes: 0.86). Hand-built swimmers of known mode
with a passive core (studies/locomotion/known_swimmers.py, ``calibration_set``) were swum: the contrast
rule and the tail mode come from that calibration set; a bending wave (two sides in antiphase) is
missed by the contraction fit (0.78–0.80, just under WAVE_FIT); on the stroke path :func:`bending_wave`
finds it. The stroke path's confusion matrices on swimmers of the paper's kind, labelled by ground
truths of their motion, are in docs/locomotion.md and docs/replication.md.

The paper's stroke, tested directly
-----------------------------------
:func:`paddling` asks of a swim what the paper (§6) says of its protrusion swimmers, without a mode:
"protrusions are fully extended when moving backwards (generating thrust) but are contracted during
their return", "a clear tendency to place the protrusions symmetrically", and "in 32-cell structures
protrusions are often built from one cell extending beyond the main outline". Over the classifier's
window, in the body frame: a skin cell *protrudes* when its height above the chord of its two skin
neighbours reaches ``PADDLE_SPIKE`` (0.9) median rest spring lengths at some time (at rest, a cell on a
straight stretch of skin has 0, a 120° corner of the triangular lattice 0.5, one cell standing out of a
straight edge 0.87; a dangling cell counts its whole distance from its neighbour); it *rows* with the correlation of its distance from the body's centre
with its backward velocity along the direction of motion (+1 when it is farthest out exactly while it
moves backwards fastest: a loop traversed out, back, in, forward; 0 for a purely radial or a purely
sweeping motion, which are a quarter period apart; −1 for the loop the other way round). The *pair
score* is the best min(rowing) over two protruding cells on opposite sides of the axis of motion; a
swim *paddles* when it reaches ``PADDLE_ROWING`` (0.6). On the hand-built swimmers with a passive core
(studies/locomotion/known_swimmers.py, ``calibration_set`` and ``held_out_set``) the whole-body ones
(undulators, synchronous contractors) score at most 0.49 and the protrusion swimmers do not paddle
either (their appendages are driven to row but follow it only loosely); on the swimmers of the paper's
kind labelled by ground truths (the stroke path's calibration and held-out sets, docs/replication.md)
97 of 140 protrusion swims paddle and 1 of 186 whole-body swims. The classifier does not use it.

Statistics (paper §6–§7)
------------------------
:func:`grow_output`, :func:`oscillator_spread`, :func:`phase_spread`, :func:`tries_per_viable`,
:func:`morphology_changes` / :func:`last_morphology_change` and :func:`best_statistics` measure the
paper's claims about the best individuals: cell count, the grow output (size increase), amplitude,
frequency and phase differentiation, tries per viable random individual, and when the best's
morphology last changed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _core
from .run import MORPHOLOGY_TOLERANCE, LineageEntry, Run, morphology_distance
from .trajectory import Trajectory, body_of, replay

__all__ = [
    "LocomotionMode",
    "WaveFit",
    "classify_locomotion",
    "classify_motion",
    "MODES",
    "NONE_DEFORMATION",
    "PROTRUSION_CONCENTRATION",
    "WAVE_FIT",
    "WAVE_LAG",
    "WAVE_TI",
    "BEND_FIT",
    "BEND_CONE",
    "BEND_BAND",
    "BEND_P",
    "BEND_PERMUTATIONS",
    "BEND_SEED",
    "BEND_BACKWARD",
    "bending_wave",
    "shuffled_fits",
    "SYNC_COHERENCE",
    "TOP_FRACTION",
    "LOCAL_CONTRAST",
    "procrustes_frames",
    "circular_linear_fit",
    "travelling_index",
    "phase_coherence",
    "harmonic_amplitudes",
    "GrowOutput",
    "OscillatorSpread",
    "PhaseSpread",
    "BestStatistics",
    "grow_output",
    "oscillator_spread",
    "phase_spread",
    "tries_per_viable",
    "morphology_changes",
    "last_morphology_change",
    "best_statistics",
    "PHASE_DIFFERENTIATED",
    "AMPLITUDE_DIFFERENTIATED",
    "FREQUENCY_DIFFERENTIATED",
    "CONTRACTION_FLOOR",
    "Paddling",
    "paddling",
    "paddling_motion",
    "PADDLE_SPIKE",
    "PADDLE_ROWING",
]

#: The modes :func:`classify_locomotion` returns.
MODES = ("undulation", "synchronous contraction", "protrusions", "tail", "other", "none")
#: Below this relative deformation amplitude the body is rigid for our purpose: mode "none".
NONE_DEFORMATION = 0.01
#: Contraction amplitudes (relative length change) below this are round-off: no spring changes length.
CONTRACTION_FLOOR = 1e-9
#: Share of the displacement energy in the most mobile 20 % of cells from which motion is "protrusions".
PROTRUSION_CONCENTRATION = 0.65
#: The most mobile fraction of the cells used by the concentration measure.
TOP_FRACTION = 0.2
#: RMS contraction amplitude of the most strained 20 % of the cells over the median cell's, from which
#: the deformation is localised in appendages (protrusions or a tail; set between the two groups of
#: the calibration set of studies/locomotion/known_swimmers.py, swum 2000 steps at d_N = 0.5 and 2:
#: undulators and synchronous contractors 1.98–3.01, protrusion and tail swimmers 4.14–7.33).
LOCAL_CONTRAST = 3.5
#: Height above the chord of its two skin neighbours, in median rest spring lengths, from which a skin
#: cell protrudes from the outline (:func:`paddling`).
PADDLE_SPIKE = 0.9
#: Pair score (min rowing correlation of two protruding cells on opposite sides of the axis of motion)
#: from which a swim paddles as the paper's protrusion swimmers do (:func:`paddling`).
PADDLE_ROWING = 0.6
#: Minimum weighted resultant of a circular-linear phase fit to count as a consistent gradient.
WAVE_FIT = 0.8
#: Minimum total phase lag (rad) along the body for a wave.
WAVE_LAG = math.pi / 2
#: Minimum travelling index for a wave (excludes standing patterns such as two halves in antiphase).
WAVE_TI = 0.15
#: Minimum fit of the bending wave (:func:`bending_wave`, the stroke path only): set in the gap of
#: the calibration swims of studies/locomotion/known_swimmers.py (paper_calibration_set and the second
#: held-out set, both seen): bending undulators 0.78-0.93, every other non-tail swim at most 0.49.
BEND_FIT = 0.65
#: Largest permutation p-value of the bending fit (:func:`bending_wave`): the fit must beat the fits of the
#: same springs with their positions along the axis shuffled (:func:`shuffled_fits`) at the 1 % level. A
#: circular-linear fit with a free gradient reaches BEND_FIT by chance on 14-22 springs (docs/locomotion.md).
BEND_P = 0.01
#: Shuffles of the permutation test (p = (1 + #shuffled fits >= the fit) / (1 + BEND_PERMUTATIONS), so
#: the smallest p is 0.001, ten times under BEND_P).
BEND_PERMUTATIONS = 999
#: Seed of the shuffles: fixed, so that the classifier is deterministic.
BEND_SEED = 0
#: Smallest angle (degrees) between the direction a bending wave travels and the direction of motion: the
#: wave must run backward along the body ("backward" of :attr:`WaveFit.travel`). A lateral wave propels a
#: body through a resistive medium whose tangential drag is lower than its normal drag (here d_T = d_N /
#: 200) only when it travels backward, against the motion (Gray & Hancock 1955); a bend that runs forward
#: or across the motion does not drive it, whatever it fits.
BEND_BACKWARD = 135.0
#: Springs within this angle (degrees) of the body's long axis carry the bending wave.
BEND_CONE = 30.0
#: ... and lie at least this far (median rest lengths) off the axis, on one side.
BEND_BAND = 0.25
#: Contraction phase coherence from which the body contracts synchronously.
SYNC_COHERENCE = 0.8
#: Phases count as differentiated when their circular range exceeds this (rad): 0.2 rad is one control
#: step of phase at the fastest oscillator (f = 12 rad per time unit, 31 steps per period).
PHASE_DIFFERENTIATED = 0.2
#: Amplitudes count as differentiated when max - min exceeds this fraction of development.amplitude_max.
AMPLITUDE_DIFFERENTIATED = 0.1
#: Frequencies count as differentiated when max - min exceeds this fraction of the frequency range
#: (1 % = 0.115 rad per time unit: over a 4000-step swim, 66.7 time units, the cells drift apart by
#: 7.7 rad, more than a cycle).
FREQUENCY_DIFFERENTIATED = 0.01

ArrayLike = Union[np.ndarray, Sequence]


# --- geometry and signal helpers ------------------------------------------------------------------------


def _kabsch_batch(X: np.ndarray, Y: np.ndarray) -> np.ndarray:
    """Rotations R_t (F, 2, 2), no reflection, minimising ||X_t R_t - Y|| for centred X (F, n, 2), Y (n, 2)."""
    H = np.einsum("fni,nj->fij", X, Y)
    U, _, Vt = np.linalg.svd(H)
    d = np.sign(np.linalg.det(U @ Vt))
    d[d == 0] = 1.0
    D = np.zeros((len(X), 2, 2))
    D[:, 0, 0] = 1.0
    D[:, 1, 1] = d
    return U @ D @ Vt


def procrustes_frames(positions: ArrayLike, iterations: int = 4) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Remove the rigid motion of every frame: generalised Procrustes alignment onto the mean shape.

    Args:
        positions: (F, n, 2) node positions.
        iterations: alignment rounds (the mean shape is re-estimated after each).
    Returns:
        ``(aligned, rotations, mean_shape)``: aligned (F, n, 2) body-frame positions (centred),
        rotations (F, 2, 2) with ``aligned[t] = (positions[t] - centroid_t) @ rotations[t]``, and the
        (n, 2) centred mean shape.
    """
    P = np.asarray(positions, dtype=np.float64)
    if P.ndim != 3 or P.shape[2] != 2:
        raise ValueError(f"procrustes_frames: positions must be (frames, n, 2), got shape {P.shape}")
    X = P - P.mean(axis=1, keepdims=True)
    ref = X[-1].copy()
    R = np.broadcast_to(np.eye(2), (len(X), 2, 2)).copy()
    for _ in range(max(1, iterations)):
        R = _kabsch_batch(X, ref)
        Q = np.einsum("fni,fij->fnj", X, R)
        ref = Q.mean(axis=0)
        ref -= ref.mean(axis=0)
    Q = np.einsum("fni,fij->fnj", X, R)
    return Q, R, Q.mean(axis=0)


def harmonic_amplitudes(signals: np.ndarray, times: np.ndarray, omega: float) -> np.ndarray:
    """Complex amplitude at angular frequency ``omega`` of each signal, by least squares.

    Fits ``s(t) = c + Re(z) sin(ωt) + Im(z) cos(ωt)``, so a signal ``A sin(ωt + φ)`` gives
    ``z = A e^{iφ}`` (the phase convention of the actuation, paper eq. 2).

    Args:
        signals: (F, ...) real samples, time along axis 0.
        times: (F,) sample times.
        omega: angular frequency (rad per time unit), > 0.
    Returns:
        complex array of shape ``signals.shape[1:]``.
    """
    s = np.asarray(signals, dtype=np.float64)
    t = np.asarray(times, dtype=np.float64)
    X = np.stack([np.ones_like(t), np.sin(omega * t), np.cos(omega * t)], axis=1)
    flat = s.reshape(len(t), -1)
    coef, *_ = np.linalg.lstsq(X, flat, rcond=None)
    z = coef[1] + 1j * coef[2]
    return z.reshape(s.shape[1:])


def phase_coherence(z: np.ndarray) -> float:
    """``|Σ a_i e^{iφ_i}| / Σ a_i`` for complex amplitudes ``z_i = a_i e^{iφ_i}``: 1 when all phases are
    equal, about 1/sqrt(n) for random phases, 0 for balanced antiphase. 0 when all amplitudes are 0."""
    z = np.asarray(z, dtype=np.complex128).ravel()
    total = float(np.abs(z).sum())
    return float(abs(z.sum()) / total) if total > 0 else 0.0


def travelling_index(z: np.ndarray) -> float:
    """How much a complex amplitude field is a travelling rather than a standing wave.

    With P = Re z and Q = Im z (flattened real vectors), TI = λ_min / λ_max of [[P·P, P·Q], [P·Q, Q·Q]]
    (the travelling index of complex orthogonal decomposition): 0 when ``z = e^{iθ} r`` with r real (a
    standing pattern, cells in phase or antiphase), 1 for ``z_k = e^{i k·x}`` over a whole wavelength.
    Independent of the global phase. 0 for an all-zero field.
    """
    z = np.asarray(z, dtype=np.complex128).ravel()
    P, Q = np.real(z), np.imag(z)
    M = np.array([[P @ P, P @ Q], [P @ Q, Q @ Q]])
    ev = np.linalg.eigvalsh(M)
    return float(ev[0] / ev[1]) if ev[1] > 0 else 0.0


@dataclass(frozen=True, eq=False)
class WaveFit:
    """The circular–linear fit ``φ_i ≈ φ_0 + gradient · x_i`` of the cells' contraction phases.

    Attributes:
        gradient: (2,) phase gradient g in the body frame (rad per length unit).
        fit: weighted resultant length after removing the gradient (1 = exact linear phase).
        lag: |g| × the extent of the (moving) cells along g: the total phase lag across the body (rad).
        travelling_index: :func:`travelling_index` of the contraction field.
        coherence: :func:`phase_coherence` of the contraction field (the fit with g = 0).
        angle: angle (degrees, 0..180) between the direction the wave travels (-g) and the
            direction of motion: ~0 the wave runs forward (back to front), ~180 backward, ~90 across.
        is_wave: the wave criterion holds (fit, lag and travelling index above their thresholds; for
            :func:`bending_wave` also ``p_value <= BEND_P``).
        p_value: the permutation p-value of the fit (:func:`bending_wave`; nan where not tested).
    """

    gradient: np.ndarray
    fit: float
    lag: float
    travelling_index: float
    coherence: float
    angle: float
    is_wave: bool
    p_value: float = float("nan")

    @property
    def travel(self) -> str:
        """Direction of travel of the wave relative to the motion: "forward" (back to front, angle <
        45°), "backward" (front to back, > 135°), or "across"."""
        if not np.isfinite(self.angle):
            return "n/a"
        return "forward" if self.angle < 45 else ("backward" if self.angle > 135 else "across")


def circular_linear_fit(
    phases: ArrayLike, weights: ArrayLike, coords: ArrayLike, max_gradient: float = math.pi, grid: int = 81
) -> Tuple[Union[float, np.ndarray], float]:
    """Best linear phase gradient: maximise ``|Σ w_i e^{i(φ_i − g·x_i)}| / Σ w_i`` over g.

    Args:
        phases: (n,) phases (rad). weights: (n,) non-negative weights (amplitudes).
        coords: (n,) or (n, 2) positions.
        max_gradient: search |g_k| ≤ this (rad per length unit; π = half a wavelength per cell spacing).
        grid: grid points per dimension of the coarse search (then refined locally four times, to
            about 1e-5 of ``max_gradient``).
    Returns:
        ``(g, R)``: the gradient (same dimension as a coordinate) and the resultant length R in [0, 1].
    """
    phi = np.asarray(phases, dtype=np.float64)
    w = np.asarray(weights, dtype=np.float64)
    x = np.asarray(coords, dtype=np.float64)
    one_d = x.ndim == 1
    if one_d:
        x = x[:, None]
    total = w.sum()
    if total <= 0 or len(phi) == 0:
        return (0.0 if one_d else np.zeros(x.shape[1])), 0.0
    zw = w * np.exp(1j * phi)
    dims = x.shape[1]

    def best_on(axes: List[np.ndarray]) -> Tuple[np.ndarray, float]:
        mesh = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, dims)
        vals = np.abs(np.exp(-1j * (mesh @ x.T)) @ zw) / total
        k = int(np.argmax(vals))
        return mesh[k], float(vals[k])

    step = 2 * max_gradient / (grid - 1)
    g, r = best_on([np.linspace(-max_gradient, max_gradient, grid)] * dims)
    for _ in range(4):
        axes = [np.linspace(gi - step, gi + step, 21) for gi in g]
        g, r = best_on(axes)
        step /= 10
    return (g[0] if one_d else g), r


def shuffled_fits(
    phases: ArrayLike,
    weights: ArrayLike,
    coords: ArrayLike,
    permutations: int = 999,
    seed: int = 0,
    max_gradient: float = math.pi,
    grid: int = 81,
) -> np.ndarray:
    """The 1-D :func:`circular_linear_fit` of ``phases`` with their ``coords`` shuffled: the null
    distribution of the fit when the phases are unrelated to the positions (each shuffle a permutation of
    the positions, the (phase, weight) pairs kept together; ``seed`` fixes them). Same search as
    :func:`circular_linear_fit` (coarse grid, four local refinements), batched over the shuffles.

    Returns:
        (permutations,) the best resultant length of each shuffle.
    """
    phi = np.asarray(phases, dtype=np.float64).ravel()
    w = np.asarray(weights, dtype=np.float64).ravel()
    x = np.asarray(coords, dtype=np.float64).ravel()
    total = w.sum()
    if total <= 0 or len(phi) == 0 or permutations <= 0:
        return np.zeros(max(permutations, 0))
    zw = w * np.exp(1j * phi)
    rng = np.random.default_rng(seed)
    X = np.stack([rng.permutation(x) for _ in range(permutations)])  # (N, m)
    rows = np.arange(permutations)

    def best_on(axes: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:  # axes (N, G) or (G,)
        A = np.broadcast_to(axes, (permutations, axes.shape[-1]))
        vals = np.abs(np.exp(-1j * A[:, :, None] * X[:, None, :]) @ zw) / total  # (N, G)
        k = np.argmax(vals, axis=1)
        return A[rows, k], vals[rows, k]

    step = 2 * max_gradient / (grid - 1)
    g, r = best_on(np.linspace(-max_gradient, max_gradient, grid))
    for _ in range(4):
        g, r = best_on(g[:, None] + np.linspace(-step, step, 21)[None, :])
        step /= 10
    return r


# --- classification --------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class LocomotionMode:
    """The locomotion mode of one swim and the numbers it was decided on (see the module docstring).

    Attributes:
        mode: one of :data:`MODES`.
        mixed: other modes whose criterion also holds (e.g. ("undulation",) for protrusions with a wave).
        deformation: RMS displacement amplitude at ω over the RMS body radius.
        coherence: phase coherence R of the cells' contraction.
        concentration: share of the displacement energy in the most mobile 20 % of the cells.
        travelling_index: of the contraction field.
        wave: the phase-gradient fit of the contraction (:class:`WaveFit`; None for mode "none").
        omega: the angular frequency analysed (rad per time unit); ``cycles``: periods in the window;
        frames: frames in the window.
        direction: (2,) direction of motion in the body frame (unit; the principal axis if the body
            did not move); ``speed``: centre-of-mass speed over the window (length per time unit).
        top_cells: indices of the most mobile 20 % of the cells (the protrusions when mode is "protrusions").
        reason: one sentence saying which criterion decided.
        phases, amplitudes: (n,) phase and amplitude of every cell's contraction.
        contrast: RMS contraction amplitude of the most strained 20 % of the cells over the median
            cell's (localised deformation: appendages).
        groups: connected groups (along springs) (along springs) of the appendage cells when the mode is "protrusions" or
            "tail" (the most strained 20 % when the contrast decided, else the most mobile 20 %); else 0.
    """

    mode: str
    mixed: Tuple[str, ...]
    deformation: float
    coherence: float
    concentration: float
    travelling_index: float
    wave: Optional[WaveFit]
    omega: float
    cycles: float
    frames: int
    direction: np.ndarray
    speed: float
    top_cells: np.ndarray
    reason: str
    phases: np.ndarray = field(repr=False, default_factory=lambda: np.zeros(0))
    amplitudes: np.ndarray = field(repr=False, default_factory=lambda: np.zeros(0))
    contrast: float = float("nan")
    groups: int = 0
    stroke: Any = None  #: :class:`animat.protrusion.ProtrusionStroke` (None without an outline)
    bend: Optional[WaveFit] = None  #: :func:`bending_wave` (None unless the bending wave was looked for)

    @property
    def label(self) -> str:
        """``mode`` plus the mixed modes, e.g. "protrusions + undulation"."""
        return " + ".join((self.mode,) + tuple(self.mixed))

    def __str__(self) -> str:
        w = self.wave
        wave = (
            f", phase lag {w.lag:.2f} rad (fit {w.fit:.2f}, TI {w.travelling_index:.2f}, travels {w.travel})"
            if w is not None
            else ""
        )
        return (
            f"{self.label}: deformation {self.deformation:.3f}, coherence {self.coherence:.2f}, "
            f"concentration {self.concentration:.2f}{wave}"
        )


def _dominant_omega(Q: np.ndarray, times: np.ndarray) -> float:
    """Peak angular frequency of the body-frame deformation spectrum (uniformly sampled frames)."""
    d = Q - Q.mean(axis=0)
    F = len(times)
    dt = float(np.median(np.diff(times)))
    spec = np.abs(np.fft.rfft(d.reshape(F, -1), axis=0)) ** 2
    power = spec.sum(axis=1)
    power[0] = 0.0
    k = int(np.argmax(power))
    if 0 < k < len(power) - 1:  # parabolic refinement of the peak
        a, b, c = power[k - 1], power[k], power[k + 1]
        den = a - 2 * b + c
        k = k + (0.5 * (a - c) / den if den != 0 else 0.0)
    return 2 * math.pi * k / (F * dt)


def _weighted_median(values: np.ndarray, weights: np.ndarray) -> float:
    order = np.argsort(values)
    v, w = values[order], weights[order]
    cum = np.cumsum(w)
    return float(v[np.searchsorted(cum, 0.5 * cum[-1])])


def _cell_contraction(positions: np.ndarray, springs: np.ndarray, n: int) -> np.ndarray:
    """(F, n): mean relative length change (vs the window mean) of each cell's springs."""
    if len(springs) == 0:
        return np.zeros(positions.shape[:2])
    i, j = springs[:, 0], springs[:, 1]
    length = np.linalg.norm(positions[:, i] - positions[:, j], axis=2)
    strain = length / length.mean(axis=0) - 1.0
    acc = np.zeros((len(positions), n))
    np.add.at(acc.T, i, strain.T)
    np.add.at(acc.T, j, strain.T)
    deg = np.bincount(np.concatenate([i, j]), minlength=n).astype(float)
    return acc / np.maximum(deg, 1.0)


def _wave_fit(z: np.ndarray, coords: np.ndarray, motion: np.ndarray) -> WaveFit:
    a = np.abs(z)
    if a.max(initial=0.0) <= 0:
        return WaveFit(np.zeros(2), 0.0, 0.0, 0.0, 0.0, float("nan"), False)
    g, fit = circular_linear_fit(np.angle(z), a, coords)
    norm = float(np.linalg.norm(g))
    moving = a >= 0.1 * a.max()
    if norm > 0:
        s = coords[moving] @ (g / norm)
        lag = norm * float(s.max() - s.min())
        travel = -g / norm
        angle = math.degrees(math.acos(float(np.clip(travel @ motion, -1.0, 1.0))))
    else:
        lag, angle = 0.0, float("nan")
    ti = travelling_index(z)
    is_wave = fit >= WAVE_FIT and lag >= WAVE_LAG and ti >= WAVE_TI
    return WaveFit(np.asarray(g), float(fit), float(lag), ti, phase_coherence(z), angle, bool(is_wave))


def bending_wave(
    Q: np.ndarray, times: np.ndarray, omega: float, springs: ArrayLike, motion: Optional[ArrayLike] = None
) -> WaveFit:
    """The wave fit of a body's bending: the side-difference signal of its axial springs.

    A bending wave makes the two sides of the body contract in antiphase while the bend runs along it.
    The cells' contraction (:func:`_cell_contraction`) mixes both sides (a cell's springs run along its
    side and across to the other), so its phases are a poor linear ramp (fit 0.75-0.80 on the hand-built
    bending undulators). Here the signal is the strain of the springs that run along the body (within
    ``BEND_CONE`` of the long principal axis of the mean shape), off its midline (``BEND_BAND`` median
    rest lengths or more), with the sign of the side they lie on: ``z_s · sign(v_s)``. A bending wave is
    then a plain travelling wave along the axis, a contraction wave or a synchronous body (both sides in
    phase) two antiphase halves that do not fit. The circular-linear fit along the axis, the lag over the
    springs with at least 10 % of the largest amplitude and the travelling index of the signal give a
    :class:`WaveFit` whose criterion is fit ``>= BEND_FIT``, lag ``>= WAVE_LAG`` and travelling index
    ``>= WAVE_TI``, and the fit significant: its permutation p-value (the share of ``BEND_PERMUTATIONS``
    shuffles of the springs' positions along the axis, :func:`shuffled_fits`, that fit as well, counting
    the fit itself) ``<= BEND_P``. With a free gradient, unrelated phases on 14-22 springs fit 0.5-0.65
    (docs/locomotion.md). Last, the wave must run backward along the body, at least ``BEND_BACKWARD``
    degrees from the direction of motion: only then does a bend propel a body whose tangential drag is
    below its normal drag; a bend that runs forward or across the motion is not undulatory swimming.

    Args:
        Q: (F, n, 2) body-frame positions (:func:`procrustes_frames`). times: (F,). omega: rad per time unit.
        springs: (m, 2) springs. motion: (2,) direction of motion in the body frame (for ``angle``; without
            it no bending wave is accepted).
    """
    sp = np.asarray(springs, dtype=np.int64).reshape(-1, 2)
    none = WaveFit(np.zeros(2), 0.0, 0.0, 0.0, 0.0, float("nan"), False)
    if len(sp) == 0 or Q.shape[1] < 3:
        return none
    mean = Q.mean(axis=0)
    c = mean - mean.mean(axis=0)
    axis = np.linalg.eigh(c.T @ c)[1][:, -1]
    normal = np.array([-axis[1], axis[0]])
    i, j = sp[:, 0], sp[:, 1]
    d = c[j] - c[i]
    rest = np.linalg.norm(d, axis=1)
    ok = rest > 0
    along = np.zeros(len(sp), dtype=bool)
    along[ok] = np.abs(d[ok] @ axis) / rest[ok] >= math.cos(math.radians(BEND_CONE))
    mid = 0.5 * (c[i] + c[j])
    u, v = mid @ axis, mid @ normal
    keep = along & (np.abs(v) >= BEND_BAND * float(np.median(rest[ok])))
    if keep.sum() < 3:
        return none
    length = np.linalg.norm(Q[:, j[keep]] - Q[:, i[keep]], axis=2)
    strain = length / length.mean(axis=0) - 1.0
    z = np.atleast_1d(harmonic_amplitudes(strain, times, omega)) * np.sign(v[keep])
    a = np.abs(z)
    if a.max(initial=0.0) < CONTRACTION_FLOOR:
        return none
    g, fit = circular_linear_fit(np.angle(z), a, u[keep])
    moving = a >= 0.1 * a.max()
    lag = abs(float(g)) * float(np.ptp(u[keep][moving]))
    gradient = float(g) * axis
    if g != 0 and motion is not None:
        travel = -np.sign(g) * axis
        angle = math.degrees(math.acos(float(np.clip(travel @ np.asarray(motion, dtype=np.float64), -1.0, 1.0))))
    else:
        angle = float("nan")
    ti = travelling_index(z)
    null = shuffled_fits(np.angle(z), a, u[keep], BEND_PERMUTATIONS, BEND_SEED)
    p = (1 + int(np.sum(null >= fit))) / (1 + len(null))
    backward = angle >= BEND_BACKWARD  # nan (no motion given) compares false
    is_wave = fit >= BEND_FIT and p <= BEND_P and lag >= WAVE_LAG and ti >= WAVE_TI and backward
    return WaveFit(gradient, float(fit), float(lag), ti, phase_coherence(z), angle, bool(is_wave), float(p))


def _groups(cells: np.ndarray, springs: np.ndarray) -> int:
    """Connected components of the spring graph restricted to ``cells``."""
    from .shape import connected_groups  # noqa: PLC0415

    return len(connected_groups([int(c) for c in cells], [(int(i), int(j)) for i, j in springs]))


def _no_wave(w: WaveFit, bend: Optional[WaveFit] = None) -> str:
    def failed(x: WaveFit, fit: float) -> str:
        out = []
        if x.fit < fit:
            out.append(f"fit {x.fit:.2f} < {fit}")
        if x.p_value > BEND_P:  # nan (not tested) compares false
            out.append(f"p {x.p_value:.3f} > {BEND_P} against shuffled positions")
        if x.lag < WAVE_LAG:
            out.append(f"lag {x.lag:.2f} rad < pi/2")
        if x.travelling_index < WAVE_TI:
            out.append(f"TI {x.travelling_index:.2f} < {WAVE_TI}")
        if np.isfinite(x.p_value) and not x.angle >= BEND_BACKWARD:  # the bending wave only
            out.append(f"travels {x.angle:.0f} deg from the motion < {BEND_BACKWARD:g} (not backward)")
        return ", ".join(out)

    text = "no travelling wave (" + failed(w, WAVE_FIT) + ")"
    if bend is not None:
        text += " and no bending wave (" + failed(bend, BEND_FIT) + ")"
    return text


def _wave_reason(w: WaveFit, bend: Optional[WaveFit]) -> str:
    if w.is_wave or bend is None or not bend.is_wave:
        return (
            f"contraction phases have a consistent gradient (fit {w.fit:.2f} >= {WAVE_FIT}) with "
            f"a lag of {w.lag:.2f} rad >= pi/2 and travelling index {w.travelling_index:.2f} "
            f">= {WAVE_TI}"
        )
    return (
        f"a bending wave: the side-difference strain of the axial springs has a consistent gradient "
        f"(fit {bend.fit:.2f} >= {BEND_FIT}, p {bend.p_value:.3f} <= {BEND_P}) with a lag of {bend.lag:.2f} rad >= pi/2 and travelling "
        f"index {bend.travelling_index:.2f} >= {WAVE_TI}, running backward ({bend.angle:.0f} deg from the motion; "
        f"contraction fit {w.fit:.2f})"
    )


def classify_motion(
    positions: ArrayLike,
    times: ArrayLike,
    *,
    springs: Optional[ArrayLike] = None,
    omega: Optional[float] = None,
    cycles: float = 4,
    outline: Optional[Sequence[int]] = None,
    rest_positions: Optional[ArrayLike] = None,
    bending: Optional[bool] = None,
) -> LocomotionMode:
    """Classify the locomotion of recorded node positions (the array core of :func:`classify_locomotion`).

    Args:
        positions: (F, n, 2) node positions over time (uniformly sampled).
        times: (F,) times of the frames.
        springs: (m, 2) node index pairs of the springs (default: the Gabriel graph of the first frame,
            as the body stage would build it).
        omega: angular frequency to analyse (default: the peak of the body-frame deformation spectrum).
        cycles: analyse the last ``cycles`` whole periods, at most the second half of the record
            (at least one period when the record is long enough, else all of it).
        outline: the outer skin loop (``Body.skin_loops[0]``); with it the paper's protrusion stroke
            (:func:`animat.protrusion.stroke_motion`) is measured and decides "protrusions" first.
        rest_positions: (n, 2) the body at rest, where protrusions are also looked for (with ``outline``).
        bending: also accept a bending wave (:func:`bending_wave`) as the wave criterion; default: with
            ``outline`` (the stroke path), so that without it the earlier rules decide.
    Returns:
        A :class:`LocomotionMode`.
    """
    P = np.asarray(positions, dtype=np.float64)
    t = np.asarray(times, dtype=np.float64)
    if P.ndim != 3 or P.shape[2] != 2:
        raise ValueError(f"classify_motion: positions must be (frames, n, 2), got shape {P.shape}")
    if t.shape != (len(P),):
        raise ValueError(f"classify_motion: times must be ({len(P)},), got shape {t.shape}")
    if len(P) < 8:
        raise ValueError(f"classify_motion: need at least 8 frames, got {len(P)}")
    F, n, _ = P.shape
    sp = (
        np.asarray(_core.gabriel_graph(P[0]), dtype=np.int64)
        if springs is None
        else np.asarray(springs, dtype=np.int64).reshape(-1, 2)
    )
    if omega is None:
        half = P[F // 2 :]
        Qh, _, _ = procrustes_frames(half)
        omega = _dominant_omega(Qh, t[F // 2 :])
    omega = float(omega)
    duration = float(t[-1] - t[0])
    if omega > 0 and math.isfinite(omega):
        period = 2 * math.pi / omega
        whole = math.floor(0.5 * duration / period + 1e-9)
        k = min(cycles, whole) if whole >= 1 else min(cycles, duration / period)
        k = max(k, 0.0)
        start = t[-1] - k * period
        sel = t >= start - 1e-9 * max(1.0, abs(start))
        if sel.sum() < 8:
            sel = np.zeros(F, dtype=bool)
            sel[-8:] = True
    else:
        k = 0.0
        sel = t >= t[0] + 0.5 * duration
    W, tw = P[sel], t[sel]

    Q, R, mean_shape = procrustes_frames(W)
    centred = mean_shape - mean_shape.mean(axis=0)
    size = float(np.sqrt(np.mean(np.sum(centred**2, axis=1)))) if n else 0.0

    com = W.mean(axis=1)
    steps = np.einsum("fi,fij->fj", np.diff(com, axis=0), R[:-1])
    drift = steps.sum(axis=0)
    path = float(np.linalg.norm(com[-1] - com[0]))
    speed = path / float(tw[-1] - tw[0]) if tw[-1] > tw[0] else 0.0
    if np.linalg.norm(drift) > 1e-9 * max(size, 1.0):
        motion = drift / np.linalg.norm(drift)
    else:  # no net motion: the body's long (principal) axis
        motion = np.linalg.eigh(centred.T @ centred)[1][:, -1] if n > 1 else np.array([1.0, 0.0])

    if omega <= 0 or not math.isfinite(omega) or size == 0:
        zeros = np.zeros(n)
        return LocomotionMode(
            "none",
            (),
            0.0,
            0.0,
            0.0,
            0.0,
            None,
            omega,
            k,
            int(sel.sum()),
            motion,
            speed,
            np.zeros(0, dtype=np.int64),
            "no oscillation to analyse",
            zeros,
            zeros,
        )

    disp = harmonic_amplitudes(Q, tw, omega)  # (n, 2) complex
    amp2 = np.sum(np.abs(disp) ** 2, axis=1)  # (n,)
    deformation = float(np.sqrt(amp2.mean())) / size
    contraction = harmonic_amplitudes(_cell_contraction(Q, sp, n), tw, omega)  # (n,)
    if np.abs(contraction).max(initial=0.0) < CONTRACTION_FLOOR:  # no spring changes length: round-off only
        contraction = np.zeros(n, dtype=np.complex128)
    coherence = phase_coherence(contraction)
    ti = travelling_index(contraction)
    n_top = max(1, int(math.ceil(TOP_FRACTION * n - 1e-9)))
    order = np.argsort(-amp2, kind="stable")
    top = np.sort(order[:n_top])
    concentration = float(amp2[top].sum() / amp2.sum()) if amp2.sum() > 0 else 0.0

    if deformation < NONE_DEFORMATION:
        return LocomotionMode(
            "none",
            (),
            deformation,
            coherence,
            concentration,
            ti,
            None,
            omega,
            k,
            int(sel.sum()),
            motion,
            speed,
            top,
            f"deformation {deformation:.4f} < {NONE_DEFORMATION}: the body does not deform",
            np.angle(contraction),
            np.abs(contraction),
        )

    wave = _wave_fit(contraction, centred, motion)
    if bending is None:
        bending = outline is not None and len(outline) >= 3
    bend = bending_wave(Q, tw, omega, sp, motion) if bending else None
    is_wave = wave.is_wave or (bend is not None and bend.is_wave)
    sync = coherence >= SYNC_COHERENCE
    ca = np.abs(contraction)
    c_order = np.argsort(-ca, kind="stable")
    c_top = np.sort(c_order[:n_top])
    median = float(np.median(ca))
    contrast = (
        float(np.sqrt(np.mean(ca[c_top] ** 2))) / median
        if median > 0
        else (float("inf") if ca.max(initial=0.0) > 0 else 0.0)
    )
    local = contrast >= LOCAL_CONTRAST
    prot = concentration >= PROTRUSION_CONCENTRATION or local
    from .protrusion import STROKE_AREA, STROKE_SCORE, stroke_motion  # noqa: PLC0415 - avoids an import cycle

    stroke = None
    if outline is not None and len(outline) >= 3:
        stroke = stroke_motion(Q, tw, omega, motion, outline, sp, rest_positions)

    mixed: List[str] = []
    groups = 0
    cells = c_top if local else top
    one_appendage = prot and (_groups(cells, sp) == 1 or (stroke is not None and len(stroke.protrusions) == 1))
    if stroke is not None and stroke.strokes and not is_wave:
        mode = "protrusions"
        groups = len(stroke.protrusions)
        a, b = stroke.pair
        reason = (
            f"a symmetric pair of protrusions ({len(stroke.protrusions[a])} and {len(stroke.protrusions[b])} "
            f"cells) rows: extended while moving backwards, pair score {stroke.score:.2f} >= {STROKE_SCORE}, "
            f"stroke area {stroke.area:.3f} >= {STROKE_AREA}"
        )
    elif (
        stroke is not None and stroke.strokes
    ):  # a travelling wave runs along the body: its corners row with it (docs/locomotion.md)
        mode = "undulation"
        groups = len(stroke.protrusions)
        mixed.append("protrusions")
        reason = (
            _wave_reason(wave, bend)
            + f"; a symmetric pair of protrusions rows with the wave (pair score {stroke.score:.2f})"
        )
    elif prot and (stroke is None or one_appendage):
        groups = _groups(cells, sp)
        mode = "protrusions" if groups >= 2 and stroke is None else "tail"
        why = []
        if local:
            why.append(
                f"the most strained {n_top} of {n} cells contract {contrast:.1f} times as much as the "
                f"median cell (>= {LOCAL_CONTRAST})"
            )
        if concentration >= PROTRUSION_CONCENTRATION:
            why.append(
                f"the most mobile {n_top} of {n} cells carry {concentration:.0%} of the motion "
                f"(>= {PROTRUSION_CONCENTRATION:.0%})"
            )
        reason = (
            " and ".join(why)
            + f"; these cells form {groups} group{'s' if groups != 1 else ''} "
            + ("(appendages)" if groups >= 2 and stroke is None else "(one appendage: a tail)")
        )
        if stroke is not None and groups >= 2:
            reason += f"; no symmetric pair rows and the outline has {len(stroke.protrusions)} protrusion"
        if is_wave:
            mixed.append("undulation")
    elif is_wave:
        mode = "undulation"
        reason = _wave_reason(wave, bend)
        if sync:
            mixed.append("synchronous contraction")
    elif sync:
        mode = "synchronous contraction"
        reason = f"contraction phases coherent (R = {coherence:.2f} >= {SYNC_COHERENCE}) and {_no_wave(wave, bend)}"
    else:
        mode = "other"
        reason = f"{_no_wave(wave, bend)} and contraction phases incoherent (R = {coherence:.2f} < {SYNC_COHERENCE})"
    return LocomotionMode(
        mode,
        tuple(mixed),
        deformation,
        coherence,
        concentration,
        ti,
        wave,
        omega,
        k,
        int(sel.sum()),
        motion,
        speed,
        top,
        reason,
        np.angle(contraction),
        np.abs(contraction),
        contrast=contrast,
        groups=groups,
        stroke=stroke,
        bend=bend,
    )


def classify_locomotion(
    thing: Any,
    config: Optional[Any] = None,
    *,
    times: Optional[ArrayLike] = None,
    springs: Optional[ArrayLike] = None,
    omega: Optional[float] = None,
    cycles: float = 4,
    every: int = 1,
    stroke: bool = True,
) -> LocomotionMode:
    """Classify how a swimmer moves: undulation, synchronous contraction, protrusions, tail, other or none.

    See the module docstring for the method and the thresholds.

    Args:
        thing: a :class:`Trajectory` (from :func:`animat.replay`), or a Genome / LineageEntry /
            Embryo / Body (replayed with ``config`` for ``config.evaluation.steps`` steps, recording every
            ``every``-th step), or an (F, n, 2) positions array (then ``times`` is required).
        config: the run's config, for replaying.
        times: (F,) frame times, for a positions array.
        springs: (m, 2) springs, for a positions array (default: its first frame's Gabriel graph).
        omega: angular frequency to analyse. Default: for a body, the amplitude-weighted median of the
            cells' frequencies (the dominant actuation); for a positions array, the deformation spectrum's
            peak.
        cycles: how many of the last periods to analyse (at most the second half of the swim).
        stroke: the stroke path (default): also apply the paper's stroke rule (:mod:`animat.protrusion`,
            measured on the body's outline) and count a bending wave (:func:`bending_wave`) as a wave;
            every class reaches the held-out target there (docs/locomotion.md). ``False`` gives the earlier
            rules (no stroke, no bending wave; the strain-contrast rule finds protrusions), for comparison
            with results classified by them. A positions array has no outline: the earlier rules apply
            to it either way.
    Returns:
        A :class:`LocomotionMode`.
    """
    if isinstance(thing, Trajectory):
        tr = thing
    elif isinstance(thing, np.ndarray) or (isinstance(thing, (list, tuple)) and not hasattr(thing, "genome")):
        if times is None:
            raise ValueError("classify_locomotion: times are required with a positions array")
        return classify_motion(thing, times, springs=springs, omega=omega, cycles=cycles)
    else:
        tr = replay(thing, config, every=every)
    if omega is None:
        period = tr.period()
        omega = 2 * math.pi / period if math.isfinite(period) else 0.0
    if tr.frame_count < 8:
        raise ValueError(f"classify_locomotion: trajectory too short ({tr.frame_count} frames)")
    loops = tr.body.skin_loops
    outline = loops[0] if stroke and len(loops) else None
    return classify_motion(
        tr.positions,
        tr.times,
        springs=tr.body.springs,
        omega=omega,
        cycles=cycles,
        outline=outline,
        rest_positions=tr.body.positions if outline is not None else None,
    )


# --- the paper's stroke -------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class Paddling:
    """How the skin cells of a swim move against the paper's description of a protrusion stroke
    (module docstring, "The paper's stroke").

    Attributes:
        cells: (k,) the skin cells (outer outline), ascending.
        spike: (k,) each one's largest height above the chord of its skin neighbours over the window, in
            median rest spring lengths.
        rowing: (k,) correlation of its distance from the body's centre with its backward velocity (nan
            when either is constant).
        side: (k,) its mean body-frame coordinate across the direction of motion (sign: which side).
        pair: the two protruding cells on opposite sides with the best min(rowing), or () if none.
        score: that min(rowing); nan without such a pair.
        spike_threshold: the height from which a cell protrudes (``PADDLE_SPIKE`` unless given).
    """

    cells: np.ndarray
    spike: np.ndarray
    rowing: np.ndarray
    side: np.ndarray
    pair: Tuple[int, ...]
    score: float
    spike_threshold: float = PADDLE_SPIKE

    @property
    def paddles(self) -> bool:
        """Whether the pair score reaches :data:`PADDLE_ROWING`."""
        return bool(self.score >= PADDLE_ROWING)

    @property
    def protruding(self) -> np.ndarray:
        """The skin cells whose spike reaches ``spike_threshold``."""
        return self.cells[self.spike >= self.spike_threshold]


def paddling_motion(
    positions: ArrayLike,
    skin_loop: Sequence[int],
    rest_length: float,
    direction: ArrayLike,
    spike: float = PADDLE_SPIKE,
) -> Paddling:
    """:class:`Paddling` of a window of frames.

    Args:
        positions: (F, n, 2) positions over the window (any rigid motion; removed by Procrustes).
        skin_loop: the outer boundary walk, body on the left (``Body.skin_loops[0]``).
        rest_length: the length unit of the spike (the body's median rest spring length).
        direction: (2,) direction of motion in the body frame of :func:`procrustes_frames` (the classifier's
            ``LocomotionMode.direction``).
        spike: protrusion threshold in rest lengths.
    """
    Q, _, _ = procrustes_frames(positions)
    loop = [int(v) for v in skin_loop]
    m = len(loop)
    if m < 3 or not rest_length > 0:
        raise ValueError(
            f"paddling_motion: need a skin loop of 3 or more cells and a rest length > 0, "
            f"got {m} cells and {rest_length}"
        )
    heights: dict = {}
    for p in range(m):
        i, j, k = loop[p], loop[p - 1], loop[(p + 1) % m]
        rel = Q[:, i] - Q[:, j]
        if j == k:  # the tip of a dangling edge: its whole distance from its neighbour
            h = np.linalg.norm(rel, axis=1)
        else:
            chord = Q[:, k] - Q[:, j]
            norm = np.linalg.norm(chord, axis=1)
            # body on the left of j -> k: a convex cell lies to the right of the chord
            cross = chord[:, 0] * rel[:, 1] - chord[:, 1] * rel[:, 0]
            h = -cross / np.where(norm > 0, norm, np.inf)
        h = float(h.max()) / rest_length
        heights[i] = max(heights.get(i, -np.inf), h)  # a cell met twice (a pinch): its larger height
    cells = np.array(sorted(heights), dtype=np.int64)
    spikes = np.array([heights[int(c)] for c in cells])
    d = np.asarray(direction, dtype=np.float64)
    d = d / np.linalg.norm(d)
    along = Q[:, cells] @ d
    radius = np.linalg.norm(Q[:, cells], axis=2)
    backward = -np.gradient(along, axis=0)
    rowing = np.full(len(cells), np.nan)
    for q in range(len(cells)):
        if np.ptp(radius[:, q]) > 0 and np.ptp(backward[:, q]) > 0:
            rowing[q] = float(np.corrcoef(radius[:, q], backward[:, q])[0, 1])
    side = Q[:, cells].mean(axis=0) @ np.array([-d[1], d[0]])
    pair: Tuple[int, ...] = ()
    score = float("nan")
    cand = [q for q in range(len(cells)) if spikes[q] >= spike and np.isfinite(rowing[q])]
    for a in cand:
        for b in cand:
            if a < b and side[a] * side[b] < 0:
                s = min(rowing[a], rowing[b])
                if not s <= score:  # first pair, or a better one
                    pair, score = (int(cells[a]), int(cells[b])), float(s)
    return Paddling(cells, spikes, rowing, side, pair, score, float(spike))


def paddling(trajectory: Trajectory, mode: Optional[LocomotionMode] = None) -> Paddling:
    """:class:`Paddling` of a recorded swim over the window of the classifier's ``mode`` (last
    ``mode.cycles`` periods; its direction of motion). ``mode`` defaults to
    :func:`classify_locomotion` of the trajectory."""
    if mode is None:
        mode = classify_locomotion(trajectory)
    window = np.asarray(trajectory.positions)[-max(int(mode.frames), 2) :]  # the classifier's window: a suffix
    rest = float(np.median(np.asarray(trajectory.body.rest_lengths)))
    return paddling_motion(window, trajectory.body.skin_loops[0], rest, mode.direction)


# --- statistics of the best individuals ------------------------------------------------------------------


@dataclass(frozen=True)
class GrowOutput:
    """The grow output (paper §2.2: "the gene responsible for size increase") of an embryo.

    Attributes:
        final_mean, final_min, final_max: the grow output (column 2 of ``Embryo.outputs``, in [0, 1]) of
            the cells at the end of development.
        realized: mean over the daughter cells of ``(r / cell_radius - 1) / max_growth``, the grow level
            their mothers had at the division that made them (the radius is set then, ``r0 (1 +
            max_growth · grow)``); nan for a single cell.
        realized_min: the smallest of those.
    """

    final_mean: float
    final_min: float
    final_max: float
    realized: float
    realized_min: float


def grow_output(embryo: Any, config: Optional[Any] = None) -> GrowOutput:
    """Measure the grow output of an embryo (or a Genome / LineageEntry developed with ``config``).

    Reads ``Embryo.outputs[:, OutputChannel.grow]`` (final GRN levels) and ``Embryo.radii`` with the
    config's ``development.cell_radius`` and ``development.max_growth``. Cell 0 (the zygote, radius r0)
    is excluded from ``realized``.
    """
    cfg = config if config is not None else _core.Config()
    thing = embryo
    if hasattr(thing, "genome") and not isinstance(thing, _core.Genome):  # LineageEntry
        thing = thing.genome
    if isinstance(thing, _core.Genome):
        thing = _core.develop(thing, cfg)
    grow = np.asarray(thing.outputs)[:, int(_core.OutputChannel.grow)]
    r0 = float(cfg["development.cell_radius"])
    mg = float(cfg["development.max_growth"])
    radii = np.asarray(thing.radii)[1:]
    realized = (radii / r0 - 1.0) / mg if mg > 0 and len(radii) else np.array([np.nan])
    return GrowOutput(
        float(grow.mean()), float(grow.min()), float(grow.max()), float(np.mean(realized)), float(np.min(realized))
    )


@dataclass(frozen=True)
class PhaseSpread:
    """How differentiated a set of phases is (on the circle).

    Attributes:
        range: the shortest arc holding every phase (rad, 0..2π): 2π minus the largest gap.
        circular_std: sqrt(-2 ln R) with R the mean resultant length (rad; 0 when all equal).
        distinct: number of distinct phases (rounded to 1e-6 rad).
        differentiated: ``range > PHASE_DIFFERENTIATED``.
    """

    range: float
    circular_std: float
    distinct: int
    differentiated: bool


def phase_spread(phases: ArrayLike) -> PhaseSpread:
    """:class:`PhaseSpread` of (n,) phases in radians (any range; taken modulo 2π)."""
    p = np.mod(np.asarray(phases, dtype=np.float64).ravel(), 2 * math.pi)
    if len(p) == 0:
        return PhaseSpread(0.0, 0.0, 0, False)
    s = np.sort(p)
    gaps = np.diff(np.append(s, s[0] + 2 * math.pi))
    rng = float(max(0.0, 2 * math.pi - gaps.max()))
    R = float(abs(np.exp(1j * p).mean()))
    std = 0.0 if R >= 1.0 - 1e-12 else (float(math.sqrt(-2.0 * math.log(R))) if R > 0 else float("inf"))
    distinct = len(np.unique(np.round(p, 6) % round(2 * math.pi, 6)))
    return PhaseSpread(rng, std, int(distinct), rng > PHASE_DIFFERENTIATED)


@dataclass(frozen=True)
class OscillatorSpread:
    """The oscillator parameters of a body, per cell (paper eq. 2).

    Attributes:
        amplitude_mean, amplitude_min, amplitude_max: of ``Body.amplitude``.
        amplitude_relative: amplitude_mean / development.amplitude_max (1 = every cell at the maximum).
        amplitude_range: (max - min) / development.amplitude_max.
        amplitude_differentiated: ``amplitude_range > AMPLITUDE_DIFFERENTIATED``.
        frequency_min, frequency_max: of ``Body.frequency`` (rad per time unit).
        frequency_range: (max - min) / (development.frequency_max - development.frequency_min).
        frequency_differentiated: ``frequency_range > FREQUENCY_DIFFERENTIATED``.
        phase: :class:`PhaseSpread` of ``Body.phase``.
        spring_amplitude_mean, spring_amplitude_range: effective relative rest-length amplitude of the
            springs, ``|a_i e^{iφ_i} + a_j e^{iφ_j}|`` (eq. 2 with equal frequencies; with unequal
            frequencies the sum of the two amplitudes is used), mean and max - min.
    """

    amplitude_mean: float
    amplitude_min: float
    amplitude_max: float
    amplitude_relative: float
    amplitude_range: float
    amplitude_differentiated: bool
    frequency_min: float
    frequency_max: float
    frequency_range: float
    frequency_differentiated: bool
    phase: PhaseSpread
    spring_amplitude_mean: float
    spring_amplitude_range: float


def oscillator_spread(body: Any, config: Optional[Any] = None) -> OscillatorSpread:
    """Amplitude, frequency and phase spread across the cells (and springs) of a body.

    ``body`` is a Body, or anything :func:`animat.trajectory.body_of` accepts (Genome / LineageEntry
    with ``config``, Embryo, Trajectory). Reads ``Body.amplitude``, ``Body.frequency``, ``Body.phase``
    and ``Body.springs``; ``development.amplitude_max`` from ``config`` (default config if None).
    """
    cfg = config if config is not None else _core.Config()
    b = body_of(body, cfg)
    a = np.asarray(b.amplitude, dtype=np.float64)
    f = np.asarray(b.frequency, dtype=np.float64)
    p = np.asarray(b.phase, dtype=np.float64)
    amax = float(cfg["development.amplitude_max"])
    fspan = float(cfg["development.frequency_max"]) - float(cfg["development.frequency_min"])
    sp = np.asarray(b.springs, dtype=np.int64).reshape(-1, 2)
    if len(sp):
        i, j = sp[:, 0], sp[:, 1]
        same = np.isclose(f[i], f[j], rtol=0, atol=1e-12)
        eff = np.where(same, np.abs(a[i] * np.exp(1j * p[i]) + a[j] * np.exp(1j * p[j])), a[i] + a[j])
        s_mean, s_range = float(eff.mean()), float(np.ptp(eff))
    else:
        s_mean = s_range = 0.0
    if len(a) == 0:
        return OscillatorSpread(0, 0, 0, 0, 0, False, 0, 0, 0, False, phase_spread(p), s_mean, s_range)
    arange = float(np.ptp(a) / amax) if amax > 0 else 0.0
    frange = float(np.ptp(f) / fspan) if fspan > 0 else 0.0
    return OscillatorSpread(
        float(a.mean()),
        float(a.min()),
        float(a.max()),
        float(a.mean() / amax) if amax > 0 else 0.0,
        arange,
        arange > AMPLITUDE_DIFFERENTIATED,
        float(f.min()),
        float(f.max()),
        frange,
        frange > FREQUENCY_DIFFERENTIATED,
        phase_spread(p),
        s_mean,
        s_range,
    )


def tries_per_viable(history: Any, population: Optional[int] = None) -> float:
    """Random genomes drawn per viable individual of the initial population (paper §5: "a few hundred").

    ``history`` is a :class:`Run` (its history and ``evolution.population``) or a history array (then
    ``population`` is required). Generation 0's ``evaluations`` counts every random genome tried until
    the population was full of viable ones, so the ratio is ``evaluations[0] / population``. nan when
    generation 0 is not recorded yet.
    """
    if isinstance(history, Run):
        if population is None:
            population = int(history.config["evolution.population"])
        history = history.history
    if population is None or population <= 0:
        raise ValueError("tries_per_viable: population must be given (a positive int) with a history array")
    h = np.asarray(history)
    if len(h) == 0:
        return float("nan")
    row = h[h["generation"] == 0]
    if len(row) == 0:
        return float("nan")
    return float(row["evaluations"][0]) / float(population)


def _morphology(entry: Any, config: Any):
    genome = entry.genome if hasattr(entry, "genome") and not isinstance(entry, _core.Genome) else entry
    embryo = _core.develop(genome, config)
    if not embryo.viable:
        return None
    pos = np.asarray(embryo.positions)
    try:
        graph = frozenset(map(tuple, np.asarray(_core.gabriel_graph(pos, config)).tolist()))
    except ValueError:
        graph = frozenset()
    return pos, graph


def morphology_changes(
    lineage: Union[Run, Sequence[LineageEntry]],
    config: Optional[Any] = None,
    tolerance: float = MORPHOLOGY_TOLERANCE,
    graph: bool = True,
) -> List[LineageEntry]:
    """The lineage entries at which the best individual's morphology changed.

    Every lineage genome is developed (``animat.develop``); an entry is a change when its cell count
    differs from the previous (viable) entry's, when :func:`animat.morphology_distance` (RMS cell
    displacement after the best rigid alignment) exceeds ``tolerance``, or, with ``graph``, when the body
    graph (the Gabriel graph of the cell centres: which cells are joined by springs) differs. A
    control-only mutation changes none of these. The first entry always counts; non-viable entries are
    skipped.

    Args:
        lineage: a :class:`Run` (its ``best_genomes`` and config) or a sequence of LineageEntry.
        config: the config to develop with (default: the run's, or the animat defaults).
    """
    if isinstance(lineage, Run):
        cfg = lineage.config if config is None else config
        entries = lineage.best_genomes
    else:
        cfg = config if config is not None else _core.Config()
        entries = list(lineage)
    out: List[LineageEntry] = []
    previous = None
    for e in entries:
        m = _morphology(e, cfg)
        if m is None:
            continue
        if previous is None:
            out.append(e)
        else:
            changed = (
                len(m[0]) != len(previous[0])
                or morphology_distance(previous[0], m[0]) > tolerance
                or (graph and m[1] != previous[1])
            )
            if changed:
                out.append(e)
        previous = m
    return out


def last_morphology_change(
    lineage: Union[Run, Sequence[LineageEntry]],
    config: Optional[Any] = None,
    tolerance: float = MORPHOLOGY_TOLERANCE,
    graph: bool = True,
) -> Optional[int]:
    """The generation at which the best's morphology last differed from its predecessor's (see
    :func:`morphology_changes`); the generation of the first entry when it never changed; None for an
    empty lineage."""
    changes = morphology_changes(lineage, config, tolerance, graph)
    return changes[-1].generation if changes else None


@dataclass(frozen=True)
class BestStatistics:
    """The paper's claims measured on one best individual.

    Attributes:
        cells, max_cells: cells of the embryo and ``development.max_cells``.
        grow: :class:`GrowOutput`. oscillators: :class:`OscillatorSpread`.
    """

    cells: int
    max_cells: int
    grow: GrowOutput
    oscillators: OscillatorSpread


def best_statistics(entry: Any, config: Optional[Any] = None) -> BestStatistics:
    """Cell count, grow output and oscillator spread of a genome / LineageEntry developed with ``config``."""
    cfg = config if config is not None else _core.Config()
    genome = entry.genome if hasattr(entry, "genome") and not isinstance(entry, _core.Genome) else entry
    embryo = _core.develop(genome, cfg)
    if not embryo.viable:
        raise ValueError("best_statistics: genome is not viable: " + "; ".join(embryo.reasons))
    return BestStatistics(
        int(embryo.cell_count),
        int(cfg["development.max_cells"]),
        grow_output(embryo, cfg),
        oscillator_spread(_core.build_body(embryo, cfg), cfg),
    )
