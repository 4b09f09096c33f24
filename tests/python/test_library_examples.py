"""The field's libraries evolving animat genomes (docs/python.md §7d): examples/deap_ga.py (DEAP's
eaMuPlusLambda) and examples/pymoo_nsga2.py (pymoo's NSGA2, ask/tell), run small: the same run for a
seed whatever the threads, fitness values that are animat.evaluate's, a pymoo front that is
non-dominated and feasible.

DEAP and pymoo are optional extras (``pip install ".[deap,pymoo]"``); requirements-dev.txt installs
them, so these tests run wherever the suite does. Every run here is tiny (200-step swims, populations of
6 to 8, 3 generations): the file runs in seconds.
"""

import copy
import importlib.util
import re
import sys
from pathlib import Path

import numpy as np
import pytest

import animat

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def load_example(name: str):
    """An example script as a module (imported once: deap_ga.py creates DEAP's creator types)."""
    if name in sys.modules:
        return sys.modules[name]
    if str(EXAMPLES) not in sys.path:  # the examples import their shared module, _common
        sys.path.insert(0, str(EXAMPLES))
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def tiny_config():
    c = animat.Config()
    c["evaluation.steps"] = 200
    return c


# --- DEAP -----------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def deap_ga():
    pytest.importorskip("deap")
    return load_example("deap_ga")


def deap_run(deap_ga, threads=1, seed=3):
    return deap_ga.run(tiny_config(), population=8, generations=3, seed=seed, threads=threads)


def deap_state(result):
    return [(ind.genome.to_json(), ind.fitness.values) for ind in result.population], list(result.logbook.select("max"))


def test_a_genome_cannot_be_a_deap_creator_base_so_an_individual_holds_one(deap_ga):
    from deap import base, creator

    with pytest.raises(TypeError, match="metaclass conflict"):
        creator.create("AnimatGenomeIndividual", animat.Genome, fitness=base.Fitness)
    genome = animat.Genome.random(1)
    individual = creator.Individual(genome)
    assert isinstance(individual, deap_ga.GenomeIndividual) and individual.genome is genome
    assert not individual.fitness.valid and individual.fitness.weights == (1.0,)
    clone = copy.deepcopy(individual)  # DEAP's toolbox.clone
    assert type(clone) is type(individual) and clone == individual and clone.genome is not genome


def test_the_deap_run_is_the_same_for_a_seed_whatever_the_threads(deap_ga):
    a = deap_run(deap_ga)
    assert deap_state(a) == deap_state(deap_run(deap_ga))
    assert deap_state(a) == deap_state(deap_run(deap_ga, threads=2))
    assert deap_state(a) != deap_state(deap_run(deap_ga, seed=4))


def test_deap_fitness_is_animat_evaluate_and_the_best_is_never_lost(deap_ga):
    result = deap_run(deap_ga)
    config = result.config
    assert len(result.population) == 8 and len(result.logbook) == 4  # generation 0 and 3 more
    for individual in result.population:
        assert individual.fitness.values == (animat.evaluate(individual.genome, config).fitness,)
    best = result.hall_of_fame[0]
    best_per_generation = result.logbook.select("max")
    assert best_per_generation == sorted(best_per_generation)  # selBest over parents and offspring
    assert best.fitness.values[0] == best_per_generation[-1] == max(i.fitness.values[0] for i in result.population)
    assert best.fitness.values[0] > 0
    assert result.logbook.select("nevals") == [8, 8, 8, 8]


def test_the_deap_example_prints_its_best_and_the_reference_check(deap_ga, capsys):
    result = deap_ga.main(["--population", "6", "--generations", "2", "--steps", "200", "--threads", "1", "--quiet"])
    out = capsys.readouterr().out
    best = result.hall_of_fame[0]
    assert "18 evaluations" in out and f"the best swims {best.fitness.values[0]:.4g}" in out
    assert "at the reference step (agrees)" in out or "(disagrees)" in out


# --- pymoo ----------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def pymoo_nsga2():
    pytest.importorskip("pymoo")
    return load_example("pymoo_nsga2")


def pymoo_run(pymoo_nsga2, threads=1, seed=3):
    return pymoo_nsga2.run(tiny_config(), population=8, generations=3, seed=seed, threads=threads)


def pymoo_state(result):
    population = [(ind.X[0].to_json(), ind.F.tolist(), ind.G.tolist()) for ind in result.algorithm.pop]
    return population, [(g.to_json(), v) for g, v in result.front], result.history


def test_the_pymoo_run_is_the_same_for_a_seed_whatever_the_threads(pymoo_nsga2):
    a = pymoo_run(pymoo_nsga2)
    assert pymoo_state(a) == pymoo_state(pymoo_run(pymoo_nsga2))
    assert pymoo_state(a) == pymoo_state(pymoo_run(pymoo_nsga2, threads=2))
    assert pymoo_state(a)[0] != pymoo_state(pymoo_run(pymoo_nsga2, seed=4))[0]


def test_the_pymoo_front_is_feasible_non_dominated_and_measured_as_animat_nsga2_does(pymoo_nsga2):
    result = pymoo_run(pymoo_nsga2)
    config, senses = result.problem.config, ["max", "min"]
    assert [r.generation for r in result.history] == [1, 2, 3] and result.history[0].evaluations == 8
    assert len(result.algorithm.pop) == 8
    genomes = [ind.X[0].to_json() for ind in result.algorithm.pop]
    assert len(set(genomes)) == len(genomes)  # the duplicate elimination compares genomes
    front = result.front
    assert front and len(front) == result.history[-1].front_size
    values = np.array([v for _, v in front])
    assert animat.moo.non_dominated_sort(values, senses) == [list(range(len(front)))]
    for genome, (distance, work) in front:
        evaluation = animat.evaluate(genome, config)
        assert evaluation.viable and evaluation.stable and evaluation.valid
        assert distance == animat.CRITERIA["distance"](evaluation, genome, config) == evaluation.fitness
        assert work == evaluation.actuation_work_positive
    # no feasible member of the population dominates a front genome; infeasible ones have no values
    feasible = [ind for ind in result.algorithm.pop if ind.G[0] <= 0]
    for ind in feasible:
        point = (-ind.F[0], ind.F[1])
        assert not any(animat.moo.dominates(point, v, senses) for v in values)
    for ind in result.algorithm.pop:
        if ind.G[0] > 0:
            assert np.all(np.isinf(ind.F)) and ind.X[0].to_json() not in {g.to_json() for g, _ in front}
    assert [d for d, _ in values] == sorted((d for d, _ in values), reverse=True)  # best distance first


def test_pymoo_minimize_runs_the_same_loop(pymoo_nsga2):
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.core.duplicate import ElementwiseDuplicateElimination
    from pymoo.optimize import minimize

    problem = pymoo_nsga2.SwimmerProblem(tiny_config(), threads=1)
    algorithm = NSGA2(
        pop_size=8,
        sampling=pymoo_nsga2.ViableGenomes(),
        crossover=pymoo_nsga2.GenomeCrossover(prob=float(problem.config["evolution.crossover_fraction"])),
        mutation=pymoo_nsga2.GenomeMutation(),
        eliminate_duplicates=ElementwiseDuplicateElimination(cmp_func=pymoo_nsga2.same_genome),
    )
    result = minimize(problem, algorithm, ("n_gen", 3), seed=3)
    front = pymoo_nsga2.front_of(result.algorithm, problem)
    assert [(g.to_json(), v) for g, v in front] == pymoo_state(pymoo_run(pymoo_nsga2))[1]


def test_a_genome_that_is_not_viable_violates_the_constraint(pymoo_nsga2):
    problem = pymoo_nsga2.SwimmerProblem(tiny_config(), threads=1)
    viable = animat.Genome.random_viable(1, problem.config)[0]
    seed = next(s for s in range(100) if not animat.develop(animat.Genome.random(s), problem.config).viable)
    X = np.array([[viable], [animat.Genome.random(seed)]], dtype=object)
    F, G = problem.evaluate(X, return_values_of=["F", "G"])
    evaluation = animat.evaluate(viable, problem.config)
    assert F[0].tolist() == [-evaluation.fitness, evaluation.actuation_work_positive] and G[0].tolist() == [0.0]
    assert np.all(np.isinf(F[1])) and G[1].tolist() == [1.0]


def test_the_pymoo_example_prints_its_front(pymoo_nsga2, capsys):
    result = pymoo_nsga2.main(["--population", "6", "--generations", "2", "--steps", "200", "--threads", "1"])
    out = capsys.readouterr().out
    assert "generation   1:    6 evaluations" in out and "generation   2:   12 evaluations" in out
    assert out.count("\n  ") == len(result.front)  # one line per front genome
    assert "the farthest swims" in out and "at the reference step" in out


# --- the page -------------------------------------------------------------------------------------


def test_the_page_shows_the_examples_own_code():
    """docs/python.md §7d shows code of the examples (indented blocks, not run by the walkthrough): every
    line of it is a line of one of them, so the page cannot drift from what the tests above run."""
    page = (EXAMPLES.parent / "docs" / "python.md").read_text(encoding="utf-8")
    section = page.split("## 7d. ")[1].split("\n## ")[0]
    blocks = re.findall(r"(?:^|\n\n)((?: {4}.*\n|\n(?= {4}))+)", section)
    code = [b for b in blocks if not b.lstrip().startswith(("pip ", "PYTHONPATH="))]
    assert len(code) >= 3
    source = {
        line.strip()
        for name in ("deap_ga", "pymoo_nsga2")
        for line in (EXAMPLES / f"{name}.py").read_text(encoding="utf-8").splitlines()
    }
    for block in code:
        for line in block.splitlines():
            assert not line.strip() or line.strip() in source, line
    for name in ("deap_ga", "pymoo_nsga2"):
        assert f"examples/{name}.py --seed 1" in section
