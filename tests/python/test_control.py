"""animat.SwimEnv: the Gymnasium API on a developed body, actions driving the rest lengths."""

import numpy as np
import pytest

import animat

gymnasium = pytest.importorskip("gymnasium")
from gymnasium.utils.env_checker import check_env  # noqa: E402


@pytest.fixture(scope="module")
def body_and_config():
    c = animat.Config()
    c["evaluation.steps"] = 400
    genome, _ = animat.Genome.random_viable(seed=3, config=c)
    return animat.build_body(animat.develop(genome, c)), c


@pytest.mark.parametrize("mode", ["rest_length", "oscillator"])
def test_passes_gymnasium_env_checker(body_and_config, mode):
    body, c = body_and_config
    env = animat.SwimEnv(body, c, mode=mode, frame_skip=4, max_episode_steps=20)
    check_env(env, skip_render_check=True)
    n, m = body.node_count, body.spring_count
    assert env.observation_space.shape == (4 * n + m,)
    assert env.action_space.shape == ((n,) if mode == "rest_length" else (2 * n,))


def test_observations_are_relative_to_the_centre_of_mass_and_start_at_rest(body_and_config):
    body, c = body_and_config
    env = animat.SwimEnv(body, c)
    obs, info = env.reset(seed=1)
    n = body.node_count
    rel = obs[: 2 * n].reshape(n, 2)
    np.testing.assert_allclose(rel.mean(axis=0), 0.0, atol=1e-9)
    np.testing.assert_allclose(rel + info["com"], np.asarray(body.positions), atol=1e-5)  # float32 Box2D positions
    np.testing.assert_array_equal(obs[2 * n : 4 * n], 0.0)  # at rest
    np.testing.assert_allclose(obs[4 * n :], 0.0, atol=1e-6)  # springs at their rest length
    obs2, reward, terminated, truncated, _ = env.step(np.zeros(n))  # no actuation: nothing moves
    assert reward == 0.0 and not terminated and not truncated
    np.testing.assert_array_equal(obs2, obs)


def test_rewards_add_up_to_the_objective_and_an_episode_truncates(body_and_config):
    body, c = body_and_config
    for objective in ("distance", "distance_per_size", "speed_toward"):
        env = animat.SwimEnv(body, c, objective=objective, max_episode_steps=30)
        env.reset(seed=0)
        total, t = 0.0, 0.0
        for k in range(30):
            action = 0.15 * np.sin(4.0 * t - np.asarray(body.positions)[:, 0])
            _, reward, terminated, truncated, info = env.step(action)
            total += reward
            t = info["time"]
            assert not terminated
            assert truncated == (k == 29)
        assert total == pytest.approx(env.objective_value(), abs=1e-12)
        assert info["objective"] == env.objective_value()
    com = info["com"]
    horizon = 30 * env.dt
    assert env.objective_value() == pytest.approx((com - env._com0) @ np.array([1.0, 0.0]) / horizon)


def test_actions_outside_the_space_are_refused(body_and_config):
    body, c = body_and_config
    env = animat.SwimEnv(body, c)
    env.reset()
    n = body.node_count
    with pytest.raises(ValueError, match=r"action\[0\] = 0.3 is outside the action space \[-0.2, 0.2\]"):
        env.step(np.full(n, 0.3))
    with pytest.raises(ValueError, match="action has shape"):
        env.step(np.zeros(n + 1))


def test_oscillator_mode_equals_the_body_oscillating_by_itself_once_started(body_and_config):
    """Amplitudes and phases set to the body's own reproduce eq. 2 (without the paper's delayed start)."""
    body, c = body_and_config
    env = animat.SwimEnv(body, c, mode="oscillator", frame_skip=1)
    env.reset()
    action = np.concatenate([np.asarray(body.amplitude), np.mod(np.asarray(body.phase), 2 * np.pi)])
    env.step(action)
    sim = env._sim
    a, f, p = body.amplitude, body.frequency, body.phase
    u = a * np.sin(f * 0.0 + p)
    springs = np.asarray(body.springs)
    expected = (1 + u[springs[:, 0]] + u[springs[:, 1]]) * env._rest0
    np.testing.assert_allclose(sim.rest_lengths_now, expected, rtol=1e-12)


def test_a_sinusoidal_controller_swims_farther_than_a_random_one(body_and_config):
    body, c = body_and_config
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "examples" / "control_swimmer.py"
    spec = importlib.util.spec_from_file_location("control_swimmer", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    env = animat.SwimEnv(body, c, max_episode_steps=100)
    random_distance = module.episode(env, module.random_controller(env, seed=0))
    wave_distance = module.episode(env, module.travelling_wave(env))
    assert wave_distance > 2 * random_distance > 0


def test_energy_and_horizontal_objectives_are_rewarded_as_the_metered_work_says(body_and_config):
    """distance_x, distance_minus_energy and distance_per_energy (docs/worlds.md) from the springs' meter."""
    body, c = body_and_config
    values = {}
    for objective in ("distance_x", "distance_minus_energy", "distance_per_energy"):
        env = animat.SwimEnv(body, c, objective=objective, max_episode_steps=30)
        env.reset(seed=0)
        total, t = 0.0, 0.0
        for _ in range(30):
            _, reward, terminated, _, info = env.step(0.15 * np.sin(4.0 * t - np.asarray(body.positions)[:, 0]))
            total += reward
            t = info["time"]
            assert not terminated
        assert total == pytest.approx(env.objective_value(), abs=1e-12)
        disp = info["com"] - env._com0
        work = env._sim.counters["actuation_work_positive"]
        assert work > 0
        values[objective] = (env.objective_value(), disp, work)
    value, disp, _ = values["distance_x"]
    assert value == pytest.approx(abs(disp[0]), rel=1e-12)
    value, disp, work = values["distance_minus_energy"]
    assert value == pytest.approx(np.linalg.norm(disp) - c["evaluation.energy_weight"] * work, rel=1e-12)
    value, disp, work = values["distance_per_energy"]
    assert value == pytest.approx(np.linalg.norm(disp) / (work + c["evaluation.energy_offset"]), rel=1e-12)
    with pytest.raises(ValueError, match="objective must be one of"):
        animat.SwimEnv(body, c, objective="farthest")


def test_crawl_episodes_start_on_the_floor_settled_as_an_evaluation_does(body_and_config):
    from pathlib import Path

    body, _ = body_and_config
    cfg = animat.load_config(Path(__file__).resolve().parents[2] / "configs" / "crawl.toml")
    env = animat.SwimEnv(body, cfg, objective="distance_x", max_episode_steps=50)
    assert env.settled == cfg.evaluation.settle_steps == 300
    start_body, start_velocities, settled = animat._core.start_state(body, None, cfg)
    obs, info = env.reset(seed=0)
    np.testing.assert_array_equal(env._sim.positions, start_body.positions)
    np.testing.assert_array_equal(env._sim.velocities, start_velocities)
    floor = cfg.scene.ground_height
    assert np.asarray(start_body.positions)[:, 1].min() >= floor - 1e-6
    t = 0.0
    for _ in range(50):
        _, _, terminated, _, info = env.step(0.15 * np.sin(4.0 * t - np.asarray(body.positions)[:, 0]))
        t = info["time"]
        assert not terminated
        assert np.asarray(env._sim.positions)[:, 1].min() >= floor - 1e-6  # never below the floor
    assert env._sim.counters["ground_contacts"] > 0


def test_external_actuation_terms_and_frequencies_can_be_read(body_and_config):
    """The ExternalActuation's array properties (they raised a nanobind ownership error before)."""
    body, c = body_and_config
    env = animat.SwimEnv(body, c, mode="oscillator", frame_skip=1)
    env.reset()
    np.testing.assert_array_equal(env._actuation.frequency, np.asarray(body.frequency))
    n = body.node_count
    amplitude, phase = np.full(n, 0.1), np.linspace(0.0, 1.0, n)
    env.step(np.concatenate([amplitude, phase]))
    np.testing.assert_allclose(env._actuation.terms, amplitude * np.sin(phase), rtol=0, atol=1e-15)
