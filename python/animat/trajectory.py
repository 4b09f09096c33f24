"""Replaying a swim: :func:`replay` returns a :class:`Trajectory` with positions, the centre of
mass and the actuation state (expanding / contracting / neutral) of every cell and spring per frame.

Actuation (paper eq. 2). The rest length of spring (i, j) is ``L = (1 + u_i(t) + u_j(t)) * L0``
with the cell term ``u_i(t) = a_i sin(f_i t + phi_i)`` once ``t >= t0_i`` (the paper's delayed start,
``animat.actuation_start_time``), else 0. The *rate* of a cell is ``du_i/dt = a_i f_i cos(f_i t +
phi_i)`` (0 before its start): how fast the cell is lengthening (> 0) or shortening (< 0) the rest
lengths of all its springs, in units of L0 per time unit. The rate of spring (i, j) is
``(dL/dt) / L0 = du_i/dt + du_j/dt``.

State. A cell or spring is *expanding* (+1, red in the paper) when its rate is above the neutral
threshold, *contracting* (-1, blue) when it is below minus the threshold, and *neutral* (0, green)
otherwise. The threshold is ``neutral * max_i(a_i f_i)``: a fraction (default 0.1,
:data:`DEFAULT_NEUTRAL`) of the largest rate any cell of the body can reach. So a cell is neutral
near the turning points of its oscillation (``|cos| <= 0.1`` for the fastest cell), while it has
not started yet, and always when its own ``a_i f_i`` is below the threshold (a practically
non-oscillating cell). A body without any oscillation is neutral everywhere.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np

from . import _core

__all__ = [
    "Trajectory",
    "replay",
    "actuation_terms",
    "actuation_rates",
    "actuation_start_times",
    "classify_rates",
    "EXPANDING",
    "CONTRACTING",
    "NEUTRAL",
    "STATE_NAMES",
    "DEFAULT_NEUTRAL",
    "body_of",
    "chemotaxis_source",
]

#: Actuation state codes used in :attr:`Trajectory.node_state` and :attr:`Trajectory.spring_state`.
EXPANDING = 1
CONTRACTING = -1
NEUTRAL = 0
STATE_NAMES = {EXPANDING: "expanding", CONTRACTING: "contracting", NEUTRAL: "neutral"}
#: Default neutral band: a fraction of the body's largest possible cell rate max_i(a_i f_i).
DEFAULT_NEUTRAL = 0.1


def actuation_start_times(frequency: np.ndarray, phase: np.ndarray) -> np.ndarray:
    """Start time of every cell's oscillation (paper §3), ``animat.actuation_start_time`` per cell.

    Args:
        frequency, phase: (n,) float arrays.
    Returns:
        (n,) float64 array; +inf for a cell that never starts.
    """
    return np.array(
        [_core.actuation_start_time(float(f), float(p)) for f, p in zip(frequency, phase)], dtype=np.float64
    )


def _broadcast(amplitude, frequency, phase, t):
    a = np.asarray(amplitude, dtype=np.float64)
    f = np.asarray(frequency, dtype=np.float64)
    p = np.asarray(phase, dtype=np.float64)
    t = np.asarray(t, dtype=np.float64)
    start = actuation_start_times(f, p)
    tt = t[..., None]  # (..., 1) against (n,)
    return a, f, p, tt, tt >= start


def actuation_terms(amplitude, frequency, phase, t) -> np.ndarray:
    """Eq. 2's cell terms ``u_i(t)``: ``a_i sin(f_i t + phi_i)`` once started, else 0.

    Vectorised ``animat.actuation_term``. Args: (n,) arrays amplitude, frequency, phase; t a
    scalar or an array of times, shape T. Returns a float64 array of shape T + (n,).
    """
    a, f, p, tt, started = _broadcast(amplitude, frequency, phase, t)
    return np.where(started, a * np.sin(f * tt + p), 0.0)


def actuation_rates(amplitude, frequency, phase, t) -> np.ndarray:
    """Time derivative of eq. 2's cell terms: ``a_i f_i cos(f_i t + phi_i)`` once started, else 0.

    Units: rest length L0 per time unit. Same arguments and shape as :func:`actuation_terms`.
    """
    a, f, p, tt, started = _broadcast(amplitude, frequency, phase, t)
    return np.where(started, a * f * np.cos(f * tt + p), 0.0)


def classify_rates(rates: np.ndarray, threshold: float) -> np.ndarray:
    """Map rates to states: :data:`EXPANDING` (+1) if ``rate > threshold``, :data:`CONTRACTING`
    (-1) if ``rate < -threshold``, else :data:`NEUTRAL` (0). Returns an int8 array of the same shape."""
    rates = np.asarray(rates, dtype=np.float64)
    out = np.zeros(rates.shape, dtype=np.int8)
    out[rates > threshold] = EXPANDING
    out[rates < -threshold] = CONTRACTING
    return out


def _swims_per_source(config: Any) -> int:
    """The swims of one evaluation, one per source direction, under an objective that one swim does
    not decide (``chemotaxis``: ``evaluation.source_directions``); 0 under any other objective."""
    name = str(config["evaluation.objective"])
    if any(spec.name == name and not spec.one_swim for spec in _core.objectives()):
        return max(1, int(config["evaluation.source_directions"]))
    return 0


def chemotaxis_source(config: Any, trial: int = 0) -> np.ndarray:
    """The chemical source of swim ``trial`` of an evaluation under objective ``chemotaxis``,
    relative to the body's start centre: ``scene.chemical_source`` rotated by offset + 2π·trial/T
    (T = ``evaluation.source_directions``), the offset uniform in [0, 2π) drawn from
    ``evaluation.source_seed``, the same for every genome (docs/control.md). The engine computes it
    (``source_direction``, src/evaluate.cpp): the swims of :func:`replay` with ``source_trial`` 0 to
    T - 1 average to the evaluation's fitness.
    """
    count = max(1, int(config["evaluation.source_directions"]))
    if not 0 <= trial < count:
        raise ValueError(f"chemotaxis_source: trial {trial} is not one of the {count} evaluation.source_directions")
    return np.asarray(_core.source_direction(config, int(trial)), dtype=float)


def body_of(thing: Any, config: Optional[Any] = None):
    """The :class:`animat.Body` of a Body, an Embryo, a Genome, a LineageEntry or a Trajectory.

    A genome is developed with ``config`` (ValueError if the embryo is not viable, naming the
    reasons) and built into a body; an embryo is built into a body.
    """
    if isinstance(thing, _core.Body):
        return thing
    if isinstance(thing, Trajectory):
        return thing.body
    if hasattr(thing, "genome") and not isinstance(thing, _core.Genome):  # LineageEntry
        thing = thing.genome
    if isinstance(thing, _core.Genome):
        thing = _core.develop(thing, config)
        if not thing.viable:
            raise ValueError("genome is not viable: " + "; ".join(thing.reasons))
    if isinstance(thing, _core.Embryo):
        return _core.build_body(thing, config)
    raise TypeError(f"expected an animat.Genome, Embryo, Body, LineageEntry or Trajectory, got {type(thing).__name__}")


@dataclass(eq=False)
class Trajectory:
    """A recorded swim: F frames of a body with n nodes (cells) and m springs.

    Arrays (all numpy, float64 unless stated):

    - ``positions``: (F, n, 2) node positions.
    - ``velocities``: (F, n, 2) node velocities.
    - ``times``: (F,) simulated time of each frame; ``steps``: (F,) int64 control steps.
    - ``com``: (F, 2) centre of mass (the mean position: all cells have the same mass).
    - ``node_terms``: (F, n) eq. 2 cell terms ``u_i(t)`` (relative rest-length change a cell
      applies to each of its springs).
    - ``node_rates``: (F, n) ``du_i/dt``; ``node_state``: (F, n) int8, +1 expanding, -1
      contracting, 0 neutral (see the module docstring for the threshold).
    - ``spring_rates``: (F, m) ``(dL/dt)/L0 = du_i/dt + du_j/dt``; ``spring_state``: (F, m) int8.
    - ``rest_lengths``: (F, m) eq. 2 rest lengths ``(1 + u_i + u_j) L0``.

    The body (``body``: springs, skin, regions, oscillator parameters) is the :class:`animat.Body`
    that swam. ``stable`` is False if the simulation left its valid domain; the frames then stop
    at the last valid state and ``failure`` holds the message. ``config`` is the config it swam
    with; ``meta`` holds ``neutral``, ``control`` ("open_loop" or "grn"), ``scene`` (the
    :class:`animat.Scene` that overrode ``config.scene``, or None) and, under objective
    ``chemotaxis``, ``source_trial`` and ``source_trials`` (which of the evaluation's swims it is).
    """

    body: Any
    positions: np.ndarray
    velocities: np.ndarray
    times: np.ndarray
    steps: np.ndarray
    com: np.ndarray
    node_terms: np.ndarray
    node_rates: np.ndarray
    node_state: np.ndarray
    spring_rates: np.ndarray
    spring_state: np.ndarray
    rest_lengths: np.ndarray
    neutral_threshold: float
    dt: float
    every: int
    config: Any = None
    stable: bool = True
    failure: str = ""
    meta: dict = field(default_factory=dict)

    # --- body views -----------------------------------------------------------------------------
    @property
    def springs(self) -> np.ndarray:
        """(m, 2) int64 node indices of every spring."""
        return self.body.springs

    @property
    def skin(self) -> np.ndarray:
        """(k, 2) int64 skin edges (the outline that feels drag)."""
        return self.body.skin

    @property
    def skin_loops(self) -> list:
        """List of (l,) int64 closed walks of the outline (counter-clockwise)."""
        return self.body.skin_loops

    @property
    def regions(self) -> list:
        """List of (k,) int64 vertex loops of the pressurised regions."""
        return self.body.regions

    @property
    def frame_count(self) -> int:
        """Number of frames F."""
        return int(self.positions.shape[0])

    @property
    def node_count(self) -> int:
        """Number of nodes n."""
        return int(self.positions.shape[1])

    def __len__(self) -> int:
        return self.frame_count

    # --- motion ---------------------------------------------------------------------------------
    @property
    def displacement(self) -> np.ndarray:
        """(2,) centre-of-mass displacement, last frame minus first."""
        return self.com[-1] - self.com[0]

    @property
    def distance(self) -> float:
        """Straight-line distance of the centre of mass, first to last frame (the fitness for a full
        ``config.evaluation.steps`` replay of a stable swim)."""
        return float(np.linalg.norm(self.displacement))

    @property
    def direction(self) -> np.ndarray:
        """(2,) unit vector of the overall direction of motion ((1, 0) if the body did not move)."""
        d = self.displacement
        norm = float(np.linalg.norm(d))
        return d / norm if norm > 1e-12 else np.array([1.0, 0.0])

    def speed(self) -> np.ndarray:
        """(F,) speed of the centre of mass (mean node velocity norm)."""
        return np.linalg.norm(self.velocities.mean(axis=1), axis=1)

    def period(self) -> float:
        """The dominant oscillation period 2π/f in time units.

        f is the amplitude-weighted median frequency of the cells that oscillate (a_i > 0); inf
        when no cell oscillates.
        """
        a = np.asarray(self.body.amplitude)
        f = np.asarray(self.body.frequency)
        keep = (a > 0) & (f > 0)
        if not keep.any():
            return math.inf
        order = np.argsort(f[keep])
        fs, ws = f[keep][order], a[keep][order]
        cum = np.cumsum(ws)
        fdom = float(fs[np.searchsorted(cum, 0.5 * cum[-1])])
        return 2.0 * math.pi / fdom

    def cycle_frames(self, count: int = 6, end: Optional[int] = None) -> list:
        """``count`` frame indices evenly spread over one dominant period (see :meth:`period`),
        ending at frame ``end`` (default: the last frame, i.e. the settled swim). The period is
        clipped to the recorded time span; the first index is the start of the cycle and the last
        index is one step (frame) short of a full cycle, so the frames do not repeat."""
        if self.frame_count == 0:
            return []
        end = self.frame_count - 1 if end is None else int(end) % self.frame_count
        frame_dt = self.dt * self.every
        span_frames = self.period() / frame_dt if math.isfinite(self.period()) else end
        span_frames = min(span_frames, end)
        start = end - span_frames
        picks = [int(round(start + k * span_frames / count)) for k in range(count)]
        return sorted(set(min(max(p, 0), end) for p in picks))

    def frame_index(self, step: int) -> int:
        """Index of the frame recorded at control step ``step`` (ValueError if none was)."""
        hits = np.nonzero(self.steps == step)[0]
        if not len(hits):
            raise ValueError(
                f"no frame at step {step} (frames are every {self.every} steps, "
                f"{int(self.steps[0])}..{int(self.steps[-1])})"
            )
        return int(hits[0])

    def __repr__(self) -> str:
        return (
            f"<animat.Trajectory {self.frame_count} frames (every {self.every} steps, t = "
            f"{self.times[0]:.3g}..{self.times[-1]:.3g}), {self.node_count} nodes, "
            f"{len(self.body.springs)} springs, distance {self.distance:.4g}"
            f"{'' if self.stable else ', UNSTABLE'}>"
        )


def replay(
    genome_or_body: Any,
    config: Optional[Any] = None,
    steps: Optional[int] = None,
    every: int = 1,
    scene: Optional[Any] = None,
    neutral: float = DEFAULT_NEUTRAL,
    source_trial: Optional[int] = None,
) -> Trajectory:
    """Swim a genome (or a developed embryo, or a body) again and record it.

    The swim is the one ``animat.evaluate`` does: ``develop`` → ``build_body`` → ``Simulation``
    with ``config``'s scene and physics (in the crawl world placed on the floor and settled first,
    ``animat._core.start_state``; frame 0 is the settled start), so a full replay of a run's best genome with the run's
    config travels exactly its recorded fitness (``trajectory.distance``).

    Args:
        genome_or_body: an :class:`animat.Genome`, a :class:`LineageEntry` (e.g. ``run.best()``),
            an :class:`animat.Embryo` or an :class:`animat.Body`.
        config: an :class:`animat.Config` (e.g. ``run.config``); None = defaults.
        steps: control steps to swim (default ``config.evaluation.steps``).
        every: record a frame every ``every`` control steps; frame 0 is the initial state, so
            there are ``steps // every + 1`` frames (trailing steps that do not fill a frame are
            not run).
        scene: an :class:`animat.Scene` overriding ``config.scene``.
        neutral: the neutral band as a fraction of the body's largest cell rate ``max_i a_i f_i``
            (see the module docstring); 0 makes every moving cell red or blue.
        source_trial: objective ``chemotaxis`` only: which of the evaluation's
            ``evaluation.source_directions`` swims to replay (default 0, the first).

    Under ``control.mode = "grn"`` (docs/control.md) the genome's GRN drives the actuation while it
    swims, as in ``animat.evaluate`` (the chemical source at ``scene.chemical_source`` from the start
    centre); the cell terms are the controller's, their rates the terms' time derivative between
    frames, and the neutral band ``neutral`` times the largest rate seen. That needs the genome: a
    Body or an Embryo under such a config is a ValueError.

    Under objective ``chemotaxis`` an evaluation swims once per source direction and scores the mean
    progress toward the source; the replay is one of those swims, ``source_trial`` (default the
    first, the one whose diagnostics the evaluation records), with the source where that swim has it
    (:func:`chemotaxis_source`, never ``scene.chemical_source`` itself). The trajectory's ``config``
    (and ``scene``) then hold that source, so figures draw it where the body swam toward it, and
    ``meta`` says which swim it is: ``source_trial`` and ``source_trials`` (T).

    Returns:
        A :class:`Trajectory`. A swim that leaves the simulator's valid domain stops early:
        ``stable`` is False, ``failure`` holds the message and a RuntimeWarning is issued.

    Raises:
        ValueError: a non-viable genome, bad ``steps``/``every``/``neutral``.
    """
    cfg = config if config is not None else _core.Config()
    if every < 1:
        raise ValueError(f"replay: every must be >= 1, got {every}")
    if neutral < 0:
        raise ValueError(f"replay: neutral must be >= 0, got {neutral}")
    n_steps = int(cfg["evaluation.steps"] if steps is None else steps)
    if n_steps < 0:
        raise ValueError(f"replay: steps must be >= 0, got {n_steps}")
    grn = str(cfg["control.mode"]) == "grn"
    trials = _swims_per_source(cfg)
    meta: dict = {"neutral": float(neutral), "control": "grn" if grn else "open_loop"}
    if source_trial is not None and not trials:
        raise ValueError(
            f"replay: source_trial is for objective 'chemotaxis' (one swim per source direction), "
            f"not {cfg['evaluation.objective']!r}"
        )
    if trials:  # the swim of the evaluation: its source, sensed (config) and drawn (config, scene)
        trial = 0 if source_trial is None else int(source_trial)
        source = [float(v) for v in chemotaxis_source(cfg, trial)]
        cfg = cfg.copy()
        cfg["scene.chemical_source"] = source
        if scene is not None:
            scene = scene.replace(chemical_source=source)
        meta.update(source_trial=trial, source_trials=trials)
    meta["scene"] = scene
    genome = genome_or_body
    if hasattr(genome, "genome") and not isinstance(genome, _core.Genome):  # LineageEntry
        genome = genome.genome
    if grn and not isinstance(genome, _core.Genome):
        raise ValueError(
            "replay: control.mode = 'grn' runs the genome's GRN while swimming; pass the Genome "
            f"(or a LineageEntry), not a {type(genome_or_body).__name__}"
        )
    body = body_of(genome_or_body, cfg)
    # The crawl world (docs/worlds.md): placed on the floor and settled, exactly as evaluate() does.
    body, start_velocities, settled = _core.start_state(body, scene, cfg)
    control = None
    if grn:  # the GRN writes the rest lengths: no open-loop actuation beside it (as in evaluate())
        base: Any = scene if scene is not None else _core.Scene.from_config(cfg)
        sim = _core.Simulation(body, base.replace(effects=[e for e in base.effects if e != "actuation"]), cfg)
        control = sim.add_grn_control(body, genome, cfg)
    else:
        sim = _core.Simulation(body, scene, cfg)
    if settled:
        sim.velocities = start_velocities
    frames = n_steps // every + 1
    n = body.node_count
    pos = np.empty((frames, n, 2))
    vel = np.empty((frames, n, 2))
    times = np.empty(frames)
    steps_done = np.empty(frames, dtype=np.int64)
    grn_terms = np.zeros((frames, n)) if control is not None else None
    failure = ""
    recorded = 0
    for k in range(frames):
        if k:
            try:
                sim.step(every)
            except RuntimeError as e:
                failure = str(e)
                break
        pos[k] = sim.positions
        vel[k] = sim.velocities
        times[k] = sim.time
        steps_done[k] = sim.steps_done
        if grn_terms is not None and control is not None:
            grn_terms[k] = control.terms
        recorded += 1
    if failure:
        import warnings

        warnings.warn(
            f"replay: swim became unstable after {int(steps_done[recorded - 1])} steps: {failure}",
            RuntimeWarning,
            stacklevel=2,
        )
    pos, vel, times, steps_done = pos[:recorded], vel[:recorded], times[:recorded], steps_done[:recorded]

    a, f, p = body.amplitude, body.frequency, body.phase
    if grn_terms is not None:
        terms = grn_terms[:recorded]
        rates = np.gradient(terms, times, axis=0) if recorded > 1 else np.zeros_like(terms)
        peak = float(np.abs(rates).max()) if rates.size else 0.0
    else:
        terms = actuation_terms(a, f, p, times)
        rates = actuation_rates(a, f, p, times)
        peak = float(np.max(a * f)) if n else 0.0
    threshold = neutral * peak
    springs = body.springs
    i, j = springs[:, 0], springs[:, 1]
    spring_rates = rates[:, i] + rates[:, j]
    rest = (1.0 + terms[:, i] + terms[:, j]) * body.rest_lengths[None, :]
    return Trajectory(
        body=body,
        positions=pos,
        velocities=vel,
        times=times,
        steps=steps_done,
        com=pos.mean(axis=1),
        node_terms=terms,
        node_rates=rates,
        node_state=classify_rates(rates, threshold),
        spring_rates=spring_rates,
        spring_state=classify_rates(spring_rates, threshold),
        rest_lengths=rest,
        neutral_threshold=threshold,
        dt=float(cfg["physics.dt"]),
        every=int(every),
        config=cfg,
        stable=not failure,
        failure=failure,
        meta=meta,
    )
