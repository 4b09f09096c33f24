"""The research API (docs/python.md): objectives, ask/tell, pickling, process pools, the quickstart,
packaging."""

import copy
import math
import multiprocessing
import os
import pickle
import re
import subprocess
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
import pytest

import animat

ROOT = Path(__file__).resolve().parents[2]


def small_config(population=10, steps=600, seed=3, threads=1):
    c = animat.Config()
    c["evolution.population"] = population
    c["evaluation.steps"] = steps
    c["evolution.seed"] = seed
    c["evolution.threads"] = threads
    return c


@pytest.fixture(scope="module")
def viable():
    """(config, genome) with a viable genome that moves."""
    c = small_config()
    genome, tries = animat.Genome.random_viable(seed=1, config=c)
    assert tries >= 1
    return c, genome


def rightward(record):
    """Centre-of-mass displacement along +x (a pure objective of the record)."""
    return float(record.com[-1, 0] - record.com[0, 0])


# --- 1. objectives --------------------------------------------------------------------------------------


def test_builtin_objectives_by_name_and_config_key(viable):
    c, g = viable
    r = animat.evaluate(g, c)
    assert r.fitness == pytest.approx(float(np.linalg.norm(r.displacement)), rel=0, abs=1e-12)
    rec = animat.record_evaluation(g, c, every=0)
    per_size = animat.evaluate(g, c, objective="distance_per_size").fitness
    assert per_size == pytest.approx(r.fitness / animat.body_length(rec.body), rel=1e-12)
    c2 = c.copy()
    c2.apply_override("evaluation.objective=speed_toward")  # exactly what animat_evolve --set does
    c2.apply_override("evaluation.direction=[0.0, 1.0]")
    speed = animat.evaluate(g, c2).fitness
    assert speed == pytest.approx(r.displacement[1] / r.simulated_time, rel=1e-12)
    assert set(animat.OBJECTIVES) == {
        "distance",
        "distance_per_size",
        "speed_toward",
        "distance_x",
        "distance_minus_energy",
        "distance_per_energy",
        "chemotaxis",
    }
    with pytest.raises(
        ValueError,
        match="expected one of distance, distance_per_size, speed_toward, distance_x, "
        "distance_minus_energy, distance_per_energy, chemotaxis, python:",
    ):
        c2["evaluation.objective"] = "fastest"


def test_the_objective_table_scores_an_evaluation_exactly_as_the_engine(viable):
    c, g = viable
    table = animat.objectives()
    assert [o.name for o in table] == list(animat.OBJECTIVES)
    assert animat.SWIM_ENV_OBJECTIVES == tuple(o.name for o in table if o.one_swim)
    assert "chemotaxis" not in animat.SWIM_ENV_OBJECTIVES
    rec = animat.record_evaluation(g, c, every=0)
    r = rec.result
    assert r.viable and r.stable and r.valid
    length = animat.body_length(rec.body)
    for spec in table:
        if not spec.one_swim:
            continue
        c2 = c.copy()
        c2["evaluation.objective"] = spec.name
        c2["evaluation.direction"] = [1.0, -2.0]
        c2["evaluation.energy_weight"] = 0.5
        engine = animat.evaluate(g, c2).fitness
        table_value = animat.objective_value(
            spec.name,
            distance=r.fitness,
            dx=r.displacement[0],
            dy=r.displacement[1],
            duration=r.simulated_time,
            body_length=length,
            actuation_work_positive=r.actuation_work_positive,
            config=c2,
        )
        assert table_value == engine, spec.name
        assert spec.meaning and (not spec.nonnegative or engine >= 0.0), spec.name
    with pytest.raises(ValueError, match='"fastest" is not a built-in objective'):
        animat.objective_value("fastest", distance=1.0, dx=1.0, dy=0.0, duration=1.0)


def test_record_exposes_every_evaluation_result_field_and_the_trajectory(viable):
    c, g = viable
    rec = animat.record_evaluation(g, c, every=25)
    result = rec.result
    fields = [n for n in dir(result) if not n.startswith("_") and not callable(getattr(result, n))]
    assert len(fields) >= 20
    for name in fields:  # generic: a field added to EvaluationResult appears on the record
        a, b = getattr(rec, name), getattr(result, name)
        assert np.array_equal(a, b) if isinstance(a, np.ndarray) else a == b, name
    n = rec.body.node_count
    assert rec.positions.shape == (600 // 25 + 1, n, 2) and rec.velocities.shape == rec.positions.shape
    assert list(rec.steps[:3]) == [0, 25, 50]
    np.testing.assert_allclose(rec.com, rec.positions.mean(axis=1))
    with pytest.raises(AttributeError):
        rec.no_such_field


def test_python_objective_in_evolve_is_deterministic_for_any_thread_count(tmp_path):
    runs = []
    for threads in (1, 2):
        c = small_config(population=8, steps=400, threads=threads)
        r = animat.evolve(c, generations=2, objective=animat.Objective(rightward, every=50), quiet=True)
        runs.append(r)
    assert list(runs[0].history["best"]) == list(runs[1].history["best"])
    assert [i.genome for i in runs[0].population] == [i.genome for i in runs[1].population]
    # The objective really scored the GA: the best's fitness is its rightward displacement.
    best = runs[0].best
    c = small_config(population=8, steps=400)
    assert best.fitness.fitness == pytest.approx(rightward(animat.record_evaluation(best.genome, c, every=50)))


def test_python_objective_is_recorded_in_the_run_and_needed_to_resume(tmp_path):
    out = tmp_path / "run"
    c = small_config(population=8, steps=300)
    animat.evolve(c, out=out, generations=1, objective=rightward, quiet=True)
    saved = animat.load_config(out / "config.toml")
    assert saved["evaluation.objective"] == "python:rightward"
    with pytest.raises(ValueError, match="python:rightward.*is a Python objective"):
        animat.evolve(None, out=out, resume=True, generations=2, quiet=True)
    r = animat.evolve(None, out=out, resume=True, generations=2, objective=rightward, quiet=True)
    assert int(r.history[-1]["generation"]) == 2
    exe = os.environ.get("ANIMAT_EVOLVE_EXE")
    if exe:
        p = subprocess.run([exe, "--resume", str(out), "--generations", "3", "--quiet"], capture_output=True, text=True)
        assert p.returncode == 2 and "is a Python objective" in p.stderr, p.stderr


def test_python_objective_errors_are_clear(viable):
    c, g = viable
    with pytest.raises(ValueError, match="returned nan"):
        animat.evaluate(g, c, objective=lambda r: float("nan"))
    with pytest.raises(ValueError, match="returned a str, expected a float"):
        animat.evaluate(g, c, objective=lambda r: "far")

    def broken(record):
        raise KeyError("no such thing")

    with pytest.raises(ValueError, match="(?s)objective python:.*broken raised.*KeyError: 'no such thing'"):
        animat.evaluate_population([g, g], c, threads=2, objective=broken)


# --- 2. ask / tell --------------------------------------------------------------------------------------


def test_ga_loop_gives_exactly_the_evolve_run():
    c = small_config(population=10, steps=400, seed=5)
    c["evolution.generations"] = 3
    ref = animat.evolve(c, quiet=True)
    ga = animat.GA(c)
    rounds = 0
    while not ga.done:
        genomes = ga.ask()
        ga.tell([animat.evaluate(g, c) for g in genomes])  # EvaluationResult objects are accepted
        rounds += 1
    assert rounds > 4 and ga.generation == 3
    for name in ("best", "mean", "median", "viable_fraction", "best_cells", "evaluations"):
        assert list(ga.history[name]) == list(ref.history[name]), name
    assert [i.genome for i in ga.population] == [i.genome for i in ref.population]
    assert [i.fitness for i in ga.population] == [i.fitness for i in ref.population]
    assert ga.best.genome == ref.best.genome


def test_ga_with_a_process_pool_checkpoint_resume_and_pickle(tmp_path):
    c = small_config(population=8, steps=300, seed=2)
    c["evolution.generations"] = 2
    ga = animat.GA(c)
    with ProcessPoolExecutor(max_workers=2, mp_context=multiprocessing.get_context("spawn")) as pool:
        while not ga.done:
            genomes = ga.ask()
            ga.tell(list(pool.map(animat.evaluate, genomes, [c] * len(genomes))))
    ref = animat.evolve(c, quiet=True)
    assert list(ga.history["best"]) == list(ref.history["best"])

    ckpt = ga.save(tmp_path / "ga.json")
    more = c.copy()
    more["evolution.generations"] = 4
    resumed = animat.GA.load(ckpt, more)
    twin = pickle.loads(pickle.dumps(resumed))
    assert twin.generation == resumed.generation == 2
    asked = resumed.ask()
    assert resumed.ask() == asked  # again before tell: the same genomes
    assert twin.ask() == asked
    while not resumed.done:
        resumed.step()
    straight = animat.evolve(more, quiet=True)
    assert list(resumed.history["best"]) == list(straight.history["best"])


def test_ga_interoperates_with_run_directories(tmp_path):
    out = tmp_path / "run"
    c = small_config(population=8, steps=300)
    animat.evolve(c, out=out, generations=2, quiet=True)
    ga = animat.GA.load(out)  # the run's own config.toml and checkpoint.json
    assert ga.generation == 2
    ga.step()
    assert ga.generation == 3


def test_tell_refuses_what_it_cannot_use():
    ga = animat.GA(small_config(population=6))
    with pytest.raises(ValueError, match="nothing was asked"):
        ga.tell([])
    genomes = ga.ask()
    with pytest.raises(ValueError, match="5 fitness values for the 6 genomes"):
        ga.tell([1.0] * 5)
    with pytest.raises(ValueError, match="must be finite"):
        ga.tell([float("nan")] * 6)
    with pytest.raises(TypeError, match="got a bool"):
        ga.tell([True] * 6)
    with pytest.raises(ValueError, match="no generation completed yet"):
        ga.checkpoint()
    assert ga.population == [] and ga.generation == -1
    stats = ga.tell([None, 1.0, animat.Fitness(2.0), 3, None, 0.5])  # None: not viable
    assert stats is None  # two slots still open
    assert len(ga.ask()) == 2 and len(genomes) == 6


# --- 2b. tell is held to the engine's rules; what save() writes, load() reads ---------------------------


def _answer_everything(ga, value):
    """Tells `value` for every asked genome until generation 0 exists (every draw viable)."""
    while ga.generation < 0:
        ga.tell([value] * len(ga.ask()))


def test_tell_refuses_what_the_engines_evaluation_refuses_naming_index_and_value():
    ga = animat.GA(small_config(population=6))  # evaluation.objective = distance: a fitness is >= 0
    n = len(ga.ask())
    with pytest.raises(ValueError, match=r"value 2 .*fitness -0\.5.*>= 0"):  # was accepted, then GA.load refused it
        ga.tell([1.0, 1.0, -0.5] + [1.0] * (n - 3))
    with pytest.raises(ValueError, match=r"value 1 .*cell_count -3"):
        ga.tell([1.0, animat.Fitness(1.0, True, True, -3)] + [1.0] * (n - 2))
    with pytest.raises(ValueError, match=r"value 0 .*fitness inf"):
        ga.tell([animat.Fitness(math.inf)] + [1.0] * (n - 1))
    with pytest.raises(ValueError, match=r"GA.tell: value 3 \(nan\).*must be finite"):
        ga.tell([1.0] * 3 + [math.nan] + [1.0] * (n - 4))
    assert ga.generation == -1 and ga._engine.asked  # nothing was taken
    ga.tell([1.0] * n)
    assert ga.generation == 0
    signed = small_config(population=6)
    signed["evaluation.objective"] = "speed_toward"  # a signed objective: negative values are fine
    sga = animat.GA(signed)
    _answer_everything(sga, -1.25)
    assert sga.history[-1]["mean"] == -1.25


def test_every_checkpoint_saved_after_an_accepted_tell_loads(tmp_path):
    # A seeded random sweep of adversarial values: tell() accepts exactly what the engine's rule allows
    # (finite; >= 0 under a distance objective; cell_count >= 0), and whatever it accepted, save() writes
    # and load() reads back as the same state. Was: negative fitness, negative cell counts and a mean
    # overflowing to inf were accepted and written, and GA.load refused the file.
    rng = np.random.default_rng(20240601)
    tiny = float(np.nextafter(0.0, 1.0))
    top = 1.7976931348623157e308
    special = [
        0.0,
        -0.0,
        tiny,
        -tiny,
        1e-300,
        -1e-300,
        1.0,
        -1.0,
        1e300,
        -1e300,
        top,
        -top,
        top / 2,
        -top / 2,
        math.nan,
        math.inf,
        -math.inf,
    ]
    cells = [0, 1, 7, 2**31 - 1, -1, -(2**31)]

    def adversarial():
        pick = rng.integers(0, 5)
        if pick == 0:
            return None  # not viable
        if pick == 1:
            return float(special[rng.integers(0, len(special))])
        if pick == 2:
            return float(rng.normal() * 10.0 ** int(rng.integers(-320, 309)))  # may overflow to inf: refused
        fit = float(special[rng.integers(0, len(special))]) if pick == 3 else float(rng.normal())
        return animat.Fitness(
            fit,
            bool(rng.integers(0, 2)),
            bool(rng.integers(0, 2)),
            int(cells[rng.integers(0, len(cells))]),
            bool(rng.integers(0, 2)),
        )

    def acceptable(v, objective):
        if v is None:
            return True
        fit, count = (v.fitness, v.cell_count) if isinstance(v, animat.Fitness) else (v, 0)
        return math.isfinite(fit) and (objective != "distance" or fit >= 0) and count >= 0

    def value(objective):
        v = adversarial()
        if rng.random() < 0.9:  # mostly acceptable values, so that the run goes on and is saved often
            while not acceptable(v, objective):
                v = adversarial()
        return v

    accepted = refused = saved = 0
    for objective in ("distance", "speed_toward"):
        c = small_config(population=4, steps=10)
        c["evolution.elites"] = 1
        c["evaluation.objective"] = objective
        c["evaluation.reference_check"] = "off"  # the values are not animat's swims
        for trial in range(5):
            c["evolution.seed"] = trial
            ga = animat.GA(c)
            for _ in range(40):
                genomes = ga.ask(3 if ga.generation < 0 else 1)
                told = [value(objective) for _ in genomes]
                bad = [k for k, v in enumerate(told) if not acceptable(v, objective)]
                if bad:
                    with pytest.raises(ValueError, match=rf"value {bad[0]} "):
                        ga.tell(told)
                    refused += 1
                    continue
                ga.tell(told)
                accepted += 1
                if ga.generation >= 0:
                    for row in ga.history:
                        assert (
                            math.isfinite(row["best"]) and math.isfinite(row["mean"]) and math.isfinite(row["median"])
                        )
                    back = animat.GA.load(ga.save(tmp_path / f"{objective}_{trial}.json"), c)
                    saved += 1
                    assert back.history.tobytes() == ga.history.tobytes()
                    assert back.ask() == ga.ask()
    assert accepted > 100 and refused > 20 and saved > 100, (accepted, refused, saved)


def test_the_generation_mean_of_huge_finite_fitnesses_is_finite_and_the_checkpoint_loads(tmp_path):
    # Was: the mean of 4 x 1.7e308 overflowed to inf, the checkpoint held null, and no resume read it.
    huge = 1.7976931348623157e308
    c = small_config(population=4, steps=10)
    c["evaluation.reference_check"] = "off"
    ga = animat.GA(c)
    _answer_everything(ga, huge)
    ga.tell([huge * 0.5] * len(ga.ask()))
    assert ga.history["mean"][0] == huge and ga.history["median"][0] == huge
    assert huge * 0.5 <= ga.history["mean"][1] <= huge
    back = animat.GA.load(ga.save(tmp_path / "huge.json"), c)
    assert list(back.history["mean"]) == list(ga.history["mean"])


@pytest.mark.parametrize("guard", ["record", "select"])
def test_ga_loop_and_evolve_give_identical_histories_with_the_exploit_guard(guard, tmp_path):
    # Was: ask/tell dropped the exploit guard (best_reference NaN; "select" ranked elites differently).
    c = small_config(population=8, steps=150, seed=4)
    c["evolution.generations"] = 3
    c["evolution.elites"] = 2
    c["evaluation.reference_check"] = guard
    c["evaluation.reference_substeps"] = 2
    ref = animat.evolve(c, quiet=True)
    ga = animat.GA(c)
    while not ga.done:
        genomes = ga.ask()
        ga.tell([animat.evaluate(g, c) for g in genomes])
    columns = [n for n in ref.history.dtype.names if n != "wall_seconds"]
    for name in columns:
        np.testing.assert_array_equal(ga.history[name], ref.history[name], err_msg=name)
    assert np.isfinite(ga.history["best_reference"]).all()
    assert [i.genome for i in ga.population] == [i.genome for i in ref.population]
    assert [i.fitness for i in ga.population] == [i.fitness for i in ref.population]
    again = animat.GA.load(ga.save(tmp_path / "ga.json"), c)  # the references survive a checkpoint
    assert list(again.history["best_reference"]) == list(ga.history["best_reference"])


def test_ga_with_a_python_objective_needs_it_for_the_exploit_guard():
    c = small_config(population=6)
    c["evaluation.objective"] = "python:rightward"
    with pytest.raises(ValueError, match=r"python:rightward.*exploit guard.*objective=.*reference_check = 'off'"):
        animat.GA(c)
    c["evaluation.steps"] = 100
    c["evaluation.reference_substeps"] = 2
    c["evolution.generations"] = 2
    objective = animat.Objective(rightward, every=10, name="rightward")
    ga = animat.GA(c, objective=objective)
    assert ga.config["evaluation.objective"] == "python:rightward"
    while not ga.done:
        ga.step()  # evaluate_population with the objective; the guard scores with it at the reference step
    ref = animat.evolve(c, objective=objective, quiet=True)
    assert np.isfinite(ga.history["best_reference"]).all()
    for name in ("best", "mean", "best_reference", "evaluations"):
        assert list(ga.history[name]) == list(ref.history[name]), name
    off = c.copy()
    off["evaluation.reference_check"] = "off"
    animat.GA(off)  # no guard: nothing to evaluate here


# --- 3. pickle and copy ----------------------------------------------------------------------------------


def _same(a, b):
    if isinstance(a, np.ndarray):
        return np.array_equal(a, b)
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if type(a).__eq__ is object.__eq__:  # a value type without ==: compare its properties
        props = _properties(a)
        return type(a) is type(b) and all(_same(v, getattr(b, k)) for k, v in props.items())
    return a == b


def _properties(obj):
    return {n: getattr(obj, n) for n in dir(obj) if not n.startswith("_") and not callable(getattr(obj, n))}


def test_every_value_type_pickles_and_copies(viable, tmp_path):
    c, g = viable
    ctrace = c.copy()
    ctrace["development.trace_every"] = 50
    embryo = animat.develop(g, ctrace)
    body = animat.build_body(embryo)
    result = animat.evaluate(g, c)
    out = tmp_path / "run"
    evo = animat.evolve(small_config(population=6, steps=200), out=out, generations=1, quiet=True)
    run = animat.Run(out)
    trajectory = animat.replay(g, c, steps=100, every=10)
    values = [
        c,
        g,
        animat.Scene(drag_normal=5.0),
        body,
        embryo,
        embryo.trace,
        result,
        animat.Fitness(1.5, True, False, 7),
        animat.record_evaluation(g, c, every=100),
        evo.population[0],
        animat.GenerationStats(_core_stats(evo)),
        animat.Rng(9),
    ]
    for v in values:
        for twin in (pickle.loads(pickle.dumps(v)), copy.copy(v), copy.deepcopy(v)):
            assert type(twin) is type(v)
            if isinstance(v, animat.Config):
                assert twin == v and twin.to_toml() == v.to_toml()
                continue
            props = _properties(v)
            assert props, type(v)
            for name, value in props.items():
                assert _same(value, getattr(twin, name)), (type(v).__name__, name)
    assert pickle.loads(pickle.dumps(c)) == c and pickle.loads(pickle.dumps(g)) == g
    # Python values holding them
    r2 = pickle.loads(pickle.dumps(run))
    assert r2.path == run.path and r2.config == run.config and np.array_equal(r2.history, run.history)
    t2 = pickle.loads(pickle.dumps(trajectory))
    np.testing.assert_array_equal(t2.positions, trajectory.positions)
    assert t2.body.node_count == trajectory.body.node_count and t2.config == trajectory.config
    h2 = pickle.loads(pickle.dumps(evo.history))
    assert type(h2) is animat.History and np.array_equal(h2, evo.history)
    e2 = pickle.loads(pickle.dumps(evo))
    assert e2.best.genome == evo.best.genome


def _core_stats(evo):
    return {
        name: float(evo.history[-1][name]) if evo.history.dtype[name].kind == "f" else int(evo.history[-1][name])
        for name in evo.history.dtype.names
    } | {"evaluations_per_second": 1.0, "swims_per_second": 0.5, "best_changed": True, "crossovers": 2}


def test_unpickling_a_foreign_state_is_a_clear_error():
    state = animat.Genome.random(seed=1).__getstate__()
    g = animat.Genome.__new__(animat.Genome)
    with pytest.raises(ValueError, match="cannot unpickle animat.Genome version 2"):
        g.__setstate__((state[0], 2, state[2]))


def test_multiprocessing_pool_and_process_pool_executor_evaluate_a_population(viable):
    c, _ = viable
    genomes = [animat.Genome.random_viable(seed=s, config=c)[0] for s in range(4)]
    expected = [animat.evaluate(g, c).fitness for g in genomes]
    ctx = multiprocessing.get_context("spawn")
    with ctx.Pool(2) as pool:
        assert [r.fitness for r in pool.starmap(animat.evaluate, [(g, c) for g in genomes])] == expected
    with ProcessPoolExecutor(max_workers=2, mp_context=ctx) as ex:
        assert [r.fitness for r in ex.map(animat.evaluate, genomes, [c] * 4)] == expected
    assert [f.fitness for f in animat.evaluate_population(genomes, c, threads=2)] == expected


# --- 5. the quickstart ----------------------------------------------------------------------------------


def test_random_genome_takes_a_seed_keyword_and_random_viable_reports_tries():
    assert animat.Genome.random(seed=42) == animat.Genome.random(42)
    c = animat.Config()
    g, tries = animat.Genome.random_viable(seed=42, config=c)
    assert animat.develop(g, c).viable
    rng = animat.Rng(42)
    drawn = [animat.Genome.random(rng, c) for _ in range(tries)]
    assert drawn[-1] == g and not any(animat.develop(x, c).viable for x in drawn[:-1])
    assert tries > 3  # seed 42: most random genomes are not viable
    with pytest.raises(ValueError, match="no viable genome in 3 tries"):
        animat.Genome.random_viable(seed=42, config=c, max_tries=3)


def test_a_non_viable_embryo_is_refused_loudly():
    embryo = animat.develop(animat.Genome.random(seed=42))
    assert not embryo.viable and embryo.cell_count == 1
    with pytest.raises(ValueError, match="embryo is not viable.*random_viable"):
        animat.build_body(embryo)
    body = animat.build_body(embryo, allow_nonviable=True)
    with pytest.warns(RuntimeWarning, match="1 cell\\(s\\) and no springs: it cannot swim"):
        animat.Simulation(body)


def test_evolve_needs_a_cap_or_says_so_and_handles_existing_runs(tmp_path):
    c = small_config(population=6, steps=200)
    uncapped = c.copy()
    uncapped["evolution.stall_generations"] = 1  # keeps this uncapped call short
    with pytest.warns(UserWarning, match="no generation cap"):
        animat.evolve(uncapped, quiet=True)
    out = tmp_path / "nb"
    first = animat.evolve(c, out=out, generations=2, quiet=True)
    (out / "figures").mkdir()
    (out / "notes.txt").write_text("mine")
    with pytest.raises(FileExistsError, match="resume=True.*overwrite=True"):
        animat.evolve(c, out=out, generations=2, quiet=True)
    again = animat.evolve(c, out=out, generations=2, overwrite=True, quiet=True)  # a re-run notebook cell
    assert list(again.history["best"]) == list(first.history["best"])
    assert (out / "notes.txt").exists() and not (out / "figures").exists()
    other = small_config(population=6, steps=200, seed=9)
    resumed = animat.evolve(None, out=out, resume=True, generations=3, quiet=True)  # the run's own config
    assert resumed.config["evolution.seed"] == c["evolution.seed"] != other["evolution.seed"]
    assert len(resumed.population) == 6 and int(resumed.history[-1]["generation"]) == 3


def test_progress_bar_unless_quiet(capfd):
    c = small_config(population=6, steps=200)
    animat.evolve(c, generations=2)
    err = capfd.readouterr().err
    assert "evolve" in err and "3/3" in err and "best=" in err
    animat.evolve(c, generations=2, quiet=True)
    assert capfd.readouterr().err == ""


def test_one_history_type_with_pandas(tmp_path):
    out = tmp_path / "run"
    r = animat.evolve(small_config(population=6, steps=200), out=out, generations=2, quiet=True)
    h = animat.Run(out).history
    assert type(h) is type(r.history) is animat.History
    assert h and not animat.History.from_rows([])  # truth is "has a row", as for a list
    assert h.dtype.names == r.history.dtype.names == animat.HISTORY_DTYPE.names
    np.testing.assert_array_equal(h["best"], r.history["best"])
    assert h[-1].generation == h[-1]["generation"] == 2
    pd = pytest.importorskip("pandas")
    frame = h.to_pandas()
    assert isinstance(frame, pd.DataFrame) and list(frame.columns) == list(animat.HISTORY_DTYPE.names)
    assert frame["best"].tolist() == h["best"].tolist()


def test_log_reports_eval_per_second_of_the_last_generation_and_an_eta(tmp_path):
    exe = os.environ.get("ANIMAT_EVOLVE_EXE")
    if not exe:
        pytest.skip("ANIMAT_EVOLVE_EXE not set")
    p = subprocess.run(
        [
            exe,
            "--set",
            "evolution.population=6",
            "--set",
            "evaluation.steps=200",
            "--generations",
            "3",
            "--out",
            str(tmp_path / "r"),
            "--set",
            "evolution.threads=1",
        ],
        capture_output=True,
        text=True,
    )
    assert p.returncode == 0, p.stderr
    lines = [l for l in p.stdout.splitlines() if "| gen " in l or "gen     3" in l]
    assert lines and "ETA" in lines[-1], p.stdout


def _python_blocks(path):
    return re.findall(r"```python\n(.*?)```", path.read_text(encoding="utf-8"), flags=re.S)


def test_readme_quickstart_runs(tmp_path, monkeypatch):
    blocks = _python_blocks(ROOT / "README.md")
    assert blocks
    monkeypatch.chdir(tmp_path)
    namespace = {"__name__": "readme"}
    for k, block in enumerate(blocks):
        exec(compile(block, f"README.md block {k + 1}", "exec"), namespace)


# --- 6. packaging ---------------------------------------------------------------------------------------


def test_paper_configs_are_package_data():
    names = animat.paper_configs()
    assert {"paper_dn10", "paper_dn2", "paper_dn0.5", "paper_dn0.2_64cells"} <= set(names)
    c = animat.load_config(animat.config_path("paper_dn10"))
    assert c["scene.drag_normal"] == 10.0
    assert animat.config_path("paper_dn10").read_text() == (ROOT / "configs" / "paper_dn10.toml").read_text()
    with pytest.raises(ValueError, match="no config named 'paper_dn3'; shipped: "):
        animat.config_path("paper_dn3")


def test_animat_evolve_subcommand_is_animat_evolve(tmp_path):
    exe = os.environ.get("ANIMAT_EVOLVE_EXE")
    if not exe:
        pytest.skip("ANIMAT_EVOLVE_EXE not set")
    flags = ["--set", "evolution.population=6", "--set", "evaluation.steps=200", "--generations", "2", "--quiet"]
    a = subprocess.run([exe, *flags, "--out", str(tmp_path / "a")], capture_output=True, text=True)
    b = subprocess.run(
        [sys.executable, "-m", "animat", "evolve", *flags, "--out", str(tmp_path / "b")], capture_output=True, text=True
    )
    assert a.returncode == b.returncode == 0, b.stderr
    strip = lambda p: [row.rsplit(",", 1)[0] for row in (p / "history.csv").read_text().splitlines()]  # noqa: E731
    assert strip(tmp_path / "a") == strip(tmp_path / "b")
    help_a = subprocess.run([exe, "--help"], capture_output=True, text=True).stdout
    help_b = subprocess.run([sys.executable, "-m", "animat", "evolve", "--help"], capture_output=True, text=True).stdout
    assert set(re.findall(r"--[a-z-]+", help_a)) == set(re.findall(r"--[a-z-]+", help_b))
    bad = subprocess.run(
        [sys.executable, "-m", "animat", "evolve", "--set", "evaluation.objective=fast"], capture_output=True, text=True
    )
    assert bad.returncode == 2 and "expected one of distance, distance_per_size, speed_toward" in bad.stderr


def test_pyproject_declares_the_console_script_extras_and_no_unused_dependency():
    text = (ROOT / "pyproject.toml").read_text()
    assert 'animat = "animat.cli:main"' in text
    assert re.search(r'control = \["gymnasium', text)
    deps = re.search(r"^dependencies = \[(.*?)\]", text, flags=re.M | re.S).group(1)
    package = "\n".join(p.read_text() for p in (ROOT / "python" / "animat").glob("*.py"))
    for dep in re.findall(r'"([A-Za-z_-]+)', deps):
        module = {"pillow": "PIL"}.get(dep, dep)
        assert re.search(rf"^\s*(import|from) {module}\b", package, flags=re.M), f"{dep} is never imported"
    assert "build-dir" not in text.split("[tool.scikit-build]")[1].split("[")[0].replace("# No build-dir", "")


def test_public_exports_and_docstrings():
    for name in animat.__all__:
        assert hasattr(animat, name), name
    core_public = {n for n in dir(animat._core) if not n.startswith("_")}
    internal = {
        "Evolution",
        "EvolutionSummary",
        "evolve_cli",
        "load_config",
        "develop",
        "build_body",
        "swim",
        "evaluate",
        "evaluate_population",
        "record_evaluation",
        "evolve",
        "start_state",
        "source_direction",  # animat.trajectory.chemotaxis_source
        "SearchEngine",  # the C++ searches' parity with animat.MapElites and animat.Nsga2 (test_search_engine.py)
        "run_search",  # animat_evolve's search run directory (SearchEngine.run: the wrappers')
        "Archive",  # the engine's archive inside animat.GridArchive and animat.CVTArchive
        "measures",  # the engine's measures table: animat.DESCRIPTORS' ranges
        "fitness_of",  # animat.to_fitness
        "shape_elongation",  # animat.shape.elongation
        "describe_shape",  # animat.shape.body_shape
        "cvt_centroids",  # the engine's CVT archive (search.archive = "cvt"; docs/search.md)
        "CVT_SAMPLES_KEY",
        "search_history_columns",  # animat.qd.QD_HISTORY_DTYPE, animat.moo.history_dtype
        "non_dominated_sort",  # animat.moo.non_dominated_sort
        "crowding_distance",  # animat.moo.crowding_distance
        "hypervolume",  # animat.moo.hypervolume
    }
    assert core_public - internal <= set(animat.__all__), core_public - internal - set(animat.__all__)
    functions = [
        getattr(animat, n)
        for n in animat.__all__
        if callable(getattr(animat, n)) and not isinstance(getattr(animat, n), type)
    ]
    assert len(functions) > 30
    for fn in functions:
        assert "nb_func" not in type(fn).__name__, fn
        assert fn.__doc__ and len(fn.__doc__.strip()) > 30, fn
    assert pickle.loads(pickle.dumps(animat.gabriel_graph)) is animat.gabriel_graph
    for fn in (
        animat.evaluate,
        animat.evolve,
        animat.develop,
        animat.build_body,
        animat.swim,
        animat.evaluate_population,
        animat.record_evaluation,
        animat.load_config,
        animat.gabriel_graph,
    ):
        out = subprocess.run(
            [sys.executable, "-c", f"import animat; help(animat.{fn.__name__})"],
            capture_output=True,
            text=True,
            check=True,
            env={**os.environ, "PAGER": "cat", "TERM": "dumb"},
        ).stdout
        assert "nanobind" not in out.splitlines()[2] and fn.__doc__.split("\n")[0].strip() in out, fn
    import inspect

    from animat import plot

    for fn in (plot.development, plot.construction, plot.motion_cycle, plot.phase_map, plot.fitness_history):
        assert inspect.signature(fn).return_annotation in ("Figure", "matplotlib.figure.Figure"), fn


def test_pyright_reports_no_error_on_the_examples_and_the_package():
    pyright = Path(sys.executable).parent / "pyright"
    if not pyright.exists():
        pytest.skip("pyright is not installed (requirements-dev.txt)")
    import json

    stage = Path(animat.__file__).resolve().parent.parent  # build/python: the package as installed, with stubs
    config = stage.parent / "pyrightconfig.json"  # pyright reads "include" relative to its config file
    config.write_text(
        json.dumps(
            {
                "include": [
                    os.path.relpath(ROOT / "examples", config.parent),
                    os.path.relpath(stage / "animat", config.parent),
                ],
                # examples/push_recovery.py imports the packed-run store from its study folder, as it runs
                "extraPaths": [str(stage), str(ROOT / "examples"), str(ROOT / "studies" / "replication")],
                "pythonVersion": f"{sys.version_info.major}.{sys.version_info.minor}",
                "typeCheckingMode": "standard",
                "exclude": [
                    os.path.relpath(stage / "animat" / "_core.pyi", config.parent)
                ],  # nanobind's generated stub
            }
        )
    )
    p = subprocess.run(
        [str(pyright), "--pythonpath", sys.executable, "-p", str(config)],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=600,
    )
    assert p.returncode == 0 and "0 errors" in p.stdout, p.stdout[-4000:] + p.stderr[-2000:]
