"""Quality diversity: MAP-Elites over descriptors of body and motion.

The paper ends (§7) by suggesting niching: protect novel morphologies until evolution has had the time
to adjust their control. MAP-Elites (Mouret & Clune 2015) does this by construction: an **archive**
keeps one elite per cell of a space of **descriptors** (how many cells, how elongated, how many
protrusions, the oscillators' frequency, the locomotion mode ...), and a candidate competes only with
the elite of its own cell. Every generation, elites chosen uniformly at random are varied by the
genome's own operators (the GA's crossover with probability ``crossover_fraction``, then its mutation)
and evaluated by the same evaluators as the GA (:func:`animat.evaluate_population`).

- :data:`DESCRIPTORS`: the table of named descriptors; :class:`Descriptor` also wraps your own
  ``f(genome, config, evaluation) -> float``. :func:`measure` computes them for one genome.
- :class:`GridArchive` (a regular grid) and :class:`CVTArchive` (a centroidal Voronoi tessellation).
- :class:`MapElites`: ask/tell, ``step()``, ``history``, ``checkpoint()`` / :meth:`MapElites.restore`.
- :func:`run_map_elites`: a run directory (``config.toml``, ``history.csv``, ``archive/gen_*.csv``,
  ``checkpoint.json``, locked by ``.lock`` while it runs) that resumes.

**The engine.** :class:`MapElites` is a thin layer over the engine's search
(``animat._core.SearchEngine``, ``search.algorithm = "map_elites"``): the engine breeds, archives,
runs the exploit guard and keeps the history and the checksummed checkpoint; this module holds the
descriptor table, the archive views and the descriptors the engine does not measure.

**Determinism.** Every random number of generation g, offspring i is drawn from
``animat.Rng.derive(seed, g, i)`` and the parents are picked from the elites in cell order, so a run is
a function of (config, archive definition, seed, batch, crossover_fraction) alone: identical for any
thread count, and across checkpoint and resume (the checkpoint also records wall-clock seconds).

**What is archived.** A candidate enters the archive only when its genome is viable, its swim stable
and valid (no simulator exploit: the engine scores those 0) and every descriptor is a number (not
NaN). It enters its cell when the cell is empty or when its **objective** is strictly greater than the
elite's (a tie keeps the elite); candidates are added in the order of ``ask()``.

**The exploit guard** (``evaluation.reference_check``, as for the GA): ``"off"``: nothing more.
``"record"`` (the default): every genome that is an elite at the end of a ``tell()`` and entered
during it is evaluated again at the reference step (``physics.substeps ×
evaluation.reference_substeps``, :func:`animat.reference_config`) with the run's objective; its
``reference`` fitness is stored with the elite and ``history["disagreements"]`` counts the elites
whose fitness and reference disagree (:func:`animat.reference_disagrees`). ``"select"``: every
archivable candidate is evaluated at the reference step *before* it is added, and the archive
compares, scores and reports the **reference** fitness (the elite's ``objective``), so a candidate
that exploits the coarse step never displaces an honest one. Under ``"record"`` and ``"off"`` the
objective is the fitness. The reference costs about ``reference_substeps`` ordinary evaluations
each: per new elite under ``"record"``, per archivable candidate under ``"select"``.

Example::

    archive = animat.GridArchive(["elongation", "protrusions"], bins=(8, 8))
    me = animat.MapElites(config, archive, batch=32, seed=1)
    for _ in range(10):
        me.step()                                   # ask, evaluate_population, tell
    print(me.history["coverage"], archive.qd_score())
    frame = archive.to_pandas()                     # index, objective, measures_0.., solution (pyribs)
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import math
import os
import weakref
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path
from typing import Any, Callable, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union, cast

import numpy as np

from . import _core
from .evolution import Objective, ObjectiveLike, _config_for, _objective, evaluate_population, to_fitness
from .pool import MpiPool, Swim, serve

__all__ = [
    "Descriptor",
    "DESCRIPTORS",
    "descriptor_table",
    "measure",
    "Elite",
    "GridArchive",
    "CVTArchive",
    "MapElites",
    "QD_HISTORY_DTYPE",
    "run_map_elites",
]

PathLike = Union[str, "os.PathLike[str]"]

#: Version tag of :meth:`MapElites.checkpoint`.
CHECKPOINT_FORMAT = "animat.map_elites/3"

# --- descriptors ----------------------------------------------------------------------------------


class _Subject:
    """One genome under a config, with the expensive intermediate results shared by the descriptors
    (development once, the body and its shape once, the locomotion replay once). ``body``: the body
    the evaluation itself developed and swam (``_core._evaluate_population_bodies``), the one
    ``build_body(develop(genome, config))`` gives; with it nothing is developed again."""

    def __init__(self, genome: Any, config: Any, evaluation: Any, body: Any = None) -> None:
        self.genome = genome
        self.config = config
        self.evaluation = evaluation
        self._body = body

    @cached_property
    def embryo(self) -> Any:
        return _core.develop(self.genome, self.config)

    @cached_property
    def body(self) -> Any:
        if self._body is not None:
            return self._body
        from . import pipeline

        return pipeline.build_body(self.embryo, config=self.config)

    @property
    def cells(self) -> int:
        # the body has a node per cell centre of the embryo, with its oscillator
        return len((self.embryo if self._body is None else self._body).positions)

    @property
    def frequency(self) -> np.ndarray:
        return (self.embryo if self._body is None else self._body).frequency

    @cached_property
    def shape(self) -> Any:
        from .shape import body_shape

        return body_shape(self.body)

    @cached_property
    def locomotion(self) -> str:
        from .locomotion import MODES, classify_locomotion

        # The engine classifies during the evaluation's own swim when the config's search names
        # locomotion (Fitness.locomotion >= 0); otherwise the swim is replayed and classified here.
        measured = int(getattr(self.evaluation, "locomotion", -1))
        if measured >= 0:
            return MODES[measured]
        return classify_locomotion(self.genome, self.config).mode

    @cached_property
    def fitness(self) -> float:
        if self.evaluation is None:
            from .evolution import evaluate

            self.evaluation = evaluate(self.genome, self.config)
        return float(self.evaluation.fitness)


def _locomotion_index(s: _Subject) -> float:
    from .locomotion import MODES

    return float(MODES.index(s.locomotion))


@dataclass(frozen=True)
class Descriptor:
    """One descriptor: a number computed from a genome, its config and its evaluation, and the range
    ``[lo, hi]`` the archives divide (values outside are clipped to it, see :class:`GridArchive`).

    ``function(genome, config, evaluation) -> float``: ``evaluation`` is what was told for the genome
    (an :class:`animat.EvaluationResult` from :func:`animat.evaluate`, an :class:`animat.Fitness` from
    :meth:`MapElites.step`), or None when :func:`measure` is called without one. It must be a pure
    function of its arguments (the run's determinism rests on it); NaN means "no descriptor" (the
    genome is not archived). ``computed`` says in words how it is computed.

    Your own: ``Descriptor("width", "body width in cells", 0, 10, my_function)``, or the tuple
    ``(my_function, 0, 10)`` wherever descriptors are given. A table entry with another range:
    ``DESCRIPTORS["elongation"].with_range(1, 3)`` or the tuple ``("elongation", 1, 3)``.
    """

    name: str
    meaning: str
    lo: float
    hi: float
    function: Callable[[Any, Any, Any], float] = field(repr=False, compare=False)
    computed: str = ""
    # Table entries compute from a shared _Subject (one development per genome for all of them).
    _of_subject: Optional[Callable[[_Subject], float]] = field(default=None, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not self.name or not isinstance(self.name, str):
            raise ValueError(f"Descriptor: a name is required, got {self.name!r}")
        lo, hi = float(self.lo), float(self.hi)
        if not (math.isfinite(lo) and math.isfinite(hi) and hi > lo):
            raise ValueError(f"Descriptor {self.name!r}: the range must be finite with hi > lo, got [{lo}, {hi}]")
        object.__setattr__(self, "lo", lo)
        object.__setattr__(self, "hi", hi)
        if not callable(self.function):
            raise TypeError(f"Descriptor {self.name!r}: function must be callable")

    def with_range(self, lo: float, hi: float) -> Descriptor:
        """The same descriptor over another range."""
        return replace(self, lo=lo, hi=hi)

    def __call__(self, genome: Any, config: Any = None, evaluation: Any = None) -> float:
        return float(self.function(genome, config, evaluation))

    def _value(self, subject: _Subject) -> float:
        if self._of_subject is not None:
            return float(self._of_subject(subject))
        return float(self.function(subject.genome, subject.config, subject.evaluation))


#: The engine's measures table (``_core.measures()``): name -> (meaning, lo, hi, maximize).
_MEASURES = {name: (meaning, lo, hi, maximize) for name, meaning, lo, hi, maximize in _core.measures()}


def _table_entry(name: str, meaning: str, of_subject: Callable[[_Subject], float], computed: str) -> Descriptor:
    """A descriptor of the table, with the engine's range for it (one owner: ``_core.measures()``)."""
    _, lo, hi, _ = _MEASURES[name]

    def function(genome: Any, config: Any = None, evaluation: Any = None) -> float:
        return float(of_subject(_Subject(genome, config, evaluation)))

    function.__name__ = name
    return Descriptor(name, meaning, lo, hi, function, computed, of_subject)


#: The named descriptors, in table order: name -> :class:`Descriptor`. Integer descriptors have a
#: range one wider than their values (``[0, 8]`` for 0..7 protrusions) so that a grid of ``hi - lo``
#: bins gives each value its own bin. The ranges are the engine's measures table's
#: (``_core.measures()``, the paper's settings); change them with :meth:`Descriptor.with_range` (or a
#: ``(name, lo, hi)`` tuple) for others.
DESCRIPTORS: Dict[str, Descriptor] = {
    d.name: d
    for d in (
        _table_entry(
            "cells",
            "number of cells of the developed embryo",
            lambda s: s.cells,
            "`animat.develop(genome, config)`: the number of cell centres",
        ),
        _table_entry(
            "elongation",
            "sqrt(λ1/λ2) of the cells' second moments: 1 for a round body",
            lambda s: s.shape.elongation,
            "`animat.shape.body_shape(body).elongation` of the body at rest",
        ),
        _table_entry(
            "protrusions",
            "number of protrusions: parts sticking out of the body's core",
            lambda s: s.shape.protrusion_count,
            "`animat.shape.body_shape(body).protrusion_count`",
        ),
        _table_entry(
            "symmetric_pair",
            "1 when two protrusions mirror each other about a principal axis, else 0",
            lambda s: 1.0 if s.shape.symmetric_pair else 0.0,
            "`animat.shape.body_shape(body).symmetric_pair`",
        ),
        _table_entry(
            "concavity",
            "1 − outline area / convex hull area: 0 for a convex body",
            lambda s: s.shape.concavity,
            "`animat.shape.body_shape(body).concavity`",
        ),
        _table_entry(
            "frequency",
            "median oscillator frequency of the cells (rad per time unit)",
            lambda s: float(np.median(s.frequency)),
            "`numpy.median(animat.develop(genome, config).frequency)`",
        ),
        _table_entry(
            "locomotion",
            "locomotion mode: the index in animat.locomotion.MODES (0 undulation ... 5 none)",
            _locomotion_index,
            "`animat.classify_locomotion(genome, config).mode`: classified during the evaluation's own swim by "
            "the engine when the config's search names it (MapElites), else by replaying the swim (about 12 "
            "evaluations)",
        ),
        _table_entry(
            "fitness",
            "the objective's own value (the paper's distance: up to about 44 in 4000 steps)",
            lambda s: s.fitness,
            "`evaluation.fitness` (evaluated again when no evaluation is given)",
        ),
    )
}


def descriptor_table() -> str:
    """:data:`DESCRIPTORS` as a Markdown table (the one in docs/python.md)."""

    def number(x: float) -> str:
        return f"{x:g}"

    lines = ["| name | meaning | range | computed by |", "| --- | --- | --- | --- |"]
    for d in DESCRIPTORS.values():
        lines.append(f"| `{d.name}` | {d.meaning} | [{number(d.lo)}, {number(d.hi)}] | {d.computed} |")
    return "\n".join(lines)


#: Descriptor values: a sequence of floats or a 1-D array.
Values = Union[Sequence[float], np.ndarray]

DescriptorLike = Union[str, Descriptor, Callable[[Any, Any, Any], float], Tuple[Any, float, float]]


def _descriptor(spec: DescriptorLike) -> Descriptor:
    if isinstance(spec, Descriptor):
        return spec
    if isinstance(spec, str):
        if spec not in DESCRIPTORS:
            raise ValueError(f"no descriptor named {spec!r}; the table has {', '.join(DESCRIPTORS)}")
        return DESCRIPTORS[spec]
    if isinstance(spec, tuple) and len(spec) == 3:
        what: Any = spec[0]
        lo, hi = spec[1], spec[2]
        if isinstance(what, str):
            return _descriptor(what).with_range(lo, hi)
        if callable(what):
            name = getattr(what, "__name__", None) or type(what).__name__
            function = cast(Callable[[Any, Any, Any], float], what)
            return Descriptor(name, f"{name} (a Python function)", lo, hi, function, "your function")
    if callable(spec):
        raise ValueError("a descriptor function needs a range: pass (function, lo, hi) or a Descriptor")
    raise TypeError(f"a descriptor is a name, a Descriptor or a (name or function, lo, hi) tuple, got {spec!r:.80}")


def _descriptors(specs: Iterable[DescriptorLike]) -> Tuple[Descriptor, ...]:
    out = tuple(_descriptor(s) for s in specs)
    if not out:
        raise ValueError("an archive needs at least one descriptor")
    names = [d.name for d in out]
    if len(set(names)) != len(names):
        raise ValueError(f"descriptor names must be distinct, got {names}")
    return out


def measure(
    genome: Any, config: Any = None, descriptors: Iterable[DescriptorLike] = ("cells",), evaluation: Any = None
) -> Optional[np.ndarray]:
    """The values of ``descriptors`` for ``genome`` under ``config`` (float64 array, in order), or None
    when the genome is not viable (its embryo, or ``evaluation.viable`` when an evaluation is given):
    a non-viable genome has no descriptor. Deterministic (a function of genome and config; ``fitness``
    and your own functions also read ``evaluation``). The table's descriptors share one development
    per call."""
    cfg = _core.Config() if config is None else config
    if evaluation is not None and not bool(getattr(evaluation, "viable", True)):
        return None
    subject = _Subject(genome, cfg, evaluation)
    if not subject.embryo.viable:
        return None
    return np.array([d._value(subject) for d in _descriptors(descriptors)], dtype=np.float64)


# --- archives -------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Elite:
    """The elite of one cell.

    Attributes:
        index: the cell.
        genome: its :class:`animat.Genome`.
        fitness: the objective's value at the run's step.
        objective: what the archive compares and sums: the fitness, or the reference under
            ``evaluation.reference_check = "select"``.
        descriptors: its descriptor values (float, in the archive's order).
        reference: the fitness at the exploit guard's reference step; NaN when not checked.
        generation: the generation that found it (-1 when added by hand).
    """

    index: int
    genome: Any = field(repr=False)
    fitness: float
    objective: float
    descriptors: Tuple[float, ...]
    reference: float = float("nan")
    generation: int = -1


class _Archive:
    """What both archives share: the elites by cell, add, QD-score, coverage, the data frame."""

    kind = ""

    def __init__(self, descriptors: Iterable[DescriptorLike], qd_offset: float = 0.0) -> None:
        self.descriptors: Tuple[Descriptor, ...] = _descriptors(descriptors)
        self.qd_offset = float(qd_offset)
        if not math.isfinite(self.qd_offset):
            raise ValueError(f"qd_offset must be finite, got {qd_offset}")
        self._elites: Dict[int, Elite] = {}
        self._core: Any = None  # the engine's archive (_core.Archive): its cells and rule

    def _make_core(self, bins: Sequence[int] = (), centroids: Any = ()) -> None:
        """The engine's archive of these descriptors (a grid of ``bins``, or a CVT of ``centroids``)."""
        ranges = [(d.lo, d.hi) for d in self.descriptors]
        try:
            self._core = _core.Archive(list(self.names), ranges, bins=list(bins), centroids=list(centroids))
        except ValueError as e:
            raise ValueError(f"{type(self).__name__}: {e}") from None

    # --- to override ------------------------------------------------------------------------------
    @property
    def cells(self) -> int:
        """Number of cells."""
        raise NotImplementedError

    def _index(self, values: np.ndarray) -> int:
        return int(self._core.index_of(values.tolist()))

    def _geometry(self) -> Dict[str, Any]:
        raise NotImplementedError

    # --- shared -----------------------------------------------------------------------------------
    @property
    def dims(self) -> int:
        """Number of descriptors."""
        return len(self.descriptors)

    @property
    def names(self) -> Tuple[str, ...]:
        """The descriptors' names, in order."""
        return tuple(d.name for d in self.descriptors)

    @property
    def lower(self) -> np.ndarray:
        return np.array([d.lo for d in self.descriptors])

    @property
    def upper(self) -> np.ndarray:
        return np.array([d.hi for d in self.descriptors])

    def index_of(self, descriptors: Values) -> Optional[int]:
        """The cell of these descriptor values; None when one of them is NaN (never archived)."""
        v = np.asarray(descriptors, dtype=np.float64).reshape(-1)
        if len(v) != self.dims:
            raise ValueError(f"{len(v)} descriptor values for an archive of {self.dims} descriptors {self.names}")
        if np.isnan(v).any():
            return None
        return self._index(v)

    def add(
        self,
        genome: Any,
        fitness: float,
        descriptors: Values,
        *,
        objective: Optional[float] = None,
        reference: float = float("nan"),
        generation: int = -1,
    ) -> bool:
        """Offer a candidate; returns whether it entered (its cell was empty, or its ``objective``,
        default the fitness, is strictly greater than the elite's: a tie keeps the elite; the engine's
        rule). A NaN descriptor is never archived (False); a fitness or objective that is not finite is
        a ValueError."""
        fitness = float(fitness)
        obj = fitness if objective is None else float(objective)
        if not (math.isfinite(fitness) and math.isfinite(obj)):
            raise ValueError(f"add: the fitness and the objective must be finite, got {fitness}, {obj}")
        index = self.index_of(descriptors)
        if index is None:
            return False
        return self._put(
            Elite(index, genome, fitness, obj, self._values(descriptors), float(reference), int(generation))
        )

    @staticmethod
    def _values(descriptors: Values) -> Tuple[float, ...]:
        return tuple(float(x) for x in np.asarray(descriptors, dtype=np.float64).reshape(-1))

    def _put(self, elite: Elite) -> bool:
        """Offers an elite of its cell to the engine's archive; keeps it when it entered."""
        entered = bool(
            self._core.add(
                elite.genome,
                elite.fitness,
                list(elite.descriptors),
                elite.objective,
                elite.reference,
                elite.generation,
            )
        )
        if entered:
            self._elites[elite.index] = elite
        return entered

    def __len__(self) -> int:
        return len(self._elites)

    def __contains__(self, index: object) -> bool:
        return index in self._elites

    def __getitem__(self, index: int) -> Elite:
        return self._elites[index]

    def elites(self) -> List[Elite]:
        """The elites, in cell order."""
        return [self._elites[i] for i in sorted(self._elites)]

    def best(self) -> Optional[Elite]:
        """The elite with the greatest objective (the lowest cell among equals); None when empty."""
        best = None
        for e in self.elites():
            if best is None or e.objective > best.objective:
                best = e
        return best

    def qd_score(self) -> float:
        """Σ (objective − qd_offset) over the elites (exactly rounded: ``math.fsum``). With a signed
        objective, give the archive a ``qd_offset`` below any objective value, so that every elite adds
        to the score (pyribs's ``qd_score_offset``)."""
        return math.fsum(e.objective - self.qd_offset for e in self._elites.values())

    def coverage(self) -> float:
        """Occupied cells / cells."""
        return len(self._elites) / self.cells

    def clear(self) -> None:
        self._elites.clear()
        self._core.clear()

    # --- export -----------------------------------------------------------------------------------
    def data(self) -> Dict[str, np.ndarray]:
        """The elites as columns (numpy arrays, one row per elite in cell order) with pyribs's names
        (its ``ArchiveDataFrame``): ``index`` (the cell), ``objective``, ``measures_0`` ..
        ``measures_{d-1}`` (the descriptors, in order), ``solution`` (the genome's JSON text: a genome
        is not a vector), and ``fitness``, ``reference``, ``generation``."""
        es = self.elites()
        cols: Dict[str, np.ndarray] = {
            "index": np.array([e.index for e in es], dtype=np.int64),
            "objective": np.array([e.objective for e in es], dtype=np.float64),
        }
        for j in range(self.dims):
            cols[f"measures_{j}"] = np.array([e.descriptors[j] for e in es], dtype=np.float64)
        cols["solution"] = np.array([e.genome.to_json() for e in es], dtype=object)
        cols["fitness"] = np.array([e.fitness for e in es], dtype=np.float64)
        cols["reference"] = np.array([e.reference for e in es], dtype=np.float64)
        cols["generation"] = np.array([e.generation for e in es], dtype=np.int64)
        return cols

    def to_pandas(self) -> Any:
        """:meth:`data` as a ``pandas.DataFrame`` (ImportError naming the package when pandas is missing);
        ``ribs.archives.ArchiveDataFrame(frame)`` reads it."""
        try:
            import pandas as pd  # type: ignore[import-not-found]
        except ImportError:
            raise ImportError("to_pandas needs pandas: pip install pandas") from None
        return pd.DataFrame(self.data())

    def as_data_frame(self) -> Any:
        """:meth:`to_pandas` when pandas is installed, else :meth:`data` (a dict of numpy arrays)."""
        try:
            return self.to_pandas()
        except ImportError:
            return self.data()

    def write_csv(self, path: PathLike) -> Path:
        """One row per elite: ``index, objective, fitness, reference, generation``, the descriptors by
        name, ``genome`` (JSON). Written atomically."""
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(["index", "objective", "fitness", "reference", "generation", *self.names, "genome"])
        for e in self.elites():
            w.writerow(
                [e.index, repr(e.objective), repr(e.fitness), repr(e.reference), e.generation]
                + [repr(x) for x in e.descriptors]
                + [e.genome.to_json()]
            )
        return _write_atomic(Path(path), buf.getvalue())

    # --- state ------------------------------------------------------------------------------------
    def state(self) -> Dict[str, Any]:
        """The archive as a JSON-able dict (:meth:`from_state` reads it back exactly)."""
        return {
            "kind": self.kind,
            "descriptors": [{"name": d.name, "lo": d.lo, "hi": d.hi} for d in self.descriptors],
            "qd_offset": self.qd_offset,
            **self._geometry(),
            "elites": [
                {
                    "index": e.index,
                    "genome": e.genome.to_json(),
                    "fitness": e.fitness,
                    "objective": e.objective,
                    "reference": _json_float(e.reference),
                    "descriptors": list(e.descriptors),
                    "generation": e.generation,
                }
                for e in self.elites()
            ],
        }

    @staticmethod
    def from_state(state: Mapping[str, Any], descriptors: Iterable[DescriptorLike] = ()) -> Any:
        """An archive from :meth:`state`. Descriptors are found by name: first in ``descriptors`` (your
        own functions must be given again: a function is not saved), then in :data:`DESCRIPTORS`; the
        saved range is used."""
        given = {d.name: d for d in (_descriptor(s) for s in descriptors)}
        ds = []
        for saved in state["descriptors"]:
            name = saved["name"]
            if name in given:
                base = given[name]
            elif name in DESCRIPTORS:
                base = DESCRIPTORS[name]
            else:
                raise ValueError(
                    f"the archive's descriptor {name!r} is not in the table: pass it again "
                    "(descriptors=[Descriptor(...)] or (function, lo, hi))"
                )
            ds.append(base.with_range(saved["lo"], saved["hi"]))
        archive: _Archive
        if state["kind"] == "grid":
            archive = GridArchive(ds, state["bins"], qd_offset=state["qd_offset"])
        elif state["kind"] == "cvt":
            archive = CVTArchive._with_centroids(
                ds, np.array(state["centroids"], dtype=np.float64), state["seed"], state["samples"], state["qd_offset"]
            )
        else:
            raise ValueError(f"unknown archive kind {state['kind']!r}")
        for e in state["elites"]:
            elite = Elite(
                int(e["index"]),
                _core.Genome.from_json(e["genome"]),
                float(e["fitness"]),
                float(e["objective"]),
                tuple(float(x) for x in e["descriptors"]),
                _from_json_float(e["reference"]),
                int(e["generation"]),
            )
            archive._put(elite)
        return archive

    def _own_descriptors(self) -> Tuple[Descriptor, ...]:
        # Descriptors that are not table entries (your functions): saved by pickle, not in the state.
        return tuple(d for d in self.descriptors if d._of_subject is None)

    def __reduce__(self) -> Tuple[Any, ...]:
        # Pickles as its state (the table's functions are found by name) and your own descriptors.
        return (_Archive.from_state, (self.state(), self._own_descriptors()))

    def __repr__(self) -> str:
        return (
            f"<animat.{type(self).__name__} {', '.join(self.names)}: {len(self)}/{self.cells} cells, "
            f"QD-score {self.qd_score():.6g}>"
        )


class GridArchive(_Archive):
    """An archive on a regular grid: descriptor j is divided into ``bins[j]`` equal bins over its range.

    Bin k of a descriptor holds the values v with ``edges[k] <= v < edges[k + 1]``, ``edges =
    numpy.linspace(lo, hi, bins + 1)`` (:attr:`edges`): a value on an interior edge belongs to the bin
    above it. Values outside the range are **clipped**: v < lo (and -inf) go to the first bin, v >= hi
    (``hi`` itself and +inf included) to the last. A NaN is never archived. The cell index is the
    row-major (C order) index of the bins, ``numpy.ravel_multi_index`` (pyribs's grid order).

    Args:
        descriptors: names from :data:`DESCRIPTORS`, :class:`Descriptor` objects, or ``(name or
            function, lo, hi)`` tuples.
        bins: one int for every descriptor, or one per descriptor.
        qd_offset: subtracted from every objective in :meth:`qd_score`.
    """

    kind = "grid"

    def __init__(
        self, descriptors: Iterable[DescriptorLike], bins: Union[int, Sequence[int]], *, qd_offset: float = 0.0
    ) -> None:
        super().__init__(descriptors, qd_offset)
        b = [int(bins)] * self.dims if isinstance(bins, (int, np.integer)) else [int(x) for x in bins]
        if len(b) != self.dims or min(b) < 1:
            raise ValueError(f"bins: one count >= 1 per descriptor ({self.dims}), got {bins}")
        self.bins: Tuple[int, ...] = tuple(b)
        self._make_core(bins=self.bins)
        #: Bin edges per descriptor (``bins[j] + 1`` values, from lo to hi).
        self.edges: Tuple[np.ndarray, ...] = tuple(
            np.linspace(d.lo, d.hi, n + 1) for d, n in zip(self.descriptors, self.bins)
        )

    @classmethod
    def from_config(cls, config: Any) -> GridArchive:
        """The grid a new run from ``config`` searches: ``search.descriptors`` (names of
        :data:`DESCRIPTORS`) and ``search.bins`` (one count for all, or one each)."""
        names = list(config["search.descriptors"])
        for name in names:
            if name not in DESCRIPTORS:
                raise ValueError(
                    f"search.descriptors = {json.dumps(names)}: no descriptor {name!r}; the names are {', '.join(DESCRIPTORS)}"
                )
        bins = [int(b) for b in config["search.bins"]]
        return cls(names, bins[0] if len(bins) == 1 else bins)

    @property
    def cells(self) -> int:
        return int(np.prod(self.bins))

    def bin_of(self, descriptors: Values) -> Optional[Tuple[int, ...]]:
        """The bin of every descriptor (clipped as described above); None for a NaN."""
        v = np.asarray(descriptors, dtype=np.float64).reshape(-1)
        if len(v) != self.dims:
            raise ValueError(f"{len(v)} descriptor values for an archive of {self.dims} descriptors {self.names}")
        if np.isnan(v).any():
            return None
        return tuple(int(x) for x in np.unravel_index(self._index(v), self.bins))

    def _geometry(self) -> Dict[str, Any]:
        return {"bins": list(self.bins)}


#: The most cells of a :class:`CVTArchive`, and the most sample-centroid distances of one of its
#: Lloyd iterations (samples × cells): bounds that keep its k-means to seconds and its memory small.
MAX_CVT_CELLS = 10_000
MAX_CVT_WORK = 2_000_000_000


class CVTArchive(_Archive):
    """An archive on a centroidal Voronoi tessellation (Vassiliades et al. 2018): ``cells`` centroids
    in the descriptor box; a value belongs to the cell of its nearest centroid.

    The centroids are computed once, deterministically, in the box scaled to the unit cube (each
    descriptor's ``(v - lo) / (hi - lo)``, so every descriptor weighs the same), by the engine's
    ``animat._core.cvt_centroids(d, cells, seed, samples, iterations)``: ``samples`` points drawn
    uniformly from the keyed stream ``animat.Rng.derive(seed, CVT_SAMPLES_KEY, 0)``, the first
    ``cells`` of them start Lloyd's k-means, and each iteration assigns every sample to its nearest
    centroid (the lowest index among equals) and moves each centroid to the mean of its samples (a
    centroid with none stays), until the assignment no longer changes or after ``iterations``. With
    the run's ``evolution.seed`` and the default iterations these are the centroids of a config's
    ``search.archive = "cvt"`` (what ``animat_evolve`` searches); checkpoints store the centroids.

    A value is scaled the same way and clipped to the unit cube, then put in the cell of its nearest
    centroid (the lowest index among equals); a NaN is never archived.

    Args:
        descriptors: as for :class:`GridArchive`.
        cells: number of centroids (at most :data:`MAX_CVT_CELLS`; ValueError beyond).
        seed: seed of the samples.
        samples: sample count (default ``max(1000, 20 * cells)``).
        iterations: the most Lloyd iterations (default 100).
        qd_offset: as for :class:`GridArchive`.
    """

    kind = "cvt"

    def __init__(
        self,
        descriptors: Iterable[DescriptorLike],
        cells: int,
        seed: int = 0,
        *,
        samples: Optional[int] = None,
        iterations: int = 100,
        qd_offset: float = 0.0,
    ) -> None:
        super().__init__(descriptors, qd_offset)
        cells = int(cells)
        n = max(1000, 20 * cells) if samples is None else int(samples)
        if cells < 1 or n < cells:
            raise ValueError(f"CVTArchive: need 1 <= cells <= samples, got cells={cells}, samples={n}")
        if cells > MAX_CVT_CELLS:
            raise ValueError(f"CVTArchive: cells = {cells} is more than {MAX_CVT_CELLS} (the most a CVT archive holds)")
        if n * cells > MAX_CVT_WORK:
            raise ValueError(
                f"CVTArchive: samples = {n} with cells = {cells} makes {n * cells:.3g} distances per Lloyd "
                f"iteration, more than {MAX_CVT_WORK:.3g}: fewer samples or cells"
            )
        self.seed = int(seed)
        self.samples = n
        self._unit = np.array(_core.cvt_centroids(self.dims, cells, self.seed, n, int(iterations)), dtype=np.float64)
        self._make_core(centroids=self._unit.tolist())

    @classmethod
    def _with_centroids(
        cls, descriptors: Sequence[Descriptor], unit: np.ndarray, seed: int, samples: int, qd_offset: float
    ) -> CVTArchive:
        archive = cls.__new__(cls)
        _Archive.__init__(archive, descriptors, qd_offset)
        archive.seed, archive.samples = int(seed), int(samples)
        archive._unit = unit.reshape(-1, archive.dims).copy()
        archive._make_core(centroids=archive._unit.tolist())
        return archive

    @property
    def cells(self) -> int:
        return len(self._unit)

    @property
    def centroids(self) -> np.ndarray:
        """(cells, d) centroids in descriptor units."""
        return self.lower + self._unit * (self.upper - self.lower)

    def _geometry(self) -> Dict[str, Any]:
        return {"seed": self.seed, "samples": self.samples, "centroids": self._unit.tolist()}


# --- MAP-Elites -----------------------------------------------------------------------------------


def _history_dtype(columns: Sequence[Tuple[str, bool]]) -> np.dtype:
    """A history's dtype from the engine's ``(name, integer)`` columns, without ``wall_seconds``."""
    return np.dtype(
        [(name, np.int64 if integer else np.float64) for name, integer in columns if name != "wall_seconds"]
    )


#: The columns of :attr:`MapElites.history`, one row per generation: the engine's
#: (``_core.search_history_columns("map_elites")``, a run's ``history.csv``) but its ``wall_seconds``. ``evaluations``: swims
#: told so far (the batches; reference swims not counted); ``best``: the greatest objective in the
#: archive (NaN when empty); ``added``: candidates of this generation that entered the archive;
#: ``discarded``: candidates never archivable (non-viable, unstable, invalid, NaN descriptor);
#: ``reference_evaluations``: the exploit guard's swims so far; ``disagreements``: elites whose fitness
#: and reference disagree (:func:`animat.reference_disagrees`).
QD_HISTORY_DTYPE = _history_dtype(_core.search_history_columns("map_elites"))


def _json_float(x: float) -> Optional[float]:
    return None if math.isnan(x) else float(x)


def _from_json_float(x: Any) -> float:
    return float("nan") if x is None else float(x)


def _write_atomic(path: Path, text: str) -> Path:
    tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)
    return path


def _comparable(config: Any) -> Dict[str, Any]:
    d = config.to_dict()
    d.get("evolution", {}).pop("threads", None)
    d.get("evolution", {}).pop("generations", None)  # a run's length is run_*'s argument
    # [search] says how a new run from the config searches; a started run's checkpoint holds its
    # archive or objectives (and runs started before [search] existed hold the defaults).
    d.pop("search", None)
    return d


class _SearchState:
    """What MAP-Elites and NSGA-II share: the run's config, its counters, the history as a data frame,
    and saving and loading the checkpoint (each class defines ``checkpoint()``, ``restore()`` and
    ``history``)."""

    _config: Any
    _engine: Any  # the engine's search (_core.SearchEngine)
    _asked: Optional[List[Any]]  # the genomes of the pending ask()
    # The swim function (animat.pool): this process's, and the MPI pool's while run_* runs one.
    _swim: Swim
    _pool: Optional[Swim] = None

    def _evaluate(self, genomes: List[Any], config: Any, **options: Any) -> List[Any]:
        return (self._pool or self._swim)(genomes, config, **options)

    @property
    def config(self) -> Any:
        """The run's :class:`animat.Config` (a copy)."""
        return self._config.copy()

    def ask(self) -> List[Any]:
        """The genomes of the next generation (a list of :class:`animat.Genome`; see the class docstring)."""
        asked = self._asked
        if asked is None:
            asked = self._asked = list(self._engine.ask())
        return list(asked)

    @property
    def generation(self) -> int:
        """The last completed generation (-1 before the first ``tell``)."""
        return int(self._engine.generation)

    @property
    def evaluations(self) -> int:
        """Candidates told so far."""
        return int(self._engine.evaluations)

    def _references(self, genomes: List[Any]) -> Tuple[List[Any], List[List[float]]]:
        raise NotImplementedError

    def history_frame(self) -> Any:
        """:attr:`history` as a ``pandas.DataFrame`` (ImportError naming the package when pandas is missing)."""
        try:
            import pandas as pd  # type: ignore[import-not-found]
        except ImportError:
            raise ImportError("history_frame needs pandas: pip install pandas") from None

        return pd.DataFrame.from_records(np.asarray(cast(Any, self).history).view(np.ndarray))

    def save(self, path: PathLike) -> Path:
        """Write :meth:`checkpoint` as JSON to ``path`` atomically."""
        return _write_atomic(Path(path), json.dumps(cast(Any, self).checkpoint(), allow_nan=False))

    def _refresh(self) -> None:
        """Brings views of the engine's state up to date (MapElites' archive)."""

    @classmethod
    def load(cls, path: PathLike, config: Any = None, **kwargs: Any) -> Any:
        """:meth:`restore` from a file written by :meth:`save`, or the search of a run directory (its
        config.toml and checkpoint.json, as :func:`run_map_elites`, :func:`run_nsga2` and
        ``animat_evolve`` write them; ``config``, if given, must be the run's but for
        ``evolution.threads`` and ``evolution.generations``); errors name the file."""
        path = Path(path)
        if not path.is_dir():
            return cast(Any, cls).restore(path.read_text(encoding="utf-8"), config, source=str(path), **kwargs)
        checkpoint = path / "checkpoint.json"
        if not checkpoint.is_file():
            raise FileNotFoundError(f"{checkpoint}: the run directory has no checkpoint")
        run = _run_config(path)
        search = cast(Any, cls)._from_run(path, run, config, **kwargs)
        search._engine.restore(checkpoint.read_text(encoding="utf-8"), str(checkpoint))
        search._refresh()
        return search


def _same_config(config: Any, saved: Any, objective: ObjectiveLike, source: str) -> None:
    """Refuses a config to resume the run of ``saved`` with that differs from it but for
    ``evolution.threads``, or sets a [search] key otherwise (:func:`_same_search`)."""
    mine = _config_for(config, _objective(objective))
    mine["evolution.seed"] = int(saved["evolution.seed"])
    if _comparable(mine) != _comparable(saved):
        raise ValueError(
            f"{source}: MapElites.restore: the config differs from the checkpoint's (only evolution.threads may)"
        )
    _same_search(mine, saved, source)


def _same_search(given: Any, saved: Any, source: str) -> None:
    """Refuses a config whose [search] sets a key (to other than its default) that the run has
    otherwise: a resume continues the search it started."""
    default = _core.Config().to_dict().get("search", {})
    run = saved.to_dict().get("search", {})
    for key, value in given.to_dict().get("search", {}).items():
        mine = run.get(key)
        if value == default.get(key):
            continue
        if key == "bins" and isinstance(value, list) and len(value) == 1 and isinstance(mine, list):
            value = value * len(mine)  # one count for every descriptor
        if value != mine:
            raise ValueError(
                f"{source}: search.{key} = {json.dumps(value)} is not the run's {json.dumps(mine)}: "
                "a resume continues the search it started"
            )


def _python_objective(objective: ObjectiveLike) -> Optional[Objective]:
    """The Python objective of a search's ``objective`` argument (None for a name or None)."""
    obj = _objective(objective)
    return obj if isinstance(obj, Objective) else None


def _fitnesses(objective: Optional[Objective]) -> Swim:
    """MAP-Elites' swim function (:mod:`animat.pool`): :func:`animat.evaluate_population` on the
    config's ``evolution.threads`` with ``objective`` (a Python objective, or None: the config's).

    ``describe=names`` (descriptors of :data:`DESCRIPTORS`): a ``(Fitness, values)`` pair per genome
    instead, ``values`` the descriptors in that order computed from the very body the evaluation
    developed and swam (the same values as :func:`measure`, without developing the genome again), or
    None where the swim was not viable, stable and valid (no candidate). Under MPI every rank
    describes the genomes it swam."""

    def swim(genomes: List[Any], config: Any, describe: Sequence[str] = ()) -> List[Any]:
        threads = int(config["evolution.threads"])
        if not describe:
            return evaluate_population(genomes, config, threads, objective=objective)
        table = [DESCRIPTORS[name]._of_subject for name in describe]
        fits, bodies = cast(Any, _core)._evaluate_population_bodies(  # private: not in the stub
            list(genomes), config, threads, _objective(objective)
        )

        def one(item: Tuple[Any, Any, Any]) -> Tuple[Any, Optional[Tuple[float, ...]]]:
            genome, fit, body = item
            if not (fit.viable and fit.stable and fit.valid):
                return fit, None
            subject = _Subject(genome, config, fit, body)
            return fit, tuple(float(cast(Callable[[_Subject], float], f)(subject)) for f in table)

        items = list(zip(genomes, fits, bodies))
        if threads == 1 or len(items) < 2:
            return [one(item) for item in items]
        # Each genome's descriptors depend on it alone, and the replays behind them release the
        # GIL: on the evaluation's threads, in order, the same values.
        workers = min(len(items), threads if threads > 0 else (os.cpu_count() or 1))
        with ThreadPoolExecutor(workers) as pool:
            return list(pool.map(one, items))

    return swim


#: The table's descriptors that every evaluation's :class:`animat.Fitness` carries (the engine's
#: measures, computed during the swim): read from the Fitness told, never computed again.
_FITNESS_MEASURES: Dict[str, Callable[[Any], float]] = {
    "cells": lambda f: float(f.cell_count),
    "elongation": lambda f: float(f.elongation),
    "protrusions": lambda f: float(f.protrusions),
    "symmetric_pair": lambda f: float(f.symmetric_pair),
    "concavity": lambda f: float(f.concavity),
    "frequency": lambda f: float(f.frequency),
    "fitness": lambda f: float(f.fitness),
}


def _is_table_entry(d: Descriptor) -> bool:
    return d.name in DESCRIPTORS and d._of_subject is not None and d._of_subject is DESCRIPTORS[d.name]._of_subject


def _worker_descriptors(descriptors: Sequence[Descriptor]) -> Tuple[str, ...]:
    """The names of the table's descriptors among ``descriptors`` (any range) that the Fitness does not
    carry: the swim computes them where it swims (:func:`_fitnesses`); your own functions are computed
    by the search."""
    return tuple(d.name for d in descriptors if _is_table_entry(d) and d.name not in _FITNESS_MEASURES)


def _not_archivable(f: Any) -> Any:
    """``f`` marked invalid: a candidate without descriptor values, which the engine counts discarded."""
    return _core.Fitness(
        f.fitness,
        f.viable,
        f.stable,
        f.cell_count,
        False,
        f.drag_limited,
        f.morphology_kind,
        f.actuation_work,
        f.actuation_work_positive,
        f.actuation_work_absolute,
        f.max_speed,
    )


def _checksum(state: Mapping[str, Any]) -> str:
    body = json.dumps({k: v for k, v in state.items() if k != "checksum"}, sort_keys=True, allow_nan=False)
    return hashlib.sha256(body.encode("utf-8")).hexdigest()


def _checked_state(state: Any, fmt: str, what: str) -> Mapping[str, Any]:
    """A checkpoint (a dict, or its JSON text) of format ``fmt`` whose checksum matches its content;
    ValueError otherwise (``what``: the class it is for)."""
    if isinstance(state, (str, bytes)):
        state = json.loads(state)
    if not isinstance(state, Mapping) or state.get("format") != fmt:
        found = state.get("format") if isinstance(state, Mapping) else type(state).__name__
        raise ValueError(f"not {what} checkpoint (format {found!r}, expected {fmt})")
    if state.get("checksum") != _checksum(state):
        raise ValueError("its checksum does not match its content (edited or corrupt)")
    return state


class MapElites(_SearchState):
    """MAP-Elites driven by ``ask``/``tell`` (or :meth:`step`), over a :class:`GridArchive` or a
    :class:`CVTArchive`: a thin layer over the engine's search (``animat._core.SearchEngine`` with
    ``search.algorithm = "map_elites"``, what ``animat_evolve`` runs). The engine breeds, archives,
    runs the exploit guard and writes the history and the checkpoint; this class computes the
    descriptors the engine does not measure (your functions, ``locomotion``) and passes them as
    supplied values, and :attr:`archive` is a view of the engine's elites after every ``tell``.

    ``ask()`` returns the batch of generation g = ``generation + 1``: for generation 0 (and whenever
    the archive is empty), ``batch`` random viable genomes, genome i drawn by
    ``animat.Genome.random_viable(seed=animat.Rng.derive(seed, g, i), config)``; afterwards ``batch``
    offspring, offspring i varied with the stream ``rng = animat.Rng.derive(seed, g, i)``: a parent
    ``elites[rng.integer(0, n - 1)]`` (the n elites in cell order); with probability
    ``crossover_fraction`` (``rng.uniform() < crossover_fraction``) a second one drawn the same way and
    ``parent.crossover(other, rng, mutation.crossover_points)``; then ``.mutate(rng, config)``, as the
    GA varies its offspring. Asking again before ``tell`` returns the same genomes.

    ``tell(results)`` takes one result per asked genome, in order: :class:`animat.EvaluationResult`
    (``animat.evaluate``), :class:`animat.Fitness`, a number or None (non-viable); ``descriptors=``
    gives their descriptor values instead of computing them (a row of None or with a NaN: not
    archived). The table's descriptors that every evaluation measures (``cells``, ``elongation``,
    ``protrusions``, ``symmetric_pair``, ``concavity``, ``frequency``, ``fitness``) are read from the
    Fitness; a plain number is described with :func:`measure`. A tell is all or nothing: a string, a
    fitness the objective forbids (negative, not finite), one so large that the QD-score could
    overflow (above ``sys.float_info.max / cells``), or a descriptor value that is infinite is a
    ValueError or TypeError naming the value, and the search is left as it was.

    A CVT archive is the engine's CVT archive with the archive's own centroids, so the engine's cells
    are the archive's.

    Example::

        me = animat.MapElites(config, animat.GridArchive(["elongation", "frequency"], 10), batch=20)
        while me.generation < 5:
            genomes = me.ask()
            me.tell([animat.evaluate(g, config) for g in genomes])     # or me.step()

    Args:
        config: the run's :class:`animat.Config` (default: the embedded paper setting).
        archive: an empty archive, filled in place (a run continues from a checkpoint: :meth:`restore`).
        batch: genomes per generation (default ``evolution.population``).
        initial: random genomes of generation 0: ``batch`` (the only value the engine runs).
        seed: the run's seed (default ``evolution.seed``; it is written into the config).
        objective: as for :class:`animat.GA`: a built-in name, a callable of an
            :class:`animat.EvaluationRecord` or an :class:`animat.Objective`. A Python objective's
            values are computed here and told to the engine, and so are the exploit guard's
            reference swims (the engine cannot swim with it).
        crossover_fraction: share of offspring made by crossover (default ``evolution.crossover_fraction``).
        threads: evaluation threads of :meth:`step` and the exploit guard (default ``evolution.threads``;
            0 = all cores). The run does not depend on it.
    """

    def __init__(
        self,
        config: Any,
        archive: Union[GridArchive, CVTArchive],
        *,
        batch: Optional[int] = None,
        initial: Optional[int] = None,
        seed: Optional[int] = None,
        objective: ObjectiveLike = None,
        crossover_fraction: Optional[float] = None,
        threads: Optional[int] = None,
    ) -> None:
        if not isinstance(archive, _Archive):
            raise TypeError(f"MapElites: archive must be a GridArchive or a CVTArchive, got {type(archive).__name__}")
        if len(archive):
            raise ValueError(
                f"MapElites: the archive holds {len(archive)} elites; a search starts from an empty one "
                "(continue a run with MapElites.restore or MapElites.load)"
            )
        self._config = _config_for(config, _objective(objective))
        self._objective = _python_objective(objective)
        self._swim = _fitnesses(self._objective)
        name = str(self._config["evaluation.objective"])
        if name.startswith("python:") and self._objective is None:
            raise ValueError(
                f"MapElites: evaluation.objective = {name!r} is a Python objective: pass "
                "objective=animat.Objective(...) with that name"
            )
        if seed is not None:
            self._config["evolution.seed"] = int(seed)
        if threads is not None:
            self._config["evolution.threads"] = int(threads)
        self.seed = int(self._config["evolution.seed"])
        self.batch = int(self._config["evolution.population"]) if batch is None else int(batch)
        if initial is not None and int(initial) != self.batch:
            raise ValueError(
                f"MapElites: initial = {initial} differs from batch = {self.batch}; generation 0 asks "
                "batch random genomes"
            )
        self.initial = self.batch
        cf = float(self._config["evolution.crossover_fraction"]) if crossover_fraction is None else crossover_fraction
        if self.batch < 1:
            raise ValueError(f"MapElites: batch must be >= 1, got {self.batch}")
        if not 0.0 <= float(cf) <= 1.0:
            raise ValueError(f"MapElites: crossover_fraction must be in [0, 1], got {cf}")
        self.crossover_fraction = float(cf)
        self._config["evolution.crossover_fraction"] = self.crossover_fraction
        self.archive = archive
        # The run's config says what search it is (its [search] section: what a run directory's
        # config.toml holds, and what animat_evolve resumes); a CVT archive's centroids are given.
        self._config, supplied = self._engine_config()
        # The exploit guard swims here (the objective may be Python's; under MPI on the ranks).
        guarded = str(self._config["evaluation.reference_check"]) != "off"
        centroids = None if isinstance(archive, GridArchive) else cast(CVTArchive, archive)._unit.tolist()
        self._engine = _core.SearchEngine(
            self._config,
            supplied=supplied,
            centroids=centroids,
            reference=_reference_hook(self) if guarded else None,
        )
        self._width = len(supplied)
        self._asked: Optional[List[Any]] = None

    def _engine_config(self) -> Tuple[Any, List[str]]:
        """The engine's config, the run's: its [search] section describes the archive (its
        descriptors, all supplied by this search; ranges, bins or cells) and the batch. A key the
        config already gives as the archive has it is left as written (``search.bins = [10]`` for
        every descriptor, ``search.ranges = []`` for the table's ranges), so that a run started by
        animat_evolve from the same config is the same run."""
        cfg = self._config.copy()
        archive = self.archive
        names = [d.name for d in archive.descriptors]
        cfg["search.algorithm"] = "map_elites"
        cfg["search.descriptors"] = names
        ranges = [x for d in archive.descriptors for x in (d.lo, d.hi)]
        table = [
            x
            for d in archive.descriptors
            if _is_table_entry(d)
            for x in (DESCRIPTORS[d.name].lo, DESCRIPTORS[d.name].hi)
        ]
        if list(cfg["search.ranges"]) != ranges and not (not list(cfg["search.ranges"]) and table == ranges):
            cfg["search.ranges"] = ranges
        if isinstance(archive, GridArchive):
            cfg["search.archive"] = "grid"
            bins = [float(b) for b in archive.bins]
            given = [float(b) for b in cfg["search.bins"]]
            if given != bins and not (len(given) == 1 and bins == given * len(bins)):
                cfg["search.bins"] = bins
        else:
            cfg["search.archive"] = "cvt"
            cfg["search.cells"] = archive.cells
            if (int(cfg["search.samples"]) or max(1000, 20 * archive.cells)) != archive.samples:
                cfg["search.samples"] = archive.samples
        if self.batch != (int(cfg["search.batch"]) or int(cfg["evolution.population"])):
            cfg["search.batch"] = self.batch
        return cfg, names

    # --- the loop ---------------------------------------------------------------------------------
    def tell(self, results: Sequence[Any], descriptors: Optional[Sequence[Optional[Values]]] = None) -> Any:
        """The result of every genome of the last ``ask()``, in order (see the class docstring);
        completes the generation and returns its history row (a numpy record)."""
        if self._asked is None:
            raise RuntimeError("MapElites.tell: nothing was asked (call ask() first)")
        genomes = self._asked
        if len(results) != len(genomes):
            raise ValueError(f"MapElites.tell: {len(results)} results for the {len(genomes)} genomes asked")
        if descriptors is not None and len(descriptors) != len(genomes):
            raise ValueError(f"MapElites.tell: {len(descriptors)} descriptor rows for {len(genomes)} genomes")
        told, rows = self._told(genomes, results, descriptors)
        self._engine.tell(told, rows)
        self._asked = None
        self._refresh()
        return self.history[-1]

    def _told(
        self, genomes: List[Any], results: Sequence[Any], descriptors: Optional[Sequence[Optional[Values]]]
    ) -> Tuple[List[Any], List[List[float]]]:
        """What the engine is told of ``results``: a Fitness and the descriptors' values for each (a
        row of NaN and a Fitness that cannot enter for a candidate without descriptors)."""
        fits = []
        for i, r in enumerate(results):
            if isinstance(r, (str, bytes)):
                raise TypeError(f"MapElites.tell: value {i} ({r!r:.60}) is a string; tell a number, None or a Fitness")
            try:
                fit = to_fitness(r)
            except (TypeError, ValueError) as e:
                raise type(e)(f"MapElites.tell: value {i} ({r!r:.60}): {e}") from None
            fits.append(fit)
        told, rows = [], []
        for i, (genome, fit, raw) in enumerate(zip(genomes, fits, results)):
            values = None
            if fit.viable and fit.stable and fit.valid:
                values = self._values(i, genome, fit, raw, descriptors)
            if values is None:
                told.append(fit if not (fit.viable and fit.stable and fit.valid) else _not_archivable(fit))
                rows.append([math.nan] * self._width)
                continue
            told.append(fit)
            rows.append(values.tolist())
        return told, rows

    def _values(
        self, i: int, genome: Any, fit: Any, raw: Any, rows: Optional[Sequence[Optional[Values]]]
    ) -> Optional[np.ndarray]:
        """The descriptor values of candidate i (None: it has none and is not archived)."""
        ds = self.archive.descriptors
        if rows is not None:
            if rows[i] is None:
                return None
            values = np.asarray(rows[i], dtype=np.float64).reshape(-1)
            if len(values) != len(ds):
                raise ValueError(
                    f"MapElites.tell: descriptor row {i} has {len(values)} values for the "
                    f"{len(ds)} descriptors {self.archive.names}"
                )
        elif isinstance(raw, (_core.Fitness, _core.EvaluationResult)):
            subject = _Subject(genome, self._config, raw)
            values = np.array(
                [
                    _FITNESS_MEASURES[d.name](fit)
                    if d.name in _FITNESS_MEASURES and _is_table_entry(d)
                    else d._value(subject)
                    for d in ds
                ],
                dtype=np.float64,
            )
        else:
            measured = measure(genome, self._config, ds, fit)
            if measured is None:
                return None
            values = measured
        return None if np.isnan(values).any() else values

    def _refresh(self) -> None:
        """Makes :attr:`archive` the engine's elites (``SearchEngine.elites()``)."""
        self.archive.clear()
        for e in self._engine.elites():
            index = int(e["index"])
            self.archive._put(
                Elite(
                    index,
                    e["genome"],
                    float(e["fitness"].fitness),
                    float(e["objective"]),
                    tuple(float(x) for x in e["values"]),
                    float(e["reference"]),
                    int(e["generation"]),
                )
            )

    def _references(self, genomes: List[Any]) -> Tuple[List[Any], List[List[float]]]:
        """The exploit guard's swims (the engine's hook): every genome at the reference step, scored
        by the search's objective; the descriptors stay those of the run's step."""
        return list(self._evaluate(list(genomes), _core.reference_config(self._config))), []

    def step(self, evaluate: Optional[Callable[[List[Any]], Sequence[Any]]] = None) -> Any:
        """Ask, evaluate (default: :func:`animat.evaluate_population` with the config's threads and the
        objective; over the MPI ranks under ``run_map_elites(..., mpi=True)``) and tell one generation;
        returns its history row. The descriptors every evaluation measures are read from its Fitness,
        the table's others (``locomotion``) computed where each genome swam, from the body its
        evaluation built; your own functions are called here."""
        genomes = self.ask()
        if evaluate is not None:
            return self.tell(list(evaluate(genomes)))
        fits, rows = self._swim_and_describe(genomes)
        return self.tell(fits, descriptors=rows)

    def _swim_and_describe(self, genomes: List[Any]) -> Tuple[List[Any], List[Optional[np.ndarray]]]:
        """Every genome's Fitness and descriptor values (None when it is not a candidate)."""
        names = _worker_descriptors(self.archive.descriptors)
        pairs = self._evaluate(genomes, self._config, describe=names) if names else None
        fits = [p[0] for p in pairs] if pairs is not None else self._evaluate(genomes, self._config)
        rows: List[Optional[np.ndarray]] = []
        for i, (genome, fit) in enumerate(zip(genomes, fits)):
            if not (fit.viable and fit.stable and fit.valid):
                rows.append(None)  # not a candidate: tell() skips it before reading its row
                continue
            done = dict(zip(names, pairs[i][1])) if pairs is not None else {}
            subject = _Subject(genome, self._config, fit)
            rows.append(
                np.array(
                    [
                        done[d.name]
                        if d.name in done
                        else _FITNESS_MEASURES[d.name](fit)
                        if d.name in _FITNESS_MEASURES and _is_table_entry(d)
                        else d._value(subject)
                        for d in self.archive.descriptors
                    ],
                    dtype=np.float64,
                )
            )
        return fits, rows

    def _run_hooks(
        self,
    ) -> Tuple[Callable[[List[Any]], List[Any]], Callable[[List[Any], List[Any]], List[List[float]]]]:
        """The engine's evaluate and describe hooks of a run (:func:`run_map_elites`): one
        generation's swims as :meth:`step` swims them, and the descriptor rows of the same swims."""
        rows: List[List[float]] = []

        def evaluate(genomes: List[Any]) -> List[Any]:
            fits, values = self._swim_and_describe(list(genomes))
            told, rows[:] = self._told(list(genomes), fits, values)
            return told

        return evaluate, lambda genomes, fitness: rows

    # --- state ------------------------------------------------------------------------------------
    @property
    def history(self) -> np.recarray:
        """One row per generation (:data:`QD_HISTORY_DTYPE`): ``h["qd_score"]``, ``h[-1].coverage`` ..."""
        columns = QD_HISTORY_DTYPE.names or ()
        rows = []
        for row in self._engine.history:
            values = [
                int(x) if QD_HISTORY_DTYPE[j].kind == "i" else float(x) for j, x in enumerate(row[: len(columns)])
            ]
            values[2] -= self.archive.qd_offset * values[5]  # the engine sums objectives with no offset
            rows.append(tuple(values))
        return np.array(rows, dtype=QD_HISTORY_DTYPE).view(np.recarray)

    def checkpoint(self) -> Dict[str, Any]:
        """The whole state as a JSON-able dict (``json.dumps`` it; :meth:`restore` reads it back): the
        engine's checksummed checkpoint (``engine``; None before the first ``tell``), the run's config
        and the archive's definition, under a SHA-256 ``checksum`` of the rest. A pending ``ask()`` is
        not saved: asking again after a restore gives the same genomes."""
        state: Dict[str, Any] = {
            "format": CHECKPOINT_FORMAT,
            "config": self._config.to_toml(),
            "batch": self.batch,
            "archive": {k: v for k, v in self.archive.state().items() if k != "elites"},
            "engine": self._engine.checkpoint() if self._engine.generation >= 0 else None,
        }
        state["checksum"] = _checksum(state)
        return state

    @classmethod
    def restore(
        cls,
        state: Union[Mapping[str, Any], str, bytes],
        config: Any = None,
        *,
        objective: ObjectiveLike = None,
        descriptors: Iterable[DescriptorLike] = (),
        threads: Optional[int] = None,
        source: str = "checkpoint",
    ) -> MapElites:
        """A MapElites from :meth:`checkpoint` (a dict, or its JSON text). ``config``: default the saved
        one; another must equal it but for ``evolution.threads`` (ValueError). ``descriptors``: your own
        descriptor functions, by name (see :meth:`GridArchive.from_state`). A checkpoint that is not
        one, was edited or is inconsistent is a ValueError naming ``source`` (the file, for
        :meth:`load`), and the engine checks its own part (checksum, identity, elites, history)."""
        try:
            state = _checked_state(state, CHECKPOINT_FORMAT, "a MapElites")
            saved = _core.Config.from_toml(state["config"], source)
            definition = {**state["archive"], "elites": []}
            batch = int(state["batch"])
            engine_text = state["engine"]
        except (ValueError, KeyError, TypeError, AttributeError) as e:
            raise ValueError(f"{source}: {e}") from None
        if config is None:
            config = saved
        else:
            _same_config(config, saved, objective, source)
        archive = _Archive.from_state(definition, descriptors)
        me = cls(config, archive, batch=batch, seed=int(saved["evolution.seed"]), objective=objective, threads=threads)
        if engine_text is not None:
            me._engine.restore(engine_text, source)
            me._refresh()
        return me

    @classmethod
    def _from_run(
        cls,
        path: Path,
        run: Any,
        config: Any = None,
        *,
        objective: ObjectiveLike = None,
        descriptors: Iterable[DescriptorLike] = (),
        threads: Optional[int] = None,
    ) -> MapElites:
        """The search of a run directory's config ``run``, not yet restored: its archive from
        [search] (your own descriptor functions by name in ``descriptors``; a CVT archive's centroids
        from the checkpoint). ``config``: must be the run's but for the keys a run may change."""
        source = str(path / "config.toml")
        _holds(run, "map_elites", source)
        if config is not None:
            _same_config(config, run, objective, source)
        names = [str(n) for n in run["search.descriptors"]]
        ranges = [float(x) for x in run["search.ranges"]]
        own = {d.name: d for d in map(_descriptor, descriptors)}
        ds = []
        for j, name in enumerate(names):
            d = own.get(name, DESCRIPTORS.get(name))
            if d is None:
                raise ValueError(
                    f"{source}: search.descriptors names {name!r}, not in animat.qd.DESCRIPTORS: pass your "
                    "descriptor function again (descriptors=[...])"
                )
            ds.append(d.with_range(ranges[2 * j], ranges[2 * j + 1]) if ranges else d)
        archive: _Archive
        if str(run["search.archive"]) == "cvt":
            state = _engine_checkpoint(path)
            try:
                unit = np.asarray(state["centroids"], dtype=np.float64)
            except (KeyError, TypeError, ValueError):
                raise ValueError(f"{path / 'checkpoint.json'}: a CVT run's checkpoint without its centroids") from None
            samples = int(run["search.samples"]) or max(1000, 20 * len(unit))
            archive = CVTArchive._with_centroids(ds, unit, int(run["evolution.seed"]), samples, 0.0)
        else:
            bins = [int(b) for b in run["search.bins"]]
            archive = GridArchive(ds, bins[0] if len(bins) == 1 else bins)
        batch = int(run["search.batch"]) or int(run["evolution.population"])
        return cls(run, archive, batch=batch, objective=objective, threads=threads)

    def __reduce__(self) -> Tuple[Any, ...]:
        # Pickles as its checkpoint, with the Python objective and your own descriptor functions.
        return (_restore, (self.checkpoint(), self._objective, self.archive._own_descriptors()))

    def __repr__(self) -> str:
        return f"<animat.MapElites generation {self.generation}, batch {self.batch}, {self.archive!r}>"


def _reference_hook(search: _SearchState) -> Callable[[List[Any]], Tuple[List[Any], List[List[float]]]]:
    """The search's ``_references`` (the exploit guard's swims, the engine's reference hook) through a
    weak reference: the engine holds the hook, and a cycle through it would keep both alive (the
    garbage collector does not see into the engine)."""
    owner = weakref.ref(search)

    def references(genomes: List[Any]) -> Tuple[List[Any], List[List[float]]]:
        return cast(_SearchState, owner())._references(genomes)

    return references


def _restore(
    state: Mapping[str, Any], objective: Optional[Objective], descriptors: Tuple[Descriptor, ...]
) -> MapElites:
    return MapElites.restore(state, objective=objective, descriptors=descriptors)


# --- the run directory ----------------------------------------------------------------------------

_RUN_FILES = ("config.toml", "history.csv", "checkpoint.json")


def _history_csv(history: np.ndarray) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    dtype = history.dtype
    names = list(dtype.names or ())
    w.writerow(names)
    for row in history:
        w.writerow([repr(float(row[n])) if dtype[n].kind == "f" else int(row[n]) for n in names])
    return buf.getvalue()


def _on_ranks(
    what: str, mpi: bool, swim: Swim, restore: Callable[[Any], Any], run: Callable[[Optional[Swim]], Any]
) -> Any:
    """``run(None)``, or with ``mpi`` ``run(pool)`` on rank 0 of COMM_WORLD with an :class:`MpiPool`
    that swims over every rank with ``swim`` (:mod:`animat.pool`), while the other ranks serve it and
    return ``restore(checkpoint)`` of the final state. Every rank calls this."""
    if not mpi:
        return run(None)
    from .experiment import _mpi_world

    comm = _mpi_world()
    if comm.Get_rank() != 0:
        return restore(serve(comm, swim, what))
    pool = MpiPool(comm, swim, what)
    try:
        search = run(pool)
    except BaseException as e:
        pool.abort(e)
        raise
    pool.stop(search.checkpoint())
    return search


def _run_search(
    what: str,
    out: PathLike,
    snapshots: str,
    every: int,
    generations: int,
    *,
    resume: bool,
    overwrite: bool,
    load: Callable[[Path], Any],
    new: Callable[[], Any],
    check_new: Callable[[], None],
    write_snapshot: Callable[[Any, Path], Any],
    callback: Optional[Callable[[Any], Optional[bool]]],
    pool: Optional[Swim] = None,
) -> Any:
    """The run directory of a search (MAP-Elites, NSGA-II), written by the engine's run layer as
    ``animat_evolve`` writes it (``SearchEngine.run``: the lock, the checked checkpoint, the resume's
    config comparison): ``config.toml``, ``history.csv``, ``checkpoint.json``; and here
    ``<snapshots>/gen_NNNNNN.csv`` every ``every`` generations and at the last. ``load(out)``: the
    search of the run's config.toml, not yet restored (the engine restores it); every refusal comes
    before any file is touched. ``pool``: where the search swims meanwhile (default its threads)."""
    if resume and overwrite:
        raise ValueError(f"{what}: resume=True and overwrite=True contradict each other")
    if every < 1:
        raise ValueError(f"{what}: {snapshots}_every must be >= 1, got {every}")
    if generations < 0:
        raise ValueError(f"{what}: generations must be >= 0, got {generations}")
    out = Path(out)
    if resume:
        if not (out / "checkpoint.json").is_file():
            raise FileNotFoundError(f"{out / 'checkpoint.json'}: no checkpoint to resume")
        search = load(out)
        if int(_engine_checkpoint(out).get("generation", -1)) >= generations:
            # there already: nothing to run, no file is written
            search._engine.restore((out / "checkpoint.json").read_text(encoding="utf-8"), str(out / "checkpoint.json"))
            search._refresh()
            return search
    else:
        has_run = any((out / f).exists() for f in _RUN_FILES) or (out / snapshots).exists()
        if has_run and not overwrite:
            raise FileExistsError(f"{out} holds a run: pass resume=True or overwrite=True")
        check_new()
        search = new()  # its sizes are checked here, before any file is touched

    stepped: List[int] = []

    def after(generation: int) -> bool:
        search._refresh()
        stepped.append(generation)
        last = generation >= generations
        (out / snapshots).mkdir(exist_ok=True)
        snapshot = out / snapshots / f"gen_{generation:06d}.csv"
        if generation % every == 0 or last:
            write_snapshot(search, snapshot)
        if callback is not None and callback(search.history[-1]) is False:
            write_snapshot(search, snapshot)
            return False
        return not last

    evaluate, describe = search._run_hooks()
    search._pool = pool
    try:
        search._engine.run(
            search._config,
            str(out),
            resume=resume,
            overwrite=overwrite,
            evaluate=evaluate,
            describe=describe,
            callback=after,
        )
    finally:
        search._pool = None
    search._refresh()
    if stepped and stepped[-1] == search.generation:
        # stopped by the engine's stall or wall-clock rule: the last generation's snapshot too
        snapshot = out / snapshots / f"gen_{search.generation:06d}.csv"
        if not snapshot.exists():
            write_snapshot(search, snapshot)
    return search


def _run_config(path: Path, generations: Optional[int] = None) -> Any:
    """A run directory's config (its config.toml), for a run to ``generations`` if given."""
    source = path / "config.toml"
    try:
        text = source.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise FileNotFoundError(f"{source}: the run directory has a checkpoint but no config.toml") from None
    config = _core.Config.from_toml(text, str(source))
    if generations:
        config["evolution.generations"] = generations
    return config


def _holds(run: Any, algorithm: str, source: str) -> None:
    """Refuses a run directory's config ``run`` whose search is not ``algorithm``."""
    if str(run["search.algorithm"]) != algorithm:
        raise ValueError(
            f'{source}: search.algorithm = "{run["search.algorithm"]}": the run directory holds a '
            f"{run['search.algorithm']} run, not a {algorithm} one (animat evolve --resume continues any)"
        )


def _engine_checkpoint(path: Path) -> Mapping[str, Any]:
    """The JSON of the engine checkpoint a run directory holds (checked when it is restored)."""
    source = path / "checkpoint.json"
    try:
        state = json.loads(source.read_text(encoding="utf-8"))
        if not isinstance(state, dict):
            raise ValueError("not a JSON object")
        payload = json.loads(state["payload"])
        if not isinstance(payload, dict):
            raise ValueError("its payload is not a JSON object")
    except (ValueError, KeyError, TypeError) as e:
        raise ValueError(f"{source}: not an animat checkpoint: {e}") from None
    return cast(Mapping[str, Any], payload)


def run_map_elites(
    config: Any,
    out: PathLike,
    generations: int,
    archive: Optional[Union[GridArchive, CVTArchive]] = None,
    *,
    batch: Optional[int] = None,
    initial: Optional[int] = None,
    seed: Optional[int] = None,
    objective: ObjectiveLike = None,
    crossover_fraction: Optional[float] = None,
    threads: Optional[int] = None,
    archive_every: int = 10,
    resume: bool = False,
    overwrite: bool = False,
    descriptors: Iterable[DescriptorLike] = (),
    callback: Optional[Callable[[Any], Optional[bool]]] = None,
    mpi: bool = False,
) -> MapElites:
    """Run MAP-Elites up to generation ``generations`` (generation 0 is the initial batch, as
    ``evolution.generations`` counts; the engine's stall and wall-clock rules may stop it before) in
    the run directory ``out``, through the engine's run layer (``SearchEngine.run``), the format
    ``animat_evolve`` writes and resumes (docs/search.md):

    - ``config.toml``: the run's config (its ``evolution.seed`` is the run's seed; its [search]
      section the archive and batch; ``evolution.generations`` the cap);
    - ``history.csv``: :data:`QD_HISTORY_DTYPE`'s columns (``generation, evaluations, qd_score,
      coverage, best, ...``) and ``wall_seconds``, one row per generation (``qd_score`` with no
      offset);
    - ``archive/gen_NNNNNN.csv``: the archive after every ``archive_every``-th generation and the last
      (:meth:`GridArchive.write_csv`: one row per elite);
    - ``checkpoint.json``: the engine's checkpoint, every ``evolution.checkpoint_every`` generations
      and at the end; ``resume=True`` continues from it (then ``archive`` may be None; your own
      descriptor functions go in ``descriptors``) and gives the very run an uninterrupted one gives.

    A new run without ``archive`` searches the grid of the config's ``search.descriptors`` and
    ``search.bins`` (:meth:`GridArchive.from_config`), with ``search.batch`` offspring per generation
    unless ``batch`` is given: a config with ``search.algorithm = "map_elites"`` defines the whole run,
    as ``animat evolve --config FILE`` runs it. The run's ``config.toml`` records the search it is.

    ``callback(row)`` is called after every generation; returning False stops (checkpointed). Returns
    the :class:`MapElites`. A directory that holds a run is refused (FileExistsError) unless ``resume``
    or ``overwrite`` (which removes the files above and ``archive/``, nothing else). On a resume, an
    ``archive``, ``batch``, ``initial``, ``seed`` or ``crossover_fraction`` that is given must be the
    run's (ValueError), as the config must (but for ``evolution.threads``).

    ``mpi=True``: the swims run on the ranks of an MPI job (mpi4py; :mod:`animat.pool`): start every
    rank with the same call (``mpirun -np R python script.py``). Rank 0 runs the search, writes ``out``
    and calls ``callback``; every rank swims a share of each batch on ``threads`` threads. The run is
    bit-identical to the one without MPI, for any number of ranks. Every rank returns the final
    :class:`MapElites`; an error on any rank raises on rank 0 and stops all
    (:class:`animat.pool.MpiAbort` on the others).
    """
    extra = tuple(descriptors) + (tuple(archive.descriptors) if archive is not None else ())

    def load(path: Path) -> MapElites:
        # the run's config first: a given archive is then compared with the run's by name
        own = threads if threads is not None or config is None else int(config["evolution.threads"])
        me = MapElites._from_run(
            path, _run_config(path, generations), config, objective=objective, descriptors=extra, threads=own
        )
        _same_as_run(
            "run_map_elites",
            archive=(None if archive is None else _archive_definition(archive), _archive_definition(me.archive)),
            batch=(batch, me.batch),
            initial=(initial, me.initial),
            seed=(seed, me.seed),
            crossover_fraction=(crossover_fraction, me.crossover_fraction),
        )
        return me

    def check_new() -> None:
        if archive is None:
            GridArchive.from_config(config)  # the names and bins, before any file is written

    def new() -> MapElites:
        from_config = int(config["search.batch"]) or None
        run = _config_for(config, _objective(objective))
        if generations > 0:  # 0: no cap in the config; the run stops after generation 0
            run["evolution.generations"] = generations
        return MapElites(
            run,
            archive if archive is not None else GridArchive.from_config(config),
            batch=batch if batch is not None else from_config,
            initial=initial,
            seed=seed,
            objective=objective,
            crossover_fraction=crossover_fraction,
            threads=threads,
        )

    def run(pool: Optional[Swim]) -> MapElites:
        return _run_search(
            "run_map_elites",
            out,
            "archive",
            archive_every,
            generations,
            resume=resume,
            overwrite=overwrite,
            load=load,
            new=new,
            check_new=check_new,
            write_snapshot=lambda me, path: me.archive.write_csv(path),
            callback=callback,
            pool=pool,
        )

    def restore(state: Any) -> MapElites:
        return MapElites.restore(state, objective=objective, descriptors=extra, threads=threads)

    return cast(MapElites, _on_ranks("run_map_elites", mpi, _fitnesses(_python_objective(objective)), restore, run))


def _same_as_run(what: str, **given: Tuple[Any, Any]) -> None:
    """Refuse a resume given an argument (``name=(given, the run's)``; None: not given) that is not the
    run's: it would be ignored."""
    for name, (mine, run) in given.items():
        if mine is not None and mine != run:
            raise ValueError(
                f"{what}: {name} {mine!r} is not the run's {run!r}: a resume continues the run as it was started"
            )


def _archive_definition(archive: _Archive) -> str:
    """An archive's cells in words (its kind, descriptors, ranges, bins or centroids), not its elites."""
    ranges = ", ".join(f"{d.name} [{d.lo!r}, {d.hi!r}]" for d in archive.descriptors)
    geometry = {k: v for k, v in archive._geometry().items() if k not in ("centroids", "seed", "samples")}
    if isinstance(archive, CVTArchive):
        # its cells are its centroids (however drawn): named by a digest
        geometry["cells"] = archive.cells
        geometry["centroids"] = "sha256:" + hashlib.sha256(archive._unit.tobytes()).hexdigest()[:12]
    if archive.qd_offset:
        geometry["qd_offset"] = archive.qd_offset
    return f"{archive.kind} archive of {ranges}, " + ", ".join(f"{k} {v!r}" for k, v in geometry.items())
