"""Evolution from Python: :func:`evolve` (the engine of ``animat_evolve``), :class:`GA` (the same
engine driven by ``ask``/``tell``, for genomes evaluated anywhere), :class:`Objective` (your own
fitness) and :class:`History` (the one history type: a structured array, ``.to_pandas()``).

Every random number of generation g, individual i derives from (seed, g, i): a run is bit-identical
for any thread count, across kill/resume, and between ``evolve`` and a ``GA`` loop.
"""

from __future__ import annotations

import math
import os
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterable, List, Optional, Sequence, Union

import numpy as np

from . import _core
from .run import history_dtype

__all__ = [
    "History",
    "EvolutionResult",
    "Objective",
    "GA",
    "evolve",
    "evaluate",
    "evaluate_population",
    "record_evaluation",
    "to_fitness",
]

PathLike = Union[str, "os.PathLike[str]"]


class History(np.recarray):
    """Per-generation statistics: a numpy structured (record) array, one row per generation, with the
    columns of ``history.csv``: ``generation``, ``best``, ``mean``, ``median``, ``viable_fraction``,
    ``best_cells``, ``evaluations``, ``best_reference`` (the best at the exploit guard's finer step; NaN
    when not checked), ``invalid`` (swims that broke the body's embedding), ``protected`` (only in runs with
    ``evolution.protection_generations`` > 0: viable individuals of a protected new morphology),
    ``wall_seconds``. ``h["best"]`` is a column, ``h[-1]`` a row
    (``h[-1]["best"]``, or ``h[-1].best``; use ``["mean"]`` for the mean column: ``.mean`` is numpy's
    method). :attr:`Run.history`, :attr:`EvolutionResult.history` and :attr:`GA.history` are all of
    this type.
    """

    def __bool__(self) -> bool:
        """True when it has a row (``if run.history:``), as for a list; numpy's elementwise truth of a
        structured array has no meaning here."""
        return len(self) > 0

    def to_pandas(self) -> Any:
        """The history as a ``pandas.DataFrame`` (ImportError naming the package when pandas is missing)."""
        try:
            import pandas as pd  # type: ignore[import-not-found]
        except ImportError:
            raise ImportError("History.to_pandas needs pandas: pip install pandas") from None
        return pd.DataFrame.from_records(np.asarray(self).view(np.ndarray), columns=list(self.dtype.names or ()))

    @staticmethod
    def from_rows(rows: Iterable[Any], protected: bool = False) -> History:
        """A History from GenerationStats objects (or anything with those attributes); ``protected``:
        with the ``protected`` column of a run with ``evolution.protection_generations`` > 0."""
        dtype = history_dtype(protected)
        records = [tuple(getattr(r, name) for name in dtype.names or ()) for r in rows]
        return np.array(records, dtype=dtype).view(History)  # type: ignore[return-value]


def _protects(config: Any) -> bool:
    """Whether a config has morphological innovation protection (its history has ``protected``)."""
    return int(config["evolution.protection_generations"]) > 0


@dataclass
class EvolutionResult:
    """What :func:`evolve` returns.

    Attributes:
        history: :class:`History`, generation 0 first.
        best: the best :class:`animat.Individual` of the last generation (``.genome``, ``.fitness``).
        population: the final population (list of :class:`animat.Individual`).
        stop_reason: why the run stopped.
        config: the :class:`animat.Config` of the run.
        out: the run directory, or None.
    """

    history: History
    best: Any
    population: List[Any]
    stop_reason: str
    config: Any
    out: Optional[Path] = None

    @property
    def best_genome(self) -> Any:
        """The best :class:`animat.Genome` of the last generation."""
        return self.best.genome

    @property
    def best_fitness(self) -> Any:
        """Its :class:`animat.Fitness`."""
        return self.best.fitness

    def __repr__(self) -> str:
        return (
            f"<animat.EvolutionResult {len(self.history)} generations, best {self.best.fitness.fitness:.6g}, "
            f"stopped: {self.stop_reason}>"
        )


@dataclass
class Objective:
    """Your own objective: a function of an :class:`animat.EvaluationRecord` (the EvaluationResult's
    fields, the body, the trajectory every ``every`` control steps) returning a float; larger is better.

    It is called for viable genomes only (a non-viable genome scores 0 and is never selected before a
    viable one), under the GIL, while the simulations run in parallel without it. Keep it pure (a
    function of the record alone) and the run stays bit-identical for any thread count. ``name``
    is recorded in the run's config as ``evaluation.objective = "python:NAME"``; a resume must pass
    the same objective again.

    Example::

        def rightward(record):            # centre-of-mass displacement along +x
            return float(record.com[-1, 0] - record.com[0, 0])
        animat.evolve(config, objective=animat.Objective(rightward, every=50))
    """

    function: Callable[[Any], float]
    every: int = 20
    name: str = ""

    def __post_init__(self) -> None:
        if not callable(self.function):
            raise TypeError(f"Objective: function must be callable, got {type(self.function).__name__}")
        if self.every < 0:
            raise ValueError(f"Objective: every must be >= 0, got {self.every}")
        if not self.name:
            self.name = getattr(self.function, "__qualname__", None) or type(self.function).__name__
        if not self.name.startswith("python:"):
            self.name = "python:" + self.name

    def __call__(self, record: Any) -> float:
        return self.function(record)


ObjectiveLike = Union[None, str, Objective, Callable[[Any], float]]


def _objective(objective: ObjectiveLike) -> Union[None, str, Objective]:
    if objective is None or isinstance(objective, (str, Objective)):
        return objective
    if callable(objective):
        return Objective(objective)
    raise TypeError(f"objective must be a name, a callable or an animat.Objective, got {type(objective).__name__}")


def _config_for(config: Any, objective: Union[None, str, Objective]) -> Any:
    cfg = _core.Config() if config is None else config.copy()
    if isinstance(objective, str):
        cfg["evaluation.objective"] = objective
    elif isinstance(objective, Objective):
        cfg["evaluation.objective"] = objective.name
    return cfg


def _core_objective(cfg: Any, objective: Union[None, str, Objective]) -> Any:
    if isinstance(objective, Objective):
        return objective
    name = str(cfg["evaluation.objective"])
    if name.startswith("python:"):
        raise ValueError(
            f"evaluation.objective = {name!r} is a Python objective: pass objective=animat.Objective(...) "
            "with that name"
        )
    return None


def evaluate(genome: Any, config: Any = None, objective: ObjectiveLike = None) -> Any:
    """genome -> development -> body -> swim, scored by the objective.

    Returns an :class:`animat.EvaluationResult`: ``fitness`` is the objective's value (default:
    ``config.evaluation.objective``, the paper's straight-line distance of the centre of mass), plus
    ``viable``, ``stable``, ``cell_count``, ``displacement`` and every diagnostic. Deterministic.
    Non-viable genomes are not swum; unstable swims give fitness 0 and ``stable=False``.
    Picklable, so ``multiprocessing.Pool().map(animat.evaluate, genomes)`` works.
    """
    return _core.evaluate(genome, config, _objective(objective))


def evaluate_population(
    genomes: Sequence[Any], config: Any = None, threads: int = 0, objective: ObjectiveLike = None
) -> List[Any]:
    """Evaluate genomes in parallel (OpenMP threads, the GIL released) and return one
    :class:`animat.Fitness` per genome, in order, identical for any thread count (0 = all cores)."""
    return _core.evaluate_population(list(genomes), config, threads, _objective(objective))


def record_evaluation(genome: Any, config: Any = None, every: int = 20) -> Any:
    """Evaluate a genome and return the :class:`animat.EvaluationRecord` an objective sees: the
    EvaluationResult's fields, the body and the trajectory every ``every`` control steps (0 = none)."""
    return _core.record_evaluation(genome, config, every)


def to_fitness(value: Any) -> Any:
    """A :class:`animat.Fitness` from what an evaluator returns: a Fitness; an EvaluationResult
    (every Fitness field copied from it, as animat_evolve's evaluations give them:
    ``_core.fitness_of``); ``None`` (not viable); or a
    number (a viable genome's fitness; it must be finite; its morphology kind is unknown, 0, so that
    ``evolution.protection_generations`` protects nothing)."""
    if isinstance(value, _core.Fitness):
        return value
    if isinstance(value, _core.EvaluationResult):
        return _core.fitness_of(value)
    if value is None:
        return _core.Fitness(0.0, False, True, 0)
    if isinstance(value, (bool, np.bool_)):
        raise TypeError("a fitness must be a number, None, an animat.Fitness or an animat.EvaluationResult, got a bool")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise TypeError(
            "a fitness must be a number, None, an animat.Fitness or an animat.EvaluationResult, got "
            f"{type(value).__name__}"
        ) from None
    if not math.isfinite(number):
        raise ValueError(f"a fitness must be finite, got {number} (tell None for a non-viable genome)")
    return _core.Fitness(number, True, True, 0)


class GA:
    """The paper's genetic algorithm driven from outside: ``ask()`` for genomes, evaluate them
    anywhere (a process pool, a cluster, your own simulator), ``tell()`` their fitness.

    It is the engine of :func:`evolve`: a GA loop evaluating with ``animat.evaluate`` gives the very
    run ``evolve`` gives (same populations, same history; under ``development.jitter_stream =
    "fixed"`` ``evolve`` also reuses the fitness of an equal network, so its ``evaluations`` and
    ``swims`` columns are smaller). Before generation 0 it asks for random
    genomes, one per initial slot still lacking a viable individual, until every slot has one; then
    each ``ask()`` returns the offspring of the next generation that need a fitness (elites and
    unchanged copies keep theirs; the list may be empty: tell ``[]``).

    The exploit guard (``evaluation.reference_check``, "record" by default, or "select") is the
    engine's, as in :func:`evolve`: when a generation brings a new best, ``tell()`` re-evaluates it
    itself, in this process, with animat's swim at the reference step (``physics.substeps`` x
    ``evaluation.reference_substeps``) and the GA's objective, and "select" ranks the elite candidates
    by their reference fitness in ``ask()``. So the loop below gives ``evolve``'s run, ``best_reference``
    included. When your fitness is not animat's swim (your own simulator), set
    ``evaluation.reference_check = "off"``: a reference of animat's swim would mean nothing there.

    Example::

        ga = animat.GA(config)
        while not ga.done:
            genomes = ga.ask()
            ga.tell([animat.evaluate(g, config) for g in genomes])
        print(ga.best.fitness, ga.history["best"])

    Args:
        config: the run's :class:`animat.Config` (default: the embedded paper setting).
        objective: as for :func:`evolve`: a built-in name, a callable or an :class:`Objective` (sets
            ``evaluation.objective``); what :meth:`step` and the exploit guard score with. A config
            whose ``evaluation.objective`` is ``"python:NAME"`` needs it unless ``reference_check`` is
            ``"off"`` (ValueError otherwise).
    """

    def __init__(self, config: Any = None, objective: ObjectiveLike = None) -> None:
        obj = _objective(objective)
        self._config = _config_for(config, obj)
        self._objective = obj if isinstance(obj, Objective) else None
        name = str(self._config["evaluation.objective"])
        guard = str(self._config["evaluation.reference_check"])
        if name.startswith("python:") and self._objective is None and guard != "off":
            raise ValueError(
                f"GA: evaluation.objective = {name!r} is a Python objective and the exploit guard "
                f"(evaluation.reference_check = {guard!r}) re-evaluates each new best with it: pass "
                "objective=animat.Objective(...) with that name, or set evaluation.reference_check = 'off'"
            )
        self._engine = _core.Evolution(self._config, self._objective)

    # --- the loop ---------------------------------------------------------------------------------
    def ask(self, lookahead: int = 1) -> List[Any]:
        """The genomes that need a fitness next (a list of :class:`animat.Genome`). Before generation 0,
        ``lookahead`` > 1 asks that many consecutive random draws per open slot at once (those after a
        slot's first viable draw are discarded; the run does not depend on it). Asking again before
        ``tell`` returns the same genomes."""
        return self._engine.ask(lookahead)

    def tell(self, fitnesses: Sequence[Any]) -> Optional[Any]:
        """The fitness of every genome of the last ``ask()``, in order: numbers, None (not viable),
        :class:`animat.Fitness` or :class:`animat.EvaluationResult` (see :func:`to_fitness`).
        Returns the :class:`animat.GenerationStats` of the generation this completed, or None while
        the initial population is still being drawn.

        Raises:
            ValueError: naming the value's index, for what the engine's own evaluations refuse: a
                fitness that is not finite, a negative one under ``evaluation.objective`` = distance
                or distance_per_size, a negative ``cell_count``. Nothing is taken: tell again.
            KeyboardInterrupt: Ctrl-C in the objective during the exploit guard's reference evaluation
                (the GA is as before the call)."""
        values = []
        for i, v in enumerate(fitnesses):
            try:
                values.append(to_fitness(v))
            except (TypeError, ValueError) as e:
                raise type(e)(f"GA.tell: value {i} ({v!r:.60}): {e}") from None
        # The engine checks every value as it checks its own evaluations (finite; >= 0 under a distance
        # objective; cell_count >= 0): what tell() accepts, a checkpoint holds and GA.load reads back.
        if self._engine.tell(values):
            return self._engine.history[-1]
        return None

    def step(
        self, evaluate: Optional[Callable[[List[Any]], Sequence[Any]]] = None, threads: Optional[int] = None
    ) -> Any:
        """Ask, evaluate and tell until the next generation is complete; returns its GenerationStats.

        ``evaluate`` maps a list of genomes to their fitness values (default: :func:`evaluate_population`
        with this GA's config and ``threads``, i.e. exactly what :func:`evolve` does)."""
        cfg = self._config
        n = int(cfg["evolution.threads"]) if threads is None else threads

        def in_parallel(genomes: List[Any]) -> Sequence[Any]:
            return evaluate_population(genomes, cfg, n, objective=self._objective)

        fitness_of = in_parallel if evaluate is None else evaluate
        target = self.generation + 1
        while self.generation < target:
            genomes = self.ask(4 if self.generation < 0 else 1)
            self.tell(list(fitness_of(genomes)))
        return self._engine.history[-1]

    # --- state ------------------------------------------------------------------------------------
    @property
    def config(self) -> Any:
        """The GA's :class:`animat.Config` (a copy)."""
        return self._config.copy()

    @property
    def generation(self) -> int:
        """The last completed generation (-1 while the initial population is being drawn)."""
        return self._engine.generation

    @property
    def population(self) -> List[Any]:
        """The population: a list of :class:`animat.Individual` (``.genome``, ``.fitness``, ``.tries``)."""
        return self._engine.population if self.generation >= 0 else []

    @property
    def best(self) -> Any:
        """The best :class:`animat.Individual`: the first of the fittest (under ``evaluation.reference_check =
        "select"``, of the best reference fitness); ValueError before generation 0."""
        return self._engine.best

    @property
    def history(self) -> History:
        """Statistics of every completed generation (:class:`History`)."""
        return History.from_rows(self._engine.history, _protects(self._config))

    @property
    def evaluations(self) -> int:
        """Fitness evaluations counted so far (the initial draws up to each slot's first viable one)."""
        return self._engine.evaluations

    @property
    def stop_reason(self) -> str:
        """Why the run would stop now: the config's generation cap, stall or wall-clock budget ('' = go on)."""
        return self._engine.stop_reason()

    @property
    def done(self) -> bool:
        """True once :attr:`stop_reason` is set."""
        return bool(self.stop_reason)

    # --- checkpoints ------------------------------------------------------------------------------
    def checkpoint(self) -> str:
        """The whole state as checkpoint JSON text (the format of a run directory's checkpoint.json);
        ValueError before generation 0 is complete. A pending ask() is not saved: ask again after
        restoring and you get the same genomes."""
        return self._engine.checkpoint()

    def save(self, path: PathLike) -> Path:
        """Write :meth:`checkpoint` to ``path`` atomically (a temporary file, then a rename)."""
        path = Path(path)
        tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")  # one per process
        tmp.write_text(self.checkpoint(), encoding="utf-8")
        os.replace(tmp, path)
        return path

    @classmethod
    def from_checkpoint(cls, text: str, config: Any, source: str = "checkpoint", objective: ObjectiveLike = None) -> GA:
        """A GA restored from checkpoint text; ``config`` must be the run's (only its stopping and
        resource knobs may differ), else ValueError. ``objective``: as for :class:`GA`."""
        ga = cls(config, objective)
        ga._engine.restore(text, source)
        return ga

    @classmethod
    def load(cls, path: PathLike, config: Any = None, objective: ObjectiveLike = None) -> GA:
        """A GA restored from a checkpoint file: one written by :meth:`save`, or a run directory's
        ``checkpoint.json`` (or the run directory itself: its config.toml is then the default config)."""
        path = Path(path)
        if path.is_dir():
            if config is None and (path / "config.toml").is_file():
                config = _core.load_config(str(path / "config.toml"))
            path = path / "checkpoint.json"
        if config is None:
            raise ValueError(f"GA.load({str(path)!r}): pass the run's config (a checkpoint holds only its identity)")
        return cls.from_checkpoint(path.read_text(encoding="utf-8"), config, str(path), objective)

    def __getstate__(self) -> dict:
        state = {"config": self._config, "checkpoint": self.checkpoint()}
        if self._objective is not None:
            state["objective"] = self._objective  # pickled with it (a module-level function pickles)
        return state

    def __setstate__(self, state: dict) -> None:
        self._config = state["config"]
        self._objective = state.get("objective")
        self._engine = _core.Evolution(self._config, self._objective)
        self._engine.restore(state["checkpoint"], "pickle")

    def __repr__(self) -> str:
        return f"<animat.GA generation {self.generation}, population {int(self._config['evolution.population'])}>"


# --- evolve ---------------------------------------------------------------------------------------------


def _progress_bar(total: Optional[int], enabled: bool) -> Any:
    if not enabled:
        return None
    from tqdm.auto import tqdm

    return tqdm(total=total, desc="evolve", unit="gen", dynamic_ncols=True)


def evolve(
    config: Any = None,
    out: Optional[PathLike] = None,
    *,
    generations: Optional[int] = None,
    wall_seconds: Optional[float] = None,
    seed: Optional[int] = None,
    threads: Optional[int] = None,
    objective: ObjectiveLike = None,
    resume: bool = False,
    overwrite: bool = False,
    callback: Optional[Callable[[Any], Optional[bool]]] = None,
    quiet: bool = False,
    progress: Optional[bool] = None,
    stop: Any = None,
) -> EvolutionResult:
    """Run the paper's genetic algorithm: the engine, checkpoints and run directory of ``animat_evolve``.

    Args:
        config: an :class:`animat.Config` (default: the embedded paper setting). With ``resume=True``
            and no config, the run directory's own ``config.toml`` is used.
        out: run directory (``config.toml``, ``history.csv``, ``best/``, ``checkpoint.json``); None
            writes nothing.
        generations, wall_seconds, seed, threads: set ``evolution.generations`` (the cap),
            ``evolution.wall_seconds`` (a budget), ``evolution.seed`` and ``evolution.threads``.
            Without a cap or a budget the run stops only after ``evolution.stall_generations``
            (500) generations without improvement: hours (a warning says so).
        objective: a built-in name (``"distance"``, ``"distance_per_size"``, ``"speed_toward"``), a
            callable of an :class:`animat.EvaluationRecord`, or an :class:`Objective`; None = the
            config's ``evaluation.objective``.
        resume: continue the run in ``out`` (its checkpoint).
        overwrite: start afresh in ``out``, removing the run there (config.toml, history.csv,
            checkpoint.json, islands.csv, resume.log, stopped.txt, best/, figures/; nothing else), once
            the directory's lock is held.
        callback: called with the :class:`animat.GenerationStats` of every generation (generation 0
            of a new run included); return False to stop (checkpointed).
        quiet: no progress bar and no log lines.
        progress: show a tqdm progress bar (default: unless ``quiet``).
        stop: an object with ``is_set()`` (e.g. a :class:`threading.Event`), polled between
            evaluations: once set, the run checkpoints its last complete generation and returns
            (``stop_reason == "interrupted"``).

    Returns:
        :class:`EvolutionResult` (history, best, population, stop_reason).

    Raises:
        FileExistsError: ``out`` holds a run (a checkpoint, or the files of a run without one) and
            neither ``resume`` nor ``overwrite`` is set; nothing is written.
        BlockingIOError: another process (or another ``evolve`` call) is writing ``out``: one writer
            per run directory, held by the lock file ``out/.lock``; the message names its pid.
        ValueError: an invalid config, or a resume with a different one.
        KeyboardInterrupt: Ctrl-C; the last complete generation is checkpointed in ``out``
            (``resume=True`` continues) and the partial :class:`EvolutionResult` is its ``.result``.
        TypeError: the callback returned something other than True, False or None.
    """
    if resume and overwrite:
        raise ValueError("evolve: resume=True and overwrite=True contradict each other")
    out_path = Path(out) if out is not None else None
    if resume:
        if out_path is None:
            raise ValueError("evolve: resume=True needs the run directory out=")
        if not out_path.is_dir():
            raise FileNotFoundError(f"{out_path}: resume directory does not exist")
        if config is None:
            if not (out_path / "config.toml").is_file():
                raise FileNotFoundError(f"{out_path / 'config.toml'}: missing; {out_path} is not a run directory")
            config = _core.load_config(str(out_path / "config.toml"))
    obj = _objective(objective)
    cfg = _config_for(config, obj)
    if generations is not None:
        cfg["evolution.generations"] = int(generations)
    if wall_seconds is not None:
        cfg["evolution.wall_seconds"] = float(wall_seconds)
    if seed is not None:
        cfg["evolution.seed"] = int(seed)
    if threads is not None:
        cfg["evolution.threads"] = int(threads)
    core_objective = _core_objective(cfg, obj)
    if int(cfg["evolution.generations"]) == 0 and float(cfg["evolution.wall_seconds"]) == 0:
        warnings.warn(
            "evolve: no generation cap (generations=) and no wall-clock budget (wall_seconds=): the run stops "
            f"only after {int(cfg['evolution.stall_generations'])} generations without improvement (hours)",
            UserWarning,
            stacklevel=2,
        )
    # The engine refuses a directory that holds a run (FileExistsError) or that another process is
    # writing (BlockingIOError), and clears it for overwrite=True only once it holds the directory's lock.

    show = (not quiet) if progress is None else bool(progress)
    cap = int(cfg["evolution.generations"])
    bar = _progress_bar(cap + 1 if cap > 0 else None, show)
    state = {"last": None}

    def on_generation(stats: Any) -> bool:
        if bar is not None:
            bar.n = stats.generation + 1  # generations 0..g done (a resumed run continues the count)
            bar.set_postfix(
                best=f"{stats.best:.4g}",
                viable=f"{100 * stats.viable_fraction:.0f}%",
                swims_per_s=f"{stats.swims_per_second:.1f}",
                refresh=False,
            )
            bar.refresh()
        state["last"] = stats
        if callback is not None:
            answer = callback(stats)
            if answer is None:
                return True
            if not isinstance(answer, (bool, np.bool_)):
                raise TypeError(
                    f"evolve: the callback must return True, False or None (None = go on), "
                    f"got {type(answer).__name__} {answer!r:.60}"
                )
            return bool(answer)
        return True

    def result_of(summary: Any) -> EvolutionResult:
        return EvolutionResult(
            history=History.from_rows(summary.history, _protects(cfg)),
            best=summary.best,
            population=list(summary.population),
            stop_reason=summary.stop_reason,
            config=cfg,
            out=out_path,
        )

    try:
        summary = _core.evolve(
            cfg,
            None if out_path is None else str(out_path),
            resume,
            on_generation,
            quiet or bar is not None,
            stop=stop,
            objective=core_objective,
            overwrite=overwrite,
        )
    except KeyboardInterrupt as e:
        partial = getattr(e, "result", None)
        if partial is not None:
            setattr(e, "result", result_of(partial))  # noqa: B010 - an attribute KeyboardInterrupt does not declare
        raise
    finally:
        if bar is not None:
            bar.close()
    return result_of(summary)
