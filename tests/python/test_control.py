"""animat.SwimEnv: the Gymnasium API on a developed body, actions driving the rest lengths."""

import json
import math
import os
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import animat

gymnasium = pytest.importorskip("gymnasium")
from gymnasium.utils.env_checker import check_env  # noqa: E402

#: The warning of render_mode="human" where no window can open (a test process without a display).
NO_WINDOW = "SwimEnv: render_mode='human' shows no window"
#: animat.evaluate(default_swimmer(), Config()).fitness: the fitness its run recorded
#: (data/replication/dn2/run_9, best/gen_000549.json).
DEFAULT_SWIMMER_DISTANCE = 37.95199243852891


@pytest.fixture(scope="module")
def genome_and_config():
    c = animat.Config()
    c["evaluation.steps"] = 400
    genome, _ = animat.Genome.random_viable(seed=3, config=c)
    return genome, c


@pytest.fixture(scope="module")
def body_and_config(genome_and_config):
    genome, c = genome_and_config
    return animat.build_body(animat.develop(genome, c)), c


def test_import_animat_registers_the_environment_with_gymnasium(body_and_config):
    body, c = body_and_config
    assert animat.SWIM_ENV_ID == "animat/Swim-v0" and animat.SWIM_ENV_ID in gymnasium.envs.registry
    assert animat.control.register_envs()  # again: a no-op, no re-registration warning
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert animat.control.register_envs()
        env = gymnasium.make("animat/Swim-v0", body=body, config=c, mode="oscillator", frame_skip=2, episode_steps=7)
        assert isinstance(env.unwrapped, animat.SwimEnv)
        assert env.unwrapped.max_episode_steps == 7 and env.unwrapped.frame_skip == 2
        env.reset(seed=0)
        for k in range(7):
            _, _, terminated, truncated, _ = env.step(env.action_space.sample())
            assert not terminated and truncated == (k == 6)
        env.close()


@pytest.mark.parametrize("mode", ["rest_length", "oscillator"])
def test_passes_gymnasium_env_checker_without_a_warning(body_and_config, mode):
    """check_env with every check on (render modes and close included: the env is made through
    gymnasium.make, so it has a spec), warnings turned into errors."""
    body, c = body_and_config
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warnings.filterwarnings("ignore", message=NO_WINDOW)  # check_env makes the human mode too
        env = gymnasium.make(
            "animat/Swim-v0",
            body=body,
            config=c,
            mode=mode,
            frame_skip=4,
            episode_steps=20,
            render_mode="rgb_array",
            render_size=(64, 48),
        )
        check_env(env.unwrapped)
        env.reset(seed=1)  # the PassiveEnvChecker wrapper's own checks
        env.step(env.action_space.sample())
        assert env.render().shape == (48, 64, 3)
        env.close()
    n, m = body.node_count, body.spring_count
    assert env.observation_space.shape == (4 * n + m,)
    assert env.action_space.shape == ((n,) if mode == "rest_length" else (2 * n,))
    assert np.all(env.action_space.low == -1.0) and np.all(env.action_space.high == 1.0)
    assert np.all(np.isfinite(env.observation_space.low)) and np.all(np.isfinite(env.observation_space.high))


def test_gymnasium_make_needs_no_arguments_and_swims_the_packaged_default_swimmer():
    """As MuJoCo's Swimmer: gym.make with no body builds the packaged swimmer under the default
    config, with float32 spaces and a spec whose max_episode_steps is the env's own episode; held for
    that episode, the swimmer's own controller swims the distance its evolution recorded."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warnings.filterwarnings("ignore", message=NO_WINDOW)
        env = gymnasium.make("animat/Swim-v0", render_mode="rgb_array")
        check_env(env.unwrapped)
        obs, _ = env.reset(seed=0)
        obs, reward, terminated, truncated, _ = env.step(env.action_space.sample())
        assert env.render().shape == (240, 320, 3)
        env.close()
    genome = animat.control.default_swimmer()
    body = animat.build_body(animat.develop(genome, animat.Config()))
    assert body.node_count == env.unwrapped.body.node_count == 32
    np.testing.assert_array_equal(env.unwrapped.body.positions, body.positions)
    assert env.spec.max_episode_steps == animat.control.DEFAULT_EPISODE_STEPS == env.unwrapped.max_episode_steps == 1000
    assert env.observation_space.dtype == env.action_space.dtype == np.float32
    assert obs.dtype == np.float32 and env.observation_space.contains(obs)
    assert env.observation_space.shape == (4 * 32 + body.spring_count,) and env.action_space.shape == (32,)
    assert isinstance(reward, float) and not terminated and not truncated
    assert animat.evaluate(genome, animat.Config()).fitness == DEFAULT_SWIMMER_DISTANCE

    env = gymnasium.make("animat/Swim-v0", mode="oscillator", delayed_start=True, normalize_actions=False)
    env.reset(seed=0)
    action, total, steps = env.unwrapped.own_action(), 0.0, 0
    while True:
        _, reward, terminated, truncated, info = env.step(action)
        total, steps = total + reward, steps + 1
        if terminated or truncated:
            break
    assert truncated and not terminated and info["valid"] and steps == 1000  # the env's end and the spec's agree
    assert env.unwrapped.objective_value() == DEFAULT_SWIMMER_DISTANCE  # bit for bit, as evaluate swims it
    assert total == pytest.approx(DEFAULT_SWIMMER_DISTANCE, rel=1e-12)


@pytest.mark.skipif(sys.platform in ("darwin", "win32"), reason="a display is found by DISPLAY / WAYLAND_DISPLAY")
def test_human_rendering_without_a_window_warns_and_still_runs(body_and_config, monkeypatch):
    """No display, or a backend that draws no window: a warning saying which, then an env that steps
    and renders nothing (render() is None, as in human mode with a window)."""
    import matplotlib

    body, c = body_and_config
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    with pytest.warns(UserWarning, match=r"shows no window: there is no display \(neither DISPLAY nor WAYLAND_DISPLAY"):
        env = gymnasium.make("animat/Swim-v0", body=body, config=c, render_mode="human", episode_steps=3)
    assert env.unwrapped._figure is None
    env.reset(seed=0)
    for _ in range(3):
        env.step(env.action_space.sample())
    assert env.render() is None
    env.close()
    monkeypatch.setenv("DISPLAY", ":0")
    matplotlib.use("Agg")
    with pytest.warns(UserWarning, match=r"(?i)shows no window: matplotlib's backend 'agg' draws no window"):
        animat.SwimEnv(body, c, render_mode="human").close()


HUMAN_WINDOW_SCRIPT = """
import json, warnings
import gymnasium, matplotlib.pyplot as plt, numpy as np
import animat
from gymnasium.utils.env_checker import check_env
warnings.simplefilter("error")
env = gymnasium.make("animat/Swim-v0", render_mode="human", episode_steps=5)
check_env(env.unwrapped)
fig = env.unwrapped._figure
env.reset(seed=0)
rendered = []
for _ in range(5):
    env.step(env.action_space.sample())
    rendered.append(env.render())
window = fig.canvas.manager.window
window.update()
rgb = np.asarray(fig.canvas.buffer_rgba())[..., :3]
report = {"backend": plt.get_backend(), "title": window.title(), "mapped": bool(window.winfo_ismapped()),
          "drawn": float((rgb < 200).any(axis=2).mean()), "rendered": rendered}
env.close()
report["figures_after_close"] = plt.get_fignums()
print(json.dumps(report))
"""


@pytest.mark.skipif(shutil.which("Xvfb") is None, reason="needs Xvfb, a virtual X display")
def test_human_rendering_opens_a_matplotlib_window_on_a_display():
    """On an X display (Xvfb) with TkAgg: the window opens titled with the env id, the body is drawn
    in it, render() returns None, check_env passes with warnings as errors, and close() closes it."""
    pytest.importorskip("tkinter")
    read_end, write_end = os.pipe()
    xvfb = subprocess.Popen(
        ["Xvfb", "-displayfd", str(write_end), "-screen", "0", "640x480x24", "-nolisten", "tcp"],
        pass_fds=(write_end,),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    os.close(write_end)
    try:
        with os.fdopen(read_end) as ready:
            display = ready.readline().strip()  # Xvfb writes its display number once it accepts clients
        assert display, "Xvfb exited before it was ready"
        env = {**os.environ, "DISPLAY": f":{display}", "MPLBACKEND": "TkAgg"}
        env["PYTHONPATH"] = os.pathsep.join(
            p for p in [str(Path(animat.__file__).parents[1]), env.get("PYTHONPATH")] if p
        )
        run = subprocess.run(
            [sys.executable, "-c", HUMAN_WINDOW_SCRIPT], env=env, capture_output=True, text=True, timeout=300
        )
    finally:
        xvfb.terminate()
        xvfb.wait()
    assert run.returncode == 0, run.stderr
    report = json.loads(run.stdout.strip().splitlines()[-1])
    assert report["backend"].lower() == "tkagg" and report["title"] == "animat/Swim-v0" and report["mapped"]
    assert report["drawn"] > 0.01  # the body's skin and springs, dark on white
    assert report["rendered"] == [None] * 5 and report["figures_after_close"] == []


def test_observations_are_relative_to_the_centre_of_mass_and_start_at_rest(body_and_config):
    body, c = body_and_config
    env = animat.SwimEnv(body, c)
    obs, info = env.reset(seed=1)
    n = body.node_count
    physical = env.physical_observation()
    rel = physical[: 2 * n].reshape(n, 2)
    np.testing.assert_allclose(rel.mean(axis=0), 0.0, atol=1e-9)
    np.testing.assert_allclose(rel + info["com"], np.asarray(body.positions), atol=1e-5)  # float32 Box2D positions
    np.testing.assert_array_equal(physical[2 * n : 4 * n], 0.0)  # at rest
    np.testing.assert_allclose(physical[4 * n :], 0.0, atol=1e-6)  # springs at their rest length
    assert obs.dtype == np.float32 and env.observation_space.dtype == np.float32
    np.testing.assert_array_equal(obs, (physical / env.obs_scale).astype(np.float32))  # in body lengths
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
            action = 0.75 * np.sin(4.0 * t - np.asarray(body.positions)[:, 0])  # u = 0.15 sin(...)
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
    with pytest.raises(ValueError, match=r"action\[0\] = 1.5 is outside the action space \[-1.0, 1.0\]"):
        env.step(np.full(n, 1.5))
    physical = animat.SwimEnv(body, c, normalize_actions=False)
    physical.reset()
    with pytest.raises(ValueError, match=r"action\[0\] = 0.3 is outside the action space \[-0.2, 0.2\]"):
        physical.step(np.full(n, 0.3))
    with pytest.raises(ValueError, match="action has shape"):
        env.step(np.zeros(n + 1))


def test_oscillator_mode_equals_the_body_oscillating_by_itself_once_started(body_and_config):
    """Amplitudes and phases set to the body's own reproduce eq. 2 (without the paper's delayed start)."""
    body, c = body_and_config
    env = animat.SwimEnv(body, c, mode="oscillator", frame_skip=1, normalize_actions=False)
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
            _, reward, terminated, _, info = env.step(0.75 * np.sin(4.0 * t - np.asarray(body.positions)[:, 0]))
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
    cfg.scene.ground_contact = "impulse"  # the floor that holds every centre on it, exactly
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
        _, _, terminated, _, info = env.step(0.75 * np.sin(4.0 * t - np.asarray(body.positions)[:, 0]))
        t = info["time"]
        assert not terminated
        assert np.asarray(env._sim.positions)[:, 1].min() >= floor - 1e-6  # never below the floor
    assert env._sim.counters["ground_contacts"] > 0


def test_external_actuation_terms_and_frequencies_can_be_read(body_and_config):
    """The ExternalActuation's array properties (they raised a nanobind ownership error before)."""
    body, c = body_and_config
    env = animat.SwimEnv(body, c, mode="oscillator", frame_skip=1, normalize_actions=False)
    env.reset()
    np.testing.assert_array_equal(env._actuation.frequency, np.asarray(body.frequency))
    n = body.node_count
    amplitude, phase = np.full(n, 0.1), np.linspace(0.0, 1.0, n)
    env.step(np.concatenate([amplitude, phase]))
    np.testing.assert_allclose(env._actuation.terms, amplitude * np.sin(phase), rtol=0, atol=1e-15)


@pytest.mark.parametrize("mode", ["rest_length", "oscillator"])
def test_normalised_actions_map_to_the_physical_ranges(body_and_config, mode):
    """[-1, 1] → u in ±a_max (rest_length), amplitude in [0, a_max] and phase in [0, 2π] (oscillator);
    a normalised action swims as its physical action does in an env that takes physical actions."""
    body, c = body_and_config
    env = animat.SwimEnv(body, c, mode=mode)
    physical_env = animat.SwimEnv(body, c, mode=mode, normalize_actions=False)
    n, a_max = body.node_count, c["development.amplitude_max"]
    assert physical_env.action_space == env.physical_action_space == physical_env.physical_action_space
    lo, hi = env.physical_action(env.action_space.low), env.physical_action(env.action_space.high)
    np.testing.assert_array_equal(lo, env.physical_action_space.low)
    np.testing.assert_array_equal(hi, env.physical_action_space.high)
    if mode == "rest_length":
        assert hi[0] == a_max and env.physical_action(np.zeros(n))[0] == 0.0
    else:
        np.testing.assert_array_equal(hi, np.concatenate([np.full(n, a_max), np.full(n, 2 * math.pi)]))
        np.testing.assert_allclose(env.physical_action(np.zeros(2 * n)), np.repeat([a_max / 2, math.pi], n))
    rng = np.random.default_rng(4)
    actions = [rng.uniform(-1, 1, env.action_space.shape) for _ in range(10)]
    for a in actions:
        np.testing.assert_allclose(env.normalized_action(env.physical_action(a)), a, rtol=0, atol=1e-15)
    env.reset(seed=0)
    physical_env.reset(seed=0)
    for a in actions:
        obs, reward, *_ = env.step(a)
        obs_p, reward_p, *_ = physical_env.step(env.physical_action(a))
        np.testing.assert_array_equal(obs, obs_p)
        assert reward == reward_p
    assert env.objective_value() > 0


def test_observations_stay_in_their_box_and_clipping_is_counted(body_and_config):
    body, c = body_and_config
    env = animat.SwimEnv(body, c, max_episode_steps=40)
    env.action_space.seed(0)
    obs, info = env.reset(seed=0)
    assert env.observation_space.contains(obs) and info["obs_clipped"] == 0
    worst = 0.0
    for _ in range(40):
        obs, _, terminated, _, info = env.step(env.action_space.sample())  # random, the roughest control
        assert env.observation_space.contains(obs) and not terminated
        worst = max(worst, np.abs(env.physical_observation() / env.obs_scale).max())
    assert env.obs_clipped == 0 and worst < 1.0  # the default limit, 10, is far from the values of a swim
    # A limit the swim exceeds: the observation is clipped into the Box and every clipped value counted.
    tight = animat.SwimEnv(body, c, max_episode_steps=40, obs_limit=0.05)
    tight.action_space.seed(0)
    _, info = tight.reset(seed=0)
    total = info["obs_clipped"]  # the positions of the start already exceed 0.05 body lengths
    assert total > 0
    for _ in range(40):
        obs, _, _, _, info = tight.step(tight.action_space.sample())
        scaled = tight.physical_observation() / tight.obs_scale
        beyond = np.abs(scaled) > 0.05
        assert info["obs_clipped"] == beyond.sum()
        np.testing.assert_array_equal(obs, np.clip(scaled, -0.05, 0.05).astype(np.float32))
        assert tight.observation_space.contains(obs)
        total += info["obs_clipped"]
    assert tight.obs_clipped == total > 0
    _, info = tight.reset(seed=0)  # counted afresh from the reset observation on
    assert tight.obs_clipped == info["obs_clipped"] > 0


def test_rgb_array_rendering_draws_the_body_as_it_moves(body_and_config):
    body, c = body_and_config
    assert animat.SwimEnv(body, c).render() is None  # render_mode None
    env = animat.SwimEnv(body, c, render_mode="rgb_array", max_episode_steps=30)
    assert env.metadata["render_fps"] == pytest.approx(15.0)  # real time: 1 / (dt · frame_skip)
    with pytest.raises(RuntimeError, match="reset"):
        env.render()
    env.reset(seed=0)
    first = env.render()
    assert first.shape == (240, 320, 3) and first.dtype == np.uint8
    assert (first < 200).any(axis=2).mean() > 0.01  # the body is drawn (dark skin and springs on white)
    for k in range(30):
        env.step(0.75 * np.sin(4.0 * k * env.dt - np.asarray(body.positions)[:, 0]))
    last = env.render()
    assert last.shape == first.shape and not np.array_equal(last, first)
    reds = (last[..., 0] > 150) & (last[..., 2] < 120)
    blues = (last[..., 2] > 150) & (last[..., 0] < 120)
    assert reds.any() and blues.any()  # cells coloured by their term: lengthening and shortening
    # Gymnasium's frame collector takes the frames of every step.
    wrapped = gymnasium.wrappers.RenderCollection(
        gymnasium.make("animat/Swim-v0", body=body, config=c, render_mode="rgb_array", episode_steps=5)
    )
    wrapped.reset(seed=0)
    for _ in range(5):
        wrapped.step(wrapped.action_space.sample())
    frames = wrapped.render()
    assert len(frames) == 6 and all(f.shape == (240, 320, 3) for f in frames)


def test_record_video_writes_an_episode(body_and_config, tmp_path):
    pytest.importorskip("moviepy")
    body, c = body_and_config
    env = gymnasium.wrappers.RecordVideo(
        gymnasium.make("animat/Swim-v0", body=body, config=c, render_mode="rgb_array", episode_steps=10),
        str(tmp_path / "videos"),
        episode_trigger=lambda k: True,
        disable_logger=True,
    )
    env.reset(seed=0)
    for _ in range(10):
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
    assert truncated and not terminated
    env.close()
    videos = list((tmp_path / "videos").glob("*.mp4"))
    assert len(videos) == 1 and videos[0].stat().st_size > 0


def test_delayed_start_replays_evaluate_exactly(genome_and_config):
    """The body's own amplitudes and phases, held for an episode with the paper's delayed start, swim
    the body exactly as animat.evaluate() does (steps across the oscillators' resynchronisation at
    step 1024); without the delayed start the swim differs."""
    genome, c = genome_and_config
    c = c.copy()
    c["evaluation.steps"] = 1200
    result = animat.evaluate(genome, c)
    assert result.valid and result.fitness > 0

    def swim(**kwargs):
        env = animat.SwimEnv(genome, c, mode="oscillator", **kwargs)
        assert env.max_episode_steps == 300
        env.reset(seed=0)
        action, total = env.own_action(), 0.0
        while True:
            _, reward, terminated, truncated, _ = env.step(action)
            total += reward
            assert not terminated
            if truncated:
                return env, total

    env, total = swim(delayed_start=True, normalize_actions=False)
    assert env.objective_value() == result.fitness  # bit for bit
    assert env.valid()  # as evaluate() judged it
    assert total == pytest.approx(result.fitness, rel=1e-12)
    assert env._sim.steps_done == result.swim_steps == 1200
    h = c["physics.dt"]
    start = np.ceil(
        np.mod(np.pi - np.mod(np.asarray(env.body.phase), np.pi), np.pi) / np.asarray(env.body.frequency) / h
    )
    np.testing.assert_array_equal(env._actuation.start_steps, start)  # the paper's start of each cell
    assert start.max() > 0
    undelayed, _ = swim(normalize_actions=False)
    assert abs(undelayed.objective_value() - result.fitness) > 1e-6 * result.fitness
    normalised, _ = swim(delayed_start=True)  # the same controller through [-1, 1]: rounding only
    assert normalised.objective_value() == pytest.approx(result.fitness, rel=1e-6)
    with pytest.raises(ValueError, match="delayed_start needs mode='oscillator'"):
        animat.SwimEnv(genome, c, delayed_start=True)
    with pytest.raises(ValueError, match="own_action"):
        animat.SwimEnv(genome, c).own_action()


def test_the_cem_example_trains_through_gymnasium_make(body_and_config):
    """examples/swim_env_cem.py, in miniature: the best return so far never falls and beats the start."""
    import importlib.util
    from pathlib import Path

    body, c = body_and_config
    path = Path(__file__).resolve().parents[2] / "examples" / "swim_env_cem.py"
    spec = importlib.util.spec_from_file_location("swim_env_cem", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    env = gymnasium.make("animat/Swim-v0", body=body, config=c, mode="oscillator", episode_steps=25)
    start = module.episode_return(env, lambda obs: np.zeros(env.action_space.shape))
    action, value, history = module.cem(env, iterations=3, population=6, seed=1, log=lambda line: None)
    assert len(history) == 3 and all(np.isfinite(h).all() for h in history)
    best_so_far = [h[2] for h in history]
    assert best_so_far == sorted(best_so_far) and value == best_so_far[-1] >= start
    assert module.episode_return(env, lambda obs: action) == value  # deterministic episodes
