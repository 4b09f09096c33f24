"""MAP-Elites (animat.qd): the descriptor table against values computed by hand, the archives' binning,
keeping and counting, and a MapElites run that is the same for any thread count and across resume.

Every run here is tiny (batches of 8, 200-step swims, a few generations): the file runs in seconds.
"""

import json
import math
import pickle
import re
from pathlib import Path

import numpy as np
import pytest
from run_dirs import without_wall

import animat
from animat import qd
from animat.locomotion import MODES

ROOT = Path(__file__).resolve().parents[2]


def small_config(guard="record", threads=1):
    c = animat.Config()
    c["evaluation.steps"] = 200
    c["evaluation.reference_check"] = guard
    c["evaluation.reference_substeps"] = 2  # the guard's reference: 2x the substeps (cheap, still a finer step)
    c["evolution.threads"] = threads
    return c


@pytest.fixture(scope="module")
def genome():
    return animat.Genome.random_viable(animat.Rng.derive(11, 0, 0), animat.Config())[0]


def shoelace(v):
    x, y = v[:, 0], v[:, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y)))


def hull(points):
    """Convex hull by gift wrapping (counter-clockwise), written independently of animat.shape."""
    p = np.unique(np.asarray(points, dtype=float), axis=0)
    start = int(np.lexsort((p[:, 1], p[:, 0]))[0])
    out, i = [], start
    while True:
        out.append(p[i])
        j = (i + 1) % len(p)
        for k in range(len(p)):
            cross = (p[j, 0] - p[i, 0]) * (p[k, 1] - p[i, 1]) - (p[j, 1] - p[i, 1]) * (p[k, 0] - p[i, 0])
            if cross < 0:
                j = k
        i = j
        if i == start:
            return np.array(out)


# --- descriptors ----------------------------------------------------------------------------------


def test_the_descriptor_table_gives_the_values_computed_by_hand(genome):
    config = small_config()
    evaluation = animat.evaluate(genome, config)
    values = qd.measure(genome, config, list(qd.DESCRIPTORS), evaluation)
    assert values is not None
    got = dict(zip(qd.DESCRIPTORS, values))

    embryo = animat.develop(genome, config)
    body = animat.build_body(embryo, config=config)
    p = body.positions
    d = np.linalg.norm(p[:, None] - p[None], axis=2)
    np.fill_diagonal(d, np.inf)
    s = float(np.median(d.min(axis=1)))  # the cell spacing
    moments = np.linalg.eigvalsh(np.cov(p.T, bias=True) + s**2 / 16 * np.eye(2))  # each cell a disc of diameter s
    outline = p[np.asarray(body.skin_loops[0])]
    shape = animat.shape.body_shape(body)

    assert got["cells"] == len(embryo.positions) == evaluation.cell_count == 32
    assert got["elongation"] == pytest.approx(math.sqrt(moments[1] / moments[0]), rel=1e-12)
    assert got["concavity"] == pytest.approx(1 - shoelace(outline) / shoelace(hull(p)), rel=1e-12)
    assert got["frequency"] == float(np.median(embryo.frequency))
    assert got["protrusions"] == shape.protrusion_count
    assert got["symmetric_pair"] == (1.0 if shape.symmetric_pair else 0.0)
    assert got["locomotion"] == MODES.index(animat.classify_locomotion(genome, config).mode)
    assert got["fitness"] == evaluation.fitness
    # the known values of this genome (fixed: they change only when development does)
    assert (got["protrusions"], got["symmetric_pair"], got["frequency"]) == (3.0, 1.0, 0.5)  # 0.5: frequency_min
    assert 1 < got["elongation"] < 2 and 0 < got["concavity"] < 0.3
    # each descriptor called alone gives the same value as measure() sharing one development
    for name, d in qd.DESCRIPTORS.items():
        assert d(genome, config, evaluation) == got[name], name


def test_a_non_viable_genome_has_no_descriptor():
    config = small_config()
    dead = next(
        g for g in (animat.Genome.random(i, config) for i in range(200)) if not animat.develop(g, config).viable
    )
    assert qd.measure(dead, config, ["cells", "elongation"]) is None
    viable = animat.Genome.random_viable(3, config)[0]
    assert qd.measure(viable, config, ["cells"], animat.Fitness(0.0, False)) is None  # told not viable


def test_own_descriptors_and_ranges():
    def width(genome, config, evaluation):
        return float(np.ptp(animat.develop(genome, config).positions[:, 0]))

    a = animat.GridArchive([(width, 0, 10), ("elongation", 1, 3), qd.DESCRIPTORS["cells"].with_range(0, 64)], 4)
    assert a.names == ("width", "elongation", "cells")
    assert (a.lower.tolist(), a.upper.tolist()) == ([0, 1, 0], [10, 3, 64])
    g = animat.Genome.random_viable(5, small_config())[0]
    v = qd.measure(g, small_config(), a.descriptors)
    assert v is not None and v[0] == width(g, small_config(), None)
    with pytest.raises(ValueError, match="no descriptor named"):
        animat.GridArchive(["legs"], 4)
    with pytest.raises(ValueError, match="needs a range"):
        animat.GridArchive([width], 4)
    with pytest.raises(ValueError, match="hi > lo"):
        animat.GridArchive([("cells", 5, 5)], 4)
    with pytest.raises(ValueError, match="distinct"):
        animat.GridArchive(["cells", "cells"], 4)


def test_the_doc_shows_the_descriptor_table():
    doc = (ROOT / "docs" / "python.md").read_text()
    assert qd.descriptor_table() in doc
    names = re.findall(r"^\| `(\w+)` \|", doc.split("Quality diversity: MAP-Elites")[1], flags=re.M)
    assert names[: len(qd.DESCRIPTORS)] == list(qd.DESCRIPTORS)


# --- archives -------------------------------------------------------------------------------------


def test_grid_bins_are_closed_below_and_clip_outside_the_range():
    a = animat.GridArchive([("concavity", 0, 1), ("elongation", 1, 4)], bins=(4, 3))
    assert a.cells == 12 and a.edges[0].tolist() == [0, 0.25, 0.5, 0.75, 1.0] and a.edges[1].tolist() == [1, 2, 3, 4]
    cases = {
        0.0: 0,
        0.2499: 0,
        0.25: 1,  # on an interior edge: the bin above
        0.5: 2,
        0.75: 3,
        1.0: 3,  # hi: clipped into the last bin
        1.5: 3,
        math.inf: 3,
        -0.1: 0,
        -math.inf: 0,
    }
    for value, b in cases.items():
        assert a.bin_of([value, 2.0]) == (b, 1), value
        assert a.index_of([value, 2.0]) == 3 * b + 1  # row-major
    assert a.bin_of([0.5, 4.0]) == (2, 2) and a.bin_of([0.5, 0.0]) == (2, 0)
    assert a.bin_of([math.nan, 2.0]) is None and a.index_of([0.1, math.nan]) is None
    with pytest.raises(ValueError, match="2 descriptors"):
        a.index_of([0.1])


def test_cvt_centroids_are_deterministic_and_values_go_to_the_nearest():
    ds = ["elongation", "frequency"]
    a, b = animat.CVTArchive(ds, 30, seed=4), animat.CVTArchive(ds, 30, seed=4)
    assert np.array_equal(a.centroids, b.centroids) and a.cells == 30 and a.samples == 1000
    assert not np.array_equal(a.centroids, animat.CVTArchive(ds, 30, seed=5).centroids)
    c = a.centroids
    assert (c >= a.lower).all() and (c <= a.upper).all()
    for k in range(a.cells):
        assert a.index_of(c[k]) == k  # a centroid is in its own cell
    # nearest in the unit-scaled box: elongation spans 3, frequency 5.5
    rng = np.random.default_rng(0)
    for v in rng.uniform(a.lower, a.upper, size=(50, 2)):
        u = (v - a.lower) / (a.upper - a.lower)
        cu = (c - a.lower) / (a.upper - a.lower)
        assert a.index_of(v) == int(np.argmin(((cu - u) ** 2).sum(axis=1)))
    assert a.index_of([100.0, -3.0]) == a.index_of([4.0, 0.5])  # clipped to the box


def test_the_archive_keeps_the_better_elite_and_counts_exactly(genome):
    a = animat.GridArchive([("concavity", 0, 1)], 4, qd_offset=-1.0)
    g2 = genome.mutate(1)
    steps = [
        ((genome, 1.0, [0.1]), True, {0: 1.0}),
        ((g2, 0.5, [0.2]), False, {0: 1.0}),  # worse: refused
        ((g2, 1.0, [0.2]), False, {0: 1.0}),  # a tie keeps the elite
        ((g2, 2.0, [0.15]), True, {0: 2.0}),
        ((genome, -0.5, [0.9]), True, {0: 2.0, 3: -0.5}),
        ((genome, 3.0, [math.nan]), False, {0: 2.0, 3: -0.5}),  # no descriptor: never archived
        ((g2, 0.25, [1.0]), True, {0: 2.0, 3: 0.25}),  # 1.0 = hi: the last cell
    ]
    for (g, f, d), entered, cells in steps:
        assert a.add(g, f, d) is entered
        assert {e.index: e.objective for e in a.elites()} == cells
    assert a.qd_score() == (2.0 + 1) + (0.25 + 1)
    assert a.coverage() == 0.5 and len(a) == 2
    assert a[0].genome == g2 and a[0].descriptors == (0.15,) and math.isnan(a[0].reference)
    assert a.best() is a[0]
    # the objective, when given, is what is compared (the exploit guard's "select")
    assert a.add(genome, 5.0, [0.6], objective=0.5, reference=0.5, generation=7)
    assert a.add(g2, 0.1, [0.6], objective=0.75)
    assert (a[2].fitness, a[2].objective, a[2].generation) == (0.1, 0.75, -1)
    assert a.qd_score() == 3.0 + 1.25 + 1.75
    with pytest.raises(ValueError, match="finite"):
        a.add(genome, math.inf, [0.5])


def test_the_data_frame_has_pyribs_columns(genome):
    a = animat.GridArchive([("concavity", 0, 1), ("elongation", 1, 4)], 4)
    a.add(genome, 1.5, [0.6, 3.5], reference=1.25, generation=2)
    a.add(genome.mutate(2), 0.5, [0.1, 1.0])
    cols = ["index", "objective", "measures_0", "measures_1", "solution", "fitness", "reference", "generation"]
    data = a.data()
    assert list(data) == cols
    assert data["index"].tolist() == [0, 11] and data["objective"].tolist() == [0.5, 1.5]
    assert data["measures_0"].tolist() == [0.1, 0.6] and data["measures_1"].tolist() == [1.0, 3.5]
    assert animat.Genome.from_json(data["solution"][1]) == genome
    assert data["reference"][1] == 1.25 and math.isnan(data["reference"][0])
    pd = pytest.importorskip("pandas")
    frame = a.to_pandas()
    assert isinstance(frame, pd.DataFrame) and list(frame.columns) == cols and len(frame) == 2
    assert frame["objective"].tolist() == [0.5, 1.5]


def test_archives_pickle_and_restore_their_state(genome):
    def width(genome, config, evaluation):
        return 0.0

    for a in (
        animat.GridArchive(["elongation", (width, 0, 1)], 3),
        animat.CVTArchive(["elongation", "frequency"], 7, seed=2, samples=100),
    ):
        a.add(genome, 1.0, [1.5, 0.7], reference=0.9)
        b = qd._Archive.from_state(json.loads(json.dumps(a.state())), a.descriptors)
        c = pickle.loads(pickle.dumps(a)) if a.kind == "cvt" else b  # a local function does not pickle
        for other in (b, c):
            assert type(other) is type(a) and other.names == a.names and other.cells == a.cells
            assert [(e.index, e.genome, e.fitness, e.reference) for e in other.elites()] == [
                (e.index, e.genome, e.fitness, e.reference) for e in a.elites()
            ]
        if a.kind == "cvt":
            assert np.array_equal(b.centroids, a.centroids)


# --- MapElites ------------------------------------------------------------------------------------


def elites_of(archive):
    return [(e.index, e.genome.to_json(), e.fitness, e.objective, e.descriptors, e.reference) for e in archive.elites()]


def same_history(a, b):
    for name in qd.QD_HISTORY_DTYPE.names:
        assert np.array_equal(a[name], b[name], equal_nan=True), name


def new_run(threads=1, guard="record", archive=None):
    archive = archive or animat.GridArchive(["elongation", "protrusions"], bins=(6, 8))
    return animat.MapElites(small_config(guard, threads), archive, batch=8, seed=5, crossover_fraction=0.5)


def test_the_descriptors_computed_on_threads_are_the_serial_ones():
    # Each batch's descriptors run on the evaluation's threads: the locomotion replay and the shape
    # give the same values, in the same order.
    archive = lambda: animat.GridArchive(["locomotion", "concavity", "frequency"], bins=(5, 4, 4))  # noqa: E731
    one, two = new_run(threads=1, archive=archive()), new_run(threads=2, archive=archive())
    for _ in range(2):
        one.step()
        two.step()
    assert len(one.archive) > 3
    assert elites_of(one.archive) == elites_of(two.archive)
    same_history(one.history, two.history)


def test_map_elites_is_the_same_for_any_thread_count_and_for_ask_tell():
    one, two = new_run(threads=1), new_run(threads=2)
    for _ in range(3):
        one.step()
        two.step()
    loop = new_run()
    config = loop.config
    while loop.generation < 2:
        genomes = loop.ask()
        assert [g.to_json() for g in loop.ask()] == [g.to_json() for g in genomes]  # asking again: the same
        loop.tell([animat.evaluate(g, config) for g in genomes])
    assert len(one.archive) > 3
    assert elites_of(one.archive) == elites_of(two.archive) == elites_of(loop.archive)
    same_history(one.history, two.history)
    same_history(one.history, loop.history)
    h = one.history
    assert h["generation"].tolist() == [0, 1, 2] and h["evaluations"].tolist() == [8, 16, 24]
    assert h["elites"][-1] == len(one.archive) and h["coverage"][-1] == len(one.archive) / 48
    assert h["qd_score"][-1] == one.archive.qd_score() and h["best"][-1] == max(e.fitness for e in one.archive.elites())
    assert (np.diff(h["qd_score"]) >= 0).all() and (np.diff(h["elites"]) >= 0).all()


def test_resume_gives_the_uninterrupted_run():
    straight = new_run(archive=animat.CVTArchive(["elongation", "frequency"], 12, seed=1, samples=200))
    for _ in range(5):
        straight.step()
    first = new_run(archive=animat.CVTArchive(["elongation", "frequency"], 12, seed=1, samples=200))
    for _ in range(3):
        first.step()
    text = json.dumps(first.checkpoint())
    resumed = animat.MapElites.restore(text, threads=2)
    assert [g.to_json() for g in resumed.ask()] == [g.to_json() for g in first.ask()]
    unpickled = pickle.loads(pickle.dumps(first))
    for me in (resumed, unpickled):
        while me.generation < 4:
            me.step()
        assert elites_of(me.archive) == elites_of(straight.archive)
        same_history(me.history, straight.history)
    other = small_config()
    other["evaluation.steps"] = 300
    with pytest.raises(ValueError, match="differs"):
        animat.MapElites.restore(text, other)


def test_the_run_directory_resumes_to_the_same_files(tmp_path):
    def run(out, generations, resume=False):
        archive = None if resume else animat.GridArchive(["elongation", "frequency"], 5)
        return animat.run_map_elites(
            small_config(),
            out,
            generations,
            archive,
            batch=8,
            seed=2,
            archive_every=2,
            resume=resume,
        )

    straight = run(tmp_path / "a", 4)
    run(tmp_path / "b", 1)
    with pytest.raises(FileExistsError):
        run(tmp_path / "b", 4)
    resumed = run(tmp_path / "b", 4, resume=True)
    assert elites_of(resumed.archive) == elites_of(straight.archive)
    a, b = tmp_path / "a", tmp_path / "b"
    assert sorted(p.name for p in (a / "archive").iterdir()) == ["gen_000000.csv", "gen_000002.csv", "gen_000004.csv"]
    assert sorted(p.name for p in (b / "archive").iterdir()) == [
        "gen_000000.csv",
        "gen_000001.csv",  # the last generation of the first session
        "gen_000002.csv",
        "gen_000004.csv",
    ]
    for name in ("archive/gen_000002.csv", "archive/gen_000004.csv", "config.toml"):
        assert (a / name).read_text() == (b / name).read_text(), name
    # history.csv and checkpoint.json differ only in the wall-clock seconds the engine records
    assert without_wall(a) == without_wall(b)
    loaded_a, loaded_b = animat.MapElites.load(a), animat.MapElites.load(b)
    assert elites_of(loaded_a.archive) == elites_of(loaded_b.archive) == elites_of(straight.archive)
    same_history(loaded_a.history, loaded_b.history)
    lines = (a / "history.csv").read_text().splitlines()
    assert lines[0].startswith("generation,evaluations,qd_score,coverage,best,") and len(lines) == 6
    rows = (a / "archive" / "gen_000004.csv").read_text().splitlines()
    assert rows[0] == "index,objective,fitness,reference,generation,elongation,frequency,genome"
    assert len(rows) == 1 + len(straight.archive)
    assert animat.load_config(str(a / "config.toml"))["evolution.seed"] == 2


def test_a_run_the_stall_rule_stops_keeps_its_last_archive(tmp_path):
    # The engine's run layer stops the run at its stall rule; the last generation's archive is
    # written even when it is not one of every archive_every.
    config = small_config()
    config["evolution.stall_generations"] = 1
    out = tmp_path / "run"
    me = animat.run_map_elites(config, out, 50, animat.GridArchive(["cells"], 4), batch=6, archive_every=100)
    assert 1 <= me.generation < 50
    assert sorted(p.name for p in (out / "archive").iterdir()) == ["gen_000000.csv", f"gen_{me.generation:06d}.csv"]
    assert len((out / "history.csv").read_text().splitlines()) == 1 + me.generation + 1


def test_non_viable_unstable_and_invalid_genomes_are_never_archived():
    me = new_run()
    genomes = me.ask()
    told = [
        None,
        animat.Fitness(1.0, False),
        animat.Fitness(1.0, True, False),  # unstable
        animat.Fitness(1.0, True, True, 32, False),  # invalid
        1.0,
        2.0,
        3.0,
        0.5,
    ]
    rows = [[1.5, 1.0]] * 4 + [[1.5, 1.0], None, [math.nan, 1.0], [3.5, 4.0]]
    row = me.tell(told, descriptors=rows)
    assert (row.added, row.discarded, row.elites) == (2, 6, 2)
    assert [(e.index, e.fitness, e.genome == genomes[i]) for e, i in zip(me.archive.elites(), (4, 7))] == [
        (8 * 1 + 1, 1.0, True),
        (8 * 5 + 4, 0.5, True),
    ]
    for _ in range(2):
        me.step()
    assert me.history["discarded"].sum() > 6  # mutations make non-viable genomes
    for e in me.archive.elites():
        assert animat.develop(e.genome, me.config).viable


def test_the_exploit_guard_stores_the_reference_of_every_elite():
    config = small_config("record")
    reference = config.copy()
    reference["physics.substeps"] = 2
    me = new_run(guard="record")
    new = 0
    for _ in range(2):
        row = me.step()
        new += sum(1 for e in me.archive.elites() if e.generation == me.generation)
        assert row.reference_evaluations == new  # one per new elite, none for a candidate replaced in its batch
    for e in me.archive.elites():
        assert e.reference == animat.evaluate(e.genome, reference).fitness
        assert e.objective == e.fitness
    assert me.history["disagreements"][-1] == sum(
        animat.reference_disagrees(e.fitness, e.reference, config) for e in me.archive.elites()
    )

    off = new_run(guard="off")
    off.step()
    assert all(math.isnan(e.reference) for e in off.archive.elites()) and off.history["reference_evaluations"][-1] == 0

    select = new_run(guard="select")
    row = select.step()
    assert row.reference_evaluations == 8 - row.discarded  # every archivable candidate
    for e in select.archive.elites():
        assert e.objective == e.reference == animat.evaluate(e.genome, reference).fitness
    assert select.archive.qd_score() == math.fsum(e.reference for e in select.archive.elites())
