"""A control environment for active-control research: :class:`SwimEnv`, a developed body in the
swim physics with its actuation set by a controller, following the Gymnasium API.

``gymnasium`` is an optional dependency (``pip install animat[control]``); without it SwimEnv
raises ImportError naming the package. With it, ``import animat`` registers the environment as
:data:`SWIM_ENV_ID` (``"animat/Swim-v0"``), so ``gymnasium.make("animat/Swim-v0")`` builds one (any
keyword argument of :class:`SwimEnv` passes through; ``episode_steps=`` sets its episode length,
since ``gymnasium.make`` keeps ``max_episode_steps=`` for its own ``TimeLimit`` wrapper). Its spec's
``max_episode_steps`` is :data:`DEFAULT_EPISODE_STEPS` (1000), the default env's episode; an env
whose own episode is longer (a config with more ``evaluation.steps``) needs the same number as
``gymnasium.make(..., max_episode_steps=)`` too, or the wrapper truncates it at 1000.

Without a body the env swims :func:`default_swimmer` under the config (default: ``animat.Config()``,
the paper's d_N = 2 environment): the best genome of the replication study at d_N = 2
(``data/replication/dn2/run_9``, generation 549, the best of its ten runs), a 32-cell body that
swims 37.95 length units in an evaluation's 4000 steps. It is packaged as ``default_swimmer.json``
(:data:`DEFAULT_SWIMMER_PATH`).

Actions set every cell's actuation (eq. 2: the rest length of spring (i, j) is
``(1 + u_i + u_j) L0``); the body's own oscillators are off. Actions are normalised to [-1, 1]
(``normalize_actions=False``: in physical units, the ``physical_action_space``, float64 so that the
body's own controller passes unrounded; the normalised action space is float32); with
``a_max = development.amplitude_max`` (the paper's 0.2):

- ``mode="rest_length"``: shape (n,), ``u_i = a_max · action_i`` (physically ``u`` in
  ``[-a_max, a_max]``);
- ``mode="oscillator"``: shape (2n,), amplitudes then phases, ``amplitude_i = a_max · (action_i + 1) / 2``
  in ``[0, a_max]`` and ``phase_i = π · (action_{n+i} + 1)`` in ``[0, 2π]``;
  ``u_i = amplitude_i · sin(f_i t + phase_i)`` with the body's frequencies (or ``frequency=``),
  stepped exactly as the body's own oscillators (effect ``actuation``). With ``delayed_start=True``
  each cell starts as the paper's cells do, at the first zero of its sine (docs/control.md), so the
  body's own amplitudes and phases (:meth:`SwimEnv.own_action`) swim it exactly as
  :func:`animat.evaluate` does.

:meth:`SwimEnv.physical_action` and :meth:`SwimEnv.normalized_action` convert between the two. An
action holds for ``frame_skip`` control steps.

Observations, shape (4n + m,), float32, in the Box ``[-obs_limit, obs_limit]`` (default 10): the cell
positions relative to the centre of mass in body lengths (n × 2, flattened; below 1 in magnitude for
any body whose cells stay within its body length ``animat.body_length`` of each other), the cell
velocities relative to the centre-of-mass velocity in body lengths per time unit (n × 2), and the
spring strains ``length / L0 - 1`` (m). A component beyond ``obs_limit`` (only a body torn far apart
or moving absurdly fast: the swim is then invalid anyway) is clipped to it, and a non-finite one
(a failed step) set to 0; ``info["obs_clipped"]`` counts the components clipped in that observation
and :attr:`SwimEnv.obs_clipped` since ``reset``. :meth:`SwimEnv.physical_observation` returns the
unscaled, unclipped values.

The reward is the increment of the objective over the step (any built-in objective of the config
that one swim decides, :data:`SWIM_ENV_OBJECTIVES`; or ``objective=``), scored by the engine's own
objective functions (``animat._core.objective_value``), so an episode's return is the objective of
its whole swim (speed_toward over the episode's full duration; the energy objectives with the
actuation work the springs metered since ``reset``, docs/worlds.md). In the crawl world (effect
``ground`` in the scene) every episode starts where an evaluation does: the body placed on the floor
and settled for ``evaluation.settle_steps`` steps without actuation (``animat._core.start_state``). An
episode ends (``terminated``) when the swim leaves the simulator's valid domain, and is truncated
after ``max_episode_steps`` steps. ``info["valid"]`` (:meth:`SwimEnv.valid`) says whether the swim so
far is one :func:`animat.evaluate` would score (no region inverted, a simple skin, no unresolved
collision); the rewards do not look at it.

``render_mode="rgb_array"``: :meth:`SwimEnv.render` returns an (H, W, 3) uint8 picture of the body
(springs, skin, cells coloured by their term u_i: red lengthening, blue shortening), the camera on
its centre of mass, a world-fixed grid and the path so far; ``metadata["render_fps"]`` is real time,
``1 / (physics.dt · frame_skip)``, so ``gymnasium.wrappers.RecordVideo`` writes the swim at its speed.
``render_mode="human"``: the same picture in a matplotlib window, redrawn by every ``reset`` and
``step`` at most ``render_fps`` times a second (``render()`` returns None). It needs a display and an
interactive matplotlib backend (e.g. TkAgg). Without either, as matplotlib's own ``show()`` does,
the env warns (a UserWarning saying which is missing) and shows nothing: it still runs, so a
script written for a desktop runs on a server too, and ``render_mode="rgb_array"`` gives the frames.
"""

from __future__ import annotations

import math
import os
import sys
import time
import warnings
from pathlib import Path
from typing import Any, Dict, Optional, Tuple

import numpy as np

from . import _core
from .trajectory import body_of

__all__ = [
    "SwimEnv",
    "SWIM_ENV_OBJECTIVES",
    "SWIM_ENV_ID",
    "DEFAULT_EPISODE_STEPS",
    "DEFAULT_SWIMMER_PATH",
    "default_swimmer",
    "gymnasium_available",
    "register_envs",
]

#: The objectives SwimEnv can reward: the built-ins one swim decides (``animat.objectives()``).
SWIM_ENV_OBJECTIVES = tuple(spec.name for spec in _core.objectives() if spec.one_swim)

#: The Gymnasium id under which ``import animat`` registers :class:`SwimEnv`.
SWIM_ENV_ID = "animat/Swim-v0"

#: The swimmer of an env built without a body (module docstring: where it comes from).
DEFAULT_SWIMMER_PATH = Path(__file__).with_name("default_swimmer.json")

_DEFAULT_FRAME_SKIP = 4

#: The episode of the default env (``evaluation.steps // frame_skip`` of ``animat.Config()``): the
#: ``max_episode_steps`` of the registered spec.
DEFAULT_EPISODE_STEPS = int(_core.Config()["evaluation.steps"]) // _DEFAULT_FRAME_SKIP

try:  # optional dependency
    import gymnasium as _gym
    from gymnasium import spaces as _spaces

    _EnvBase: Any = _gym.Env
except ImportError:  # pragma: no cover - exercised only without gymnasium
    _gym = None
    _spaces = None
    _EnvBase = object


def gymnasium_available() -> bool:
    """True if ``gymnasium`` is installed (``pip install animat[control]``)."""
    return _gym is not None


def default_swimmer() -> Any:
    """The :class:`animat.Genome` an env swims without a body (module docstring: its origin)."""
    return _core.Genome.load(str(DEFAULT_SWIMMER_PATH))


class SwimEnv(_EnvBase):
    """A developed body swimming under external control (Gymnasium API; see the module docstring).

    Args:
        body: an :class:`animat.Body`, :class:`animat.Embryo`, :class:`animat.Genome` (developed with
            ``config``) or a :class:`animat.LineageEntry` (e.g. ``run.best()``); None (the default):
            :func:`default_swimmer`.
        config: an :class:`animat.Config` (scene, physics, objective); None = defaults.
        mode: ``"rest_length"`` or ``"oscillator"``.
        frame_skip: control steps per environment step (each ``physics.dt``).
        max_episode_steps: steps before truncation (default: ``evaluation.steps // frame_skip``).
        objective: one of :data:`SWIM_ENV_OBJECTIVES` (default: the config's
            ``evaluation.objective``, which must be one of these).
        frequency: oscillator mode: (n,) frequencies or one number (default: the body's).
        velocity_noise: standard deviation of random initial cell velocities drawn at ``reset``
            from the environment's seeded generator (default 0: every episode starts at rest).
        delayed_start: oscillator mode: each cell starts at the first zero of its sine, as the
            body's own actuation starts it (the paper's delayed start; default False: every cell
            oscillates from the first step).
        normalize_actions: actions in [-1, 1] (default) or, if False, in physical units
            (``physical_action_space``).
        obs_limit: the observation Box is ``[-obs_limit, obs_limit]`` (finite, > 0; default 10).
        render_mode: None, ``"rgb_array"`` or ``"human"`` (a matplotlib window; without a display
            or an interactive backend a warning and no window).
        render_size: (width, height) of a rendered frame in pixels (default (320, 240)).
    """

    metadata: Dict[str, Any] = {"render_modes": ["human", "rgb_array"], "render_fps": 15}

    def __init__(
        self,
        body: Any = None,
        config: Any = None,
        *,
        mode: str = "rest_length",
        frame_skip: int = _DEFAULT_FRAME_SKIP,
        max_episode_steps: Optional[int] = None,
        objective: Optional[str] = None,
        frequency: Any = None,
        velocity_noise: float = 0.0,
        delayed_start: bool = False,
        normalize_actions: bool = True,
        obs_limit: float = 10.0,
        render_mode: Optional[str] = None,
        render_size: Tuple[int, int] = (320, 240),
    ) -> None:
        if _gym is None or _spaces is None:
            raise ImportError("animat.SwimEnv needs gymnasium: pip install gymnasium (or animat[control])")
        super().__init__()
        self.config = _core.Config() if config is None else config.copy()
        if mode not in ("rest_length", "oscillator"):
            raise ValueError(f"SwimEnv: mode must be 'rest_length' or 'oscillator', got {mode!r}")
        if frame_skip < 1:
            raise ValueError(f"SwimEnv: frame_skip must be >= 1, got {frame_skip}")
        if velocity_noise < 0 or not math.isfinite(velocity_noise):
            raise ValueError(f"SwimEnv: velocity_noise must be finite and >= 0, got {velocity_noise}")
        if delayed_start and mode != "oscillator":
            raise ValueError("SwimEnv: delayed_start needs mode='oscillator'")
        if not (math.isfinite(obs_limit) and obs_limit > 0):
            raise ValueError(f"SwimEnv: obs_limit must be finite and > 0, got {obs_limit}")
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"SwimEnv: render_mode must be None or one of {self.metadata['render_modes']}, got {render_mode!r}"
            )
        width, height = (int(v) for v in render_size)
        if width < 32 or height < 32:
            raise ValueError(f"SwimEnv: render_size {tuple(render_size)} is too small (at least 32 x 32 pixels)")
        self.body = body_of(default_swimmer() if body is None else body, self.config)
        if self.body.node_count < 2:
            raise ValueError(f"SwimEnv: the body has {self.body.node_count} cell(s) and no springs; it cannot swim")
        self.mode = mode
        self.delayed_start = bool(delayed_start)
        self.normalize_actions = bool(normalize_actions)
        self.frame_skip = int(frame_skip)
        self.dt = float(self.config["physics.dt"]) * self.frame_skip  # simulated time per env step
        self.render_mode = render_mode
        self.render_size = (width, height)
        self.metadata = dict(type(self).metadata, render_fps=1.0 / self.dt)  # real time
        steps = int(self.config["evaluation.steps"])
        self.max_episode_steps = (
            int(max_episode_steps) if max_episode_steps is not None else max(1, steps // frame_skip)
        )
        if self.max_episode_steps < 1:
            raise ValueError(f"SwimEnv: max_episode_steps must be >= 1, got {self.max_episode_steps}")
        self.objective = str(self.config["evaluation.objective"]) if objective is None else objective
        if self.objective not in SWIM_ENV_OBJECTIVES:
            raise ValueError(
                f"SwimEnv: objective must be one of {', '.join(SWIM_ENV_OBJECTIVES)}, got {self.objective!r}"
            )
        self._length = float(_core.body_length(self.body))
        self._frequency = frequency
        self.velocity_noise = float(velocity_noise)
        self.amplitude_max = float(self.config["development.amplitude_max"])
        if not self.amplitude_max > 0:
            raise ValueError("SwimEnv: development.amplitude_max is 0, so no action can move the body")
        scene_effects = [e for e in self.config["scene.effects"] if e != "actuation"]
        self._scene = _core.Scene.from_config(self.config).replace(effects=scene_effects)
        # Crawl world: on the floor and settled, as swim() starts (without ground: the body at rest).
        self._start_body, self._start_velocities, self.settled = _core.start_state(self.body, None, self.config)
        self._start_velocities = np.asarray(self._start_velocities)
        n = self.body.node_count
        m = self.body.spring_count
        self._springs = np.asarray(self.body.springs)
        a = self.amplitude_max
        if mode == "rest_length":
            self.physical_action_space = _spaces.Box(low=-a, high=a, shape=(n,), dtype=np.float64)
        else:
            low = np.zeros(2 * n)
            high = np.concatenate([np.full(n, a), np.full(n, 2 * math.pi)])
            self.physical_action_space = _spaces.Box(low=low, high=high, dtype=np.float64)
        if self.normalize_actions:
            self.action_space = _spaces.Box(
                low=-1.0, high=1.0, shape=self.physical_action_space.shape, dtype=np.float32
            )
        else:
            self.action_space = self.physical_action_space
        self.obs_limit = float(obs_limit)
        #: Divisors of the physical observation (body length for positions and velocities, 1 for strains).
        self.obs_scale = np.concatenate([np.full(4 * n, self._length), np.ones(m)])
        self.observation_space = _spaces.Box(
            low=-self.obs_limit, high=self.obs_limit, shape=(4 * n + m,), dtype=np.float32
        )
        #: Observation components clipped since ``reset`` (beyond ``obs_limit`` or not finite).
        self.obs_clipped = 0
        self._sim: Any = None
        self._actuation: Any = None
        self._rest0 = np.zeros(m)
        self._steps = 0
        self._com0 = np.zeros(2)
        self._value = 0.0
        self._failure = ""
        self._last_clipped = 0
        self._path: list = []
        self._canvas: Any = None
        self._figure: Any = None
        self._shown_at = -math.inf
        if render_mode == "human":
            self._figure, missing = _open_window((width, height))
            if missing:
                warnings.warn(
                    f"SwimEnv: render_mode='human' shows no window: {missing}; render_mode='rgb_array' "
                    "returns the frames instead",
                    UserWarning,
                    stacklevel=2,
                )

    # --- actions --------------------------------------------------------------------------------------
    def physical_action(self, action: Any) -> np.ndarray:
        """The physical action of a normalised one (module docstring): ``u`` (rest_length mode) or
        (amplitudes, phases) (oscillator mode). No range check."""
        a = np.asarray(action, dtype=np.float64)
        if self.mode == "rest_length":
            return self.amplitude_max * a
        n = self.body.node_count
        return np.concatenate([self.amplitude_max * (a[:n] + 1.0) / 2.0, math.pi * (a[n:] + 1.0)])

    def normalized_action(self, physical: Any) -> np.ndarray:
        """The inverse of :meth:`physical_action` (up to rounding). No range check."""
        p = np.asarray(physical, dtype=np.float64)
        if self.mode == "rest_length":
            return p / self.amplitude_max
        n = self.body.node_count
        return np.concatenate([2.0 * p[:n] / self.amplitude_max - 1.0, p[n:] / math.pi - 1.0])

    def own_action(self) -> np.ndarray:
        """Oscillator mode: the body's own amplitudes and phases (its evolved controller) as an action
        in the units of ``action_space``. With ``normalize_actions=False`` (physical units, no
        rounding) and ``delayed_start=True`` holding it for a whole episode swims the body exactly
        as :func:`animat.evaluate` does."""
        if self.mode != "oscillator":
            raise ValueError("SwimEnv.own_action: the body's own oscillators are an action of mode='oscillator'")
        physical = np.concatenate(
            [np.asarray(self.body.amplitude, dtype=np.float64), np.asarray(self.body.phase, dtype=np.float64)]
        )
        if not self.normalize_actions:
            return physical
        return np.clip(self.normalized_action(physical), -1.0, 1.0)

    # --- helpers ----------------------------------------------------------------------------------
    def physical_observation(self) -> np.ndarray:
        """The observation unscaled and unclipped: positions and velocities relative to the centre of
        mass (length units, length per time unit) and spring strains, shape (4n + m,)."""
        x = np.asarray(self._sim.positions)
        v = np.asarray(self._sim.velocities)
        rel_x = x - x.mean(axis=0)
        rel_v = v - v.mean(axis=0)
        d = x[self._springs[:, 1]] - x[self._springs[:, 0]]
        strain = np.linalg.norm(d, axis=1) / self._rest0 - 1.0
        return np.concatenate([rel_x.ravel(), rel_v.ravel(), strain]).astype(np.float64)

    def _observe(self) -> np.ndarray:
        with np.errstate(invalid="ignore", over="ignore"):
            obs = self.physical_observation() / self.obs_scale
        bad = ~np.isfinite(obs)
        out = ~bad & (np.abs(obs) > self.obs_limit)
        self._last_clipped = int(bad.sum() + out.sum())
        self.obs_clipped += self._last_clipped
        if self._last_clipped:
            obs[bad] = 0.0
            obs = np.clip(obs, -self.obs_limit, self.obs_limit)
        return obs.astype(np.float32)  # a clipped value rounds to the Box's float32 bound

    def objective_value(self) -> float:
        """The objective of the swim so far (the rewards of an episode add up to it)."""
        disp = np.asarray(self._sim.center_of_mass()) - self._com0
        dx, dy = float(disp[0]), float(disp[1])
        return _core.objective_value(
            self.objective,
            distance=math.sqrt(dx * dx + dy * dy),
            dx=dx,
            dy=dy,  # as the engine's norm()
            duration=self.max_episode_steps * self.dt,
            body_length=self._length,
            actuation_work_positive=float(self._sim.counters["actuation_work_positive"]),
            config=self.config,
        )

    def valid(self) -> bool:
        """Whether the swim so far is one :func:`animat.evaluate` would score: it has not failed, no cell
        passed through an edge unresolved and, with ``evaluation.check_embedding`` (the default), no
        region turned inside out and the skin stayed a simple polygon. An invalid swim's rewards still
        count its motion; evaluate() would score it 0."""
        embedding = self._sim.embedding
        return (
            not self._failure
            and self._sim.counters["collisions_unresolved"] == 0
            and (embedding is None or bool(embedding["intact"]))
        )

    def _info(self) -> Dict[str, Any]:
        return {
            "time": float(self._sim.time),
            "steps": int(self._sim.steps_done),
            "com": np.asarray(self._sim.center_of_mass()),
            "objective": self._value,
            "failure": self._failure,
            "obs_clipped": self._last_clipped,
            "valid": self.valid(),
        }

    # --- Gymnasium API ------------------------------------------------------------------------------
    def reset(
        self, *, seed: Optional[int] = None, options: Optional[Dict[str, Any]] = None
    ) -> Tuple[np.ndarray, Dict[str, Any]]:
        """Start an episode: the body at rest (plus ``velocity_noise``), actuation off. Returns (obs, info)."""
        super().reset(seed=seed)
        self._sim = _core.Simulation(self._start_body, self._scene, self.config)
        self._actuation = self._sim.add_external_actuation(self._start_body, self.mode, self.delayed_start)
        if self.config["evaluation.check_embedding"]:
            self._sim.monitor_embedding(self._start_body)
        if self._frequency is not None:
            f = np.broadcast_to(np.asarray(self._frequency, dtype=np.float64), (self.body.node_count,))
            self._actuation.frequency = f
        velocities = self._start_velocities.copy()
        if self.velocity_noise > 0:
            velocities += self.np_random.normal(0.0, self.velocity_noise, size=(self.body.node_count, 2))
        if self.settled or self.velocity_noise > 0:
            self._sim.velocities = velocities
        self._rest0 = np.asarray(self._sim.rest_lengths_now)
        self._steps = 0
        self._com0 = np.asarray(self._sim.center_of_mass())
        self._path = [self._com0]
        self._value = 0.0
        self._failure = ""
        self.obs_clipped = 0
        obs = self._observe()
        if self.render_mode == "human":
            self.render()
        return obs, self._info()

    def step(self, action: Any) -> Tuple[np.ndarray, float, bool, bool, Dict[str, Any]]:
        """Apply ``action`` for ``frame_skip`` control steps. Returns (obs, reward, terminated,
        truncated, info); ValueError for an action outside ``action_space``."""
        if self._sim is None:
            raise RuntimeError("SwimEnv.step: call reset() first")
        a = np.asarray(action, dtype=np.float64)
        if a.shape != self.action_space.shape:
            raise ValueError(f"SwimEnv.step: action has shape {a.shape}, expected {self.action_space.shape}")
        low, high = self.action_space.low, self.action_space.high
        outside = ~np.isfinite(a) | (a < low - 1e-12) | (a > high + 1e-12)
        if np.any(outside):
            bad = int(np.flatnonzero(outside)[0])
            raise ValueError(
                f"SwimEnv.step: action[{bad}] = {a[bad]} is outside the action space [{low[bad]}, {high[bad]}]"
            )
        a = np.clip(a, low, high)  # only the 1e-12 rounding slack
        physical = self.physical_action(a) if self.normalize_actions else a
        n = self.body.node_count
        if self.mode == "rest_length":
            self._actuation.set_terms(physical)
        else:
            self._actuation.set_oscillators(physical[:n], physical[n:])
        terminated = False
        try:
            self._sim.step(self.frame_skip)
        except RuntimeError as e:
            self._failure = str(e)
            terminated = True
        self._steps += 1
        previous = self._value
        if not terminated:
            self._value = self.objective_value()
            self._path.append(np.asarray(self._sim.center_of_mass()))
        reward = float(self._value - previous)
        truncated = not terminated and self._steps >= self.max_episode_steps
        obs = self._observe()
        if self.render_mode == "human":
            self.render()
        return obs, reward, terminated, truncated, self._info()

    # --- rendering --------------------------------------------------------------------------------
    def render(self) -> Optional[np.ndarray]:
        """``render_mode="rgb_array"``: the body now as an (H, W, 3) uint8 array (module docstring);
        ``render_mode="human"``: the same picture drawn in the window (None; ``reset`` and ``step``
        call it); ``render_mode=None``: nothing (None)."""
        if self.render_mode is None:
            return None
        if self._sim is None:
            raise RuntimeError("SwimEnv.render: call reset() first")
        if self.render_mode == "human" and self._figure is None:
            return None  # no window to draw in (warned at construction)
        canvas = self._canvas if self._canvas is not None else self._setup_render()
        pos = np.asarray(self._sim.positions)
        art = self._artists
        if art["fill"] is not None:
            art["fill"].set_verts([pos[reg] for reg in self._regions])
        art["springs"].set_segments(pos[self._springs])
        art["skin"].set_segments([pos[np.append(loop, loop[0])] for loop in self._loops])
        art["nodes"].set_offsets(pos)
        terms = np.asarray(self._actuation.terms)
        art["nodes"].set_facecolor(self._cmap(0.5 + 0.5 * np.clip(terms / self.amplitude_max, -1.0, 1.0)))
        path = np.asarray(self._path)
        self._trail.set_data(path[:, 0], path[:, 1])
        centre = path[-1]
        half_w, half_h = self._view
        x0, x1, y0, y1 = centre[0] - half_w, centre[0] + half_w, centre[1] - half_h, centre[1] + half_h
        g = self._grid_spacing
        xs = np.arange(math.floor(x0 / g), math.ceil(x1 / g) + 1) * g
        ys = np.arange(math.floor(y0 / g), math.ceil(y1 / g) + 1) * g
        self._grid.set_segments([((x, y0), (x, y1)) for x in xs] + [((x0, y), (x1, y)) for y in ys])
        self._ax.set_xlim(x0, x1)
        self._ax.set_ylim(y0, y1)
        self._label.set_text(f"t = {self._sim.time:.2f}   distance {math.dist(path[-1], path[0]):.2f}")
        if self.render_mode == "human":
            return self._show()
        canvas.draw()
        width, height = self.render_size
        return np.array(np.asarray(canvas.buffer_rgba())[:height, :width, :3], dtype=np.uint8)

    def _setup_render(self) -> Any:
        """Build the figure, its canvas (returned) and the artists render() updates."""
        import matplotlib
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.collections import LineCollection
        from matplotlib.figure import Figure

        from . import plot as aplot

        width, height = self.render_size
        dpi = 100
        if self._figure is not None:  # human: the window's figure
            fig = self._figure
            self._canvas = fig.canvas
        else:
            fig = Figure(figsize=(width / dpi, height / dpi), dpi=dpi)
            self._canvas = FigureCanvasAgg(fig)
        fig.patch.set_facecolor("white")
        ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
        ax.set_axis_off()
        self._ax = ax
        # The view: 1.5 body lengths across the shorter side, the same scale on both axes.
        short = 1.5 * self._length
        self._view = (0.5 * short * max(1.0, width / height), 0.5 * short * max(1.0, height / width))
        self._grid_spacing = _nice_spacing(2 * self._view[0] / 6)
        self._grid = LineCollection([], colors="#e3e7ec", linewidths=0.8, zorder=0)
        ax.add_collection(self._grid)
        self._cmap = matplotlib.colormaps["coolwarm"]
        self._regions = [np.asarray(r) for r in self.body.regions]
        self._loops = [np.asarray(loop) for loop in self.body.skin_loops if len(loop)]
        self._artists = aplot.draw_body(ax, self.body, np.asarray(self._sim.positions), "#bbbbbb")
        (self._trail,) = ax.plot([], [], color="#7f7f7f", lw=1.0, ls="--", zorder=1)
        self._label = ax.text(0.02, 0.97, "", transform=ax.transAxes, va="top", ha="left", fontsize=8, color="#333333")
        return self._canvas

    def _show(self) -> None:
        """Draw the window's figure and let the GUI show it, at most ``render_fps`` frames a second."""
        import matplotlib.pyplot as plt

        wait = self._shown_at + 1.0 / self.metadata["render_fps"] - time.perf_counter()
        self._figure.canvas.draw_idle()
        plt.pause(max(wait, 1e-3))  # runs the GUI's event loop: the window repaints
        self._shown_at = time.perf_counter()
        return None

    def close(self) -> None:
        """Drop the simulation and the rendering canvas; close the window of ``render_mode="human"``."""
        self._sim = None
        self._actuation = None
        self._canvas = None
        if self._figure is not None:
            import matplotlib.pyplot as plt

            plt.close(self._figure)
            self._figure = None


def _window_missing() -> str:
    """Why this process has no display for a window ('' when it has one; Linux and other X11 or
    Wayland systems need DISPLAY or WAYLAND_DISPLAY, macOS and Windows always have one)."""
    if sys.platform in ("darwin", "win32") or os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"):
        return ""
    return "there is no display (neither DISPLAY nor WAYLAND_DISPLAY is set)"


def _open_window(size: Tuple[int, int]) -> Tuple[Any, str]:
    """A pyplot figure of ``size`` pixels in a window of an interactive backend (shown by the first
    render) and '', or None and why no window can open."""
    missing = _window_missing()
    if missing:
        return None, missing
    import matplotlib.pyplot as plt

    dpi = 100
    try:
        fig = plt.figure(figsize=(size[0] / dpi, size[1] / dpi), dpi=dpi)
    except Exception as e:  # e.g. an explicit MPLBACKEND=TkAgg whose display does not answer
        return None, f"matplotlib could not open a window ({type(e).__name__}: {e})"
    if getattr(fig.canvas, "required_interactive_framework", None) is None:  # Agg, PDF, ...: no window
        backend = plt.get_backend()
        plt.close(fig)
        return None, (
            f"matplotlib's backend {backend!r} draws no window (choose an interactive one, e.g. "
            "MPLBACKEND=TkAgg, with its GUI toolkit installed)"
        )
    if fig.canvas.manager is not None:
        fig.canvas.manager.set_window_title(SWIM_ENV_ID)
    return fig, ""


def _nice_spacing(span: float) -> float:
    """1, 2 or 5 times a power of ten, at most ``span``."""
    base = 10.0 ** math.floor(math.log10(span))
    return max(m * base for m in (1.0, 2.0, 5.0) if m * base <= span)


def _make_registered(*, episode_steps: Optional[int] = None, **kwargs: Any) -> SwimEnv:
    """The entry point of :data:`SWIM_ENV_ID`: ``SwimEnv(**kwargs)`` with ``episode_steps`` as its
    ``max_episode_steps`` (``gymnasium.make`` keeps that name for its TimeLimit wrapper)."""
    return SwimEnv(max_episode_steps=episode_steps, **kwargs)


_make_registered.metadata = SwimEnv.metadata  # type: ignore[attr-defined]  # gymnasium.make reads render_modes here


def register_envs() -> bool:
    """Register :data:`SWIM_ENV_ID` with Gymnasium (``import animat`` does; again is a no-op).
    Returns False without gymnasium."""
    if _gym is None:
        return False
    if SWIM_ENV_ID not in _gym.envs.registry:
        _gym.register(
            id=SWIM_ENV_ID, entry_point="animat.control:_make_registered", max_episode_steps=DEFAULT_EPISODE_STEPS
        )
    return True


register_envs()
