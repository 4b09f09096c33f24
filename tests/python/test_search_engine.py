"""The C++ searches of animat_evolve (animat._core.SearchEngine, search.hpp) are animat.qd's MAP-Elites
and animat.moo's NSGA-II: told the same fitness, they ask the same genomes and write the same history
rows, generation after generation (a cheap deterministic stub stands in for the swims)."""

import hashlib
import json
import math

import numpy as np
import pytest

import animat
from animat import _core


def stub(genome):
    """A Fitness that depends on the genome only: a quarter not viable, the rest spread over the
    descriptors' ranges and the criteria."""
    h = int(hashlib.sha256(genome.to_json().encode()).hexdigest()[:15], 16)
    if h % 4 == 0:
        return animat.Fitness(0.0, False, True, 0)
    fitness = (h >> 8) % 5000 / 100.0
    return animat.Fitness(
        fitness, True, True, 1 + (h >> 24) % 64, actuation_work_positive=fitness * (1 + (h >> 32) % 100 / 50.0)
    )


def config_for(algorithm, seed):
    config = animat.Config()
    config["search.algorithm"] = algorithm
    config["search.descriptors"] = ["cells", "fitness"]
    config["search.bins"] = [8.0, 5.0]
    config["search.batch"] = 12
    config["search.objectives"] = ["distance:max", "actuation_work_positive:min"]
    config["evolution.population"] = 12
    config["evolution.seed"] = seed
    config["evolution.threads"] = 1
    config["evaluation.reference_check"] = "off"
    return config


def same(a, b):
    return len(a) == len(b) and all(x == y or (math.isnan(x) and math.isnan(y)) for x, y in zip(a, b))


def run_both(engine, me, generations=6):
    """Drives the engine and animat.qd's MapElites (descriptors cells and fitness) with the same stubs,
    checking that they ask the same genomes and write the same history rows."""
    for _ in range(generations):
        genomes = engine.ask()
        assert [g.to_json() for g in genomes] == [g.to_json() for g in me.ask()]
        told = [stub(g) for g in genomes]
        assert engine.tell(told)
        row = me.tell(told, descriptors=[[f.cell_count, f.fitness] if f.viable else None for f in told])
        assert same(engine.history[-1][:10], [float(x) for x in row]), (engine.history[-1], row)


def test_map_elites_is_animat_qd():
    config = config_for("map_elites", 3)
    engine = _core.SearchEngine(config)
    me = animat.MapElites(config, animat.GridArchive(["cells", "fitness"], bins=(8, 5)), batch=12, seed=3)
    assert [c[0] for c in engine.history_columns][:10] == list(animat.QD_HISTORY_DTYPE.names)
    run_both(engine, me)
    assert engine.history[-1][5] > 3  # the archive holds several elites: a real comparison


def test_search_ranges_are_animat_qd_descriptor_ranges():
    # search.ranges is what ("name", lo, hi) descriptors are to animat.qd: the same grid edges, so
    # the same cells, elites and parents.
    config = config_for("map_elites", 4)
    config["search.bins"] = [6.0, 4.0]
    config["search.ranges"] = [10.0, 40.0, 5.0, 45.0]
    engine = _core.SearchEngine(config)
    archive = animat.GridArchive([("cells", 10.0, 40.0), ("fitness", 5.0, 45.0)], bins=(6, 4))
    me = animat.MapElites(config, archive, batch=12, seed=4)
    run_both(engine, me)
    assert engine.history[-1][5] > 3  # several elites: a real comparison


def test_supplied_descriptors_are_animat_qd_python_descriptors():
    # A descriptor the engine's table lacks is computed by the caller and passed to tell, as
    # animat.qd takes a Python function's values: the same cells, elites and parents.
    def shade(genome, config=None, evaluation=None):
        return int(hashlib.sha256(genome.to_json().encode()).hexdigest()[20:24], 16) / 65536.0

    config = config_for("map_elites", 6)
    config["search.descriptors"] = ["shade", "cells"]
    config["search.bins"] = [4.0, 8.0]
    config["search.ranges"] = [0.0, 1.0, 1.0, 65.0]
    engine = _core.SearchEngine(config, supplied=["shade"])
    me = animat.MapElites(config, animat.GridArchive([(shade, 0.0, 1.0), "cells"], bins=(4, 8)), batch=12, seed=6)
    for _ in range(6):
        genomes = engine.ask()
        assert [g.to_json() for g in genomes] == [g.to_json() for g in me.ask()]
        told = [stub(g) for g in genomes]
        assert engine.tell(told, values=[[shade(g)] for g in genomes])
        row = me.tell(told, descriptors=[[shade(g), f.cell_count] if f.viable else None for g, f in zip(genomes, told)])
        assert same(engine.history[-1][:10], [float(x) for x in row]), (engine.history[-1], row)
    assert engine.history[-1][5] > 3  # several elites: a real comparison
    again = _core.SearchEngine(config, supplied=["shade"])
    again.restore(engine.checkpoint())
    assert again.history == engine.history
    with pytest.raises(Exception, match="descriptor shade = nan"):
        genomes = again.ask()
        again.tell([stub(g) for g in genomes], values=[[math.nan]] * len(genomes))
    with pytest.raises(Exception, match="supplied descriptors"):
        _core.SearchEngine(config_for("map_elites", 6)).tell([], values=[[0.5]])


@pytest.mark.parametrize(
    "ranges, message",
    [
        ([0.0, 10.0], r"search.ranges = \[0.0, 10.0\]: give lo and hi for each of the 2"),
        ([0.0, 10.0, 3.0, 3.0], r'the range of "fitness", \[3.0, 3.0\], is not finite lo < hi'),
        ([0.0, math.inf, 0.0, 1.0], r"search.ranges = \[0.0, inf, 0.0, 1.0\]: entry inf: must be finite"),
    ],
)
def test_bad_search_ranges_are_refused_by_key_and_value(ranges, message):
    config = config_for("map_elites", 3)
    with pytest.raises(Exception, match=message):
        config["search.ranges"] = ranges
        _core.SearchEngine(config)


def test_nsga2_is_animat_moo():
    config = config_for("nsga2", 5)
    engine = _core.SearchEngine(config)
    nsga = animat.Nsga2(config, [("distance", "max"), ("actuation_work_positive", "min")], population=12, seed=5)
    assert [c[0] for c in engine.history_columns][:-1] == list(nsga.history_dtype.names)
    for _ in range(6):
        genomes = engine.ask()
        assert [g.to_json() for g in genomes] == [g.to_json() for g in nsga.ask()]
        told = [stub(g) for g in genomes]
        assert engine.tell(told)
        row = nsga.tell([[f.fitness, f.actuation_work_positive] if f.viable else None for f in told])
        assert same(engine.history[-1][:-1], [float(x) for x in row]), (engine.history[-1], row)
    assert engine.history[-1][2] > 2  # a front of several members: a real comparison


def test_a_refused_tell_changes_nothing_and_names_the_value():
    engine = _core.SearchEngine(config_for("map_elites", 3))
    genomes = engine.ask()
    told = [stub(g) for g in genomes]
    k = next(i for i, f in enumerate(told) if f.viable)
    bad = list(told)
    bad[k] = animat.Fitness(math.inf, True, True, 5)
    with pytest.raises(Exception, match=f"value {k} .*fitness inf"):
        engine.tell(bad)
    assert engine.generation == -1 and engine.history == []
    assert [g.to_json() for g in engine.ask()] == [g.to_json() for g in genomes]
    assert engine.tell(told)
    text = engine.checkpoint()
    again = _core.SearchEngine(config_for("map_elites", 3))
    again.restore(text)
    assert again.history == engine.history
    with pytest.raises(Exception, match="checksum"):
        again.restore(text.replace('\\"generation\\":0', '\\"generation\\":1'))


@pytest.mark.parametrize("guard", ["record", "select"])
@pytest.mark.parametrize("algorithm", ["map_elites", "nsga2"])
def test_the_exploit_guard_swims_the_same_references(algorithm, guard):
    # The exploit guard swims each new elite or front member ("record"), or every candidate before
    # the archive or the selection compares the reference values ("select"), as animat.qd and
    # animat.moo do: the same genomes, the same reference values, the same counts.
    config = config_for(algorithm, 7)
    config["evaluation.reference_check"] = guard
    config["evaluation.steps"] = 40
    engine = _core.SearchEngine(config)
    if algorithm == "map_elites":
        search = animat.MapElites(config, animat.GridArchive(["cells", "fitness"], bins=(8, 5)), batch=12, seed=7)
    else:
        search = animat.Nsga2(config, [("distance", "max"), ("actuation_work_positive", "min")], population=12, seed=7)
    for _ in range(3):
        genomes = engine.ask()
        assert [g.to_json() for g in genomes] == [g.to_json() for g in search.ask()]
        told = [stub(g) for g in genomes]
        engine.tell(told)
        if algorithm == "map_elites":
            row = search.tell(told, descriptors=[[f.cell_count, f.fitness] if f.viable else None for f in told])
        else:
            row = search.tell([[f.fitness, f.actuation_work_positive] if f.viable else None for f in told])
        assert same(
            engine.history[-1][:-1] if algorithm == "nsga2" else engine.history[-1][:10], [float(x) for x in row]
        )
    assert row["reference_evaluations"] > 0


def test_run_search_resumes_to_the_same_run(tmp_path):
    config = config_for("nsga2", 9)
    config["evaluation.steps"] = 40
    config["evolution.generations"] = 4
    straight = _core.run_search(config, tmp_path / "straight")
    assert straight["generation"] == 4 and straight["stop_reason"].startswith("generation cap")
    config["evolution.generations"] = 2
    _core.run_search(config, tmp_path / "resumed")
    with pytest.raises(Exception, match="already holds a run"):
        _core.run_search(config, tmp_path / "resumed")
    config["evolution.generations"] = 4
    resumed = _core.run_search(config, tmp_path / "resumed", resume=True)
    assert [row[:-1] for row in resumed["history"]] == [row[:-1] for row in straight["history"]]
    assert resumed["columns"][-1] == "wall_seconds"


def test_map_elites_state_is_animat_qd_archive():
    # elites(), archive and index_of() are the archive animat.qd builds from the same stubs: the same
    # cells, genomes, values, objectives and generations.
    config = config_for("map_elites", 3)
    config["search.ranges"] = [1.0, 65.0, 0.0, 50.0]
    engine = _core.SearchEngine(config)
    me = animat.MapElites(
        config, animat.GridArchive([("cells", 1.0, 65.0), ("fitness", 0.0, 50.0)], bins=(8, 5)), batch=12, seed=3
    )
    for _ in range(4):
        genomes = engine.ask()
        me.ask()
        told = [stub(g) for g in genomes]
        engine.tell(told)
        me.tell(told, descriptors=[[f.cell_count, f.fitness] if f.viable else None for f in told])
    assert engine.archive == {
        "kind": "grid",
        "descriptors": ["cells", "fitness"],
        "lower": [1.0, 0.0],
        "upper": [65.0, 50.0],
        "cells": 40,
        "bins": [8, 5],
    }
    elites = engine.elites()
    expected = me.archive.elites()
    assert len(elites) == len(expected) > 3
    for got, want in zip(elites, expected):
        assert got["index"] == want.index
        assert got["genome"].to_json() == want.genome.to_json()
        assert got["fitness"].fitness == want.fitness and got["objective"] == want.objective
        assert got["values"] == [got["fitness"].cell_count, got["fitness"].fitness] == list(want.descriptors)
        assert math.isnan(got["reference"]) and math.isnan(want.reference)
        assert got["generation"] == want.generation
        assert engine.index_of(got["values"]) == got["index"] == me.archive.index_of(want.descriptors)
    assert engine.index_of([0.0, 49.0]) == 4 and engine.index_of([1000.0, -1.0]) == 35
    with pytest.raises(ValueError, match="descriptor fitness = nan"):
        engine.index_of([3.0, math.nan])
    with pytest.raises(ValueError, match="1 values for the 2 descriptors"):
        engine.index_of([3.0])
    with pytest.raises(ValueError, match=r"SearchEngine.population: a nsga2 search only; .*\"map_elites\""):
        engine.population()


def test_nsga2_state_is_animat_moo_population():
    # population(), front(), reference_point and criteria are animat.moo's for the same stubs.
    config = config_for("nsga2", 5)
    engine = _core.SearchEngine(config)
    assert engine.criteria == [("distance", "max"), ("actuation_work_positive", "min")]
    assert engine.reference_point == [] and engine.population() == [] and engine.front() == []
    nsga = animat.Nsga2(config, [("distance", "max"), ("actuation_work_positive", "min")], population=12, seed=5)
    for _ in range(5):
        genomes = engine.ask()
        nsga.ask()
        told = [stub(g) for g in genomes]
        engine.tell(told)
        nsga.tell([[f.fitness, f.actuation_work_positive] if f.viable else None for f in told])
    population = engine.population()
    assert len(population) == len(nsga.population) == 12
    for got, want in zip(population, nsga.population):
        assert got["genome"].to_json() == want.genome.to_json()
        assert same(got["objectives"], want.objectives)
        assert got["reference"] == [] and want.reference is None
        assert (got["generation"], got["feasible"], got["rank"]) == (want.generation, want.feasible, want.rank)
        assert got["crowding"] == want.crowding
        assert got["fitness"].fitness == stub(got["genome"]).fitness
    front = engine.front()
    assert len(front) > 2
    assert [population[i]["genome"].to_json() for i in front] == [s.genome.to_json() for s in nsga.front()]
    assert engine.reference_point == list(nsga.reference_point)
    with pytest.raises(ValueError, match=r"SearchEngine.elites: a map_elites search only"):
        engine.elites()
    with pytest.raises(ValueError, match=r"SearchEngine.archive: a map_elites search only"):
        engine.archive  # noqa: B018


def shade(genome, config=None, evaluation=None):
    """A caller's measure the engine's table lacks: a number in [0, 1) from the genome alone."""
    return int(hashlib.sha256(genome.to_json().encode()).hexdigest()[20:24], 16) / 65536.0


def shade_config(seed):
    config = config_for("nsga2", seed)
    config["search.objectives"] = ["distance:max", "shade:min"]
    return config


def test_supplied_criteria_are_animat_moo_python_criteria():
    # A criterion the engine's table lacks is computed by the caller and passed to tell, as
    # animat.moo takes a Python criterion's values: the same selection, history and front.
    config = shade_config(8)
    engine = _core.SearchEngine(config, supplied=["shade"])
    assert engine.criteria == [("distance", "max"), ("shade", "min")]
    nsga = animat.Nsga2(
        config, [("distance", "max"), animat.moo.Criterion("shade", "min", lambda e: 0.0)], population=12, seed=8
    )
    for _ in range(6):
        genomes = engine.ask()
        assert [g.to_json() for g in genomes] == [g.to_json() for g in nsga.ask()]
        told = [stub(g) for g in genomes]
        assert engine.tell(told, values=[[shade(g)] for g in genomes])
        row = nsga.tell([[f.fitness, shade(g)] if f.viable else None for g, f in zip(genomes, told)])
        assert same(engine.history[-1][:-1], [float(x) for x in row]), (engine.history[-1], row)
    assert engine.history[-1][2] > 2  # a front of several members: a real comparison
    population = engine.population()
    assert [population[i]["genome"].to_json() for i in engine.front()] == [s.genome.to_json() for s in nsga.front()]
    again = _core.SearchEngine(config, supplied=["shade"])
    again.restore(engine.checkpoint())
    assert again.history == engine.history
    assert [p["objectives"] for p in again.population()] == [p["objectives"] for p in population]
    # a feasible member's value must be finite: refused by index and name, changing nothing
    genomes = again.ask()
    told = [stub(g) for g in genomes]
    k = next(i for i, f in enumerate(told) if f.viable)
    values = [[shade(g)] for g in genomes]
    values[k] = [math.inf]
    with pytest.raises(ValueError, match=f"value {k} .*criterion shade = inf"):
        again.tell(told, values)
    assert again.history == engine.history
    with pytest.raises(ValueError, match="rows of supplied values for the 12 genomes"):
        again.tell(told, values[:3])


def test_supplied_criteria_are_checked_by_key_and_value():
    config = shade_config(8)
    config["search.objectives"] = ["distance:max", "shade"]
    with pytest.raises(ValueError, match=r'search.objectives: "shade" is supplied by the caller: give its sense'):
        _core.SearchEngine(config, supplied=["shade"])
    with pytest.raises(ValueError, match=r'search.objectives: the caller supplies "speed", which is not one of'):
        _core.SearchEngine(shade_config(8), supplied=["speed"])
    with pytest.raises(ValueError, match='search.objectives: no measure "shade"'):
        _core.SearchEngine(shade_config(8))  # not in the table and not supplied
    with pytest.raises(ValueError, match="the GA has none"):
        _core.SearchEngine(config_for("ga", 8), supplied=["shade"])
    # the checkpoint keeps the supplied values: a missing one is refused on restore
    engine = _core.SearchEngine(shade_config(8), supplied=["shade"])
    genomes = engine.ask()
    engine.tell([stub(g) for g in genomes], [[shade(g)] for g in genomes])
    payload = json.loads(json.loads(engine.checkpoint())["payload"])
    for member in payload["population"]:
        member.pop("supplied", None)
    body = json.dumps(payload, separators=(",", ":"))
    with pytest.raises(ValueError, match="has no list of its 1 supplied criterion values"):
        _core.SearchEngine(shade_config(8), supplied=["shade"]).restore(
            json.dumps({"checksum": fnv1a(body), "payload": body})
        )


def fnv1a(text):
    h = 0xCBF29CE484222325
    for b in text.encode():
        h = ((h ^ b) * 0x100000001B3) % (1 << 64)
    return f"{h:016x}"


def test_run_search_hooks_evaluate_and_describe(tmp_path):
    # evaluate and describe replace the config's own evaluation and give the supplied values: the
    # run is the engine's told the same stubs; an exception in a hook stops the run with its message,
    # leaves the last checkpoint, and the resume is the uninterrupted run.
    config = shade_config(9)
    config["evolution.generations"] = 4
    config["evolution.checkpoint_every"] = 1
    calls = []

    def evaluate(genomes):
        calls.append(len(genomes))
        return [stub(g) for g in genomes]

    def describe(genomes, fitness):
        return [[shade(g)] for g in genomes]

    hooks = dict(supplied=["shade"], evaluate=evaluate, describe=describe)
    straight = _core.run_search(config, tmp_path / "straight", **hooks)
    assert straight["generation"] == 4 and calls == [12] * 5
    engine = _core.SearchEngine(config, supplied=["shade"])
    for _ in range(5):
        genomes = engine.ask()
        engine.tell([stub(g) for g in genomes], [[shade(g)] for g in genomes])
    assert [row[:-1] for row in straight["history"]] == [row[:-1] for row in engine.history]

    def failing(genomes, fitness):
        if len(failing.seen) == 2:
            raise RuntimeError("describe failed at generation 2")
        failing.seen.append(1)
        return describe(genomes, fitness)

    failing.seen = []
    with pytest.raises(RuntimeError, match="describe failed at generation 2"):
        _core.run_search(config, tmp_path / "resumed", supplied=["shade"], evaluate=evaluate, describe=failing)
    checkpoint = (tmp_path / "resumed" / "checkpoint.json").read_text()
    assert json.loads(json.loads(checkpoint)["payload"])["generation"] == 1
    resumed = _core.run_search(config, tmp_path / "resumed", resume=True, **hooks)
    assert [row[:-1] for row in resumed["history"]] == [row[:-1] for row in straight["history"]]
    with pytest.raises(ValueError, match="gives no describe hook"):
        _core.run_search(config, tmp_path / "refused", supplied=["shade"], evaluate=evaluate)
    assert not (tmp_path / "refused").exists()


def cvt_config(seed, cells=10):
    config = config_for("map_elites", seed)
    config["search.archive"] = "cvt"
    config["search.cells"] = cells
    config["search.samples"] = 400
    config["search.ranges"] = [1.0, 65.0, 0.0, 50.0]
    return config


def lloyd(samples, k, iterations):
    """Lloyd's k-means as the engine documents it, in numpy: the first k samples start; each
    iteration assigns every sample to its nearest centroid (the first among equals) and moves each
    centroid to the mean of its samples (one without samples stays), until nothing changes."""
    centroids = samples[:k].copy()
    previous = None
    for _ in range(iterations):
        labels = np.argmin(((samples[:, None, :] - centroids[None, :, :]) ** 2).sum(axis=2), axis=1)
        if previous is not None and np.array_equal(labels, previous):
            break
        counts = np.bincount(labels, minlength=k)
        filled = counts > 0
        for j in range(samples.shape[1]):
            sums = np.bincount(labels, weights=samples[:, j], minlength=k)
            centroids[filled, j] = sums[filled] / counts[filled]
        previous = labels
    return centroids


def test_cvt_centroids_are_lloyd_kmeans_of_the_engine_samples():
    # Lloyd's k-means of the samples of the engine's keyed stream, computed independently in numpy:
    # the same numbers, bit for bit; animat.qd.CVTArchive's centroids are the engine's.
    rng = _core.Rng.derive(5, _core.CVT_SAMPLES_KEY, 0)
    samples = np.array([[rng.uniform() for _ in range(3)] for _ in range(300)])
    expected = lloyd(samples, 12, 100)
    names = [("cells", 1.0, 65.0), ("fitness", 0.0, 50.0), ("elongation", 1.0, 4.0)]
    assert animat.CVTArchive(names, 12, seed=5, samples=300).state()["centroids"] == expected.tolist()
    assert _core.cvt_centroids(3, 12, 5, 300) == expected.tolist()
    assert _core.cvt_centroids(3, 12, 5, 300, iterations=0) == samples[:12].tolist()
    assert len(_core.cvt_centroids(2, 4, 5)) == 4  # samples 0: max(1000, 20 cells)
    with pytest.raises(ValueError, match="samples = 3: fewer samples than the 4 cells"):
        _core.cvt_centroids(2, 4, 5, 3)
    with pytest.raises(ValueError, match=r"cells = 1000000 with samples = 20000000 samples makes 2e\+13"):
        _core.cvt_centroids(2, 1000000, 5)


def test_map_elites_on_a_cvt_archive_is_animat_qd_cvt_archive():
    # The engine's CVT archive, given animat.qd.CVTArchive's centroids, puts every candidate in
    # the same cell: the same elites, parents and history as animat.qd.MapElites.
    descriptors = [("cells", 1.0, 65.0), ("fitness", 0.0, 50.0)]
    archive = animat.CVTArchive(descriptors, cells=10, seed=2, samples=400)
    unit = archive.state()["centroids"]
    engine = _core.SearchEngine(cvt_config(4), centroids=unit)
    assert engine.archive == {
        "kind": "cvt",
        "descriptors": ["cells", "fitness"],
        "lower": [1.0, 0.0],
        "upper": [65.0, 50.0],
        "cells": 10,
        "centroids": unit,
    }
    me = animat.MapElites(config_for("map_elites", 4), archive, batch=12, seed=4)
    run_both(engine, me)
    assert [e["index"] for e in engine.elites()] == [e.index for e in archive.elites()]
    assert len(engine.elites()) > 3  # several elites: a real comparison
    # a value is scaled to the unit cube, clipped, then put in its nearest centroid's cell
    points = [[0.0, -10.0], [30.0, 25.0], [100.0, 49.0], [64.9, 0.1]]
    for p in points:
        u = np.clip((np.array(p) - [1.0, 0.0]) / [64.0, 50.0], 0.0, 1.0)
        assert engine.index_of(p) == int(np.argmin(((np.array(unit) - u) ** 2).sum(axis=1))) == archive.index_of(p)


def test_cvt_archive_from_the_config_and_its_checks():
    config = cvt_config(6)
    engine = _core.SearchEngine(config)
    assert engine.archive["centroids"] == _core.cvt_centroids(2, 10, 6, 400)
    genomes = engine.ask()
    engine.tell([stub(g) for g in genomes])
    text = engine.checkpoint()
    again = _core.SearchEngine(config)
    again.restore(text)
    assert [(e["index"], e["objective"]) for e in again.elites()] == [
        (e["index"], e["objective"]) for e in engine.elites()
    ]
    other = [[min(1.0, x + 0.01) for x in row] for row in engine.archive["centroids"]]
    with pytest.raises(ValueError, match="the CVT archive's centroids are not this search's"):
        _core.SearchEngine(config, centroids=other).restore(text)
    with pytest.raises(ValueError, match="centroids: row 1 holds 1.5; a centroid lies in the unit cube"):
        _core.SearchEngine(config, centroids=[[0.5, 0.5], [1.5, 0.0]])
    with pytest.raises(ValueError, match="centroids: row 0 has 3 values for the 2 descriptors"):
        _core.SearchEngine(config, centroids=[[0.5, 0.5, 0.5]])
    with pytest.raises(ValueError, match='centroids: given for search.archive = "grid"'):
        _core.SearchEngine(config_for("map_elites", 6), centroids=[[0.5, 0.5]])
    with pytest.raises(ValueError, match="search.cells = 1000000 with search.samples = 20000000 samples"):
        config["search.samples"] = 0
        config["search.cells"] = 1000000
        _core.SearchEngine(config)


@pytest.mark.parametrize(
    "algorithm, reason",
    [("map_elites", "no elite added or improved"), ("nsga2", "hypervolume not increased")],
)
def test_the_stall_rule_stops_a_search_without_improvement(tmp_path, algorithm, reason):
    # Every genome swims the same: generation 0 fills the archive or sets the hypervolume, and
    # nothing improves after it; evolution.stall_generations = 3 stops the run at generation 3.
    config = config_for(algorithm, 2)
    config["evolution.stall_generations"] = 3
    config["evolution.generations"] = 50

    def same_swim(genomes):
        return [animat.Fitness(7.0, True, True, 9, actuation_work_positive=3.0) for _ in genomes]

    run = _core.run_search(config, tmp_path / "run", evaluate=same_swim)
    assert run["generation"] == 3
    assert run["stop_reason"] == f"{reason} for evolution.stall_generations = 3 generations"
    config["evolution.stall_generations"] = 5
    config["evolution.generations"] = 7
    resumed = _core.run_search(config, tmp_path / "run", resume=True, evaluate=same_swim)
    assert resumed["generation"] == 5 and resumed["stop_reason"].startswith(reason)
