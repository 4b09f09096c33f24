"""Training a controller in animat.SwimEnv with the cross-entropy method (numpy only, CPU).

The environment is made through Gymnasium (``gymnasium.make("animat/Swim-v0", ...)``) in oscillator
mode: the policy is one normalised action in [-1, 1]^(2n), held for the whole episode, that sets every
cell's amplitude and phase (the frequencies stay the body's own). The cross-entropy method samples a
population of such actions from a diagonal Gaussian, keeps the best fifth by episode return (the
distance swum; 0 for a swim that animat.evaluate() would not score) and refits the Gaussian to them.
For comparison: random actions every step, and the body's own evolved controller (its amplitudes
and phases held, with the paper's delayed start: exactly the swim :func:`animat.evaluate` scores).

    PYTHONPATH=build/python .venv/bin/python examples/swim_env_cem.py \
        [--run data/paper_100_generations/dn10/run_1] [--iterations 30] [--population 16] [--steps 250]

Needs ``gymnasium`` (``pip install .[control]``) and nothing else beyond the package.
"""

import argparse
import time
from typing import Callable, List, Tuple

import gymnasium
import numpy as np

import animat


def episode_return(
    env: gymnasium.Env, policy: Callable[[np.ndarray], np.ndarray], seed: int = 0, valid_only: bool = True
) -> float:
    """The undiscounted return of one episode (the objective of its swim: here the distance); 0 for a
    swim that animat.evaluate() would not score (``info["valid"]`` false), as the GA does."""
    obs, _ = env.reset(seed=seed)
    total = 0.0
    while True:
        obs, reward, terminated, truncated, info = env.step(policy(obs))
        total += float(reward)
        if terminated or truncated:
            return total if info["valid"] or not valid_only else 0.0


def cem(
    env: gymnasium.Env,
    iterations: int,
    population: int,
    elite_fraction: float = 0.2,
    seed: int = 0,
    init_std: float = 0.5,
    extra_std: float = 0.02,
    log: Callable[[str], None] = print,
) -> Tuple[np.ndarray, float, List[Tuple[float, float, float]]]:
    """The cross-entropy method over one held action. Returns (best action, its return, per-iteration
    (mean, best, best so far) returns)."""
    rng = np.random.default_rng(seed)
    dim = int(np.prod(env.action_space.shape or (1,)))
    mean, std = np.zeros(dim), np.full(dim, init_std)
    elites = max(2, int(round(elite_fraction * population)))
    best_action, best_return = mean.copy(), episode_return(env, lambda obs: mean)
    history = []
    for it in range(iterations):
        samples = np.clip(mean + std * rng.standard_normal((population, dim)), -1.0, 1.0)
        returns = np.array([episode_return(env, lambda obs, a=a: a) for a in samples])
        order = np.argsort(returns)[::-1]
        top = samples[order[:elites]]
        mean = top.mean(axis=0)
        std = top.std(axis=0) + extra_std
        if returns[order[0]] > best_return:
            best_action, best_return = samples[order[0]].copy(), float(returns[order[0]])
        history.append((float(returns.mean()), float(returns[order[0]]), best_return))
        log(
            f"iteration {it + 1:3d}: mean return {returns.mean():7.3f}   best {returns[order[0]]:7.3f}   "
            f"best so far {best_return:7.3f}"
        )
    return best_action, best_return, history


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument(
        "--run",
        default="data/paper_100_generations/dn10/run_1",
        help="run directory whose best body is controlled (default: a d_N = 10 run of 100 generations)",
    )
    p.add_argument("--iterations", type=int, default=30, help="CEM iterations (default 30)")
    p.add_argument("--population", type=int, default=16, help="actions tried per iteration (default 16)")
    p.add_argument(
        "--steps", type=int, default=250, help="environment steps per episode, 4 control steps each (default 250)"
    )
    p.add_argument("--seed", type=int, default=0, help="CEM seed (default 0)")
    args = p.parse_args()

    run = animat.Run(args.run)
    best = run.best()
    config = run.config.copy()
    config["evaluation.steps"] = 4 * args.steps  # the evolved controller's score over the same swim
    env = gymnasium.make("animat/Swim-v0", body=best, config=config, mode="oscillator", episode_steps=args.steps)
    swim_env = env.unwrapped
    assert isinstance(swim_env, animat.SwimEnv)
    body = swim_env.body
    print(
        f"body: the best of {args.run} (generation {best.generation}), {body.node_count} cells; "
        f"episodes of {args.steps} steps ({args.steps * swim_env.dt:.1f} time units)"
    )

    env.action_space.seed(args.seed)
    random_return = np.mean([episode_return(env, lambda obs: env.action_space.sample(), seed=s) for s in range(3)])
    evolved = gymnasium.make(
        "animat/Swim-v0",
        body=best,
        config=config,
        mode="oscillator",
        episode_steps=args.steps,
        delayed_start=True,
        normalize_actions=False,
    )
    assert isinstance(evolved.unwrapped, animat.SwimEnv)
    own = evolved.unwrapped.own_action()
    evolved_return = episode_return(evolved, lambda obs: own)
    evaluated = animat.evaluate(best.genome, config).fitness
    print(f"random actions every step: {random_return:.3f}")
    print(f"the evolved controller (exact replay): {evolved_return:.6f}; animat.evaluate: {evaluated:.6f}")

    t0 = time.perf_counter()
    action, value, _ = cem(env, args.iterations, args.population, seed=args.seed)
    seconds = time.perf_counter() - t0
    physical = swim_env.physical_action(action)
    n = body.node_count
    print(
        f"CEM: best return {value:.3f} after {args.iterations} x {args.population} episodes ({seconds:.0f} s); "
        f"amplitudes {physical[:n].min():.3f}..{physical[:n].max():.3f}"
    )


if __name__ == "__main__":
    main()
