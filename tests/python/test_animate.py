"""animat.animate: GIF with the expected frames and size; MP4 only where ffmpeg exists."""

import numpy as np
import pytest
from PIL import Image, ImageSequence

import animat
from animat.animation import default_frames


def wave_body():
    xs, ys = np.meshgrid(np.arange(6.0), np.arange(3.0))
    pos = np.column_stack([xs.ravel() + 0.5 * (ys.ravel() % 2), 0.87 * ys.ravel()])
    n = len(pos)
    return animat.build_body(pos, np.full(n, 0.15), np.full(n, 2 * np.pi), 1.5 * pos[:, 0] % (2 * np.pi))


@pytest.fixture(scope="module")
def trajectory():
    return animat.replay(wave_body(), steps=240, every=2)


def test_gif_has_the_expected_frames_and_size(trajectory, tmp_path):
    frames = list(range(0, 60, 4))
    out = animat.animate(trajectory, tmp_path / "swim.gif", frames=frames, size=(200, 120), fps=20)
    assert out == tmp_path / "swim.gif"
    with Image.open(out) as im:
        assert im.format == "GIF" and im.size == (200, 120)
        assert im.n_frames == len(frames)
        assert im.info["duration"] == 50 and im.info["loop"] == 0
        sizes = {frame.size for frame in ImageSequence.Iterator(im)}
        assert sizes == {(200, 120)}
    import imageio.v3 as iio

    stack = iio.imread(out, index=None)
    assert stack.shape[:3] == (len(frames), 120, 200)
    # the nodes are drawn in the paper's colours: some red and some blue pixels somewhere
    rgb = stack[..., :3].reshape(-1, 3).astype(int)
    red = np.sum(np.abs(rgb - [214, 39, 40]).sum(axis=1) < 40)
    blue = np.sum(np.abs(rgb - [31, 119, 180]).sum(axis=1) < 40)
    assert red > 50 and blue > 50


def test_default_frames_resolve_the_oscillation(trajectory, tmp_path):
    idx = default_frames(trajectory, max_frames=20)
    # period 1 time unit = 60 steps = 30 frames (every=2): 8 frames per period, ending at the end
    assert len(idx) == 20 and set(np.diff(idx)) == {3} and idx[-1] == trajectory.frame_count - 1
    assert default_frames(trajectory, max_frames=20, start=0)[:3] == [0, 3, 6]
    assert default_frames(trajectory, max_frames=500) == list(range(trajectory.frame_count))
    out = animat.animate(trajectory, tmp_path / "d.gif", max_frames=12, size=(160, 100), follow=True)
    with Image.open(out) as im:
        assert im.n_frames == 12 and im.size == (160, 100)


def test_progress_bar_and_errors(trajectory, tmp_path, capsys):
    animat.animate(trajectory, tmp_path / "p.gif", frames=[0, 1, 2], size=(120, 80), progress=True)
    assert "rendering p.gif" in capsys.readouterr().err
    with pytest.raises(ValueError, match="unsupported format"):
        animat.animate(trajectory, tmp_path / "x.avi", frames=[0])
    with pytest.raises(ValueError, match="out of range"):
        animat.animate(trajectory, tmp_path / "x.gif", frames=[10_000])
    with pytest.raises(ValueError, match="too small"):
        animat.animate(trajectory, tmp_path / "x.gif", frames=[0], size=(10, 10))


def test_mp4_where_ffmpeg_is_available(trajectory, tmp_path):
    path = tmp_path / "swim.mp4"
    if not animat.mp4_available():
        with pytest.raises(RuntimeError, match="ffmpeg"):
            animat.animate(trajectory, path, frames=[0, 1])
        pytest.skip("no ffmpeg here: MP4 raises a clear RuntimeError instead")
    animat.animate(trajectory, path, frames=list(range(10)), size=(161, 101))
    assert path.stat().st_size > 0


def test_animate_replays_a_body_first(tmp_path):
    body = wave_body()
    out = animat.animate(
        body, tmp_path / "b.gif", max_frames=5, size=(100, 80), config=animat.Config({"evaluation.steps": 40})
    )
    with Image.open(out) as im:
        assert im.n_frames == 5
