"""The GA through `import animat`: evolve, callbacks, run directories, parallel evaluation."""

import csv
import json

import pytest

import animat


def small_config(population=12, generations=3, steps=300, seed=3):
    c = animat.Config()
    c["evolution.population"] = population
    c["evolution.generations"] = generations
    c["evaluation.steps"] = steps
    c["evolution.seed"] = seed
    return c


def test_tournament_probability_ramps_from_0_8_to_1():
    assert animat.tournament_probability(0) == pytest.approx(0.8)
    assert animat.tournament_probability(500) == pytest.approx(0.9)
    assert animat.tournament_probability(1000) == pytest.approx(1.0)
    assert animat.tournament_probability(4000) == pytest.approx(1.0)


def test_reference_disagrees_needs_both_tolerances_exceeded():
    # Defaults: 1 % of the reference and 0.05 length units; both must be exceeded, on either side.
    assert animat.reference_disagrees(10.0, 10.2)  # 0.2 > 0.05 and 2 % > 1 %
    assert animat.reference_disagrees(10.2, 10.0)
    assert not animat.reference_disagrees(100.0, 100.9)  # 0.9 > 0.05 but 0.9 % < 1 %
    assert not animat.reference_disagrees(1.0, 1.04)  # 4 % > 1 % but 0.04 < 0.05
    cfg = animat.Config()
    cfg["evaluation.reference_tolerance"] = 0.001
    assert animat.reference_disagrees(100.0, 100.9, cfg)  # 0.9 % > 0.1 % with the config's tolerance
    cfg["evaluation.reference_abs_tolerance"] = 1.0
    assert not animat.reference_disagrees(100.0, 100.9, cfg)


@pytest.mark.parametrize("substeps, factor", [(1, 4), (3, 2), (2, 1)])
def test_reference_config_multiplies_the_substeps_and_keeps_everything_else(substeps, factor):
    c = small_config()
    c["physics.substeps"] = substeps
    c["evaluation.reference_substeps"] = factor
    c["scene.drag_normal"] = 7.5
    c["evaluation.reference_check"] = "off"  # the reference swim's own guard is the engine's business
    ref = animat.reference_config(c)
    assert ref["physics.substeps"] == c["physics.substeps"] * c["evaluation.reference_substeps"] == substeps * factor
    mine, theirs = c.to_dict(), ref.to_dict()
    mine["physics"].pop("substeps")
    theirs["physics"].pop("substeps")
    assert mine == theirs
    assert c["physics.substeps"] == substeps  # a copy: the config itself is unchanged
    assert animat.reference_config.__doc__ and "reference_substeps" in animat.reference_config.__doc__


def test_evolve_returns_history_and_best_and_elitism_holds():
    r = animat.evolve(small_config(generations=4))
    assert [h.generation for h in r.history] == [0, 1, 2, 3, 4]
    bests = [h.best for h in r.history]
    assert all(b2 >= b1 for b1, b2 in zip(bests, bests[1:]))
    assert r.best_fitness.fitness == pytest.approx(bests[-1])
    assert r.best_fitness.viable
    assert isinstance(r.best_genome, animat.Genome)
    assert "generation cap" in r.stop_reason


def test_callback_sees_every_generation_and_can_stop_the_run():
    seen = []

    def cb(stats):
        seen.append(stats.generation)
        return stats.generation < 2

    r = animat.evolve(small_config(generations=10), callback=cb)
    assert seen == [0, 1, 2]  # generation 0 (the initial population) included
    assert r.stop_reason == "stopped by callback"


def test_run_directory_layout_and_resume(tmp_path):
    out = tmp_path / "run"
    c = small_config(generations=2)
    animat.evolve(c, out=str(out))
    assert (out / "config.toml").exists() and (out / "checkpoint.json").exists()
    rows = list(csv.reader(open(out / "history.csv")))
    assert rows[0] == [
        "generation",
        "best",
        "mean",
        "median",
        "viable_fraction",
        "best_cells",
        "evaluations",
        "swims",
        "best_reference",
        "invalid",
        "drag_limited",
        "wall_seconds",
    ]
    assert [r[0] for r in rows[1:]] == ["0", "1", "2"]
    lineage = sorted((out / "best").glob("gen_*.json"))
    assert lineage and lineage[0].name == "gen_000000.json"
    entry = json.loads(lineage[-1].read_text())
    assert {"generation", "fitness", "cell_count", "genome"} <= set(entry)
    assert animat.Genome.from_json(json.dumps(entry["genome"])).__len__() > 0

    with pytest.raises(FileExistsError, match="already holds a run.*resume=True.*overwrite=True"):
        animat.evolve(c, out=str(out))
    c["evolution.generations"] = 4
    r = animat.evolve(c, out=str(out), resume=True)
    assert r.history[-1].generation == 4
    straight = animat.evolve(c)
    assert [h.best for h in straight.history] == [h.best for h in r.history]
    assert list(straight.history["mean"]) == list(r.history["mean"])

    other = small_config(generations=4)
    other["scene.drag_normal"] = 10.0
    with pytest.raises(ValueError, match=r"cannot resume with changed settings: scene\.drag_normal"):
        animat.evolve(other, out=str(out), resume=True)


def test_resume_of_a_missing_directory_is_a_clear_error(tmp_path):
    with pytest.raises(OSError, match="resume directory does not exist"):
        animat.evolve(small_config(), out=str(tmp_path / "nope"), resume=True)


def test_evaluate_population_is_thread_count_independent():
    c = small_config(steps=300)
    genomes = [animat.Genome.random(s) for s in range(1500)]
    one = animat.evaluate_population(genomes, c, threads=1)
    two = animat.evaluate_population(genomes, c, threads=2)
    assert [(f.fitness, f.viable, f.cell_count) for f in one] == [(f.fitness, f.viable, f.cell_count) for f in two]
    viable = [f for f in one if f.viable]
    assert viable, "1500 random genomes should contain a viable one (about 0.7% are)"
    assert all(f.fitness >= 0 and f.stable for f in one)
    assert all(f.fitness == 0 for f in one if not f.viable)


def test_a_run_checkpointed_under_identity_scheme_1_resumes_and_is_saved_under_scheme_2(tmp_path):
    """A committed study run (checkpointed before identity scheme 2) restores against its config,
    refuses a changed one, and a re-save records the current scheme."""
    import gzip
    from pathlib import Path

    run = Path(__file__).resolve().parents[2] / "data" / "paper_100_generations" / "dn2" / "run_1"
    text = gzip.decompress((run / "checkpoint.json.gz").read_bytes()).decode()
    assert "identity_scheme" not in text
    config = animat.load_config(run / "config.toml")
    ga = animat.GA.from_checkpoint(text, config, "study run_1")
    assert ga.generation == 100
    changed = config.copy()
    changed["development.steps"] = 399
    with pytest.raises(ValueError, match="belongs to a different run configuration"):
        animat.GA.from_checkpoint(text, changed, "study run_1")
    resaved = json.loads(json.loads(ga.checkpoint())["payload"])
    assert resaved["identity_scheme"] == 2
    assert animat.GA.from_checkpoint(ga.checkpoint(), config).generation == 100


def test_generation_stats_fields_pickling_and_history_columns_follow_one_descriptor(tmp_path):
    import pickle

    c = animat.Config()
    c["evolution.population"] = 6
    c["evolution.elites"] = 1
    c["evaluation.steps"] = 100
    animat.evolve(c, generations=1, out=tmp_path / "run", quiet=True)
    run = animat.Run(tmp_path / "run")
    header = (tmp_path / "run" / "history.csv").read_text().splitlines()[0].split(",")
    assert list(animat.HISTORY_DTYPE.names) == header == [n for n, _ in animat.GenerationStats.HISTORY_COLUMNS]
    assert run.history.dtype == animat.HISTORY_DTYPE
    d = {
        "generation": 3,
        "best": 1.5,
        "mean": 0.5,
        "median": 0.25,
        "viable_fraction": 0.75,
        "best_cells": 9,
        "evaluations": 120,
        "swims": 30,
        "best_reference": float("nan"),
        "invalid": 2,
        "drag_limited": 0,
        "protected": 0,
        "wall_seconds": 1.25,
        "best_changed": True,
        "evaluations_per_second": 40.0,
        "swims_per_second": 10.0,
        "crossovers": 1,
    }
    s = animat.GenerationStats(d)
    back = s.to_dict()
    assert set(back) == set(d)
    for k, v in d.items():
        assert back[k] == v or (v != v and back[k] != back[k]), k
        assert type(s).__dict__[k].__doc__, k
    assert pickle.loads(pickle.dumps(s)).to_dict().keys() == back.keys()
    # Fields an older checkpoint may lack keep their defaults; the others are required.
    older = {k: v for k, v in d.items() if k not in ("best_reference", "invalid", "drag_limited")}
    assert animat.GenerationStats(older).invalid == 0
    with pytest.raises(Exception):
        animat.GenerationStats({k: v for k, v in d.items() if k != "best"})
