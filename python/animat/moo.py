"""Several objectives: NSGA-II over a vector of objectives (distance against actuation work, ...).

The GA and MAP-Elites rank a genome by one number. Here an objective is a **vector**: each genome is
scored by several **criteria** (how far it swims, how much positive work its actuators spend, ...),
each maximised or minimised, and the search keeps the genomes no other beats on every criterion at
once, the **Pareto front**. NSGA-II (Deb, Pratap, Agarwal & Meyarivan 2002) does it with a fast
non-dominated sort, a crowding distance, a binary tournament on (rank, crowding) and an elitist
(mu + lambda) selection; the offspring are varied by the genome's own operators (the GA's crossover
with probability ``crossover_fraction``, then its mutation).

- :data:`CRITERIA`: the named criteria: ``fitness`` (the config's ``evaluation.objective``), every row
  of the engine's objective table (:data:`animat.OBJECTIVES`: ``distance``, ``distance_per_size``, ...)
  and the numeric fields of :class:`animat.EvaluationResult` (``actuation_work_positive``,
  ``cell_count``, ``max_speed``, ...). :class:`Criterion` also wraps your own ``f(evaluation) -> float``.
- :func:`non_dominated_sort`, :func:`crowding_distance`, :func:`hypervolume`, :func:`dominates`: the
  pieces, on plain arrays.
- :class:`Nsga2`: ask/tell, ``step()``, ``front()``, ``history``, ``checkpoint()`` / :meth:`Nsga2.restore`.
- :func:`run_nsga2`: a run directory (``config.toml``, ``history.csv``, ``front/gen_*.csv``,
  ``checkpoint.json``) that resumes.

**Objectives.** A sequence of: a name (``"distance"``: the table's default sense), a ``(name,
sense)`` or ``(function, sense)`` pair, or a :class:`Criterion`; a sense is ``"max"`` or ``"min"``
(``"maximize"``, ``"minimize"`` too). Distance against positive actuation work::

    animat.Nsga2(config, [("distance", "max"), ("actuation_work_positive", "min")])

Every swim meters its actuation work (the effect ``springs`` does, in every scene: docs/worlds.md),
so no setting is needed for the work criteria.

**Determinism.** Every random number of generation g, offspring i is drawn from
``animat.Rng.derive(seed, g, i)`` (the tournaments, the crossover draw, the crossover and the
mutation), and the sort, the crowding distance and the selection are exact functions of the
objective values with fixed tie rules, so a run is a function of (config, objectives, seed,
population, crossover_fraction, reference_point) alone: identical for any thread count, and across
checkpoint and resume.

**Feasible.** A candidate is **feasible** when its genome is viable, its swim stable and valid (no
simulator exploit: the engine scores those 0) and every criterion is a finite number. Only feasible
candidates are sorted into fronts; the others share the worst rank (below every front, crowding 0):
they are never on the front, and they stay in the population only when fewer than ``population``
candidates are feasible. So do **copies**: a candidate whose genome equals one already in the
population or earlier in its batch (mutation leaves some offspring unchanged) adds no point to the
front and would only crowd it with duplicates (Deb et al. do not treat them; pymoo's NSGA-II drops
duplicate offspring too, before it evaluates them).

**The exploit guard** (``evaluation.reference_check``, as for the GA and MAP-Elites): ``"off"``:
nothing more. ``"record"`` (the default): at the end of every ``tell()``, every genome on the front
that has no reference yet is evaluated again at the reference step (``physics.substeps ×
evaluation.reference_substeps``); its criteria there are stored with it (``Solution.reference``) and
``history["disagreements"]`` counts the front's genomes for which one criterion and its reference
disagree (:func:`animat.reference_disagrees`; a reference swim that is not valid disagrees).
``"select"``: every feasible candidate is evaluated at the reference step *before* the selection (a
copy takes its original's reference), and the selection compares the **reference** values
(``Solution.objectives``; the step's own are ``Solution.measured``): a candidate whose swim exploits
the coarse step, or is not valid at the reference step, never reaches the front. Under ``"record"``
and ``"off"`` the objectives are the measured values.

Example::

    nsga = animat.Nsga2(config, [("distance", "max"), ("actuation_work_positive", "min")], population=20)
    for _ in range(10):
        nsga.step()                                     # ask, evaluate, tell
    for s in nsga.front():
        print(s.objectives)                             # (distance, work) of every Pareto-optimal genome
    print(nsga.history["hypervolume"])
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Callable, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union, cast

import numpy as np

from . import _core
from .pool import Swim, evaluate_results
from .qd import (
    _checked_state,
    _checksum,
    _comparable,
    _engine_checkpoint,
    _history_dtype,
    _holds,
    _on_ranks,
    _reference_hook,
    _run_config,
    _run_search,
    _same_as_run,
    _SearchState,
    _write_atomic,
)

__all__ = [
    "Criterion",
    "CRITERIA",
    "Solution",
    "Nsga2",
    "dominates",
    "non_dominated_sort",
    "crowding_distance",
    "hypervolume",
    "history_dtype",
    "objectives_from_config",
    "run_nsga2",
]

PathLike = Union[str, "os.PathLike[str]"]

#: Version tag of :meth:`Nsga2.checkpoint`.
CHECKPOINT_FORMAT = "animat.nsga2/3"

_SENSES = {"max": "max", "maximize": "max", "maximise": "max", "min": "min", "minimize": "min", "minimise": "min"}


def _sense(sense: Any, name: str) -> str:
    s = _SENSES.get(sense) if isinstance(sense, str) else None
    if s is None:
        raise ValueError(f"objective {name!r}: the sense is 'max' or 'min' (or 'maximize', 'minimize'), got {sense!r}")
    return s


# --- criteria -------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Criterion:
    """One objective of a multi-objective search: a number computed from a genome's evaluation, and
    whether larger (``sense="max"``) or smaller (``"min"``) is better.

    ``function(evaluation) -> float``: ``evaluation`` is the genome's :class:`animat.EvaluationResult`
    (from :func:`animat.evaluate`), called for viable, stable and valid swims only. It must be a pure
    function of it (the run's determinism rests on it); NaN or an infinity means "no value" (the
    candidate is not feasible). ``name`` names its columns in ``history.csv`` and the front's CSV: an
    identifier. (Not :class:`animat.Objective`, the GA's one objective, nor
    :class:`animat.ObjectiveSpec`, a row of the engine's table.)

    Your own: ``Criterion("speed", "max", lambda e: e.max_speed)``, or the pair ``(function, "max")``
    (named by the function's ``__name__``) wherever objectives are given. A table entry with another
    sense: ``CRITERIA["max_speed"].with_sense("min")`` or the pair ``("max_speed", "min")``.
    """

    name: str
    sense: str
    function: Callable[[Any], float] = field(repr=False, compare=False)
    meaning: str = ""
    # Table entries compute from (evaluation, genome, config): the engine's rows read the config's
    # evaluation parameters and, for distance_per_size, the body.
    _of: Optional[Callable[[Any, Any, Any], float]] = field(default=None, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise ValueError(
                f"Criterion: the name must be an identifier (it names CSV columns), got {self.name!r}: "
                "name a function with Criterion('name', 'max', function)"
            )
        # "" only in the table: a field with no natural sense (say which: ("max_speed", "max")).
        object.__setattr__(self, "sense", _sense(self.sense, self.name) if self.sense else "")
        if not callable(self.function):
            raise TypeError(f"Criterion {self.name!r}: function must be callable")

    @property
    def maximize(self) -> bool:
        """True when larger is better."""
        return self.sense == "max"

    def with_sense(self, sense: str) -> Criterion:
        """The same criterion with another sense."""
        return replace(self, sense=_sense(sense, self.name))

    def __call__(self, evaluation: Any, genome: Any = None, config: Any = None) -> float:
        """Its value for an evaluation (``genome`` and ``config``: for the table's engine rows, see
        :data:`CRITERIA`)."""
        if self._of is not None:
            return float(self._of(evaluation, genome, config))
        return float(self.function(evaluation))


def _engine_row(spec: Any) -> Criterion:
    name = str(spec.name)

    def of(evaluation: Any, genome: Any, config: Any) -> float:
        cfg = _core.Config() if config is None else config
        if str(cfg["evaluation.objective"]) == name:
            return float(evaluation.fitness)  # the engine scored it: exactly its value
        if not spec.one_swim:
            raise ValueError(
                f"objective {name!r} needs one swim per source direction: set evaluation.objective = {name!r}"
            )
        dx, dy = (float(v) for v in evaluation.displacement)
        distance = math.sqrt(dx * dx + dy * dy) if evaluation.valid else 0.0  # the engine's SwimResult.distance
        length = 0.0
        if spec.needs_body:
            if genome is None:
                raise ValueError(f"objective {name!r} reads the body: pass the genome")
            from .pipeline import build_body

            length = float(_core.body_length(build_body(_core.develop(genome, cfg), config=cfg)))
        return float(
            _core.objective_value(
                name,
                distance,
                dx,
                dy,
                float(evaluation.simulated_time),
                length,
                float(evaluation.actuation_work_positive),
                float(evaluation.source_progress),
                cfg,
            )
        )

    def function(evaluation: Any) -> float:
        return of(evaluation, None, None)

    function.__name__ = name
    return Criterion(name, "max", function, f"{spec.meaning} (the engine's objective {name!r})", of)


# The numeric fields of EvaluationResult that are functions of the genome and the config (not the
# wall-clock seconds), with the sense that is better where one is (the work an actuator spends).
_FIELDS: Tuple[Tuple[str, str], ...] = (
    ("actuation_work_positive", "min"),
    ("actuation_work_absolute", "min"),
    ("actuation_work", "min"),
    ("cell_count", ""),
    ("spring_count", ""),
    ("region_count", ""),
    ("skin_edge_count", ""),
    ("development_steps", ""),
    ("simulated_time", ""),
    ("max_speed", ""),
    ("max_step_displacement", ""),
    ("max_stretch", ""),
    ("min_stretch", ""),
    ("max_kinetic_energy", ""),
    ("final_kinetic_energy", ""),
    ("max_kinetic_energy_per_cell", ""),
    ("min_area_ratio", ""),
    ("collisions", ""),
    ("collisions_inelastic", ""),
    ("drag_limited", ""),
    ("ground_contacts", ""),
    ("ground_slips", ""),
    ("airborne_steps", ""),
    ("source_progress", ""),
    ("grn_updates", ""),
)


def _field(name: str, sense: str) -> Criterion:
    def function(evaluation: Any) -> float:
        return float(getattr(evaluation, name))

    function.__name__ = name
    doc = (getattr(_core.EvaluationResult, name).__doc__ or "").strip().split("\n")[0]
    return Criterion(name, sense, function, f"{doc} (EvaluationResult.{name})")


def _fitness(evaluation: Any) -> float:
    return float(evaluation.fitness)


#: The named criteria, name -> :class:`Criterion`: ``fitness`` (the config's ``evaluation.objective``,
#: maximised), the engine's objective table (:data:`animat.OBJECTIVES`, maximised: scored from the
#: evaluation with :func:`animat.objective_value`, exactly as the engine scores them; the config's own
#: objective is ``evaluation.fitness``; ``chemotaxis`` only when it is the config's objective), and
#: the numeric fields of :class:`animat.EvaluationResult` (the actuation work minimised; the others
#: have no default sense: give one, ``("max_speed", "max")``).
CRITERIA: Dict[str, Criterion] = {
    "fitness": Criterion("fitness", "max", _fitness, "the config's evaluation.objective (EvaluationResult.fitness)"),
    **{str(spec.name): _engine_row(spec) for spec in _core.objectives()},
    **{name: _field(name, sense) for name, sense in _FIELDS},
}

#: The engine's objectives that one swim does not decide (chemotaxis): only as the config's own.
_SEVERAL_SWIMS = frozenset(str(spec.name) for spec in _core.objectives() if not spec.one_swim)

CriterionLike = Union[str, Criterion, Tuple[Any, str]]


def _criterion(spec: CriterionLike) -> Criterion:
    if isinstance(spec, Criterion):
        return spec
    if isinstance(spec, str):
        if spec not in CRITERIA:
            raise ValueError(f"no objective named {spec!r}; the names are {', '.join(CRITERIA)}")
        return CRITERIA[spec]
    if isinstance(spec, tuple) and len(spec) == 2:
        what: Any = spec[0]
        if isinstance(what, str):
            return _criterion(what).with_sense(spec[1])
        if callable(what):
            name = getattr(what, "__name__", None) or type(what).__name__
            function = cast(Callable[[Any], float], what)
            return Criterion(name, _sense(spec[1], name), function, f"{name} (a Python function)")
    if callable(spec):
        raise ValueError("an objective function needs a sense: pass (function, 'max') or (function, 'min')")
    raise TypeError(
        f"an objective is a name, a Criterion or a (name or function, 'max' or 'min') pair, got {spec!r:.80}"
    )


def objectives_from_config(config: Any) -> List[Tuple[str, str]]:
    """The objectives a new run from ``config`` optimises: ``search.objectives``, each ``"NAME"`` (the
    table's sense) or ``"NAME:max"`` / ``"NAME:min"``, as ``(name, sense)`` pairs of :data:`CRITERIA`."""
    entries = list(config["search.objectives"])
    out = []
    for entry in entries:
        name, _, sense = entry.partition(":")
        if name not in CRITERIA:
            raise ValueError(
                f"search.objectives = {json.dumps(entries)}: no objective {name!r}; the names are {', '.join(CRITERIA)}"
            )
        sense = sense or CRITERIA[name].sense
        if sense not in ("max", "min"):
            what = f"sense {sense!r}" if sense else "no default sense"
            raise ValueError(
                f"search.objectives = {json.dumps(entries)}: {name} has {what}: write {name}:max or {name}:min"
            )
        out.append((name, sense))
    if len({name for name, _ in out}) != len(out):
        raise ValueError(f"search.objectives = {json.dumps(entries)}: an objective appears twice")
    return out


def _criteria(specs: Iterable[CriterionLike]) -> Tuple[Criterion, ...]:
    if isinstance(specs, (str, Criterion)):
        specs = [specs]
    out = tuple(_criterion(s) for s in specs)
    if not out:
        raise ValueError("NSGA-II needs at least one objective")
    names = [c.name for c in out]
    if len(set(names)) != len(names):
        raise ValueError(f"objective names must be distinct, got {names}")
    for c in out:
        if not c.sense:
            raise ValueError(
                f"objective {c.name!r} has no default sense: pass ({c.name!r}, 'max') or ({c.name!r}, 'min')"
            )
    return out


# --- the pieces: dominance, fronts, crowding, hypervolume -----------------------------------------


def _points(points: Any) -> np.ndarray:
    p = np.asarray(points, dtype=np.float64)
    if p.ndim == 1:
        p = p.reshape(-1, 1) if p.size else p.reshape(0, 0)
    if p.ndim != 2:
        raise ValueError(f"points: one row of objective values per point, got an array of shape {p.shape}")
    return p


def _minimized(points: Any, senses: Optional[Sequence[str]]) -> np.ndarray:
    p = _points(points)
    if senses is None:
        return p
    if len(senses) != p.shape[1]:
        raise ValueError(f"{len(senses)} senses for {p.shape[1]} objectives")
    signs = np.array([-1.0 if _sense(s, f"#{j}") == "max" else 1.0 for j, s in enumerate(senses)])
    return p * signs


def dominates(a: Sequence[float], b: Sequence[float], senses: Optional[Sequence[str]] = None) -> bool:
    """Whether ``a`` Pareto-dominates ``b``: no worse in every objective and better in one. ``senses``:
    ``"max"`` or ``"min"`` per objective (default: all minimised)."""
    p = _minimized([list(a), list(b)], senses)
    return bool((p[0] <= p[1]).all() and (p[0] < p[1]).any())


def non_dominated_sort(points: Any, senses: Optional[Sequence[str]] = None) -> List[List[int]]:
    """The fronts of ``points`` (one row of objective values per point; ``senses``: ``"max"`` or
    ``"min"`` per objective, default all minimised), best first: front 0 holds the points no other
    dominates, front k those dominated only by points of fronts < k (Deb et al.'s fast non-dominated
    sort, the engine's). Each front lists row indices in increasing order. Equal points are in the
    same front. A row with a NaN is in no front (NSGA-II ranks such candidates last)."""
    p = _minimized(points, senses)
    rows = np.flatnonzero(~np.isnan(p).any(axis=1)) if p.size else np.arange(len(p))
    fronts = _core.non_dominated_sort(p[rows].tolist())
    return [[int(rows[i]) for i in front] for front in fronts]


def crowding_distance(points: Any) -> np.ndarray:
    """Deb et al.'s crowding distance of every point of one front (rows of objective values, not
    NaN), the engine's: for each objective, the points are ordered by their value (a stable sort:
    equal values in row order), the first and the last get infinity and every other one adds
    ``(next − previous) / (max − min)`` (nothing when max = min); the objectives are added in order.
    Fronts of one or two points are all infinity. The sense of an objective does not change it."""
    p = _points(points)
    if np.isnan(p).any():
        raise ValueError("crowding_distance: a front's points have no NaN (a row with one is in no front)")
    return np.asarray(_core.crowding_distance(p.tolist()), dtype=np.float64).reshape(len(p))


def hypervolume(points: Any, reference: Sequence[float], senses: Optional[Sequence[str]] = None) -> float:
    """The hypervolume of ``points`` against ``reference`` (the volume they dominate and the reference
    point bounds), for one or two objectives (``senses`` as for :func:`non_dominated_sort`), the
    engine's. Only the points better than the reference in every objective count (a point on its
    boundary adds nothing); no such point: 0. Two objectives: the sum of the staircase's rectangles,
    ordered by the first objective, summed exactly (as ``math.fsum``). ValueError for three or more
    objectives."""
    p = _minimized(points, senses)
    r = _minimized([list(reference)], senses)[0]
    m = len(r)
    if p.size and p.shape[1] != m:
        raise ValueError(f"hypervolume: {p.shape[1]} objectives and a reference point of {m}")
    if m not in (1, 2):
        raise ValueError(f"hypervolume: one or two objectives, got {m}")
    if not np.isfinite(r).all():
        raise ValueError(f"hypervolume: the reference point must be finite, got {list(reference)}")
    return float(_core.hypervolume(p.reshape(-1, m).tolist(), r.tolist()))


# --- NSGA-II --------------------------------------------------------------------------------------

Floats = Tuple[float, ...]


@dataclass(frozen=True)
class Solution:
    """A genome of the population, with its objective values.

    Attributes:
        genome: the :class:`animat.Genome`.
        objectives: the values the selection compares, one per criterion in order: the measured
            values, or under ``reference_check = "select"`` the reference values.
        measured: the criteria of its evaluation at the run's step (what was told).
        reference: the criteria at the exploit guard's reference step (NaN where that swim was not
            valid); None when it was not evaluated there.
        generation: the generation that made it.
        feasible: viable, stable, valid, every objective finite (see the module docstring).
        rank: its front when it was selected (0 = the first; infeasible or a copy: one past the last
            front).
        crowding: its crowding distance in that front (infinity at the ends; 0 when infeasible or a copy).
    """

    genome: Any
    objectives: Floats
    measured: Floats
    reference: Optional[Floats]
    generation: int
    feasible: bool
    rank: int = -1
    crowding: float = float("nan")


def history_dtype(names: Sequence[str]) -> np.dtype:
    """The columns of :attr:`Nsga2.history` and ``history.csv`` for objectives named ``names``:
    ``generation``, ``evaluations`` (candidates told so far; reference swims not counted),
    ``front_size``, ``hypervolume`` (NaN until the reference point is set, and for three or more
    objectives), ``best_<name>`` for every objective (the best value on the front, in its sense;
    NaN when the front is empty), ``feasible`` (in the population), ``discarded`` (infeasible
    candidates of this generation), ``copies`` (candidates of this generation whose genome was in the
    population or earlier in the batch), ``reference_evaluations`` (the exploit guard's swims so far),
    ``disagreements`` (front genomes whose reference disagrees). The engine's columns
    (``_core.search_history_columns``) but its ``wall_seconds``: a run's history is the same on any
    machine."""
    return _history_dtype(_core.search_history_columns("nsga2", list(names)))


def _floats(values: Iterable[Any]) -> Floats:
    return tuple(float(v) for v in values)


#: The largest NSGA-II population (the engine's bound): the selection compares every pair of the
#: 2 × population parents and candidates.
MAX_POPULATION = 10_000


class Nsga2(_SearchState):
    """NSGA-II driven by ``ask``/``tell`` (or :meth:`step`) over several objectives (see the module
    docstring for the objectives, what is feasible and the exploit guard): a thin layer over the
    engine's search (``animat._core.SearchEngine``, ``search.algorithm = "nsga2"``), which draws,
    sorts, selects, runs the exploit guard and checkpoints as ``animat_evolve`` does; the criteria
    are computed here, from each evaluation, and told to it.

    ``ask()`` returns the candidates of generation g = ``generation + 1``: for generation 0,
    ``population`` random viable genomes, genome i drawn by
    ``animat.Genome.random_viable(animat.Rng.derive(seed, 0, i), config)``; afterwards
    ``population`` offspring, offspring i varied with the stream ``rng = animat.Rng.derive(seed, g,
    i)``: a parent by binary tournament (two members ``population[rng.integer(0, n - 1)]``, the one
    of lower rank wins, then the one of larger crowding distance, then the first drawn); with
    probability ``crossover_fraction`` (``rng.uniform() < crossover_fraction``) a second parent by
    another tournament and ``parent.crossover(other, rng, mutation.crossover_points)``; then
    ``.mutate(rng, config)``. Asking again before ``tell`` returns the same genomes.

    ``tell(results)`` takes one result per asked genome, in order: an :class:`animat.EvaluationResult`
    (``animat.evaluate``; its criteria are computed here), the objective values themselves (a
    sequence of floats, one per objective; a NaN: not feasible) or None (not viable). It then selects
    the next population from the current one and the candidates, parents first (Deb's (mu + lambda)
    selection): whole fronts while they fit, then the rest of the front that does not fit by
    decreasing crowding distance (equal distances: parents first, then in ``ask()`` order), then, if
    fewer than ``population`` are feasible and distinct, copies and infeasible ones in that order. The new
    population keeps that order, and each member the rank and crowding distance it had in the
    selection (those of the fronts of parents and candidates together, as in Deb et al.). A tell is
    all or nothing: a refused value (an error naming it) changes nothing.

    Example::

        nsga = animat.Nsga2(config, [("distance", "max"), ("actuation_work_positive", "min")], population=16)
        while nsga.generation < 5:
            genomes = nsga.ask()
            nsga.tell([animat.evaluate(g, config) for g in genomes])     # or nsga.step()
        front = nsga.front()

    Args:
        config: the run's :class:`animat.Config` (default: the embedded paper setting). Its
            ``evaluation.objective`` must be a built-in (the ``fitness`` criterion).
        objectives: the criteria (see the module docstring).
        population: the population size N, also the offspring per generation (default
            ``evolution.population``; written into the config).
        seed: the run's seed (default ``evolution.seed``; written into the config).
        crossover_fraction: share of offspring made by crossover (default ``evolution.crossover_fraction``;
            written into the config).
        reference_point: the hypervolume's reference point, one value per objective, in the
            objectives' units (e.g. ``(0.0, 1e5)``: no distance, a work of 1e5). Default: the worst
            value of every objective over the feasible candidates of the first generation that has
            any (normally generation 0), fixed then and saved with the run.
        threads: evaluation threads of :meth:`step` and the exploit guard (default ``evolution.threads``;
            0 = all cores). The run does not depend on it.
    """

    def __init__(
        self,
        config: Any,
        objectives: Iterable[CriterionLike],
        *,
        population: Optional[int] = None,
        seed: Optional[int] = None,
        crossover_fraction: Optional[float] = None,
        reference_point: Optional[Sequence[float]] = None,
        threads: Optional[int] = None,
    ) -> None:
        self.criteria: Tuple[Criterion, ...] = _criteria(objectives)
        self._config = _core.Config() if config is None else config.copy()
        objective = str(self._config["evaluation.objective"])
        if objective.startswith("python:"):
            raise ValueError(
                f"Nsga2: evaluation.objective = {objective!r} is a Python objective; NSGA-II evaluates with "
                "animat.evaluate: make your function an objective, (function, 'max')"
            )
        for c in self.criteria:
            if c._of is not None and c.name in _SEVERAL_SWIMS and c.name != objective:
                raise ValueError(
                    f"Nsga2: objective {c.name!r} needs one swim per source direction: set "
                    f"evaluation.objective = {c.name!r} in the config"
                )
        if seed is not None:
            self._config["evolution.seed"] = int(seed)
        if threads is not None:
            self._config["evolution.threads"] = int(threads)
        size = int(self._config["evolution.population"]) if population is None else int(population)
        cf = float(self._config["evolution.crossover_fraction"]) if crossover_fraction is None else crossover_fraction
        if not 1 <= size <= MAX_POPULATION:
            raise ValueError(
                f"Nsga2: population (evolution.population) = {size}: it must be 1 to "
                f"{MAX_POPULATION} (the selection compares every pair of parents and candidates)"
            )
        if not 0.0 <= float(cf) <= 1.0:
            raise ValueError(f"Nsga2: crossover_fraction must be in [0, 1], got {cf}")
        point: Optional[Floats] = None
        if reference_point is not None:
            point = tuple(float(x) for x in reference_point)
            if len(point) != len(self.criteria) or not all(math.isfinite(x) for x in point):
                raise ValueError(
                    f"Nsga2: reference_point needs {len(self.criteria)} finite values (one per objective), "
                    f"got {list(reference_point)}"
                )
        # The run's config.toml says what it is (`animat evolve --resume` dispatches on it).
        self._config["evolution.population"] = size
        self._config["evolution.crossover_fraction"] = float(cf)
        self._config["search.algorithm"] = "nsga2"
        # the config's entries where they say the same (a sense left to the table's)
        given = [str(e).partition(":") for e in self._config["search.objectives"]]
        meant = [(n, s or (CRITERIA[n].sense if n in CRITERIA else "")) for n, _, s in given]
        if meant != [(c.name, c.sense) for c in self.criteria]:
            self._config["search.objectives"] = [f"{c.name}:{c.sense}" for c in self.criteria]
        self.seed = int(self._config["evolution.seed"])
        self.population_size = size
        self.crossover_fraction = float(cf)
        self._reference_point_given = point is not None
        self._swim = evaluate_results
        # Every criterion is computed here (from an EvaluationResult, or told as a value), so the
        # engine is told them all, at the run's step and, through the hook, at the reference step.
        guarded = str(self._config["evaluation.reference_check"]) != "off"
        self._engine = _core.SearchEngine(
            self._config, supplied=list(self.names), reference=_reference_hook(self) if guarded else None
        )
        if point is not None:
            self._engine.set_reference_point(list(point))
        self._asked: Optional[List[Any]] = None

    # --- names ------------------------------------------------------------------------------------
    @property
    def names(self) -> Tuple[str, ...]:
        """The objectives' names, in order."""
        return tuple(c.name for c in self.criteria)

    @property
    def senses(self) -> Tuple[str, ...]:
        """``"max"`` or ``"min"`` per objective."""
        return tuple(c.sense for c in self.criteria)

    @property
    def reference_point(self) -> Optional[Floats]:
        """The hypervolume's reference point (None until it is set; see the class docstring)."""
        point = self._engine.reference_point
        return _floats(point) if len(point) else None

    @property
    def history_dtype(self) -> np.dtype:
        """:func:`history_dtype` of this run's objectives."""
        return history_dtype(self.names)

    # --- the loop ---------------------------------------------------------------------------------
    def _measure(self, genome: Any, result: Any, config: Any) -> Tuple[Floats, bool]:
        m = len(self.criteria)
        if result is None:
            return (float("nan"),) * m, False
        if isinstance(result, _core.EvaluationResult):
            if not (result.viable and result.stable and result.valid):
                return (float("nan"),) * m, False
            values = tuple(c(result, genome, config) for c in self.criteria)
        elif isinstance(result, _core.Fitness):
            raise TypeError(
                "a Fitness holds one number: tell an animat.EvaluationResult (animat.evaluate) or the "
                f"{m} objective values"
            )
        elif isinstance(result, (str, bytes)) or not hasattr(result, "__len__"):
            raise TypeError(
                "a result is an animat.EvaluationResult, a sequence of objective values or None, got "
                f"{type(result).__name__}"
            )
        else:
            values = tuple(float(x) for x in np.asarray(result, dtype=np.float64).reshape(-1))
            if len(values) != m:
                raise ValueError(f"{len(values)} values for the {m} objectives {self.names}")
        return values, all(math.isfinite(x) for x in values)

    def _told(self, genomes: Sequence[Any], results: Sequence[Any], config: Any) -> Tuple[List[Any], List[List[float]]]:
        """What the engine is told of ``results``: a Fitness and the criteria's values for each."""
        fits, rows = [], []
        for i, (genome, r) in enumerate(zip(genomes, results)):
            try:
                values, ok = self._measure(genome, r, config)
            except (TypeError, ValueError) as e:
                raise type(e)(f"Nsga2.tell: value {i} ({r!r:.60}): {e}") from None
            if not ok:  # not viable, or not valid: the engine counts it discarded
                fits.append(_core.Fitness(0.0, r is not None, True, 0, False))
            elif isinstance(r, _core.EvaluationResult):
                fits.append(_core.fitness_of(r))
            else:  # its objective values, told directly
                fits.append(_core.Fitness(0.0, True, True, 0))
            rows.append(list(values))
        return fits, rows

    def tell(self, results: Sequence[Any]) -> Any:
        """The result of every genome of the last ``ask()``, in order (see the class docstring);
        completes the generation and returns its history row (a numpy record)."""
        if self._asked is None:
            raise RuntimeError("Nsga2.tell: nothing was asked (call ask() first)")
        genomes = self._asked
        if len(results) != len(genomes):
            raise ValueError(f"Nsga2.tell: {len(results)} results for the {len(genomes)} genomes asked")
        fits, rows = self._told(genomes, results, self._config)
        self._engine.tell(fits, rows)
        self._asked = None
        return self.history[-1]

    def _references(self, genomes: List[Any]) -> Tuple[List[Any], List[List[float]]]:
        """The exploit guard's swims (the engine's hook): every genome at the reference step."""
        ref = _core.reference_config(self._config)
        return self._told(genomes, self._evaluate(list(genomes), ref), ref)

    def _run_hooks(
        self,
    ) -> Tuple[Callable[[List[Any]], List[Any]], Callable[[List[Any], List[Any]], List[List[float]]]]:
        """The engine's evaluate and describe hooks of a run (:func:`run_nsga2`): one generation's
        swims as :meth:`step` swims them, and the criteria of the same swims."""
        rows: List[List[float]] = []

        def evaluate(genomes: List[Any]) -> List[Any]:
            fits, rows[:] = self._told(genomes, self._evaluate(list(genomes), self._config), self._config)
            return fits

        return evaluate, lambda genomes, fitness: rows

    @classmethod
    def _from_run(
        cls,
        path: Path,
        run: Any,
        config: Any = None,
        *,
        objectives: Iterable[CriterionLike] = (),
        threads: Optional[int] = None,
    ) -> Nsga2:
        """The search of a run directory's config ``run``, not yet restored (its hypervolume reference
        point comes with the checkpoint). ``config``: must be the run's but for the keys a run may
        change (ValueError naming the file)."""
        source = str(path / "config.toml")
        _holds(run, "nsga2", source)
        if config is not None:
            _same_run_config(config, run, source)
        pairs = []
        for entry in run["search.objectives"]:
            name, _, sense = str(entry).partition(":")
            pairs.append((name, sense or (CRITERIA[name].sense if name in CRITERIA else "")))
        try:
            criteria = _run_criteria(pairs, objectives)
        except ValueError as e:
            raise ValueError(f"{source}: {e}") from None
        if threads is None and config is not None:
            threads = int(config["evolution.threads"])
        return cls(run, criteria, threads=threads)

    def step(self, evaluate: Optional[Callable[[List[Any]], Sequence[Any]]] = None) -> Any:
        """Ask, evaluate (default: ``animat.evaluate`` on the config's threads: the GIL is released
        while each genome swims; over the MPI ranks under ``run_nsga2(..., mpi=True)``) and tell one
        generation; returns its history row."""
        genomes = self.ask()
        results = self._evaluate(genomes, self._config) if evaluate is None else evaluate(genomes)
        return self.tell(list(results))

    # --- state ------------------------------------------------------------------------------------
    def front(self) -> List[Solution]:
        """The first front of the current population: its feasible members no other member dominates,
        ordered by the first objective, best first (then the second ..., then population order)."""
        population = self.population
        return [population[i] for i in self._engine.front()]

    def front_values(self) -> np.ndarray:
        """:meth:`front`'s objectives as a (k, objectives) float64 array."""
        return np.array([s.objectives for s in self.front()], dtype=np.float64).reshape(-1, len(self.criteria))

    @property
    def population(self) -> List[Solution]:
        """The current population (a list of :class:`Solution`, in selection order)."""
        return [
            Solution(
                s["genome"],
                _floats(s["objectives"]),
                _floats(s["measured"]),
                _floats(s["reference"]) if len(s["reference"]) else None,
                int(s["generation"]),
                bool(s["feasible"]),
                int(s["rank"]),
                float(s["crowding"]),
            )
            for s in self._engine.population()
        ]

    @property
    def history(self) -> np.recarray:
        """One row per generation (:func:`history_dtype`): ``h["hypervolume"]``, ``h[-1].front_size`` ..."""
        dtype = self.history_dtype
        columns = len(dtype.names or ())
        rows = [
            tuple(int(x) if dtype[j].kind == "i" else float(x) for j, x in enumerate(row[:columns]))
            for row in self._engine.history
        ]
        return np.array(rows, dtype=dtype).view(np.recarray)

    def write_front(self, path: PathLike) -> Path:
        """:meth:`front` as CSV, one row per genome: ``generation`` (that made it), ``crowding``, the
        objectives by name (what the selection compares), ``measured_<name>`` and ``reference_<name>``
        (NaN when not evaluated) for each, ``genome`` (JSON). Written atomically."""
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        names = self.names
        w.writerow(
            ["generation", "crowding", *names, *[f"measured_{n}" for n in names], *[f"reference_{n}" for n in names]]
            + ["genome"]
        )
        nan = (float("nan"),) * len(names)
        for s in self.front():
            w.writerow(
                [s.generation, repr(s.crowding)]
                + [repr(x) for x in (*s.objectives, *s.measured, *(s.reference or nan))]
                + [s.genome.to_json()]
            )
        return _write_atomic(Path(path), buf.getvalue())

    def checkpoint(self) -> Dict[str, Any]:
        """The whole state as a JSON-able dict (``json.dumps`` it; :meth:`restore` reads it back): the
        engine's checksummed checkpoint (``engine``; None before the first ``tell``), the run's config
        and objectives, under a SHA-256 ``checksum`` of the rest. A pending ``ask()`` is not saved:
        asking again after a restore gives the same genomes."""
        point = self.reference_point if self._reference_point_given else None
        state: Dict[str, Any] = {
            "format": CHECKPOINT_FORMAT,
            "config": self._config.to_toml(),
            "objectives": [{"name": c.name, "sense": c.sense} for c in self.criteria],
            "reference_point": None if point is None else list(point),
            "engine": self._engine.checkpoint() if self.generation >= 0 else None,
        }
        state["checksum"] = _checksum(state)
        return state

    @classmethod
    def restore(
        cls,
        state: Union[Mapping[str, Any], str, bytes],
        config: Any = None,
        *,
        objectives: Iterable[CriterionLike] = (),
        threads: Optional[int] = None,
        source: str = "checkpoint",
    ) -> Nsga2:
        """An Nsga2 from :meth:`checkpoint` (a dict, or its JSON text). ``config``: default the saved
        one; another must equal it but for ``evolution.threads`` and what the run's own arguments set
        (seed, population, crossover fraction; ValueError). ``objectives``: found by name, first there
        (your own functions must be given again: a function is not saved), then in :data:`CRITERIA`,
        with the saved sense; given ones must be the run's, in order (ValueError). A checkpoint that
        is not one, was edited or is inconsistent is a ValueError naming ``source`` (the file, for
        :meth:`load`), and the engine checks its own part (checksum, identity, population, history)."""
        try:
            state = _checked_state(state, CHECKPOINT_FORMAT, "an Nsga2")
            saved = _core.Config.from_toml(state["config"], source)
            run = [(str(o["name"]), str(o["sense"])) for o in state["objectives"]]
            point = state["reference_point"]
            engine_text = state["engine"]
        except (ValueError, KeyError, TypeError, AttributeError) as e:
            raise ValueError(f"{source}: {e}") from None
        if config is not None:
            _same_run_config(config, saved, source)
        criteria = _run_criteria(run, objectives)
        if threads is None and config is not None:
            threads = int(config["evolution.threads"])
        nsga = cls(saved, criteria, reference_point=point, threads=threads)
        if engine_text is not None:
            nsga._engine.restore(engine_text, source)
        return nsga

    def _own_criteria(self) -> Tuple[Criterion, ...]:
        # Criteria that are not table entries (your functions): saved by pickle, not in the checkpoint.
        return tuple(
            c for c in self.criteria if CRITERIA.get(c.name) is None or c.function is not CRITERIA[c.name].function
        )

    def __reduce__(self) -> Tuple[Any, ...]:
        # Pickles as its checkpoint, with your own criteria.
        return (_restore, (self.checkpoint(), self._own_criteria()))

    def __repr__(self) -> str:
        objectives = ", ".join(f"{c.name} ({c.sense})" for c in self.criteria)
        return (
            f"<animat.Nsga2 generation {self.generation}, population {self.population_size}, {objectives}: "
            f"front of {len(self._engine.front())}>"
        )


def _same_run_config(config: Any, saved: Any, source: str) -> None:
    """Refuses a config that differs from the run's ``saved`` but for ``evolution.threads`` and
    what the run's own arguments set (seed, population, crossover fraction, length)."""
    mine = config.copy()
    for key in ("evolution.seed", "evolution.population", "evolution.crossover_fraction"):
        mine[key] = saved[key]
    if _comparable(mine) != _comparable(saved):
        raise ValueError(
            f"{source}: Nsga2.restore: the config differs from the checkpoint's (only evolution.threads may)"
        )


def _run_criteria(run: List[Tuple[str, str]], objectives: Iterable[CriterionLike]) -> List[Criterion]:
    """The run's criteria (``run``: its (name, sense) pairs): given ones, by name, else the table's."""
    given = list(objectives) if not isinstance(objectives, (str, Criterion)) else [objectives]
    mine = _criteria(given) if given else ()
    if mine and [(c.name, c.sense) for c in mine] != run:
        raise ValueError(
            f"Nsga2.restore: the objectives {[(c.name, c.sense) for c in mine]} are not the checkpoint's {run}"
        )
    by_name = {c.name: c for c in mine}
    criteria = []
    for name, sense in run:
        if name in by_name:
            criteria.append(by_name[name])
        elif name in CRITERIA:
            criteria.append(CRITERIA[name].with_sense(sense))
        else:
            raise ValueError(
                f"the run's objective {name!r} is not in the table: pass it again "
                "(objectives=[Criterion(...)] or (function, sense))"
            )
    return criteria


def _restore(state: Mapping[str, Any], criteria: Tuple[Criterion, ...]) -> Nsga2:
    return Nsga2.restore(state, objectives=_merge(state, criteria))


def _merge(state: Mapping[str, Any], own: Tuple[Criterion, ...]) -> List[Criterion]:
    by_name = {c.name: c for c in own}
    out = []
    for o in state["objectives"]:
        c = by_name.get(o["name"])
        out.append(c if c is not None else CRITERIA[o["name"]].with_sense(o["sense"]))
    return out


# --- the run directory ----------------------------------------------------------------------------


def run_nsga2(
    config: Any,
    objectives: Optional[Iterable[CriterionLike]],
    out: PathLike,
    generations: int,
    *,
    population: Optional[int] = None,
    seed: Optional[int] = None,
    crossover_fraction: Optional[float] = None,
    reference_point: Optional[Sequence[float]] = None,
    threads: Optional[int] = None,
    front_every: int = 1,
    resume: bool = False,
    overwrite: bool = False,
    callback: Optional[Callable[[Any], Optional[bool]]] = None,
    mpi: bool = False,
) -> Nsga2:
    """Run NSGA-II up to generation ``generations`` (generation 0 is the initial population, as
    ``evolution.generations`` counts) in the run directory ``out``:

    The run goes through the engine's run layer (``SearchEngine.run``), the format ``animat_evolve``
    writes and resumes (docs/search.md); the engine's stall and wall-clock rules may stop it before.

    - ``config.toml``: the run's config (its ``evolution.seed`` is the run's seed; ``search.objectives``
      the criteria with their senses; ``evolution.generations`` the cap);
    - ``history.csv``: :func:`history_dtype`'s columns (``generation, evaluations, front_size,
      hypervolume, best_<name>..., feasible, discarded, reference_evaluations, disagreements``) and
      ``wall_seconds``, one row per generation;
    - ``front/gen_NNNNNN.csv``: the front after every ``front_every``-th generation and the last
      (:meth:`Nsga2.write_front`: one row per genome);
    - ``checkpoint.json``: the engine's checkpoint (with the hypervolume's reference point), every
      ``evolution.checkpoint_every`` generations and at the end; ``resume=True`` continues from it
      and gives the very run an uninterrupted one gives (``objectives`` may then be None; your own
      functions must be passed again, and given objectives must be the run's).

    A new run with ``objectives`` None optimises the config's ``search.objectives``
    (:func:`objectives_from_config`): a config with ``search.algorithm = "nsga2"`` defines the whole run,
    as ``animat evolve --config FILE`` runs it. The run's ``config.toml`` records the search it is.

    ``callback(row)`` is called after every generation; returning False stops (checkpointed). Returns
    the :class:`Nsga2`. A directory that holds a run is refused (FileExistsError) unless ``resume``
    or ``overwrite`` (which removes the files above and ``front/``, nothing else). On a resume, a
    ``population``, ``seed``, ``crossover_fraction`` or ``reference_point`` that is given must be the
    run's (ValueError), as the config must (but for ``evolution.threads``).

    ``mpi=True``: the swims run on the ranks of an MPI job, as for :func:`animat.run_map_elites`
    (start every rank with the same call; rank 0 runs the search and writes ``out``; bit-identical
    to the run without MPI for any number of ranks; every rank returns the final :class:`Nsga2`).
    """
    given = () if objectives is None else objectives

    def load(path: Path) -> Nsga2:
        nsga = Nsga2._from_run(path, _run_config(path, generations), config, objectives=given, threads=threads)
        # the run's reference point is its checkpoint's (checked when the engine restores it)
        point = _engine_checkpoint(path).get("reference_point")
        _same_as_run(
            "run_nsga2",
            population=(population, nsga.population_size),
            seed=(seed, nsga.seed),
            crossover_fraction=(crossover_fraction, nsga.crossover_fraction),
            reference_point=(
                None if reference_point is None else tuple(float(x) for x in reference_point),
                None if not isinstance(point, list) else tuple(float(x) for x in point),
            ),
        )
        return nsga

    def check_new() -> None:
        if objectives is None:
            objectives_from_config(config)  # the names and senses, before any file is written

    def new() -> Nsga2:
        run = _core.Config() if config is None else config.copy()
        if generations > 0:  # 0: no cap in the config; the run stops after generation 0
            run["evolution.generations"] = generations
        return Nsga2(
            run,
            objectives if objectives is not None else objectives_from_config(config),
            population=population,
            seed=seed,
            crossover_fraction=crossover_fraction,
            reference_point=reference_point,
            threads=threads,
        )

    def run(pool: Optional[Swim]) -> Nsga2:
        return _run_search(
            "run_nsga2",
            out,
            "front",
            front_every,
            generations,
            resume=resume,
            overwrite=overwrite,
            load=load,
            new=new,
            check_new=check_new,
            write_snapshot=lambda nsga, path: nsga.write_front(path),
            callback=callback,
            pool=pool,
        )

    def restore(state: Any) -> Nsga2:
        return Nsga2.restore(state, objectives=given, threads=threads)

    return cast(Nsga2, _on_ranks("run_nsga2", mpi, evaluate_results, restore, run))
