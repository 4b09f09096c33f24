"""DEAP evolving animat genomes: DEAP's own loop (``algorithms.eaMuPlusLambda``), selection,
statistics and hall of fame, with the genome's own crossover and mutation as DEAP's ``mate`` and
``mutate`` and :func:`animat.evaluate` (on a pool of threads: it releases the GIL) as its evaluation.

    .venv/bin/pip install "deap>=1.4"           # or, from the repository: pip install ".[deap]"
    PYTHONPATH=build/python .venv/bin/python examples/deap_ga.py [--generations 20] [--population 20]

An individual *holds* its genome (``individual.genome``): ``creator.create("Individual",
GenomeIndividual, fitness=creator.FitnessMax)``. An ``animat.Genome`` cannot be the base class of a
creator type (``creator.create("Individual", animat.Genome, ...)`` is a metaclass conflict with the
compiled class), and a Python subclass of it would not survive the genome's operators, which return a
new ``animat.Genome``, nor ``copy.deepcopy``, which DEAP clones individuals with.

Every random number comes from Python's ``random`` module, seeded once with ``--seed``: DEAP's
variation draws from it, and the genome's operators take a seed drawn from it (in this thread, before
the evaluations); the evaluation is deterministic. So a seed gives the same run for any ``--threads``.
"""

# DEAP's creator and toolbox make their attributes at run time (creator.create, toolbox.register).
# pyright: reportAttributeAccessIssue=false

import random
import time
from concurrent.futures import ThreadPoolExecutor
from typing import Any, List, NamedTuple, Optional, Sequence

import numpy as np
from deap import algorithms, base, creator, tools

import animat

from _common import at_reference, search_config, search_parser

SEED_BITS = 63  # the genome's operators take a seed in [0, 2^63)


class GenomeIndividual:
    """One animat genome as a DEAP individual: ``creator.create`` adds the ``fitness``. Two
    individuals are equal when their genomes are (DEAP's hall of fame keeps one of equal ones)."""

    def __init__(self, genome: Any) -> None:
        self.genome = genome

    def __eq__(self, other: object) -> bool:
        return isinstance(other, GenomeIndividual) and self.genome == other.genome

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.genome!r})"


creator.create("FitnessMax", base.Fitness, weights=(1.0,))
creator.create("Individual", GenomeIndividual, fitness=creator.FitnessMax)


def new_individual(config: Any) -> Any:
    """A random viable genome, as animat.GA seeds its initial population."""
    genome, _tries = animat.Genome.random_viable(random.getrandbits(SEED_BITS), config)
    return creator.Individual(genome)


def crossover(a: Any, b: Any, points: Optional[int] = None) -> tuple:
    """The genome's crossover, both ways with the same cut points (``mutation.crossover_points``):
    two complementary children."""
    seed = random.getrandbits(SEED_BITS)
    a.genome, b.genome = a.genome.crossover(b.genome, seed, points), b.genome.crossover(a.genome, seed, points)
    return a, b


def mutate(individual: Any, config: Any) -> tuple:
    """The genome's mutation at the rates of ``config.mutation`` (it leaves some genomes unchanged)."""
    individual.genome = individual.genome.mutate(random.getrandbits(SEED_BITS), config)
    return (individual,)


def evaluate(individual: Any, config: Any) -> tuple:
    """DEAP's fitness values: ``animat.evaluate``'s fitness, the config's objective (0 for a genome
    that is not viable, a swim that is unstable or not valid)."""
    return (animat.evaluate(individual.genome, config).fitness,)


class Result(NamedTuple):
    population: List[Any]
    logbook: Any  # deap.tools.Logbook
    hall_of_fame: Any  # deap.tools.HallOfFame
    config: Any
    seconds: float


def run(
    config: Any,
    population: int = 20,
    generations: int = 20,
    seed: int = 1,
    threads: int = 0,
    crossover_fraction: Optional[float] = None,
    verbose: bool = False,
) -> Result:
    """``generations`` generations of ``deap.algorithms.eaMuPlusLambda`` from ``population`` random
    viable genomes: each generation ``population`` offspring, each made by crossover of two random
    members with probability ``crossover_fraction`` (default the config's
    ``evolution.crossover_fraction``), else by mutation of one; the next population is the best
    ``population`` of parents and offspring together (``tools.selBest``: the best is never lost).
    ``threads``: evaluations at once (0 = all cores)."""
    cxpb = float(config["evolution.crossover_fraction"]) if crossover_fraction is None else crossover_fraction
    random.seed(seed)
    toolbox = base.Toolbox()
    toolbox.register("individual", new_individual, config)
    toolbox.register("population", tools.initRepeat, list, toolbox.individual)
    toolbox.register("mate", crossover, points=int(config["mutation.crossover_points"]))
    toolbox.register("mutate", mutate, config=config)
    toolbox.register("select", tools.selBest)
    toolbox.register("evaluate", evaluate, config=config)

    stats = tools.Statistics(key=lambda individual: individual.fitness.values[0])
    stats.register("max", np.max)
    stats.register("mean", np.mean)
    hall_of_fame = tools.HallOfFame(1)
    start = time.perf_counter()
    with ThreadPoolExecutor(max_workers=threads or None) as pool:
        toolbox.register("map", pool.map)  # DEAP evaluates through toolbox.map: here, on threads
        pop = toolbox.population(n=population)
        pop, logbook = algorithms.eaMuPlusLambda(
            pop,
            toolbox,
            mu=population,
            lambda_=population,
            cxpb=cxpb,
            mutpb=1.0 - cxpb,
            ngen=generations,
            stats=stats,
            halloffame=hall_of_fame,
            verbose=verbose,
        )
    return Result(pop, logbook, hall_of_fame, config, time.perf_counter() - start)


def main(argv: Optional[Sequence[str]] = None) -> Result:
    p = search_parser(__doc__)
    p.add_argument("--quiet", action="store_true", help="no table of generations")
    args = p.parse_args(argv)
    config = search_config(args)
    result = run(config, args.population, args.generations, args.seed, args.threads, verbose=not args.quiet)
    best = result.hall_of_fame[0]
    distance = best.fitness.values[0]
    cells = animat.evaluate(best.genome, config).cell_count
    print(
        f"{sum(result.logbook.select('nevals'))} evaluations in {result.seconds:.1f} s; the best swims "
        f"{distance:.4g} ({cells} cells), {at_reference(best.genome, distance, config)}"
    )
    return result


if __name__ == "__main__":
    main()
