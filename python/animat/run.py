"""Reading run directories written by ``animat_evolve`` / ``animat.evolve(config, out=DIR)``.

A run directory holds::

    config.toml       the full resolved config of the run
    history.csv       one row per generation, appended as the run goes
    best/gen_NNNNNN.json
                      the lineage: the best genome each time it changed
    checkpoint.json   the state to resume from (absent in the first moments of a run)

:class:`Run` reads all of it, including runs that are still going (a half-written last line of
``history.csv`` is ignored, and a missing checkpoint is fine).
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any, List, Optional, Tuple, Union

import numpy as np

from . import _core

__all__ = [
    "Run",
    "LineageEntry",
    "HISTORY_DTYPE",
    "PROTECTED_HISTORY_DTYPE",
    "read_history",
    "morphology_distance",
    "MORPHOLOGY_TOLERANCE",
]

#: Columns of ``history.csv`` and their numpy types (the dtype of :attr:`Run.history`), from the
#: engine's descriptor of a generation's statistics (``GenerationStats.HISTORY_COLUMNS``).
HISTORY_DTYPE = np.dtype([(name, np.dtype(kind)) for name, kind in _core.GenerationStats.HISTORY_COLUMNS])
#: The history of a run with morphological innovation protection (``evolution.protection_generations``
#: > 0): :data:`HISTORY_DTYPE` plus ``protected`` (int64: viable individuals whose morphology is younger
#: than the protection), before ``wall_seconds``. Other runs write and read :data:`HISTORY_DTYPE` as
#: before the protection existed.
PROTECTED_HISTORY_DTYPE = np.dtype(
    [(name, np.dtype(kind)) for name, kind in _core.GenerationStats.PROTECTED_HISTORY_COLUMNS]
)


def history_dtype(protected: bool = False) -> np.dtype:
    """:data:`PROTECTED_HISTORY_DTYPE` for a run with protection, else :data:`HISTORY_DTYPE`."""
    return PROTECTED_HISTORY_DTYPE if protected else HISTORY_DTYPE


#: Columns that older runs do not have, and the value they read as.
_LATER_COLUMNS = {"best_reference": float("nan"), "invalid": 0, "drag_limited": 0, "swims": 0}
#: The headers of earlier releases: before the exploit guard, before the drag limiter's column, and
#: before the swims column.
_OLDER_HEADERS = ({"best_reference", "invalid", "drag_limited", "swims"}, {"drag_limited", "swims"}, {"swims"})

_LINEAGE_NAME = re.compile(r"^gen_(\d+)\.json$")

PathLike = Union[str, "Path"]


@dataclass(frozen=True)
class LineageEntry:
    """One improvement of the best genome: the file ``best/gen_NNNNNN.json`` of a run.

    Attributes:
        generation: the generation at which this genome became the best (int).
        fitness: its fitness, the distance travelled by its centre of mass (float).
        cell_count: cells of its embryo (int).
        genome: the :class:`animat.Genome`.
        path: the JSON file it was read from.
        reference_fitness: its fitness at the exploit guard's reference step (float; NaN when the
            run did not check it).
        id: its id in the run's genealogy (:meth:`Run.genealogy`); -1 in runs made before ids.
    """

    generation: int
    fitness: float
    cell_count: int
    genome: Any
    path: Path
    reference_fitness: float = float("nan")
    id: int = -1

    def develop(self, config: Optional[Any] = None):
        """Develop the genome (``animat.develop``) with ``config`` (default: the animat defaults)."""
        return _core.develop(self.genome, config)

    def __repr__(self) -> str:
        return f"<LineageEntry generation={self.generation} fitness={self.fitness:.6g} cells={self.cell_count}>"


def _history_type() -> type:
    from .evolution import History  # evolution.py imports this module

    return History


def read_history(path: PathLike) -> np.ndarray:
    """Read a ``history.csv`` into a structured array of dtype :data:`HISTORY_DTYPE` (that of a run
    with morphological innovation protection, which has a ``protected`` column: :data:`PROTECTED_HISTORY_DTYPE`).

    The file must start with the header ``generation,best,...``. A last line without its newline
    (a row being written by a run in progress) is ignored. Any other malformed line raises
    ValueError naming the file and the line number. A missing file raises FileNotFoundError.

    Returns:
        :class:`animat.History` (a numpy structured array with ``.to_pandas()``), shape (rows,), one
        row per completed generation; fields
        ``generation`` (int64), ``best``, ``mean``, ``median``, ``viable_fraction`` (float64),
        ``best_cells``, ``evaluations`` (int64, cumulative, developments included), ``swims`` (int64: this
        generation's evaluations that swam), ``best_reference`` (float64: the best's fitness at
        the exploit guard's reference step, NaN when not evaluated), ``invalid`` (int64: viable
        individuals whose swim was unstable or broke an invariant), ``wall_seconds`` (float64, the
        only machine-dependent column, always last). Runs written before ``best_reference`` and
        ``invalid`` existed read with NaN and 0 there, and those before ``drag_limited`` and ``swims``
        with 0 there.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such file (a run directory has a history.csv after its first generation)")
    text = path.read_text(encoding="utf-8", errors="replace")
    lines = text.split("\n")
    # `text` ends with "\n" when complete: the last element is then "". Otherwise it is a partial row.
    complete = lines[:-1]
    expected = list(HISTORY_DTYPE.names or ())
    if not complete:
        if lines[0] and not ",".join(expected).startswith(lines[0]):
            raise ValueError(f"{path}:1: not a history.csv header: {lines[0]!r}")
        return np.zeros(0, dtype=HISTORY_DTYPE).view(_history_type())  # empty or header being written
    header = complete[0].strip().split(",")
    olders = [[name for name in expected if name not in missing] for missing in _OLDER_HEADERS]
    dtype = HISTORY_DTYPE
    if header == list(PROTECTED_HISTORY_DTYPE.names or ()):
        dtype = PROTECTED_HISTORY_DTYPE
        expected = header
    elif header != expected and header not in olders:
        raise ValueError(f"{path}:1: unexpected header {complete[0].strip()!r}; expected {','.join(expected)!r}")
    column = {name: k for k, name in enumerate(header)}
    rows = []
    for number, line in enumerate(complete[1:], start=2):
        if not line.strip():
            continue
        fields = line.strip().split(",")
        if len(fields) != len(header):
            raise ValueError(
                f"{path}:{number}: expected {len(header)} comma-separated values, got {len(fields)}: {line!r}"
            )
        try:
            rows.append(
                tuple(
                    _LATER_COLUMNS[name]
                    if name not in column
                    else int(fields[column[name]])
                    if dtype[name].kind == "i"
                    else float(fields[column[name]])
                    for name in expected
                )
            )
        except ValueError:
            raise ValueError(f"{path}:{number}: not a number in {line!r}") from None
    return np.array(rows, dtype=dtype).view(_history_type())


def _read_lineage_file(path: Path) -> LineageEntry:
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as e:
        raise ValueError(f"{path}: not valid JSON ({e})") from None
    if not isinstance(data, dict):
        raise ValueError(f"{path}: expected a JSON object with generation, fitness, cell_count and genome")
    missing = [k for k in ("generation", "fitness", "cell_count", "genome") if k not in data]
    if missing:
        raise ValueError(f"{path}: missing field(s) {', '.join(missing)}")
    try:
        genome = _core.Genome.from_json(json.dumps(data["genome"]))
    except ValueError as e:
        raise ValueError(f"{path}: invalid genome: {e}") from None
    reference = data.get("reference_fitness")
    return LineageEntry(
        int(data["generation"]),
        float(data["fitness"]),
        int(data["cell_count"]),
        genome,
        path,
        float("nan") if reference is None else float(reference),
        int(data.get("id", -1)),
    )


#: One row of ``genealogy.csv``: an individual's birth.
GENEALOGY_DTYPE = np.dtype(
    [
        ("generation", np.int64),
        ("id", np.int64),
        ("parent_a", np.int64),
        ("parent_b", np.int64),
        ("fitness", np.float64),
        ("cells", np.int64),
    ]
)
#: ``genealogy.csv`` of a run with morphological innovation protection (``evolution.protection_generations``
#: > 0): :data:`GENEALOGY_DTYPE` plus each newborn's ``morphology_kind`` and ``morphology_age`` (0: a kind
#: neither parent had; else its parent's age + 1).
PROTECTED_GENEALOGY_DTYPE = np.dtype(
    GENEALOGY_DTYPE.descr + [("morphology_kind", np.int64), ("morphology_age", np.int64)]
)


def read_genealogy(path: PathLike) -> np.ndarray:
    """``genealogy.csv`` as a structured array (:data:`GENEALOGY_DTYPE`, or :data:`PROTECTED_GENEALOGY_DTYPE`
    for a run with protection), one row per individual born.

    Raises ValueError naming the file and line for a malformed file.
    """
    path = Path(path)
    dtype = GENEALOGY_DTYPE
    names: Tuple[str, ...] = GENEALOGY_DTYPE.names or ()
    with open(path, encoding="utf-8") as fh:
        header = fh.readline().strip()
        if header.split(",") == list(PROTECTED_GENEALOGY_DTYPE.names or ()):
            dtype = PROTECTED_GENEALOGY_DTYPE
            names = PROTECTED_GENEALOGY_DTYPE.names or ()
        elif header.split(",") != list(names):
            raise ValueError(f"{path}:1: expected the header {','.join(names)}, got {header!r}")
        rows = []
        for number, line in enumerate(fh, start=2):
            fields = line.strip().split(",")
            if fields == [""]:
                continue
            if len(fields) != len(names):
                raise ValueError(f"{path}:{number}: expected {len(names)} fields, got {len(fields)} in {line!r}")
            try:
                rows.append(tuple(float(v) if k == "fitness" else int(v) for k, v in zip(names, fields)))
            except ValueError:
                raise ValueError(f"{path}:{number}: not a number in {line!r}") from None
    return np.array(rows, dtype=dtype)


def morphology_distance(a, b) -> float:
    """How different two morphologies are: the RMS distance between corresponding cells after the
    best rigid alignment (translation and rotation, no reflection) of ``b`` onto ``a``.

    ``a`` and ``b`` are (n, 2) position arrays or anything with ``.positions`` (Body, Embryo).
    Cells correspond by index (cell i is the i-th cell of development). Returns inf when the
    cell counts differ. Units: the simulation's length unit (a cell diameter is about 1).
    """
    pa = np.asarray(getattr(a, "positions", a), dtype=np.float64)
    pb = np.asarray(getattr(b, "positions", b), dtype=np.float64)
    if pa.shape != pb.shape:
        return float("inf")
    if len(pa) == 0:
        return 0.0
    pa = pa - pa.mean(axis=0)
    pb = pb - pb.mean(axis=0)
    u, _, vt = np.linalg.svd(pb.T @ pa)
    d = np.sign(np.linalg.det(u @ vt)) or 1.0
    rot = u @ np.diag([1.0, d]) @ vt
    return float(np.sqrt(np.mean(np.sum((pb @ rot - pa) ** 2, axis=1))))


#: Default tolerance of :meth:`Run.morphology_changes` (length units; a cell diameter is about 1).
MORPHOLOGY_TOLERANCE = 0.25


class Run:
    """A run directory, read-only.

    ``Run(path)`` checks that ``path`` is a directory with a readable ``config.toml``; everything
    else is read when asked for, and read again every time, so a run in progress can be followed
    by re-reading :attr:`history` and :attr:`best_genomes`.

    Raises:
        FileNotFoundError: ``path`` or its ``config.toml`` does not exist.
        ValueError: ``config.toml`` is not a valid config (the message names file, line and key).

    Example::

        run = animat.Run("runs/demo")
        run.history["best"]            # best fitness per generation, (generations,) float64
        entry = run.best()             # LineageEntry of the best genome so far
        traj = animat.replay(entry.genome, run.config)
    """

    def __init__(self, path: PathLike):
        self.path = Path(path)
        if not self.path.exists():
            raise FileNotFoundError(f"{self.path}: no such run directory")
        if not self.path.is_dir():
            raise NotADirectoryError(f"{self.path}: not a directory (expected a run directory)")
        config_path = self.path / "config.toml"
        if not config_path.is_file():
            raise FileNotFoundError(
                f"{config_path}: missing; {self.path} is not a run directory written by animat_evolve "
                "(expected config.toml, history.csv, best/)"
            )
        self._config = _core.load_config(str(config_path))

    @property
    def config(self):
        """The run's :class:`animat.Config` (from ``config.toml``; a copy, so edits do not stick)."""
        return self._config.copy()

    @property
    def history(self) -> np.ndarray:
        """Per-generation statistics from ``history.csv`` (structured array, see :func:`read_history`).

        Empty (shape (0,)) when the run has not finished generation 0 yet. Read afresh on every
        access. Columns: ``run.history["best"]`` etc.; rows: ``run.history[-1]``.
        """
        path = self.path / "history.csv"
        if not path.exists():
            return np.zeros(0, dtype=HISTORY_DTYPE).view(_history_type())
        return read_history(path)

    @property
    def best_genomes(self) -> List[LineageEntry]:
        """The lineage of best genomes, oldest first: one :class:`LineageEntry` per ``best/gen_*.json``.

        Each entry is the genome that became the best at that generation. Read afresh on every
        access; a malformed file raises ValueError naming it.
        """
        folder = self.path / "best"
        if not folder.is_dir():
            return []
        files = sorted(p for p in folder.iterdir() if _LINEAGE_NAME.match(p.name))
        return [_read_lineage_file(p) for p in files]

    def best(self) -> LineageEntry:
        """The current best: the last entry of :attr:`best_genomes`.

        Raises ValueError when the run has no lineage yet (``best/`` is empty or missing).
        """
        lineage = self.best_genomes
        if not lineage:
            raise ValueError(f"{self.path / 'best'}: no gen_*.json yet (the run has not finished generation 0)")
        return lineage[-1]

    @property
    def checkpoint(self) -> Optional[dict]:
        """``checkpoint.json`` as a dict, or None when there is none yet."""
        path = self.path / "checkpoint.json"
        if not path.is_file():
            return None
        try:
            return json.loads(path.read_text(encoding="utf-8"))
        except json.JSONDecodeError as e:
            raise ValueError(f"{path}: not valid JSON ({e})") from None

    @property
    def generations(self) -> int:
        """Completed generations recorded in ``history.csv`` (0 before generation 0 is done)."""
        return len(self.history)

    def summary(self) -> str:
        """A few human-readable lines: path, generations, best fitness and its lineage."""
        h = self.history
        lineage = self.best_genomes
        lines = [f"run {self.path}: {len(h)} generation(s) recorded"]
        if len(h):
            last = h[-1]
            lines.append(
                f"  generation {int(last['generation'])}: best {last['best']:.4f}, mean {last['mean']:.4f}, "
                f"viable {100 * last['viable_fraction']:.0f}%, {int(last['evaluations'])} evaluations, "
                f"{last['wall_seconds']:.1f} s"
            )
        if lineage:
            b = lineage[-1]
            lines.append(
                f"  best genome: generation {b.generation}, fitness {b.fitness:.4f}, {b.cell_count} cells "
                f"({len(lineage)} improvement(s))"
            )
        return "\n".join(lines)

    def genealogy(self) -> np.ndarray:
        """Every individual born in the run, from ``genealogy.csv`` (:func:`read_genealogy`): generation,
        id, parent_a, parent_b (-1: none), fitness, cells. Empty for a run made before the genealogy
        was recorded."""
        path = self.path / "genealogy.csv"
        if not path.is_file():
            return np.zeros(0, dtype=GENEALOGY_DTYPE)
        return read_genealogy(path)

    def ancestry(self, id: Optional[int] = None) -> np.ndarray:
        """The family tree of individual ``id`` (default: the current best): its genealogy row and
        those of all its ancestors recorded in ``genealogy.csv``, newest first (each id once).

        Raises ValueError when the run has no genealogy or ``id`` is not in it.
        """
        rows = self.genealogy()
        if id is None:
            id = self.best().id
        if not len(rows):
            raise ValueError(f"{self.path / 'genealogy.csv'}: no genealogy (a run made before it was recorded)")
        index = {int(i): k for k, i in enumerate(rows["id"])}
        if int(id) not in index:
            raise ValueError(f"{self.path / 'genealogy.csv'}: no individual with id {id}")
        seen, todo, out = set(), [int(id)], []
        while todo:
            current = todo.pop()
            if current in seen or current not in index:
                continue
            seen.add(current)
            row = rows[index[current]]
            out.append(index[current])
            todo.extend(int(p) for p in (row["parent_a"], row["parent_b"]) if p >= 0)
        out.sort(key=lambda k: (-int(rows[k]["generation"]), int(rows[k]["id"])))
        return rows[out]

    def morphology_changes(self, tolerance: float = MORPHOLOGY_TOLERANCE, config=None) -> List[LineageEntry]:
        """The lineage entries at which the best's *morphology* changed (paper Figs. 8-9).

        Every lineage genome is developed with ``config`` (default: the run's config); an entry
        counts as a morphological change when its cell count differs from the previous entry's or
        when :func:`morphology_distance` to it exceeds ``tolerance`` (default 0.25, a quarter of a cell
        diameter). A mutation that only changes control (the oscillator outputs) leaves every cell
        where it was (distance 0); mutations that touch development in practice move cells by 0.3 or
        more (RMS), so the default separates the two. The first entry always counts. Entries whose genome does
        not develop into a viable embryo are skipped.
        """
        cfg = self._config if config is None else config
        out = []
        previous = None
        for entry in self.best_genomes:
            embryo = _core.develop(entry.genome, cfg)
            if not embryo.viable:
                continue
            if previous is None or morphology_distance(previous, embryo) > tolerance:
                out.append(entry)
            previous = embryo
        return out

    def __repr__(self) -> str:
        return (
            f"<animat.Run {str(self.path)!r}: {self.generations} generations, {len(self.best_genomes)} lineage entries>"
        )
