"""A control environment for active-control research: :class:`SwimEnv`, a developed body in the
swim physics with its actuation set by a controller, following the Gymnasium API.

``gymnasium`` is an optional dependency (``pip install animat[control]``); without it SwimEnv
raises ImportError naming the package.

Actions set every cell's actuation (eq. 2: the rest length of spring (i, j) is
``(1 + u_i + u_j) L0``); the body's own oscillators are off:

- ``mode="rest_length"``: the action is ``u`` itself, shape (n,), each in
  ``[-amplitude_max, amplitude_max]`` (``development.amplitude_max``, the paper's 0.2);
- ``mode="oscillator"``: the action is (amplitudes, phases), shape (2n,): amplitudes in
  ``[0, amplitude_max]``, phases in ``[0, 2π]``; ``u_i = a_i sin(f_i t + phase_i)`` with the body's
  frequencies (or ``frequency=``).

An action holds for ``frame_skip`` control steps. Observations, shape (4n + m,), float64: the cell
positions relative to the centre of mass (n × 2, flattened), the cell velocities relative to the
centre-of-mass velocity (n × 2) and the spring strains ``length / L0 - 1`` (m). The reward is the
increment of the objective over the step (any built-in objective of the config that one swim decides,
:data:`SWIM_ENV_OBJECTIVES`; or ``objective=``), scored by the engine's own objective functions
(``animat._core.objective_value``), so an episode's return is the objective of its whole
swim (speed_toward over the episode's full duration; the energy objectives with the actuation work
the springs metered since ``reset``, docs/worlds.md). In the crawl world (effect ``ground`` in the
scene) every episode starts where an evaluation does: the body placed on the floor and settled for
``evaluation.settle_steps`` steps without actuation (``animat._core.start_state``). An episode ends (``terminated``) when the swim
leaves the simulator's valid domain, and is truncated after ``max_episode_steps`` steps.
"""

from __future__ import annotations

import math
from typing import Any, Dict, Optional, Tuple

import numpy as np

from . import _core
from .trajectory import body_of

__all__ = ["SwimEnv", "SWIM_ENV_OBJECTIVES", "gymnasium_available"]

#: The objectives SwimEnv can reward: the built-ins one swim decides (``animat.objectives()``).
SWIM_ENV_OBJECTIVES = tuple(spec.name for spec in _core.objectives() if spec.one_swim)

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


class SwimEnv(_EnvBase):
    """A developed body swimming under external control (Gymnasium API; see the module docstring).

    Args:
        body: an :class:`animat.Body`, :class:`animat.Embryo`, :class:`animat.Genome` (developed with
            ``config``) or a :class:`animat.LineageEntry` (e.g. ``run.best()``).
        config: an :class:`animat.Config` (scene, physics, objective); None = defaults.
        mode: ``"rest_length"`` or ``"oscillator"``.
        frame_skip: control steps per environment step (each ``physics.dt``).
        max_episode_steps: steps before truncation (default: ``evaluation.steps // frame_skip``).
        objective: one of :data:`SWIM_ENV_OBJECTIVES` (default: the config's
            ``evaluation.objective``, which must be one of these).
        frequency: oscillator mode: (n,) frequencies or one number (default: the body's).
        velocity_noise: standard deviation of random initial cell velocities drawn at ``reset``
            from the environment's seeded generator (default 0: every episode starts at rest).
    """

    metadata: Dict[str, Any] = {"render_modes": []}

    def __init__(
        self,
        body: Any,
        config: Any = None,
        *,
        mode: str = "rest_length",
        frame_skip: int = 4,
        max_episode_steps: Optional[int] = None,
        objective: Optional[str] = None,
        frequency: Any = None,
        velocity_noise: float = 0.0,
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
        self.body = body_of(body, self.config)
        if self.body.node_count < 2:
            raise ValueError(f"SwimEnv: the body has {self.body.node_count} cell(s) and no springs; it cannot swim")
        self.mode = mode
        self.frame_skip = int(frame_skip)
        self.dt = float(self.config["physics.dt"]) * self.frame_skip  # simulated time per env step
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
        scene_effects = [e for e in self.config["scene.effects"] if e != "actuation"]
        self._scene = _core.Scene.from_config(self.config).replace(effects=scene_effects)
        # Crawl world: on the floor and settled, as swim() starts (without ground: the body at rest).
        self._start_body, self._start_velocities, self.settled = _core.start_state(self.body, None, self.config)
        self._start_velocities = np.asarray(self._start_velocities)
        n = self.body.node_count
        m = self.body.spring_count
        self._springs = np.asarray(self.body.springs)
        if mode == "rest_length":
            a = self.amplitude_max
            self.action_space = _spaces.Box(low=-a, high=a, shape=(n,), dtype=np.float64)
        else:
            low = np.concatenate([np.zeros(n), np.zeros(n)])
            high = np.concatenate([np.full(n, self.amplitude_max), np.full(n, 2 * math.pi)])
            self.action_space = _spaces.Box(low=low, high=high, dtype=np.float64)
        self.observation_space = _spaces.Box(low=-np.inf, high=np.inf, shape=(4 * n + m,), dtype=np.float64)
        self._sim: Any = None
        self._actuation: Any = None
        self._rest0 = np.zeros(m)
        self._steps = 0
        self._com0 = np.zeros(2)
        self._value = 0.0
        self._failure = ""

    # --- helpers ----------------------------------------------------------------------------------
    def _observe(self) -> np.ndarray:
        x = np.asarray(self._sim.positions)
        v = np.asarray(self._sim.velocities)
        rel_x = x - x.mean(axis=0)
        rel_v = v - v.mean(axis=0)
        d = x[self._springs[:, 1]] - x[self._springs[:, 0]]
        strain = np.linalg.norm(d, axis=1) / self._rest0 - 1.0
        return np.concatenate([rel_x.ravel(), rel_v.ravel(), strain]).astype(np.float64)

    def objective_value(self) -> float:
        """The objective of the swim so far (the rewards of an episode add up to it)."""
        disp = np.asarray(self._sim.center_of_mass()) - self._com0
        return _core.objective_value(
            self.objective,
            distance=float(np.linalg.norm(disp)),
            dx=float(disp[0]),
            dy=float(disp[1]),
            duration=self.max_episode_steps * self.dt,
            body_length=self._length,
            actuation_work_positive=float(self._sim.counters["actuation_work_positive"]),
            config=self.config,
        )

    def _info(self) -> Dict[str, Any]:
        return {
            "time": float(self._sim.time),
            "steps": int(self._sim.steps_done),
            "com": np.asarray(self._sim.center_of_mass()),
            "objective": self._value,
            "failure": self._failure,
        }

    # --- Gymnasium API ------------------------------------------------------------------------------
    def reset(
        self, *, seed: Optional[int] = None, options: Optional[Dict[str, Any]] = None
    ) -> Tuple[np.ndarray, Dict[str, Any]]:
        """Start an episode: the body at rest (plus ``velocity_noise``), actuation off. Returns (obs, info)."""
        super().reset(seed=seed)
        self._sim = _core.Simulation(self._start_body, self._scene, self.config)
        self._actuation = self._sim.add_external_actuation(self._start_body, self.mode)
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
        self._value = 0.0
        self._failure = ""
        return self._observe(), self._info()

    def step(self, action: Any) -> Tuple[np.ndarray, float, bool, bool, Dict[str, Any]]:
        """Apply ``action`` for ``frame_skip`` control steps. Returns (obs, reward, terminated,
        truncated, info); ValueError for an action outside ``action_space``."""
        if self._sim is None:
            raise RuntimeError("SwimEnv.step: call reset() first")
        a = np.asarray(action, dtype=np.float64)
        if a.shape != self.action_space.shape:
            raise ValueError(f"SwimEnv.step: action has shape {a.shape}, expected {self.action_space.shape}")
        if (
            not np.all(np.isfinite(a))
            or np.any(a < self.action_space.low - 1e-12)
            or np.any(a > self.action_space.high + 1e-12)
        ):
            bad = int(
                np.flatnonzero(
                    ~np.isfinite(a) | (a < self.action_space.low - 1e-12) | (a > self.action_space.high + 1e-12)
                )[0]
            )
            raise ValueError(
                f"SwimEnv.step: action[{bad}] = {a[bad]} is outside the action space "
                f"[{self.action_space.low[bad]}, {self.action_space.high[bad]}]"
            )
        a = np.clip(a, self.action_space.low, self.action_space.high)  # only the 1e-12 rounding slack
        n = self.body.node_count
        if self.mode == "rest_length":
            self._actuation.set_terms(a)
        else:
            self._actuation.set_oscillators(a[:n], a[n:])
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
        reward = float(self._value - previous)
        truncated = not terminated and self._steps >= self.max_episode_steps
        return self._observe(), reward, terminated, truncated, self._info()

    def render(self) -> None:
        """No rendering: record ``obs`` or use :func:`animat.animate` on a replay."""
        return None

    def close(self) -> None:
        """Drop the simulation."""
        self._sim = None
        self._actuation = None
