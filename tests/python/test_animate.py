"""animat.animate: GIF with the expected frames and size; MP4 only where ffmpeg exists; the world
(floor, chemical source) and the objective's progress drawn in it."""

import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from PIL import Image, ImageSequence  # noqa: E402

import animat  # noqa: E402
from animat.animation import default_frames, frame_figure  # noqa: E402


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


# --- the world in the GIF ------------------------------------------------------------------------------

ROOT = Path(__file__).resolve().parents[2]


def crawl_trajectory():
    data = ROOT / "tests" / "data" / "crawl"
    config = animat.load_config(str(data / "crawl.toml"))
    genome = animat.Genome.from_json(json.dumps(json.loads((data / "s1_g7.json").read_text())["genome"]))
    return animat.replay(genome, config, steps=300, every=10)


@pytest.fixture(scope="module")
def chemotaxis():
    run = ROOT / "data" / "control" / "chemotaxis_amplitude_seed2"
    config = animat.load_config(f"{run}_config.toml")
    return animat.Genome.load(f"{run}_best_genome.json"), config


def texts_of(fig):
    return {t.get_label(): t.get_text() for t in fig.texts}


def count_colour(path, colour):
    rgb = np.array([int(colour[k : k + 2], 16) for k in (1, 3, 5)])
    with Image.open(path) as im:
        return [
            int(np.all(np.asarray(frame.convert("RGB")) == rgb, axis=2).sum()) for frame in ImageSequence.Iterator(im)
        ]


def test_crawl_gif_draws_the_floor_and_names_the_world(tmp_path):
    from animat import plot

    tr = crawl_trajectory()
    h = tr.config["scene.ground_height"]
    fig = frame_figure(tr, size=(280, 180))
    ax = fig.axes[0]
    floors = [ln for ln in ax.get_lines() if ln.get_label() == "floor"]
    assert len(floors) == 1 and np.allclose(floors[0].get_ydata(), h)
    assert [p.get_label() for p in ax.patches].count("ground") == 1
    # not rotated (down stays down): the body rests on the floor, in view
    nodes = next(c for c in ax.collections if c.get_label() == "nodes").get_offsets()
    assert nodes[:, 1].min() == pytest.approx(h, abs=1e-3)
    assert ax.get_ylim()[0] < h < ax.get_ylim()[1]
    text = texts_of(fig)
    assert text["world"] == plot.world_text(tr.config)
    assert "d_N" not in text["world"] and "gravity g = 1" in text["world"] and "floor at y = 0" in text["world"]
    # distance_x: the clock shows the horizontal distance, the objective of the crawl world
    dx = abs(tr.com[-1, 0] - tr.com[0, 0])
    assert "x distance" in text["clock"] and f"{dx:8.3f}" in text["clock"]
    # and the GIF itself has the floor in every frame
    out = animat.animate(tr, tmp_path / "crawl.gif", max_frames=6, size=(280, 180), progress=False)
    assert min(count_colour(out, plot.FLOOR_COLOR)) > 280 // 2  # a floor line across the frame


def test_chemotaxis_gif_draws_the_source_and_the_progress_toward_it(chemotaxis, tmp_path):
    """A chemotaxis replay is the evaluation's first swim, toward that swim's source (never
    scene.chemical_source itself, where no evaluation puts one), and draws that source."""
    from animat import plot
    from animat.trajectory import chemotaxis_source

    genome, config = chemotaxis
    tr = animat.replay(genome, config, steps=600, every=10)
    source = chemotaxis_source(config, 0)
    assert tr.meta["source_trial"] == 0 and tr.meta["source_trials"] == config["evaluation.source_directions"] == 4
    assert not np.allclose(source, config["scene.chemical_source"])  # turned by the seed's offset
    np.testing.assert_array_equal(tr.config["scene.chemical_source"], source)
    # the swim is the GRN-controlled one evaluate() scores, toward that source
    assert tr.meta["control"] == "grn"
    ref = animat.grn_swim(genome, config, steps=600, every=10, source=list(source))
    assert np.allclose(tr.com, ref["com"]) and np.allclose(tr.node_terms, ref["terms"])
    fig = frame_figure(tr, align=False, size=(400, 240))
    ax = fig.axes[0]
    stars = [ln for ln in ax.get_lines() if ln.get_label() == "chemical source"]
    assert len(stars) == 1 and stars[0].get_marker() == "*"
    assert np.allclose(np.column_stack(stars[0].get_data())[0], tr.com[0] + source)
    arrow = next(p for p in ax.patches if p.get_label() == "toward source")
    assert arrow is not None
    text = texts_of(fig)
    d = tr.com[-1] - tr.com[0]
    progress = np.linalg.norm(source) - np.linalg.norm(source - d)
    assert "to source" in text["clock"] and f"{progress:8.3f}" in text["clock"]
    assert "distance" not in text["clock"]
    at = f"point source at ({source[0]:.3g}, {source[1]:.3g}) from the start (swim 1 of 4)"
    assert at in text["world"].replace("\n", " ") and "GRN control" in text["world"]
    # aligned (the default in a fluid), the star is rotated with the world but stays as far from the start
    fig = frame_figure(tr, size=(400, 240))
    star = next(ln for ln in fig.axes[0].get_lines() if ln.get_label() == "chemical source")
    first = default_frames(tr)[0]  # the aligned view is centred on the first rendered frame's centre
    assert np.linalg.norm(np.column_stack(star.get_data())[0]) == pytest.approx(
        np.linalg.norm(tr.com[0] + source - tr.com[first])
    )
    out = animat.animate(tr, tmp_path / "chem.gif", max_frames=6, size=(400, 240), align=False, progress=False)
    assert min(count_colour(out, plot.SOURCE_COLOR)) > 20


def control_run(name):
    """A run of data/control (flat files: config, history, best genome) as (genome, config)."""
    run = ROOT / "data" / "control" / name
    return animat.Genome.load(f"{run}_best_genome.json"), animat.load_config(f"{run}_config.toml")


def test_the_replays_of_every_source_direction_average_to_the_evaluations_fitness():
    """chemotaxis_amplitude_seed1 swims away from scene.chemical_source (+x, -0.59 in 2000 steps: what
    the replay used to draw) while its fitness is +0.47: the mean progress over the evaluation's four
    turned sources, which replay(source_trial=k) swims one by one."""
    from animat.trajectory import chemotaxis_source

    genome, config = control_run("chemotaxis_amplitude_seed1")
    result = animat.evaluate(genome, config)
    progress = []
    for k in range(4):
        tr = animat.replay(genome, config, every=100, source_trial=k)
        source = chemotaxis_source(config, k)
        assert tr.meta["source_trial"] == k and np.linalg.norm(source) == pytest.approx(20.0, rel=1e-12)
        progress.append(np.linalg.norm(source) - np.linalg.norm(source - (tr.com[-1] - tr.com[0])))
    assert result.source_progress == pytest.approx(0.47014513761968235, rel=1e-12)
    assert np.mean(progress) == pytest.approx(result.source_progress, rel=1e-12)
    assert progress[0] == pytest.approx(0.8528, abs=1e-4)  # the first swim, the default replay's
    with pytest.raises(ValueError, match="not one of the 4 evaluation.source_directions"):
        animat.replay(genome, config, steps=10, source_trial=4)
    with pytest.raises(ValueError, match="source_trial is for objective 'chemotaxis'"):
        animat.replay(wave_body(), steps=10, source_trial=0)


def window_boxes(fig):
    """The display boxes of the frame's texts, its source star and its nodes (each node's disc)."""
    renderer = fig.canvas.get_renderer()
    ax = fig.axes[0]
    texts = {t.get_label(): t.get_window_extent(renderer) for t in fig.texts}
    star = next(ln for ln in ax.get_lines() if ln.get_label() == "chemical source").get_window_extent(renderer)
    nodes = next(c for c in ax.collections if c.get_label() == "nodes")
    centres = ax.transData.transform(nodes.get_offsets())
    radius = (ax.transData.transform([[nodes._widths[0], 0]]) - ax.transData.transform([[0, 0]]))[0, 0]
    return texts, star, centres, radius


@pytest.mark.parametrize("name", ["chemotaxis_amplitude_seed1", "chemotaxis_amplitude_seed2"])
def test_the_texts_keep_clear_of_the_source_and_the_body(name):
    """The star of seed 1's source sat under the world text, seed 2's under the caption; now the
    view keeps the bands of the texts clear: no text box overlaps the star's or a node's."""
    genome, config = control_run(name)
    tr = animat.replay(genome, config, every=10)
    for frame in (0, -1):
        fig = frame_figure(tr, frame)
        fig.canvas.draw()
        texts, star, centres, radius = window_boxes(fig)
        assert set(texts) == {"clock", "world", "caption", "motion"}
        frame_box = fig.bbox
        assert (
            frame_box.x0 <= star.x0 and star.x1 <= frame_box.x1 and frame_box.y0 <= star.y0 and star.y1 <= frame_box.y1
        )
        for label, box in texts.items():
            assert not box.overlaps(star), (label, box, star)
            near_x = (centres[:, 0] + radius > box.x0) & (centres[:, 0] - radius < box.x1)
            near_y = (centres[:, 1] + radius > box.y0) & (centres[:, 1] - radius < box.y1)
            assert not np.any(near_x & near_y), label


def test_a_body_that_does_not_move_is_drawn_with_a_warning(tmp_path):
    """The open-loop chemotaxis run's best (generation 0, fitness 0) has every amplitude 0."""
    from animat import plot

    genome, config = control_run("chemotaxis_open_loop_seed1")
    still = animat.replay(genome, config, steps=200, every=10)
    assert plot.motionless(still) and np.all(np.asarray(still.body.amplitude) == 0.0)
    with pytest.warns(UserWarning, match=r"animate: the body does not move \(no cell moves in the 200 steps"):
        animat.animate(still, tmp_path / "still.gif", max_frames=3, size=(200, 120), progress=False)
    with pytest.warns(UserWarning, match="motion_cycle: the body does not move"):
        plot.motion_cycle(still, count=3)
    moving = animat.replay(wave_body(), steps=60, every=2)
    assert not plot.motionless(moving)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        animat.animate(moving, tmp_path / "moving.gif", max_frames=3, size=(200, 120), progress=False)
        plot.motion_cycle(moving, count=3)
