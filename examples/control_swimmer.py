"""Active control of a developed body with animat.SwimEnv (Gymnasium API): a random controller and a
hand-written travelling wave, compared by the distance they swim.

    PYTHONPATH=build/python .venv/bin/python examples/control_swimmer.py [--seed 3] [--steps 300]
"""

import argparse
from typing import Callable

import numpy as np

import animat

Controller = Callable[[np.ndarray, float], np.ndarray]


def random_controller(env: animat.SwimEnv, seed: int = 0) -> Controller:
    """Uniform random rest-length terms every step (the action space's own sampler, in [-1, 1])."""
    env.action_space.seed(seed)
    return lambda obs, t: np.asarray(env.action_space.sample())


def travelling_wave(env: animat.SwimEnv, frequency: float = 4.0, wavelength: float = 6.0) -> Controller:
    """u_i(t) = a sin(f t - 2 pi x_i / wavelength): a wave running along the body's x axis (amplitude a
    = development.amplitude_max, the paper's 0.2: the normalised action sin(...) in [-1, 1])."""
    x = np.asarray(env.body.positions)[:, 0]
    return lambda obs, t: np.sin(frequency * t - 2 * np.pi * x / wavelength)


def episode(env: animat.SwimEnv, controller: Controller, seed: int = 0) -> float:
    """Run one episode; returns the distance travelled by the centre of mass."""
    obs, info = env.reset(seed=seed)
    start = info["com"]
    t = 0.0
    while True:
        obs, reward, terminated, truncated, info = env.step(controller(obs, t))
        t = info["time"]
        if terminated or truncated:
            return float(np.linalg.norm(info["com"] - start))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--seed", type=int, default=3, help="seed of the random viable genome (default 3)")
    p.add_argument("--steps", type=int, default=300, help="environment steps per episode (default 300)")
    args = p.parse_args()
    config = animat.Config()
    genome, tries = animat.Genome.random_viable(seed=args.seed, config=config)
    body = animat.build_body(animat.develop(genome, config))
    print(f"body: {body.node_count} cells, {body.spring_count} springs (genome drawn in {tries} tries)")
    env = animat.SwimEnv(body, config, max_episode_steps=args.steps)
    for name, controller in (("random", random_controller(env)), ("travelling wave", travelling_wave(env))):
        print(f"{name:>16}: {episode(env, controller):.3f} length units in {args.steps * env.dt:.1f} time units")


if __name__ == "__main__":
    main()
