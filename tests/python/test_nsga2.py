"""NSGA-II (animat.moo): the non-dominated sort, the crowding distance and the hypervolume against values
computed by hand, a selection computed by hand, and runs that are the same for any thread count and
across resume, with infeasible candidates never on the front.

Every run here is tiny (populations of 8, 200-step swims, a few generations): the file runs in seconds.
"""

import csv
import io
import json
import math
import pickle

import numpy as np
import pytest
from run_dirs import without_wall

import animat
from animat import moo

NAN = float("nan")
INF = float("inf")
DISTANCE_VS_WORK = [("distance", "max"), ("actuation_work_positive", "min")]


def small_config(guard="record", threads=1):
    c = animat.Config()
    c["evaluation.steps"] = 200
    c["evaluation.reference_check"] = guard
    c["evaluation.reference_substeps"] = 2  # the guard's reference: 2x the substeps (cheap, still a finer step)
    c["evolution.threads"] = threads
    return c


def new_run(guard="record", threads=1, population=8, seed=5, **kwargs):
    return animat.Nsga2(
        small_config(guard, threads),
        DISTANCE_VS_WORK,
        population=population,
        seed=seed,
        crossover_fraction=0.5,
        **kwargs,
    )


def solutions_of(nsga):
    """Everything of a population that a run decides, comparable with ==."""
    return [
        (s.genome.to_json(), s.objectives, s.measured, s.reference, s.generation, s.feasible, s.rank, s.crowding)
        for s in nsga.population
    ]


def altered(result, **fields):
    """An EvaluationResult with some fields changed (through its pickle state: the fields are read-only)."""
    name, version, state = result.__getstate__()
    out = animat.EvaluationResult.__new__(animat.EvaluationResult)
    out.__setstate__((name, version, {**state, **fields}))
    return out


def same_history(a, b):
    assert a.dtype == b.dtype
    for name in a.dtype.names:
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)


# --- the pieces -----------------------------------------------------------------------------------


def test_the_non_dominated_sort_gives_the_fronts_computed_by_hand():
    points = [[1, 5], [2, 3], [3, 1], [2, 4], [3, 3], [4, 4], [1, 5], [NAN, 0]]
    # minimised: [2, 4] and [3, 3] are dominated by [2, 3] only; [4, 4] also by them; the duplicate of
    # [1, 5] is in its front; the NaN row in none
    assert moo.non_dominated_sort(points) == [[0, 1, 2, 6], [3, 4], [5]]
    # the first objective maximised: [3, 1] and [4, 4] first; then [3, 3] (dominated by [3, 1]), which
    # dominates [2, 3], which dominates [2, 4], which dominates [1, 5] and its duplicate
    assert moo.non_dominated_sort(points, ["max", "min"]) == [[2, 5], [4], [1], [3], [0, 6]]
    assert moo.non_dominated_sort(points, ["maximize", "minimize"]) == [[2, 5], [4], [1], [3], [0, 6]]
    assert moo.non_dominated_sort(np.zeros((0, 2))) == []
    assert moo.dominates([1, 1], [1, 2]) and not moo.dominates([1, 1], [1, 1])
    assert not moo.dominates([1, 2], [2, 1]) and moo.dominates([2, 1], [1, 1], ["max", "min"])
    with pytest.raises(ValueError, match="'max' or 'min'"):
        moo.non_dominated_sort(points, ["up", "min"])


def test_the_crowding_distance_gives_the_values_computed_by_hand():
    # distance 0, 1, 2, 4 (span 4): B (2 - 0) / 4 = 0.5, C (4 - 1) / 4 = 0.75;
    # work 8, 4, 2, 0 (span 8): C (4 - 0) / 8 = 0.5, B (8 - 2) / 8 = 0.75
    d = moo.crowding_distance([[0, 8], [1, 4], [2, 2], [4, 0]])
    assert d.tolist() == [INF, 1.25, 1.25, INF]
    # equal values: a stable sort, so the first and the last row are the ends; no span adds nothing
    assert moo.crowding_distance([[1, 1], [1, 1], [1, 1]]).tolist() == [INF, 0.0, INF]
    assert moo.crowding_distance([[3, 1], [1, 3]]).tolist() == [INF, INF]
    assert moo.crowding_distance(np.zeros((0, 2))).tolist() == []


def test_the_hypervolume_gives_the_values_computed_by_hand():
    # the staircase of (1, 3), (2, 2), (3, 1) under (4, 4): 3·1 + 2·1 + 1·1; (3, 3) is dominated,
    # (5, 0) beyond the reference, (4, 0) on its boundary
    points = [[1, 3], [2, 2], [3, 1], [3, 3], [5, 0], [4, 0]]
    assert moo.hypervolume(points, (4, 4)) == 6.0
    # the first objective maximised: the same staircase mirrored
    assert moo.hypervolume([[3, 3], [2, 2], [1, 1]], (0, 4), ["max", "min"]) == 6.0
    assert moo.hypervolume([[2], [3]], (5,)) == 3.0
    assert moo.hypervolume([[5, 5]], (4, 4)) == 0.0 and moo.hypervolume(np.zeros((0, 2)), (4, 4)) == 0.0
    with pytest.raises(ValueError, match="one or two objectives"):
        moo.hypervolume([[1, 1, 1]], (2, 2, 2))


# --- objectives -----------------------------------------------------------------------------------


def test_bad_objective_names_raise_naming_the_name_and_the_valid_ones():
    with pytest.raises(ValueError, match="no objective named 'distnace'") as e:
        animat.Nsga2(small_config(), [("distnace", "max"), "actuation_work_positive"])
    for name in ("fitness", "distance", "distance_per_size", "actuation_work_positive", "max_speed"):
        assert name in str(e.value)
    with pytest.raises(ValueError, match="no default sense"):
        animat.Nsga2(small_config(), ["distance", "max_speed"])
    with pytest.raises(ValueError, match="'max' or 'min'"):
        animat.Nsga2(small_config(), [("distance", "up")])
    with pytest.raises(ValueError, match="needs a sense"):
        animat.Nsga2(small_config(), ["distance", lambda e: e.max_speed])
    with pytest.raises(ValueError, match="identifier"):
        animat.Nsga2(small_config(), ["distance", (lambda e: e.max_speed, "max")])
    with pytest.raises(ValueError, match="distinct"):
        animat.Nsga2(small_config(), ["distance", ("distance", "min")])
    with pytest.raises(ValueError, match="evaluation.objective = 'chemotaxis'"):
        animat.Nsga2(small_config(), ["distance", "chemotaxis"])
    with pytest.raises(ValueError, match="one per objective"):
        animat.Nsga2(small_config(), DISTANCE_VS_WORK, reference_point=(0.0,))


def test_the_table_scores_as_the_engine_does():
    config = small_config()
    config["evaluation.steps"] = 1000
    genome = animat.Genome.random_viable(animat.Rng.derive(3, 0, 3), config)[0]
    evaluation = animat.evaluate(genome, config)
    assert evaluation.valid and evaluation.fitness > 0
    for name in animat.OBJECTIVES:
        if name == "chemotaxis":
            continue
        engine = config.copy()
        engine["evaluation.objective"] = name
        assert moo.CRITERIA[name](evaluation, genome, config) == animat.evaluate(genome, engine).fitness, name
    assert moo.CRITERIA["fitness"](evaluation) == evaluation.fitness
    assert moo.CRITERIA["actuation_work_positive"](evaluation) == evaluation.actuation_work_positive > 0
    assert moo.CRITERIA["actuation_work_positive"].sense == "min" and moo.CRITERIA["distance"].sense == "max"
    assert moo.CRITERIA["max_speed"].sense == "" and moo.CRITERIA["max_speed"].with_sense("max").maximize

    def speed(e):
        return e.max_speed

    nsga = animat.Nsga2(config, ["distance", (speed, "max"), animat.Criterion("cells", "min", lambda e: e.cell_count)])
    assert nsga.names == ("distance", "speed", "cells") and nsga.senses == ("max", "max", "min")


# --- NSGA-II --------------------------------------------------------------------------------------


def test_a_selection_computed_by_hand():
    nsga = new_run(guard="off", population=4)
    nsga.ask()
    # (distance, work): b is not viable; d is dominated by a
    row = nsga.tell([(1.0, 1.0), None, (2.0, 2.0), (0.5, 3.0)])
    assert [(s.rank, s.crowding) for s in nsga.population] == [(0, INF), (2, 0.0), (0, INF), (1, INF)]
    assert nsga.reference_point == (0.5, 3.0)  # the worst distance and work of generation 0
    # hypervolume under (0.5, 3): (2, 2) gives 1.5 · 1, (1, 1) adds 0.5 · 1
    assert (row.front_size, row.hypervolume, row.best_distance, row.best_actuation_work_positive) == (2, 2.0, 2.0, 1.0)
    assert (row.feasible, row.discarded, row.evaluations) == (3, 1, 4)

    parents = nsga.population
    offspring = nsga.ask()
    # the tournament of the class docstring, replayed
    points = int(nsga.config["mutation.crossover_points"])
    for i, genome in enumerate(offspring):
        rng = animat.Rng.derive(5, 1, i)

        def tournament(rng=rng):
            a, b = parents[rng.integer(0, 3)], parents[rng.integer(0, 3)]
            return b if (b.rank, -b.crowding) < (a.rank, -a.crowding) else a

        child = tournament().genome
        if rng.uniform() < 0.5:
            child = child.crossover(tournament().genome, rng, points)
        assert child.mutate(rng, nsga.config) == genome

    row = nsga.tell([(3.0, 3.0), (1.5, 1.5), (2.0, 2.0), None])
    # parents and offspring: a (1, 1), c (2, 2), e (3, 3), f (1.5, 1.5), g (2, 2) are the first front,
    # d the second, b and h infeasible. Crowding of the first front (both objectives order it alike:
    # a, f, c, g, e; span 2): f (2 - 1) / 2 twice = 1, c (2 - 1.5) / 2 twice = 0.5, g (3 - 2) / 2 twice = 1;
    # four of the five: a and e (infinite), then f and g (1, in pool order), not c.
    assert [s.genome.to_json() for s in nsga.population] == [
        g.to_json() for g in (parents[0].genome, offspring[0], offspring[1], offspring[2])
    ]
    assert [(s.objectives, s.rank, s.crowding) for s in nsga.population] == [
        ((1.0, 1.0), 0, INF),
        ((3.0, 3.0), 0, INF),
        ((1.5, 1.5), 0, 1.0),
        ((2.0, 2.0), 0, 1.0),
    ]
    assert [s.objectives for s in nsga.front()] == [
        (3.0, 3.0),
        (2.0, 2.0),
        (1.5, 1.5),
        (1.0, 1.0),
    ]  # best distance first
    # hypervolume under (0.5, 3): e lies on the work bound; (2, 2) 1.5 · 1, (1.5, 1.5) 1 · 0.5, (1, 1) 0.5 · 0.5
    assert (row.front_size, row.hypervolume, row.best_distance, row.best_actuation_work_positive) == (4, 2.25, 3.0, 1.0)
    assert (row.feasible, row.discarded, row.copies, row.evaluations) == (4, 1, 0, 8)
    np.testing.assert_array_equal(nsga.front_values(), [[3, 3], [2, 2], [1.5, 1.5], [1, 1]])


def test_infeasible_candidates_are_never_on_the_front():
    nsga = new_run(guard="off")
    nsga.ask()
    row = nsga.tell([None, [NAN, 1.0], [1.0, INF], None, None, None, None, None])
    assert (row.front_size, row.feasible, row.discarded) == (0, 0, 8)
    assert math.isnan(row.hypervolume) and math.isnan(row.best_distance) and nsga.reference_point is None
    assert nsga.front() == [] and len(nsga.population) == 8
    for _ in range(3):
        nsga.step()
    assert nsga.reference_point is not None and len(nsga.front()) > 0
    config = nsga.config
    for s in nsga.front():
        e = animat.evaluate(s.genome, config)
        assert e.viable and e.stable and e.valid and s.feasible and s.rank == 0
        assert s.objectives == (e.fitness, e.actuation_work_positive)
    for s in nsga.population:
        assert s.feasible or s.rank > 0

    told = new_run(guard="off")
    genomes = told.ask()
    results = [animat.evaluate(g, told.config) for g in genomes]
    told.tell([altered(results[0], stable=False), altered(results[1], valid=False), *results[2:]])
    assert not told.population[0].feasible and not told.population[1].feasible
    assert all(s.genome not in genomes[:2] for s in told.front())
    with pytest.raises(TypeError, match="a Fitness holds one number"):
        told.ask()
        told.tell([animat.Fitness(1.0)] * 8)


def test_nsga2_is_the_same_for_any_thread_count_seed_and_ask_tell():
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
    assert len(one.front()) >= 2
    assert solutions_of(one) == solutions_of(two) == solutions_of(loop)
    same_history(one.history, two.history)
    same_history(one.history, loop.history)
    again = new_run()
    for _ in range(3):
        again.step()
    assert solutions_of(again) == solutions_of(one)
    other = new_run(seed=6)
    for _ in range(3):
        other.step()
    assert solutions_of(other) != solutions_of(one)
    h = one.history
    assert h["generation"].tolist() == [0, 1, 2] and h["evaluations"].tolist() == [8, 16, 24]
    assert h["front_size"][-1] == len(one.front()) and h["best_distance"][-1] == one.front()[0].objectives[0]
    assert (np.diff(h["hypervolume"]) >= 0).all()  # elitist: the front never loses ground here


def test_copies_are_never_on_the_front():
    nsga = new_run(guard="off")
    copies = 0
    for _ in range(3):
        parents = {s.genome.to_json() for s in nsga.population}
        asked = [g.to_json() for g in nsga.ask()]
        expected = sum(1 for i, key in enumerate(asked) if key in parents or key in asked[:i])
        row = nsga.step()
        assert row.copies == expected
        copies += expected
        front = [s.genome.to_json() for s in nsga.front()]
        assert len(set(front)) == len(front)
        worst = max(s.rank for s in nsga.population)
        seen = set()
        for s in nsga.population:
            key = s.genome.to_json()
            if key in seen:
                assert s.rank == worst and s.crowding == 0.0
            seen.add(key)
    assert copies > 0  # mutation leaves some offspring unchanged


def test_resume_gives_the_uninterrupted_run():
    straight = new_run()
    for _ in range(5):
        straight.step()
    first = new_run()
    for _ in range(3):
        first.step()
    text = json.dumps(first.checkpoint(), allow_nan=False)
    resumed = animat.Nsga2.restore(text, threads=2)
    assert [g.to_json() for g in resumed.ask()] == [g.to_json() for g in first.ask()]
    unpickled = pickle.loads(pickle.dumps(first))
    for nsga in (resumed, unpickled):
        while nsga.generation < 4:
            nsga.step()
        assert solutions_of(nsga) == solutions_of(straight)
        same_history(nsga.history, straight.history)
        assert nsga.reference_point == straight.reference_point
    other = small_config()
    other["evaluation.steps"] = 300
    with pytest.raises(ValueError, match="differs"):
        animat.Nsga2.restore(text, other)
    with pytest.raises(ValueError, match="not the checkpoint's"):
        animat.Nsga2.restore(text, objectives=["distance", "actuation_work_absolute"])


def test_own_objectives_are_passed_again_on_restore():
    def speed(e):
        return e.max_speed

    nsga = animat.Nsga2(small_config("off"), ["distance", (speed, "max")], population=6, seed=1)
    nsga.step()
    state = nsga.checkpoint()
    with pytest.raises(ValueError, match="'speed' is not in the table"):
        animat.Nsga2.restore(state)
    back = animat.Nsga2.restore(state, objectives=["distance", (speed, "max")])
    assert solutions_of(back) == solutions_of(nsga)
    back.step()
    nsga.step()
    assert solutions_of(back) == solutions_of(nsga)
    assert [s.objectives[1] for s in nsga.population if s.feasible] == [
        s.measured[1] for s in nsga.population if s.feasible
    ]


def test_the_run_directory_is_written_and_resumes_to_the_same_files(tmp_path):
    def run(out, generations, resume=False):
        return animat.run_nsga2(
            small_config(),
            None if resume else DISTANCE_VS_WORK,
            out,
            generations,
            population=8,
            seed=2,
            front_every=2,
            resume=resume,
        )

    straight = run(tmp_path / "a", 4)
    run(tmp_path / "b", 1)
    with pytest.raises(FileExistsError):
        run(tmp_path / "b", 4)
    resumed = run(tmp_path / "b", 4, resume=True)
    assert solutions_of(resumed) == solutions_of(straight)
    a, b = tmp_path / "a", tmp_path / "b"
    assert sorted(p.name for p in (a / "front").iterdir()) == ["gen_000000.csv", "gen_000002.csv", "gen_000004.csv"]
    assert sorted(p.name for p in (b / "front").iterdir()) == [
        "gen_000000.csv",
        "gen_000001.csv",  # the last generation of the first session
        "gen_000002.csv",
        "gen_000004.csv",
    ]
    for name in ("front/gen_000002.csv", "front/gen_000004.csv", "config.toml"):
        assert (a / name).read_text() == (b / name).read_text(), name
    assert without_wall(a) == without_wall(b)
    lines = (a / "history.csv").read_text().splitlines()
    assert lines[0] == (
        "generation,evaluations,front_size,hypervolume,best_distance,best_actuation_work_positive,"
        "feasible,discarded,copies,reference_evaluations,disagreements,wall_seconds"
    )
    assert len(lines) == 6
    rows = (a / "front" / "gen_000004.csv").read_text().splitlines()
    assert rows[0] == (
        "generation,crowding,distance,actuation_work_positive,measured_distance,measured_actuation_work_positive,"
        "reference_distance,reference_actuation_work_positive,genome"
    )
    assert len(rows) == 1 + len(straight.front())
    table = list(csv.DictReader(io.StringIO((a / "front" / "gen_000004.csv").read_text())))
    for row, s in zip(table, straight.front()):
        assert (float(row["distance"]), float(row["actuation_work_positive"])) == s.objectives
        assert float(row["reference_distance"]) == s.reference[0] and int(row["generation"]) == s.generation
        assert animat.Genome.from_json(row["genome"]) == s.genome
    assert animat.load_config(str(a / "config.toml"))["evolution.seed"] == 2
    overwritten = animat.run_nsga2(
        small_config(), DISTANCE_VS_WORK, a, 1, population=8, seed=2, overwrite=True, front_every=2
    )
    assert overwritten.generation == 1 and sorted(p.name for p in (a / "front").iterdir()) == [
        "gen_000000.csv",
        "gen_000001.csv",
    ]
    with pytest.raises(ValueError, match="not the checkpoint's"):
        animat.run_nsga2(small_config(), ["distance"], b, 5, resume=True)


def test_the_exploit_guard_checks_the_front_at_the_reference_step():
    reference = small_config()
    reference["physics.substeps"] = 2

    def at_reference(genome):
        e = animat.evaluate(genome, reference)
        return (e.fitness, e.actuation_work_positive)

    record = new_run(guard="record")
    checked = set()
    for _ in range(2):
        row = record.step()
        for s in record.front():
            checked.add(s.genome.to_json())
        assert row.reference_evaluations == len(checked)  # one per genome that reached the front
    for s in record.front():
        assert s.reference == at_reference(s.genome) and s.objectives == s.measured
    assert record.history["disagreements"][-1] == sum(
        any(animat.reference_disagrees(v, r, reference) for v, r in zip(s.measured, s.reference))
        for s in record.front()
    )

    off = new_run(guard="off")
    off.step()
    assert all(s.reference is None for s in off.population) and off.history["reference_evaluations"][-1] == 0

    select = new_run(guard="select")
    row = select.step()
    assert row.reference_evaluations == sum(1 for s in select.population if s.reference is not None)
    for s in select.population:
        if s.feasible:
            assert s.objectives == s.reference == at_reference(s.genome)
