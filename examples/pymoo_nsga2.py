"""pymoo's NSGA-II evolving animat genomes: distance (maximised) against positive actuation work
(minimised), the pair of examples/nsga2_distance_vs_work.py, through pymoo's ask/tell interface.

    .venv/bin/pip install "pymoo>=0.6.2"        # or, from the repository: pip install ".[pymoo]"
    PYTHONPATH=build/python .venv/bin/python examples/pymoo_nsga2.py [--generations 20] [--population 20]

The decision variable is the genome itself, an object (pymoo's custom-variable idiom): a
:class:`SwimmerProblem` of one variable, a sampling of random viable genomes, the genome's own
crossover and mutation as pymoo operators, and a duplicate elimination that compares genomes. The
problem evaluates a batch with :func:`animat.evaluate` on a pool of threads (it releases the GIL) and
scores it with ``animat.CRITERIA`` (what ``animat.Nsga2`` measures); a genome that is not viable, or a
swim that is unstable or not valid, violates the problem's one constraint, so it is never on the front.

pymoo draws every random number from the generator it passes its operators (``random_state``, seeded by
``algorithm.setup(..., seed=)``); the genome's operators take a seed drawn from it. So a seed gives the
same run for any ``--threads``.
"""

import time
from concurrent.futures import ThreadPoolExecutor
from typing import Any, List, NamedTuple, Optional, Sequence, Tuple

import numpy as np
from pymoo.algorithms.moo.nsga2 import NSGA2
from pymoo.core.crossover import Crossover
from pymoo.core.duplicate import ElementwiseDuplicateElimination
from pymoo.core.mutation import Mutation
from pymoo.core.problem import Problem
from pymoo.core.sampling import Sampling

import animat

from _common import at_reference, search_config, search_parser

OBJECTIVES = [("distance", "max"), ("actuation_work_positive", "min")]
SEED_LIMIT = 2**63 - 1  # the genome's operators take a seed in [0, 2^63)


def _seed(random_state: Any) -> int:
    return int(random_state.integers(SEED_LIMIT))


class SwimmerProblem(Problem):
    """One decision variable, an ``animat.Genome``; the objectives are ``animat.CRITERIA`` rows,
    given to pymoo minimised (a maximised one negated); one constraint, ``G <= 0`` when the swim is
    feasible (viable, stable, valid, every criterion finite)."""

    def __init__(self, config: Any, objectives: Sequence[Tuple[str, str]] = OBJECTIVES, threads: int = 0) -> None:
        self.config = config
        self.criteria = [animat.CRITERIA[name].with_sense(sense) for name, sense in objectives]
        self.threads = threads
        super().__init__(n_var=1, n_obj=len(self.criteria), n_ieq_constr=1, vtype=object)

    def measure(self, genome: Any, evaluation: Any) -> Optional[List[float]]:
        """The criteria of an evaluation, in their own senses; None when it is not feasible."""
        if not (evaluation.viable and evaluation.stable and evaluation.valid):
            return None
        values = [c(evaluation, genome, self.config) for c in self.criteria]
        return values if all(np.isfinite(values)) else None

    def _evaluate(self, X: Any, out: dict, *args: Any, **kwargs: Any) -> None:
        genomes = [x[0] for x in X]
        with ThreadPoolExecutor(max_workers=self.threads or None) as pool:
            evaluations = list(pool.map(lambda g: animat.evaluate(g, self.config), genomes))
        F = np.full((len(genomes), self.n_obj), np.inf)  # an infeasible point has no objective values
        G = np.ones((len(genomes), 1))
        for i, (genome, evaluation) in enumerate(zip(genomes, evaluations)):
            values = self.measure(genome, evaluation)
            if values is not None:
                F[i] = [-v if c.maximize else v for c, v in zip(self.criteria, values)]
                G[i] = 0.0
        out["F"], out["G"] = F, G


class ViableGenomes(Sampling):
    """Random viable genomes, as animat.GA seeds its initial population."""

    def _do(self, problem: Any, n_samples: int, *args: Any, random_state: Any = None, **kwargs: Any) -> Any:
        X = np.empty((n_samples, 1), dtype=object)
        for i in range(n_samples):
            X[i, 0], _tries = animat.Genome.random_viable(_seed(random_state), problem.config)
        return X


class GenomeCrossover(Crossover):
    """The genome's crossover, both ways with the same cut points (``mutation.crossover_points``):
    two complementary children of two parents."""

    def __init__(self, prob: float) -> None:
        super().__init__(n_parents=2, n_offsprings=2, prob=prob)

    def _do(self, problem: Any, X: Any, *args: Any, random_state: Any = None, **kwargs: Any) -> Any:
        points = int(problem.config["mutation.crossover_points"])
        Y = np.empty_like(X)  # (parents, matings, 1) objects
        for k in range(X.shape[1]):
            a, b, seed = X[0, k, 0], X[1, k, 0], _seed(random_state)
            Y[0, k, 0], Y[1, k, 0] = a.crossover(b, seed, points), b.crossover(a, seed, points)
        return Y


class GenomeMutation(Mutation):
    """The genome's mutation at the rates of ``config.mutation`` (every offspring; it leaves some
    genomes unchanged, and the duplicate elimination drops those)."""

    def _do(self, problem: Any, X: Any, *args: Any, random_state: Any = None, **kwargs: Any) -> Any:
        Y = np.empty_like(X)
        for i in range(len(X)):
            Y[i, 0] = X[i, 0].mutate(_seed(random_state), problem.config)
        return Y


def same_genome(a: Any, b: Any) -> bool:
    """pymoo's duplicate test: two candidates are duplicates when their genomes are equal."""
    return a.X[0] == b.X[0]


class Row(NamedTuple):
    generation: int  # pymoo's n_gen: 1 is the initial population
    evaluations: int
    front_size: int
    best_distance: float
    least_work: float


class Result(NamedTuple):
    front: List[Tuple[Any, Tuple[float, float]]]  # (genome, (distance, work)), best distance first
    history: List[Row]
    problem: SwimmerProblem
    algorithm: Any  # the pymoo NSGA2, after its last tell
    seconds: float


def front_of(algorithm: Any, problem: SwimmerProblem) -> List[Tuple[Any, Tuple[float, float]]]:
    """The feasible genomes of rank 0 of the population with their criteria (in their own senses)."""
    out = []
    for individual in algorithm.pop:
        if individual.get("rank") == 0 and individual.feas:
            values = tuple(float(-f if c.maximize else f) for c, f in zip(problem.criteria, individual.F))
            out.append((individual.X[0], values))
    return sorted(out, key=lambda s: (-s[1][0], s[1][1]))


def run(
    config: Any,
    population: int = 20,
    generations: int = 20,
    seed: int = 1,
    threads: int = 0,
    crossover_fraction: Optional[float] = None,
    callback: Any = None,
) -> Result:
    """``generations`` generations of pymoo's NSGA2 (the initial population is generation 1) over
    ``population`` genomes: binary tournaments on (rank, crowding), crossover with probability
    ``crossover_fraction`` (default the config's ``evolution.crossover_fraction``), then every
    offspring mutated. ``callback(row)`` after every generation."""
    cf = float(config["evolution.crossover_fraction"]) if crossover_fraction is None else crossover_fraction
    problem = SwimmerProblem(config, OBJECTIVES, threads)
    # (pyright types NSGA2's operator parameters by their defaults: FloatRandomSampling, SBX, PM.)
    algorithm = NSGA2(
        pop_size=population,
        sampling=ViableGenomes(),  # pyright: ignore[reportArgumentType]
        crossover=GenomeCrossover(prob=cf),  # pyright: ignore[reportArgumentType]
        mutation=GenomeMutation(),  # pyright: ignore[reportArgumentType]
        eliminate_duplicates=ElementwiseDuplicateElimination(cmp_func=same_genome),
    )
    algorithm.setup(problem, termination=("n_gen", generations), seed=seed, verbose=False)
    history: List[Row] = []
    evaluations = 0
    start = time.perf_counter()
    while algorithm.has_next():
        infills = algorithm.ask()  # the genomes to evaluate: pymoo's Population
        assert infills is not None  # (NSGA2 always asks)
        algorithm.evaluator.eval(problem, infills)  # SwimmerProblem._evaluate: animat.evaluate on threads
        algorithm.tell(infills=infills)
        evaluations += len(infills)
        front = front_of(algorithm, problem)
        values = [v for _, v in front]
        row = Row(
            len(history) + 1,
            evaluations,
            len(front),
            float(max((d for d, _ in values), default=float("nan"))),
            float(min((w for _, w in values), default=float("nan"))),
        )
        history.append(row)
        if callback is not None:
            callback(row)
    return Result(front_of(algorithm, problem), history, problem, algorithm, time.perf_counter() - start)


def main(argv: Optional[Sequence[str]] = None) -> Result:
    p = search_parser(__doc__)
    p.add_argument("--quiet", action="store_true", help="no line per generation")
    args = p.parse_args(argv)
    config = search_config(args)

    def report(row: Row) -> None:
        if not args.quiet:
            print(
                f"generation {row.generation:3d}: {row.evaluations:4d} evaluations, front {row.front_size:3d}, "
                f"best distance {row.best_distance:.4g}, least work {row.least_work:.4g}"
            )

    result = run(config, args.population, args.generations, args.seed, args.threads, callback=report)
    print(f"{result.history[-1].evaluations} evaluations in {result.seconds:.1f} s")
    print("the front (distance, positive work, distance per work):")
    for _genome, (distance, work) in result.front:
        print(f"  {distance:10.4g} {work:12.4g} {distance / work if work > 0 else float('nan'):12.4g}")
    genome, (distance, _work) = result.front[0]
    print(f"the farthest swims {at_reference(genome, distance, config)}")
    return result


if __name__ == "__main__":
    main()
