"""Reading run directories written by ``animat_evolve`` / ``animat.evolve(config, out=DIR)``.

A run directory holds::

    config.toml       the full resolved config of the run
    history.csv       one row per generation, appended as the run goes
    best/gen_NNNNNN.json
                      the lineage: the best genome each time it changed
    checkpoint.json   the state to resume from (absent in the first moments of a run)

:class:`Run` reads all of it, including runs that are still going (a half-written last line of
``history.csv`` is ignored, and a missing checkpoint is fine). It also reads, in place and read-only:

- a *packed* run (``data/README.md``; ``studies/replication/replication_store.py`` packs and unpacks
  them): ``config.toml``, ``history.csv.gz``, ``best.tar.gz``, ``checkpoint.json.gz``, ``status.json``
  and ``manifest.json``, whose sizes and sha256 digests are checked for every file read;
- the run directory of a MAP-Elites or NSGA-II search (:func:`animat.run_map_elites`,
  :func:`animat.run_nsga2`): ``history.csv`` with that search's columns and the snapshots
  ``archive/gen_*.csv`` or ``front/gen_*.csv`` (:meth:`Run.snapshot`) in place of ``best/``;
  ``animat_evolve``'s run of one writes no snapshot files (and a ``wall_seconds`` history column):
  its ``checkpoint.json`` gives the last archive or front.
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import re
import tarfile
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Dict, List, Optional, Tuple, Union

import numpy as np

from . import _core

__all__ = [
    "Run",
    "LineageEntry",
    "Snapshot",
    "PACKED_FILES",
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

    The file must start with the header ``generation,best,...``, or be that of a MAP-Elites run
    (:data:`animat.qd.QD_HISTORY_DTYPE`'s columns) or of an NSGA-II run (:func:`animat.moo.history_dtype`'s),
    which read with those columns. A last line without its newline
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
    return _parse_history(path.read_text(encoding="utf-8", errors="replace"), path)


def _search_history_dtype(header: List[str]) -> Optional[np.dtype]:
    """The dtype of a MAP-Elites or NSGA-II ``history.csv`` with this header, or None for another header."""
    if header[:3] == ["generation", "evaluations", "qd_score"]:
        from .qd import QD_HISTORY_DTYPE

        return QD_HISTORY_DTYPE
    if header[:4] == ["generation", "evaluations", "front_size", "hypervolume"]:
        from .moo import history_dtype as nsga2_history_dtype

        return nsga2_history_dtype([n[len("best_") :] for n in header if n.startswith("best_")])
    return None


def _parse_history(text: str, path: Any) -> np.ndarray:
    """:func:`read_history` of the text of ``path`` (a file, or a packed run's ``history.csv.gz``)."""
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
    search = _search_history_dtype(header)
    if header == list(PROTECTED_HISTORY_DTYPE.names or ()):
        dtype = PROTECTED_HISTORY_DTYPE
        expected = header
    elif search is not None:
        if header == [*(search.names or ()), "wall_seconds"]:  # animat_evolve's: the engine's clock too
            search = np.dtype([*search.descr, ("wall_seconds", np.float64)])
        if header != list(search.names or ()):
            raise ValueError(
                f"{path}:1: unexpected header {complete[0].strip()!r} for a search run; expected "
                f"{','.join(search.names or ())!r}"
            )
        dtype, expected = search, header
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
    return _lineage_entry(path.read_text(encoding="utf-8"), path)


def _lineage_entry(text: str, path: Path) -> LineageEntry:
    """The LineageEntry of a ``best/gen_*.json`` text read from ``path`` (named in errors)."""
    try:
        data = json.loads(text)
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


#: The files of a packed run (``data/README.md``) besides ``manifest.json``, which lists their sizes and
#: sha256 digests; :class:`Run` reads them in place.
PACKED_FILES = ("config.toml", "history.csv.gz", "best.tar.gz", "checkpoint.json.gz", "status.json")
_PACKED_NEEDED = ("history.csv.gz", "best.tar.gz")
_MANIFEST = "manifest.json"
_MANIFEST_FORMAT = "animat.replication_store.manifest"
#: At most this many bytes from one gzip stream of a packed run without a manifest (a checkpoint is a few MB).
_MAX_GUNZIPPED = 1 << 30
_SNAPSHOT_NAME = re.compile(r"^gen_(\d+)\.csv$")
#: What a run directory holds besides config.toml from its first moments on (``.lock``: a run is writing
#: it; ``best/``, ``archive/``, ``front/``: made before the first generation ends).
_RUN_MARKS = ("history.csv", "best", "checkpoint.json", "genealogy.csv", ".lock", "archive", "front", "stopped.txt")
#: The folder of snapshots of each search that writes them.
_SNAPSHOT_FOLDERS = {"map_elites": "archive", "nsga2": "front"}


def _gunzip(data: bytes, where: Path, limit: int) -> bytes:
    """The content of the gzip stream ``data`` (read from ``where``), at most ``limit`` bytes; ValueError
    naming ``where`` for a corrupt, truncated or oversized stream (zlib checks the CRC and length)."""
    d = zlib.decompressobj(16 + zlib.MAX_WBITS)
    try:
        out = d.decompress(data, limit + 1)
    except zlib.error as e:
        raise ValueError(f"{where}: corrupt gzip stream ({e})") from None
    if len(out) > limit:
        raise ValueError(f"{where}: expands past {limit} bytes, more than manifest.json says (corrupt?)")
    if not d.eof:
        raise ValueError(f"{where}: the gzip stream ends early (truncated)")
    if d.unused_data:
        raise ValueError(f"{where}: bytes after the end of the gzip stream (corrupt)")
    return out


def _check_digest(where: Path, what: str, data: bytes, want: Any) -> None:
    """ValueError naming ``where`` unless ``data`` has the size and sha256 of the manifest entry ``want``."""
    if not isinstance(want, dict):
        raise ValueError(f"{where}: manifest.json has no entry for {what}")
    if len(data) != want.get("size"):
        raise ValueError(f"{where}: {what} is {len(data)} bytes, manifest.json says {want.get('size')}")
    sha = hashlib.sha256(data).hexdigest()
    if sha != want.get("sha256"):
        raise ValueError(f"{where}: the sha256 of {what}, {sha}, is not manifest.json's {want.get('sha256')}")


def _runs_below(path: Path) -> List[Path]:
    return sorted({c.parent for c in list(path.glob("*/config.toml")) + list(path.glob("*/*/config.toml"))})


@dataclass(frozen=True)
class Snapshot:
    """One snapshot of a search run: ``archive/gen_NNNNNN.csv`` (MAP-Elites: one row per elite) or
    ``front/gen_NNNNNN.csv`` (NSGA-II: one row per genome of the first front).

    Attributes:
        kind: ``"archive"`` or ``"front"``.
        generation: the generation after which it was written.
        path: the file.
        columns: every column but ``genome``: name -> array with one value per row (int64 for
            ``index`` and ``generation``, the generation that made the genome; float64 otherwise). An
            archive has ``index`` (the cell), ``objective``, ``fitness``, ``reference`` and its
            descriptors; a front ``crowding``, the objectives, ``measured_<name>`` and ``reference_<name>``.
        genomes: each row's genome as JSON text (:meth:`genome` parses one).
        objectives: what "best" means: ``[("objective", "max")]`` for an archive, the objectives and
            their senses (``"max"`` or ``"min"``) for a front, in the run's order.
        descriptors: an archive's descriptor names (empty for a front).
    """

    kind: str
    generation: int
    path: Path
    columns: Dict[str, np.ndarray]
    genomes: List[str]
    objectives: List[Tuple[str, str]]
    descriptors: List[str] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.genomes)

    def genome(self, row: int):
        """The :class:`animat.Genome` of row ``row``."""
        try:
            return _core.Genome.from_json(self.genomes[row])
        except ValueError as e:
            raise ValueError(f"{self.path}: row {row + 2}: invalid genome: {e}") from None

    def best(self) -> int:
        """The row best by the first of :attr:`objectives` (-1 when there is none)."""
        if not len(self):
            return -1
        name, sense = self.objectives[0]
        values = np.asarray(self.columns[name], dtype=float)
        values = np.where(np.isnan(values), -np.inf if sense == "max" else np.inf, values)
        return int(np.argmax(values) if sense == "max" else np.argmin(values))


def _objective_senses(config: Any, names: List[str]) -> List[Tuple[str, str]]:
    """The sense of each NSGA-II objective column: from the config's ``search.objectives`` (``NAME:max``),
    else the criterion's own (:data:`animat.moo.CRITERIA`), else ``"max"``."""
    from .moo import CRITERIA

    given = {}
    for entry in list(config["search.objectives"]):
        name, _, sense = str(entry).partition(":")
        given[name] = sense
    out = []
    for name in names:
        sense = given.get(name) or getattr(CRITERIA.get(name), "sense", "") or "max"
        out.append((name, "min" if sense.startswith("min") else "max"))
    return out


def _read_snapshot(path: Path, kind: str, config: Any) -> Snapshot:
    """A :class:`Snapshot` from its CSV file; ValueError naming the file and line when malformed."""
    match = _SNAPSHOT_NAME.match(path.name)
    generation = int(match.group(1)) if match else -1
    with open(path, encoding="utf-8", newline="") as fh:
        rows = list(csv.reader(fh))
    if not rows or not rows[0] or rows[0][-1] != "genome":
        raise ValueError(f"{path}:1: not a {kind} snapshot (the last column is not genome)")
    header = rows[0]
    if kind == "archive":
        needed = ["index", "objective", "fitness", "reference", "generation"]
        if header[:5] != needed:
            raise ValueError(f"{path}:1: expected the header to begin with {','.join(needed)}, got {','.join(header)}")
        descriptors, objectives = header[5:-1], [("objective", "max")]
    else:
        if header[:2] != ["generation", "crowding"]:
            raise ValueError(f"{path}:1: expected the header to begin with generation,crowding, got {','.join(header)}")
        names = [n for n in header[2:-1] if not n.startswith(("measured_", "reference_"))]
        descriptors, objectives = [], _objective_senses(config, names)
    values: Dict[str, list] = {n: [] for n in header[:-1]}
    genomes = []
    for number, row in enumerate(rows[1:], start=2):
        if not row:
            continue
        if len(row) != len(header):
            raise ValueError(f"{path}:{number}: expected {len(header)} comma-separated values, got {len(row)}")
        try:
            for name, v in zip(header[:-1], row):
                values[name].append(int(v) if name in ("index", "generation") else float(v))
        except ValueError:
            raise ValueError(f"{path}:{number}: not a number in {','.join(row[:-1])!r}") from None
        genomes.append(row[-1])
    columns = {
        n: np.asarray(v, dtype=np.int64 if n in ("index", "generation") else np.float64) for n, v in values.items()
    }
    return Snapshot(kind, generation, path, columns, genomes, objectives, descriptors)


def _engine_generation(path: Path) -> Optional[int]:
    """The generation of the engine's checkpoint ``path`` (``animat_evolve``'s MAP-Elites or NSGA-II
    run), or None when it is not one (a library run's checkpoint, or none)."""
    try:
        with open(path, "rb") as fh:
            if not fh.read(16).startswith(b'{"checksum"'):
                return None
        payload = json.loads(json.loads(path.read_text(encoding="utf-8"))["payload"])
        return int(payload["generation"])
    except (OSError, ValueError, KeyError, TypeError):
        return None


def _engine_snapshot(path: Path, kind: str, config: Any) -> Snapshot:
    """The archive or front that the engine's checkpoint ``path`` holds, as a :class:`Snapshot` with
    the columns of the library's snapshot files; ValueError naming the file when it does not restore."""
    engine = _core.SearchEngine(config)
    try:
        engine.restore(path.read_text(encoding="utf-8"), str(path))
    except (RuntimeError, ValueError) as e:
        raise ValueError(str(e)) from None
    values: Dict[str, list] = {}
    genomes = []
    if kind == "archive":
        descriptors = list(engine.archive["descriptors"])
        for name in ["index", "objective", "fitness", "reference", "generation", *descriptors]:
            values[name] = []
        for e in engine.elites():
            for name, v in zip(
                ["index", "objective", "fitness", "reference", "generation"],
                [e["index"], e["objective"], e["fitness"].fitness, e["reference"], e["generation"]],
            ):
                values[name].append(v)
            for name, v in zip(descriptors, e["values"]):
                values[name].append(v)
            genomes.append(e["genome"].to_json())
        objectives = [("objective", "max")]
    else:
        descriptors = []
        names = [name for name, _ in engine.criteria]
        for name in ["generation", "crowding", *names, *[f"{p}_{n}" for p in ("measured", "reference") for n in names]]:
            values[name] = []
        population = engine.population()
        for i in engine.front():
            s = population[i]
            reference = list(s["reference"]) or [float("nan")] * len(names)
            values["generation"].append(s["generation"])
            values["crowding"].append(s["crowding"])
            for j, name in enumerate(names):
                values[name].append(s["objectives"][j])
                values[f"measured_{name}"].append(s["measured"][j])
                values[f"reference_{name}"].append(reference[j])
            genomes.append(s["genome"].to_json())
        objectives = [(name, sense) for name, sense in engine.criteria]
    columns = {
        n: np.asarray(v, dtype=np.int64 if n in ("index", "generation") else np.float64) for n, v in values.items()
    }
    return Snapshot(kind, int(engine.generation), path, columns, genomes, objectives, descriptors)


class Run:
    """A run directory, read-only: that of the GA (``animat_evolve``, :func:`animat.evolve`), of a
    MAP-Elites or NSGA-II search (:attr:`search`), or a packed run (:attr:`packed`).

    ``Run(path)`` checks that ``path`` is a directory with a readable ``config.toml`` (and, for a
    packed run, its ``history.csv.gz`` and ``best.tar.gz``); everything else is read when asked for,
    and read again every time, so a run in progress can be followed by re-reading :attr:`history`
    and :attr:`best_genomes`. A packed run is read in place without unpacking, every file checked
    against the size and sha256 ``manifest.json`` lists (runs packed before manifests: the gzip
    CRC only); ``studies/replication/replication_store.py unpack`` gives a run directory to resume.

    Raises:
        FileNotFoundError: ``path`` or its ``config.toml`` does not exist (the message says when runs lie
            below it), or a packed run lacks ``history.csv.gz`` or ``best.tar.gz``.
        ValueError: ``config.toml`` is not a valid config (the message names file, line and key), or
            a packed run's file does not match ``manifest.json``.

    Example::

        run = animat.Run("runs/demo")  # or a packed run: animat.Run("data/replication_regime/dn0.5/run_0")
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
            below = _runs_below(self.path)
            hint = (
                f"; it holds {len(below)} run(s) below it ({below[0].relative_to(self.path).as_posix()}, ...): "
                f"`animat explore {self.path}` shows them all"
                if below
                else ""
            )
            raise FileNotFoundError(
                f"{config_path}: missing; {self.path} is neither a run directory (config.toml, history.csv, best/) "
                f"nor a packed run (config.toml, history.csv.gz, best.tar.gz, manifest.json){hint}"
            )
        self._cache: Dict[str, Tuple[Tuple[int, int], Any]] = {}
        self._manifest: Optional[dict] = None
        self.packed = not (self.path / "history.csv").exists() and any(
            (self.path / n).is_file() for n in PACKED_FILES[1:] + (_MANIFEST,)
        )
        """True for a packed run (``history.csv.gz``, ``best.tar.gz``, ... and no ``history.csv``)."""
        if self.packed:
            missing = [n for n in _PACKED_NEEDED if not (self.path / n).is_file()]
            if missing:
                raise FileNotFoundError(
                    f"{self.path / missing[0]}: missing; {self.path} holds part of a packed run (data/README.md) "
                    f"but not {' or '.join(missing)}"
                )
            if (self.path / _MANIFEST).is_file():
                self._manifest = self._read_manifest()
            self._packed_bytes("config.toml")  # checked against the manifest before it is trusted
        elif not any((self.path / n).exists() for n in _RUN_MARKS):
            raise FileNotFoundError(
                f"{self.path}: holds config.toml but nothing of a run (no history.csv, best/ or checkpoint.json, "
                "and no run is writing it: no .lock); neither a run directory nor a packed run "
                "(config.toml, history.csv.gz, best.tar.gz, manifest.json)"
            )
        self._config = _core.load_config(str(config_path))

    # --- the files of a packed run ---------------------------------------------------------------------

    def _read_manifest(self) -> dict:
        path = self.path / _MANIFEST
        try:
            m = json.loads(path.read_bytes())
        except (ValueError, RecursionError) as e:
            raise ValueError(f"{path}: not valid JSON ({e})") from None
        if not (
            isinstance(m, dict)
            and m.get("format") == _MANIFEST_FORMAT
            and isinstance(m.get("packed"), dict)
            and isinstance(m.get("unpacked"), dict)
        ):
            raise ValueError(f"{path}: not a manifest of format {_MANIFEST_FORMAT} (with packed and unpacked)")
        return m

    def _packed_bytes(self, name: str) -> bytes:
        """The bytes of the packed file ``name``, checked against the manifest."""
        path = self.path / name
        data = path.read_bytes()
        if self._manifest is not None:
            _check_digest(path, name, data, self._manifest["packed"].get(name))
        return data

    def _gunzipped(self, name: str) -> bytes:
        """The content of the packed gzip file ``name``, checked against the manifest; kept while the
        file is unchanged."""
        path = self.path / name
        st = path.stat()
        key = (st.st_mtime_ns, st.st_size)
        cached = self._cache.get(name)
        if cached is not None and cached[0] == key:
            return cached[1]
        want = self._manifest["packed"].get(name, {}).get("gunzipped") if self._manifest is not None else None
        limit = int(want["size"]) if isinstance(want, dict) and isinstance(want.get("size"), int) else _MAX_GUNZIPPED
        data = _gunzip(self._packed_bytes(name), path, limit)
        if self._manifest is not None:
            _check_digest(path, f"the content of {name}", data, want)
        self._cache[name] = (key, data)
        return data

    # --- what the run holds ----------------------------------------------------------------------------

    @property
    def config(self):
        """The run's :class:`animat.Config` (from ``config.toml``; a copy, so edits do not stick)."""
        return self._config.copy()

    @property
    def search(self) -> str:
        """The search that wrote the run: ``"ga"`` (the paper's GA), ``"map_elites"`` or ``"nsga2"`` (its
        config's ``search.algorithm``)."""
        return str(self._config["search.algorithm"])

    @property
    def history(self) -> np.ndarray:
        """Per-generation statistics from ``history.csv`` (structured array, see :func:`read_history`).

        Empty (shape (0,)) when the run has not finished generation 0 yet. Read afresh on every
        access. Columns: ``run.history["best"]`` etc.; rows: ``run.history[-1]``. A MAP-Elites run has
        :data:`animat.qd.QD_HISTORY_DTYPE`'s columns, an NSGA-II run :func:`animat.moo.history_dtype`'s.
        """
        if self.packed:
            text = self._gunzipped("history.csv.gz").decode("utf-8", errors="replace")
            return _parse_history(text, self.path / "history.csv.gz")
        path = self.path / "history.csv"
        if not path.exists():
            return np.zeros(0, dtype=HISTORY_DTYPE).view(_history_type())
        return read_history(path)

    @property
    def best_genomes(self) -> List[LineageEntry]:
        """The lineage of best genomes, oldest first: the record holders, each the genome that became the
        best at its generation (not an ancestry: :meth:`ancestry` traces parents).

        A GA run: one :class:`LineageEntry` per ``best/gen_*.json`` (a packed run: per member of
        ``best.tar.gz``; the entry's path is ``best.tar.gz/best/gen_*.json`` below the run). A search
        run: the best row of each snapshot (:meth:`snapshot`) where it changed, by the archive's
        objective (MAP-Elites) or the first objective (NSGA-II, in its sense); ``generation`` is the
        generation that made the genome, ``fitness`` that objective's value.

        Read afresh on every access; a malformed file raises ValueError naming it.
        """
        if self.search in _SNAPSHOT_FOLDERS and not self.packed:
            return self._search_lineage()
        if self.packed:
            return self._packed_lineage()
        folder = self.path / "best"
        if not folder.is_dir():
            return []
        files = sorted(p for p in folder.iterdir() if _LINEAGE_NAME.match(p.name))
        return [_read_lineage_file(p) for p in files]

    def _packed_lineage(self) -> List[LineageEntry]:
        path = self.path / "best.tar.gz"
        entries = []
        try:
            with tarfile.open(fileobj=io.BytesIO(self._gunzipped("best.tar.gz")), mode="r:") as tar:
                for member in tar.getmembers():
                    name = member.name
                    if not (member.isfile() and name.startswith("best/") and _LINEAGE_NAME.match(name[5:])):
                        continue
                    handle = tar.extractfile(member)
                    data = handle.read() if handle is not None else b""
                    if self._manifest is not None:
                        _check_digest(path, name, data, self._manifest["unpacked"].get(name))
                    entries.append((name, _lineage_entry(data.decode("utf-8", errors="replace"), path / name)))
        except tarfile.TarError as e:
            raise ValueError(f"{path}: not a tar archive of best/gen_*.json ({e})") from None
        return [entry for _, entry in sorted(entries, key=lambda item: item[0])]

    def snapshots(self) -> List[Tuple[int, Path]]:
        """A search run's snapshots, oldest first: ``(generation, path)`` of every ``archive/gen_*.csv``
        (MAP-Elites) or ``front/gen_*.csv`` (NSGA-II); for ``animat_evolve``'s run, which writes
        none, its ``checkpoint.json`` (the last generation's); empty for a GA run."""
        folder = self.path / _SNAPSHOT_FOLDERS.get(self.search, "")
        if self.search not in _SNAPSHOT_FOLDERS:
            return []
        if folder.is_dir():
            found = [(int(m.group(1)), p) for p in folder.iterdir() if (m := _SNAPSHOT_NAME.match(p.name))]
            if found:
                return sorted(found)
        # animat_evolve's run writes no snapshot files: its checkpoint holds the last archive or front.
        checkpoint = self.path / "checkpoint.json"
        generation = None if self.packed else _engine_generation(checkpoint)
        return [] if generation is None else [(generation, checkpoint)]

    def snapshot(self, generation: Optional[int] = None) -> Snapshot:
        """The archive (MAP-Elites) or front (NSGA-II) written after ``generation`` (default: the last
        one written), as a :class:`Snapshot`.

        Raises ValueError for a GA run, for a generation without a snapshot (naming those there are)
        and for a malformed file (naming it and the line).
        """
        found = self.snapshots()
        if not found:
            if self.search not in _SNAPSHOT_FOLDERS:
                raise ValueError(f"{self.path}: a GA run (search.algorithm = {self.search!r}) has no archive or front")
            folder = self.path / _SNAPSHOT_FOLDERS[self.search]
            raise ValueError(f"{folder}: no gen_*.csv yet (the run has not finished generation 0)")
        if generation is None:
            path = found[-1][1]
        else:
            paths = dict(found)
            if int(generation) not in paths:
                raise ValueError(
                    f"{self.path}: no snapshot of generation {generation}; there are {', '.join(str(g) for g, _ in found)}"
                )
            path = paths[int(generation)]
        return self._snapshot_file(path)

    def _snapshot_file(self, path: Path) -> Snapshot:
        st = path.stat()
        key = (st.st_mtime_ns, st.st_size)
        cached = self._cache.get(str(path))
        if cached is not None and cached[0] == key:
            return cached[1]
        kind = _SNAPSHOT_FOLDERS[self.search]
        if path.name == "checkpoint.json":
            snap = _engine_snapshot(path, kind, self._config)
        else:
            snap = _read_snapshot(path, kind, self._config)
        self._cache[str(path)] = (key, snap)
        return snap

    def _search_lineage(self) -> List[LineageEntry]:
        found = self.snapshots()
        history = self.history
        names = history.dtype.names or ()
        column = "best" if "best" in names else next((n for n in names if n.startswith("best_")), None)
        if len(history) and column is not None and found:
            # Only the snapshots that can show a new best: the first at or after each change of the
            # history's best (a long run writes a snapshot every few generations).
            best = np.asarray(history[column], dtype=float)
            gens = np.asarray(history["generation"], dtype=np.int64)
            changes = gens[np.concatenate([[0], np.nonzero(np.diff(best) != 0)[0] + 1])]
            at = np.array([g for g, _ in found])
            picked = np.unique(np.searchsorted(at, changes).clip(0, len(found) - 1))
            found = [found[k] for k in sorted(set(picked.tolist()) | {len(found) - 1})]
        out: List[LineageEntry] = []
        previous = None
        for _, path in found:
            snap = self._snapshot_file(path)
            k = snap.best()
            if k < 0 or snap.genomes[k] == previous:
                continue
            previous = snap.genomes[k]
            name = snap.objectives[0][0]
            reference = "reference" if snap.kind == "archive" else f"reference_{name}"
            genome = snap.genome(k)
            out.append(
                LineageEntry(
                    int(snap.columns["generation"][k]),
                    float(snap.columns[name][k]),
                    int(_core.develop(genome, self._config).cell_count),
                    genome,
                    path,
                    float(snap.columns[reference][k]) if reference in snap.columns else float("nan"),
                )
            )
        return out

    def best(self) -> LineageEntry:
        """The current best: the last entry of :attr:`best_genomes`.

        Raises ValueError when the run has no lineage yet (``best/`` is empty or missing).
        """
        lineage = self.best_genomes
        if not lineage:
            folder = self.path / _SNAPSHOT_FOLDERS.get(self.search, "best")
            raise ValueError(f"{folder}: no gen_* file yet (the run has not finished generation 0)")
        return lineage[-1]

    @property
    def checkpoint(self) -> Optional[dict]:
        """``checkpoint.json`` (a packed run's ``checkpoint.json.gz``) as a dict, or None when there is none yet."""
        path = self.path / "checkpoint.json"
        if self.packed and (self.path / "checkpoint.json.gz").is_file():
            path = self.path / "checkpoint.json.gz"
            text = self._gunzipped("checkpoint.json.gz").decode("utf-8", errors="replace")
        elif not path.is_file():
            return None
        else:
            text = path.read_text(encoding="utf-8")
        try:
            return json.loads(text)
        except json.JSONDecodeError as e:
            raise ValueError(f"{path}: not valid JSON ({e})") from None

    @property
    def status(self) -> Optional[dict]:
        """A packed run's ``status.json``: ``{"generation": last generation, "stop_reason": why its last
        session stopped}``; None for a run directory (or a packed run without one)."""
        if not (self.packed and (self.path / "status.json").is_file()):
            return None
        try:
            data = json.loads(self._packed_bytes("status.json"))
        except ValueError as e:
            raise ValueError(f"{self.path / 'status.json'}: not valid JSON ({e})") from None
        return data if isinstance(data, dict) else None

    @property
    def generations(self) -> int:
        """Completed generations recorded in ``history.csv`` (0 before generation 0 is done)."""
        return len(self.history)

    def summary(self) -> str:
        """A few human-readable lines: path, generations, best fitness and its lineage."""
        h = self.history
        lineage = self.best_genomes
        kind = {"map_elites": "MAP-Elites run", "nsga2": "NSGA-II run"}.get(self.search, "run")
        lines = [f"{'packed ' if self.packed else ''}{kind} {self.path}: {len(h)} generation(s) recorded"]
        if len(h):
            last = h[-1]
            names = h.dtype.names or ()
            if self.search == "map_elites" and "qd_score" in names:
                text = (
                    f"QD-score {last['qd_score']:.4g}, coverage {last['coverage']:.3f}, {int(last['elites'])} elites, "
                    f"best {last['best']:.4f}, {int(last['evaluations'])} evaluations"
                )
            elif self.search == "nsga2" and "hypervolume" in names:
                bests = ", ".join(f"{n} {last[n]:.4g}" for n in names if n.startswith("best_"))
                text = (
                    f"front of {int(last['front_size'])}, hypervolume {last['hypervolume']:.4g}, {bests}, "
                    f"{int(last['evaluations'])} evaluations"
                )
            else:
                text = (
                    f"best {last['best']:.4f}, mean {last['mean']:.4f}, viable {100 * last['viable_fraction']:.0f}%, "
                    f"{int(last['evaluations'])} evaluations, {last['wall_seconds']:.1f} s"
                )
            lines.append(f"  generation {int(last['generation'])}: {text}")
        status = self.status
        if status and status.get("stop_reason"):
            lines.append(f"  stopped: {status['stop_reason']} (status.json)")
        if lineage:
            b = lineage[-1]
            what = "improvement(s)" if self.search == "ga" else "change(s) of the best over the snapshots"
            lines.append(
                f"  best genome: generation {b.generation}, fitness {b.fitness:.4f}, {b.cell_count} cells "
                f"({len(lineage)} {what})"
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
