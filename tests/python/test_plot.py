"""animat.plot on a small real run, headless (Agg): every function returns a Figure and draws what
the paper's figure shows; motion_cycle colours follow eq. 2, phase_map's colour range the phases."""

import json
import math
import re
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.colors import to_rgba  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

import animat  # noqa: E402
from animat import plot  # noqa: E402

RED, BLUE, GREEN = (to_rgba(c) for c in ("#d62728", "#1f77b4", "#2ca02c"))


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    c = animat.Config()
    c["evolution.population"] = 12
    c["evolution.generations"] = 3
    c["evaluation.steps"] = 300
    c["evolution.seed"] = 5
    out = tmp_path_factory.mktemp("plot") / "run"
    animat.evolve(c, out=str(out))
    return animat.Run(out)


@pytest.fixture(scope="module")
def trajectory(run):
    return animat.replay(run.best(), run.config)


@pytest.fixture(autouse=True)
def no_show_and_close(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("plot functions must never call show()")

    monkeypatch.setattr(plt, "show", refuse)
    monkeypatch.setattr(Figure, "show", refuse)
    yield
    plt.close("all")


def nodes_of(ax):
    found = [c for c in ax.collections if c.get_label() == "nodes"]
    assert len(found) == 1
    return found[0]


def test_backend_is_headless():
    assert matplotlib.get_backend().lower() == "agg"


def test_every_plot_function_returns_a_figure(run, trajectory, tmp_path):
    best = run.best()
    figures = {
        "development": plot.development(best, config=run.config),
        "construction": plot.construction(best, config=run.config),
        "motion_cycle": plot.motion_cycle(trajectory),
        "phase_map": plot.phase_map(best, config=run.config),
        "fitness_history": plot.fitness_history(run),
    }
    for name, fig in figures.items():
        assert isinstance(fig, Figure), name
        fig.savefig(tmp_path / f"{name}.png", dpi=50)
        assert (tmp_path / f"{name}.png").stat().st_size > 1000


def expected_state(body, t, neutral=animat.DEFAULT_NEUTRAL):
    """Eq. 2 independently: a cell expands its springs when d/dt[a sin(f t + phi)] > 0 (after its
    delayed start, the first zero crossing of the sine), contracts when < 0, with a neutral band."""
    a, f, p = np.asarray(body.amplitude), np.asarray(body.frequency), np.asarray(body.phase)
    theta = np.mod(p, math.pi)
    start = np.where(theta == 0, 0.0, np.where(f > 0, (math.pi - theta) / np.where(f > 0, f, 1), np.inf))
    rate = np.where(t >= start, a * f * np.cos(f * t + p), 0.0)
    thr = neutral * np.max(a * f)
    return np.where(rate > thr, 1, np.where(rate < -thr, -1, 0))


def check_motion_cycle_colours(fig, tr):
    dt = animat.Config()["physics.dt"]
    seen = set()
    panels = [ax for ax in fig.axes if ax.get_visible() and any(c.get_label() == "nodes" for c in ax.collections)]
    assert panels
    for ax in panels:
        step = int(re.search(r"step (\d+)", ax.get_title()).group(1))
        state = expected_state(tr.body, step * dt)
        colours = nodes_of(ax).get_facecolor()
        assert len(colours) == tr.body.node_count
        for c, s in zip(colours, state):
            assert tuple(c) == {1: RED, -1: BLUE, 0: GREEN}[int(s)]
            seen.add(int(s))
    return panels, seen


def test_motion_cycle_node_colours_follow_eq2(trajectory):
    fig = plot.motion_cycle(trajectory, count=5)
    panels, _ = check_motion_cycle_colours(fig, trajectory)
    assert len(panels) == 5
    # the skin is drawn thick in every panel and the direction of motion is marked
    for ax in panels:
        widths = [
            lc.get_linewidth()[0]
            for lc in ax.collections
            if lc.get_label() != "nodes" and hasattr(lc, "get_segments") and len(lc.get_segments())
        ]
        assert max(widths) >= 2.0
    assert any("direction of motion" in t.get_text() for t in fig.legends[0].get_texts())


def test_motion_cycle_on_a_wave_shows_all_three_states():
    xs, ys = np.meshgrid(np.arange(7.0), np.arange(3.0))
    pos = np.column_stack([xs.ravel() + 0.5 * (ys.ravel() % 2), 0.87 * ys.ravel()])
    n = len(pos)
    body = animat.build_body(pos, np.full(n, 0.15), np.full(n, 2 * np.pi), 1.5 * pos[:, 0] % (2 * np.pi))
    tr = animat.replay(body, steps=240)
    fig = plot.motion_cycle(tr, frames=[180, 190, 200, 210, 220, 230], align=False, color_springs=True)
    panels, seen = check_motion_cycle_colours(fig, tr)
    assert seen == {-1, 0, 1}
    assert [ax.get_title() for ax in panels] == [f"step {s}" for s in (180, 190, 200, 210, 220, 230)]
    with pytest.raises(ValueError, match="out of range"):
        plot.motion_cycle(tr, frames=[10_000])


def test_phase_map_colour_range_matches_the_phases(run):
    embryo = animat.develop(run.best().genome, run.config)
    phase = np.random.default_rng(1).uniform(0.3, 2.9, embryo.cell_count)  # evolved phases may all be equal
    body = animat.build_body(embryo.positions, embryo.amplitude, embryo.frequency, phase)
    fig = plot.phase_map(body)
    ax = fig.axes[0]
    nodes = nodes_of(ax)
    assert nodes.norm.vmin == pytest.approx(phase.min())
    assert nodes.norm.vmax == pytest.approx(phase.max())
    assert np.allclose(nodes.get_array(), phase)
    # the red node is the maximum, and its value is written out
    rgba = nodes.get_facecolor()
    cmap = plt.get_cmap(plot.PHASE_CMAP)
    assert np.allclose(rgba[int(np.argmax(phase))], cmap(1.0))
    assert np.allclose(rgba[int(np.argmin(phase))], cmap(0.0))
    label = f"{phase.max():.2f}"
    texts = [t.get_text() for t in ax.texts] + [ax.get_title()]
    assert any(label in t for t in texts)
    # the colour bar spans the same range
    cbar_ax = fig.axes[1]
    assert cbar_ax.get_ylim() == pytest.approx((phase.min(), phase.max()))


def test_phase_map_of_uniform_phases_and_into_given_axes(run):
    pos = np.array([[0, 0], [1, 0], [0.5, 0.9], [1.5, 0.9]], dtype=float)
    body = animat.build_body(pos, np.full(4, 0.1), np.full(4, 3.0), np.full(4, 1.25))
    fig, ax = plt.subplots()
    out = plot.phase_map(body, ax=ax, colorbar=False)
    assert out is fig and "all equal" in ax.get_title() and "1.25" in ax.get_title()
    nodes = nodes_of(ax)
    assert nodes.norm.vmax == pytest.approx(1.25) and nodes.norm.vmin == pytest.approx(0.25)
    assert np.allclose(nodes.get_facecolor(), plt.get_cmap(plot.PHASE_CMAP)(1.0))  # all red: all are the max
    # the run's own best, whatever its phases, from a LineageEntry
    phase = animat.develop(run.best().genome, run.config).phase
    fig = plot.phase_map(run.best(), config=run.config)
    assert nodes_of(fig.axes[0]).norm.vmax == pytest.approx(phase.max())


def test_fitness_history_marks_morphology_changes(run):
    fig = plot.fitness_history(run, max_thumbnails=2)
    main = next(ax for ax in fig.axes if ax.get_label() == "fitness")
    h = run.history
    line = main.get_lines()[0]
    assert np.array_equal(line.get_xdata(), h["generation"]) and np.allclose(line.get_ydata(), h["best"])
    changes = run.morphology_changes()
    diamonds = [ln for ln in main.get_lines() if ln.get_marker() == "D"]
    assert len(diamonds) == 1 and list(diamonds[0].get_xdata()) == [e.generation for e in changes]
    thumbs = [ax for ax in fig.axes if ax is not main]
    assert len(thumbs) == min(2, len(changes))
    for ax in thumbs:
        assert nodes_of(ax) is not None and ax.get_title().startswith("gen ")
    assert main.get_xlabel() == "generation" and "fitness" in main.get_ylabel()
    # a run given by its path works too
    assert isinstance(plot.fitness_history(run.path, max_thumbnails=0), Figure)


def test_development_panels_and_errors(run):
    cfg = run.config
    cfg["development.trace_every"] = 1
    embryo = animat.develop(run.best().genome, cfg)
    steps = [0, embryo.division_steps[0], embryo.steps_run]
    fig = plot.development(embryo, steps=steps)
    visible = [ax for ax in fig.axes if ax.get_visible()]
    assert [ax.get_title().split(" (")[0] for ax in visible] == [f"step {s}" for s in steps]
    assert visible[0].get_title() == "step 0 (1 cell)"
    assert isinstance(plot.development(embryo.trace), Figure)  # a bare trace and default steps
    with pytest.raises(ValueError, match="no trace"):
        plot.development(animat.develop(run.best().genome, run.config))
    with pytest.raises(ValueError, match="not in the trace"):
        plot.development(embryo, steps=[100_000])


def test_construction_shows_delaunay_then_gabriel(run):
    embryo = animat.develop(run.best().genome, run.config)
    body = animat.build_body(embryo)
    fig = plot.construction(embryo)
    a, b, c = fig.axes
    delaunay = animat.delaunay_edges(embryo.positions)
    segs_b = [len(lc.get_segments()) for lc in b.collections if hasattr(lc, "get_segments")]
    assert segs_b == [len(delaunay)]
    segs_c = sorted(len(lc.get_segments()) for lc in c.collections if hasattr(lc, "get_segments"))
    assert segs_c == sorted([body.spring_count, len(body.skin)])
    assert "Delaunay" in b.get_title() and "Gabriel" in c.get_title()
    # points work too
    assert isinstance(plot.construction(embryo.positions), Figure)


# --- figures that fit every world -----------------------------------------------------------------------


def small_config(config=None, **keys):
    c = (config if config is not None else animat.Config()).copy()
    c["evolution.population"] = 10
    c["evolution.generations"] = 2
    c["evaluation.steps"] = 300
    c["evolution.seed"] = 5
    for k, v in keys.items():
        c[k.replace("__", ".")] = v
    return c


ROOT = Path(__file__).resolve().parents[2]


def crawl_trajectory(steps=300):
    data = ROOT / "tests" / "data" / "crawl"
    config = animat.load_config(str(data / "crawl.toml"))
    genome = animat.Genome.from_json(json.dumps(json.loads((data / "s1_g7.json").read_text())["genome"]))
    return animat.replay(genome, config, steps=steps, every=10)


def test_world_text_names_the_world_as_it_is():
    assert plot.world_text(animat.Config()) == "fluid d_N = 2, d_T = 0.01"
    crawl = animat.load_config(str(ROOT / "configs" / "crawl.toml"))
    assert crawl["scene.drag_normal"] == 2.0  # the key is set, but effect drag is not in the scene
    text = plot.world_text(crawl)
    assert "d_N" not in text and "drag" in text and "gravity g = 1" in text and "floor at y = 0" in text
    chem = animat.load_config(str(ROOT / "configs" / "chemotaxis.toml"))
    text = plot.world_text(chem)  # no evaluation swims toward (20, 0) itself: four turned directions
    assert "fluid d_N = 2" in text and "GRN control" in text and "point source 20 from the start, 4 directions" in text
    assert "(20, 0)" not in text
    turned = chem.copy()
    turned["scene.chemical_source"] = [-5.83, -19.13]
    assert plot.world_text(turned, source_trial=0).endswith(
        "point source at (-5.83, -19.1) from the start (swim 1 of 4)"
    )
    assert plot.chemical_source_of(animat.Config()) is None
    assert list(plot.chemical_source_of(chem)) == [20.0, 0.0]


def test_construction_names_the_body_graph_used(run):
    genome = run.best().genome
    for graph, words in (
        ("alpha_shape", "alpha-shape graph (α = 1)"),
        ("distance", "distance graph"),
        ("gabriel", "Gabriel graph"),
    ):
        c = run.config.copy()
        c["body.graph"] = graph
        title = plot.construction(genome, config=c).axes[2].get_title()
        assert title.startswith(f"(c) {words}"), title
        if graph != "gabriel":
            assert "Gabriel" not in title
    # a bare Body: Gabriel if its springs are the Gabriel graph of its cells, else not claimed
    c = run.config.copy()
    c["body.graph"] = "alpha_shape"
    embryo = animat.develop(genome, c)
    alpha_body = animat.build_body(embryo, config=c)
    assert "Gabriel" not in plot.construction(alpha_body).axes[2].get_title()
    gabriel_body = animat.build_body(embryo)
    assert "(c) Gabriel graph" in plot.construction(gabriel_body).axes[2].get_title()


def fitness_axes(fig):
    return next(ax for ax in fig.axes if ax.get_label() == "fitness")


def test_fitness_history_labels_the_objective(run):
    ax = fitness_axes(plot.fitness_history(run, max_thumbnails=0))
    assert ax.get_ylabel() == "fitness: distance" and "distance travelled" not in ax.get_ylabel()
    spec = next(o for o in animat.objectives() if o.name == "distance")
    assert ax.get_title(loc="left") == f"objective distance: {spec.meaning}"
    assert ax.get_ylim()[0] == 0.0  # non-negative objective: the axis starts at 0


def test_fitness_history_of_a_signed_objective_is_not_clipped(tmp_path):
    def standstill(record):  # a signed Python objective: minus the distance travelled
        return -float(np.linalg.norm(record.com[-1] - record.com[0]))

    animat.evolve(
        small_config(),
        out=str(tmp_path / "run"),
        quiet=True,
        objective=animat.Objective(standstill, every=50, name="standstill"),
    )
    run = animat.Run(tmp_path / "run")
    assert run.config["evaluation.objective"] == "python:standstill"
    lowest = float(run.history["mean"].min())
    assert lowest < 0.0
    ax = fitness_axes(plot.fitness_history(run, max_thumbnails=0))
    assert ax.get_ylabel() == "fitness: standstill"
    bottom, top = ax.get_ylim()
    assert bottom <= lowest < 0.0 <= top
    mean = next(ln for ln in ax.get_lines() if ln.get_label() == "mean fitness (viable)")
    assert np.allclose(mean.get_ydata(), run.history["mean"])
    assert any(list(ln.get_ydata()) == [0.0, 0.0] for ln in ax.get_lines())  # 0 is marked


def test_motion_cycle_in_the_crawl_world_draws_the_floor():
    tr = crawl_trajectory()
    h = tr.config["scene.ground_height"]
    fig = plot.motion_cycle(tr, count=3)
    panels = [ax for ax in fig.axes if any(c.get_label() == "nodes" for c in ax.collections)]
    assert len(panels) == 3
    for ax in panels:
        floors = [ln for ln in ax.get_lines() if ln.get_label() == "floor"]
        assert len(floors) == 1 and np.allclose(floors[0].get_ydata(), h)
        # not rotated: the nodes rest on the floor, none below it
        nodes = nodes_of(ax).get_offsets()
        assert nodes[:, 1].min() == pytest.approx(h, abs=1e-3)
    title = fig._suptitle.get_text()
    assert "d_N" not in title and "floor at y = 0" in title and "gravity g = 1" in title


def test_show_draws_the_stiffness_map_of_evolved_stiffness(run, tmp_path):
    from animat.cli import show_figures

    assert "stiffness_map" not in show_figures(run)  # the paper's uniform springs: no map
    config = small_config(**{"genome__extra_outputs": "stiffness", "body__graph": "alpha_shape"})
    config["evolution.seed"] = 7  # a best whose cells differ in stiffness
    animat.evolve(config, out=str(tmp_path / "stiff"), quiet=True)
    stiff = animat.Run(tmp_path / "stiff")
    makers = show_figures(stiff)
    assert list(makers) == [
        "development",
        "construction",
        "motion_cycle",
        "phase_map",
        "stiffness_map",
        "fitness_history",
    ]
    body = animat.build_body(animat.develop(stiff.best().genome, stiff.config), config=stiff.config)
    f = np.asarray(body.stiffness)
    assert len(f) == body.node_count and f.max() > f.min()
    fig = makers["stiffness_map"]()
    ax, bar = fig.axes
    assert np.allclose(nodes_of(ax).get_array(), f)
    assert "stiffness" in bar.get_ylabel() and bar.get_ylim() == pytest.approx((f.min(), f.max()))
    assert ax.get_title().startswith("Evolved stiffness")
    # the same run's construction names its alpha-shape graph, and the history its objective
    assert "alpha-shape graph" in makers["construction"]().axes[2].get_title()
    assert fitness_axes(makers["fitness_history"]()).get_ylabel() == "fitness: distance"


def control_run_dir(name, tmp_path):
    """A run directory of data/control's flat files (config, history, best genome) for animat.Run:
    the best genome recorded at the generation where the best fitness was reached."""
    import csv
    import shutil

    data = ROOT / "data" / "control"
    run = tmp_path / name
    (run / "best").mkdir(parents=True)
    shutil.copy(data / f"{name}_config.toml", run / "config.toml")
    shutil.copy(data / f"{name}_history.csv", run / "history.csv")
    rows = list(csv.DictReader((run / "history.csv").open()))
    best = max(float(r["best"]) for r in rows)
    generation = next(int(r["generation"]) for r in rows if float(r["best"]) == best)
    genome = json.loads((data / f"{name}_best_genome.json").read_text())
    entry = {"cell_count": 32, "fitness": best, "generation": generation, "genome": genome}
    (run / "best" / f"gen_{generation:06d}.json").write_text(json.dumps(entry))
    return animat.Run(run)


def test_no_phase_map_for_bodies_the_grn_drives_directly(tmp_path):
    """Under control.actuation = "direct" no oscillator runs: no phase axes, a note instead, and the
    history's thumbnails are plain; under "amplitude" the phases still time the oscillators."""
    direct = control_run_dir("chemotaxis_grn_seed1", tmp_path)
    assert direct.config["control.mode"] == "grn" and direct.config["control.actuation"] == "direct"
    assert not plot.oscillator_phases_used(direct.config)
    fig = plot.phase_map(direct.best(), config=direct.config)
    assert fig.axes == []
    assert [t.get_label() for t in fig.texts] == ["no phase map"] and "direct" in fig.texts[0].get_text()
    fig = plot.fitness_history(direct)
    thumbnails = [ax for ax in fig.axes if ax.get_label() != "fitness"]
    assert thumbnails and all(nodes_of(ax).get_array() is None for ax in thumbnails)
    assert thumbnails[-1].get_title().endswith("GRN control (direct)") and "plain nodes" in fig._suptitle.get_text()
    amplitude = control_run_dir("chemotaxis_amplitude_seed2", tmp_path)
    assert amplitude.config["control.actuation"] == "amplitude" and plot.oscillator_phases_used(amplitude.config)
    fig = plot.phase_map(amplitude.best(), config=amplitude.config)
    assert len(fig.axes) == 2 and nodes_of(fig.axes[0]).get_array() is not None  # the map and its colour bar
    assert plot.oscillator_phases_used(animat.Config())


def test_fitness_history_of_negative_values_keeps_its_labels_in_the_figure(tmp_path):
    """The open-loop chemotaxis run's mean fitness goes down to -0.0015: the wide tick labels pushed
    the y label out of the figure, and the one-line title was wider than the figure."""
    run = control_run_dir("chemotaxis_open_loop_seed1", tmp_path)
    assert float(run.history["mean"].min()) < -0.001
    fig = plot.fitness_history(run)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    ax = fitness_axes(fig)
    assert ax.get_ylim()[0] < -0.001
    frame = fig.bbox
    for artist in (ax.yaxis.label, fig._suptitle, *ax.get_yticklabels()):
        box = artist.get_window_extent(renderer)
        assert frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0 and box.y1 <= frame.y1, artist


def test_motion_cycle_of_a_chemotaxis_swim_names_its_source_and_the_progress_toward_it():
    from animat.trajectory import chemotaxis_source

    data = ROOT / "data" / "control" / "chemotaxis_amplitude_seed1"
    config = animat.load_config(f"{data}_config.toml")
    tr = animat.replay(animat.Genome.load(f"{data}_best_genome.json"), config, steps=600, every=5)
    source = chemotaxis_source(config, 0)
    gain = np.linalg.norm(source) - np.linalg.norm(source - tr.displacement)
    fig = plot.motion_cycle(tr, count=3)
    title = fig._suptitle.get_text()
    assert f"distance {tr.distance:.3g} ({gain:.3g} toward the source) in 600 steps" in title
    assert f"point source at ({source[0]:.3g}, {source[1]:.3g}) from the start (swim 1 of 4)" in title
    star = next(ln for ax in fig.axes for ln in ax.get_lines() if ln.get_label() == "chemical source")
    rot = plot.rotation_to(tr.direction)
    frames = tr.cycle_frames(3)
    np.testing.assert_allclose(np.column_stack(star.get_data())[0], (tr.com[0] + source - tr.com[frames[0]]) @ rot.T)


def test_show_and_explore_draw_a_chemotaxis_run_as_its_evaluation_swims(tmp_path):
    """`animat show` draws no phase map where no oscillator runs, and the explore page replays one of
    the evaluation's sources and draws that source, not scene.chemical_source (where no evaluation
    puts one)."""
    from animat import explore
    from animat.cli import show_figures
    from animat.trajectory import chemotaxis_source

    direct = control_run_dir("chemotaxis_grn_seed1", tmp_path)
    assert "phase_map" not in show_figures(direct) and "motion_cycle" in show_figures(direct)
    amplitude = control_run_dir("chemotaxis_amplitude_seed1", tmp_path)
    assert "phase_map" in show_figures(amplitude)
    swim = explore._swim_payload(amplitude.best(), amplitude.config, frames=4)
    source = chemotaxis_source(amplitude.config, 0)
    assert f"at ({source[0]:.3g}, {source[1]:.3g}) from the start (swim 1 of" in swim["world"]["banner"]
    nominal = np.asarray(amplitude.config["scene.chemical_source"], dtype=float)
    assert not np.allclose(source, nominal)  # the case the page drew wrongly
