"""python -m animat show|animate|info RUN_DIR: files written, paths printed, clear errors."""

import os
import subprocess
import sys

import pytest
from PIL import Image

import animat


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    c = animat.Config()
    c["evolution.population"] = 12
    c["evolution.generations"] = 2
    c["evaluation.steps"] = 300
    out = tmp_path_factory.mktemp("cli") / "run"
    animat.evolve(c, out=str(out))
    return out


def cli(*args):
    env = {**os.environ, "MPLBACKEND": "Agg"}
    env.pop("DISPLAY", None)
    return subprocess.run([sys.executable, "-m", "animat", *map(str, args)], capture_output=True, text=True, env=env)


def test_show_writes_every_figure_and_prints_the_paths(run_dir):
    r = cli("show", run_dir)
    assert r.returncode == 0, r.stderr
    paths = r.stdout.split()
    names = ["development", "construction", "motion_cycle", "phase_map", "fitness_history"]
    assert paths == [str(run_dir / "figures" / f"{n}.png") for n in names]
    for p in paths:
        with Image.open(p) as im:
            assert im.format == "PNG" and im.size[0] > 300


def test_animate_writes_best_gif(run_dir):
    r = cli("animate", run_dir, "--max-frames", 15, "--size", "200x140")
    assert r.returncode == 0, r.stderr
    path = run_dir / "figures" / "best.gif"
    assert r.stdout.strip() == str(path)
    with Image.open(path) as im:
        assert im.n_frames == 15 and im.size == (200, 140)


def test_info(run_dir):
    r = cli("info", run_dir)
    assert r.returncode == 0 and "3 generation(s)" in r.stdout and "best genome" in r.stdout


def test_bad_directories_fail_with_a_clear_message(tmp_path):
    for command in ("show", "animate", "info"):
        r = cli(command, tmp_path / "nope")
        assert r.returncode == 1
        assert "error" in r.stderr and "nope" in r.stderr and "Traceback" not in r.stderr
    r = cli("show", tmp_path)
    assert r.returncode == 1 and "config.toml" in r.stderr
    r = cli("animate", tmp_path, "--size", "big")
    assert r.returncode == 2 and "WIDTHxHEIGHT" in r.stderr
    r = cli()
    assert r.returncode == 2
