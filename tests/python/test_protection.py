"""Morphological innovation protection (``evolution.protection_generations``) from Python and the
command line, and the morphology kind it compares: the C++ elongation is ``animat.shape``'s."""

import csv
import math
import os
import pickle
import subprocess

import numpy as np
import pytest

import animat
from animat import shape

EXE = os.environ.get("ANIMAT_EVOLVE_EXE")


def small_config(protection=2, population=8, generations=2, steps=100, seed=3):
    c = animat.Config()
    c["evolution.population"] = population
    c["evolution.generations"] = generations
    c["evaluation.steps"] = steps
    c["evolution.seed"] = seed
    c["evolution.threads"] = 1
    c["evolution.protection_generations"] = protection
    return c


def _band(elongation):
    return min(15, int(math.floor(math.log(elongation) / math.log(1.5))))


def test_the_cxx_elongation_is_animat_shapes_on_random_viable_bodies():
    for cells in (32, 64):
        config = animat.Config()
        config["development.max_cells"] = cells
        rng = animat.Rng(cells)
        for _ in range(4):
            genome, _tries = animat.Genome.random_viable(rng, config)
            body = animat.build_body(animat.develop(genome, config), config=config)
            p = np.asarray(body.positions)
            assert animat._core._cell_spacing(p) == pytest.approx(shape.cell_spacing(p), rel=1e-9, abs=0)
            e = shape.elongation(p)
            assert animat._core.shape_elongation(p) == pytest.approx(e, rel=1e-9, abs=0)
            kind = animat.morphology_kind(p)
            assert kind == len(p) * 16 + _band(e)
            result = animat.evaluate(genome, config)
            assert result.morphology_kind == kind
            assert animat.to_fitness(result).morphology_kind == kind
            assert animat.evaluate_population([genome], config)[0].morphology_kind == kind
    # Point clouds of any spread and size, with and without the cells' own extent.
    rng = np.random.default_rng(5)
    for n in (2, 3, 7, 40):
        for stretch in (1.0, 3.0, 30.0):
            p = rng.normal(size=(n, 2)) * np.array([stretch, 1.0])
            for diameter in (1.0, 0.5):
                params = shape.ShapeParams(cell_diameter=diameter)
                expected = shape.elongation(p, params)
                assert animat._core.shape_elongation(p, diameter) == pytest.approx(expected, rel=1e-9, abs=0)
    assert animat.morphology_kind(np.zeros((0, 2))) == 0
    assert animat.morphology_kind([[0.0, 0.0]]) == 16


def test_protection_runs_through_evolve_and_ga_alike(tmp_path):
    config = small_config()
    result = animat.evolve(config, quiet=True, out=tmp_path / "run")
    assert result.history.dtype == animat.PROTECTED_HISTORY_DTYPE
    assert "protected" in result.history.dtype.names
    assert result.history["protected"][0] == 8  # generation 0: every morphology is new
    assert all(0 <= p <= 8 for p in result.history["protected"])
    ages = [i.morphology_age for i in result.population]
    assert all(0 <= a <= 2 for a in ages)
    assert all(i.fitness.morphology_kind > 0 for i in result.population if i.fitness.viable)
    # The ask/tell loop with animat.evaluate is the same run.
    ga = animat.GA(config)
    while not ga.done:
        ga.tell([animat.evaluate(g, config) for g in ga.ask()])
    assert [i.morphology_age for i in ga.population] == ages
    assert [i.fitness for i in ga.population] == [i.fitness for i in result.population]
    assert list(ga.history["protected"]) == list(result.history["protected"])
    # The run directory: history.csv's column, read back; the genealogy's kinds and ages.
    run = animat.Run(tmp_path / "run")
    assert run.history.dtype == animat.PROTECTED_HISTORY_DTYPE
    assert list(run.history["protected"]) == list(result.history["protected"])
    genealogy = run.genealogy()
    assert genealogy.dtype == animat.PROTECTED_GENEALOGY_DTYPE
    assert set(genealogy["morphology_age"][genealogy["generation"] == 0]) == {0}
    # Without protection: the history as it always was.
    plain = animat.evolve(small_config(protection=0), quiet=True)
    assert plain.history.dtype == animat.HISTORY_DTYPE
    assert "protected" not in plain.history.dtype.names


def test_individual_and_fitness_carry_kind_and_age_through_pickles():
    config = small_config(generations=1)
    result = animat.evolve(config, quiet=True)
    for ind in result.population:
        back = pickle.loads(pickle.dumps(ind))
        assert back.morphology_age == ind.morphology_age
        assert back.fitness == ind.fitness
        assert back.fitness.morphology_kind == ind.fitness.morphology_kind
    # States pickled before the kind and the age existed still load (kind and age 0).
    ind = result.population[0]
    old_fitness = animat.Fitness.__new__(animat.Fitness)
    old_fitness.__setstate__(ind.fitness.__getstate__()[:6])
    assert old_fitness.morphology_kind == 0 and old_fitness.fitness == ind.fitness.fitness
    old = animat.Individual.__new__(animat.Individual)
    old.__setstate__(ind.__getstate__()[:6])
    assert old.morphology_age == 0 and old.id == ind.id
    with pytest.raises(ValueError, match="morphology_kind must be >= 0"):
        animat.Fitness(1.0, True, True, 3, morphology_kind=-1)


def test_bad_values_are_refused_naming_key_and_value():
    c = animat.Config()
    for bad in (-1, 2.5):
        with pytest.raises(ValueError, match=rf"evolution\.protection_generations = {bad}"):
            c["evolution.protection_generations"] = bad
    assert c["evolution.protection_generations"] == 0
    assert "protection" in animat.Config().to_toml()


@pytest.mark.skipif(not EXE or not os.path.exists(EXE), reason="ANIMAT_EVOLVE_EXE not set")
def test_animat_evolve_writes_the_protected_column(tmp_path):
    out = tmp_path / "run"
    args = [
        "--out",
        str(out),
        "--generations",
        "2",
        "--threads",
        "1",
        "--seed",
        "4",
        "--quiet",
        "--set",
        "evolution.population=8",
        "--set",
        "evaluation.steps=100",
        "--set",
        "evolution.protection_generations=3",
    ]
    r = subprocess.run([EXE, *args], capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert r.returncode == 0, r.stderr
    rows = list(csv.DictReader(open(out / "history.csv")))
    assert [row["generation"] for row in rows] == ["0", "1", "2"]
    assert rows[0]["protected"] == "8"
    assert all(0 <= int(row["protected"]) <= 8 for row in rows)
    genealogy = (out / "genealogy.csv").read_text().splitlines()
    assert genealogy[0].endswith(",morphology_kind,morphology_age")
    # The same run from Python.
    config = animat.load_config(out / "config.toml")
    assert config["evolution.protection_generations"] == 3
    again = animat.evolve(config, quiet=True)
    assert [int(row["protected"]) for row in rows] == list(again.history["protected"])
    assert [float(row["best"]) for row in rows] == list(again.history["best"])
