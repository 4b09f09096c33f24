"""Evolution runs kept in the repository: pack a run directory into ``data/<study>/<env>/run_<i>/``
(the replication study's runs in ``data/replication``; ``data/README.md`` lists the other folders in
this format) and unpack it again to resume or re-analyse it. Study code, not part of the installed
package: scripts import it from this folder (``sys.path``), the tests through ``tests/python/conftest.py``.

A packed run holds what is needed to check and to continue it, compressed:

- ``config.toml``: the resolved config the run was last run with (plain text, a few KB);
- ``history.csv.gz``: one row per generation;
- ``best.tar.gz``: the lineage of best individuals (``best/gen_*.json``);
- ``checkpoint.json.gz``: the population, random state and history to resume from;
- ``resume.log`` when the run was resumed with other caps;
- ``status.json``: the stop reason of its last session (``"in progress"`` when unknown) and the
  last generation;
- ``manifest.json``: the sha256 and size of every file above, of every decompressed stream and of
  every file unpacking writes (``history.csv``, ``checkpoint.json``, ``best/gen_*.json``...).

Packing is deterministic (sorted members, fixed times and owners, gzip without a time stamp), so
packing an unchanged run gives the same bytes and git sees no change.

Packing refuses, before writing anything, a run that would not restore (config.toml not TOML,
history.csv cut short or out of order, a best/ file that is not JSON, a checkpoint that is not JSON,
fails its checksum or does not match its history) and a run behind the one already packed at the
destination (a lower checkpoint generation). Unpacking verifies every size and checksum of the
manifest, decompresses in a streaming way with a size limit (the manifest's sizes, else
``MAX_UNPACKED_BYTES`` per stream), stages the run next to its directory and renames the verified
files into place, the checkpoint last; a run that fails verification writes nothing. A packed run
without ``manifest.json`` (packed before manifests existed) is checked only by the gzip CRC-32 and
length of each stream, read to its end: a change to its plain files (config.toml, resume.log,
status.json) or a consistent re-compression of other content is not detected. Command line::

    python studies/replication/replication_store.py unpack data/replication runs/replication   # into work dirs
    python studies/replication/replication_store.py pack runs/replication data/replication     # back into the repository

Both exit 1 with one line per refused run (naming the run and the file) when something is wrong.
"""

from __future__ import annotations

import argparse
import gzip
import hashlib
import io
import json
import os
import re
import shutil
import statistics
import sys
import tarfile
import tempfile
import tomllib
import zlib
from pathlib import Path
from typing import Dict, List, Optional, Sequence, Tuple

__all__ = [
    "PACKED_FILES",
    "MANIFEST",
    "MAX_UNPACKED_BYTES",
    "StoreError",
    "pack_run",
    "unpack_run",
    "pack_tree",
    "unpack_tree",
    "packed_runs",
    "is_packed_run",
    "next_round_cap",
    "main",
]

PACKED_FILES = ("config.toml", "history.csv.gz", "best.tar.gz", "checkpoint.json.gz", "status.json")
OPTIONAL_FILES = ("resume.log",)
MANIFEST = "manifest.json"
# The format name written into every manifest.json (data kept in the repository carries it: do not change).
MANIFEST_FORMAT = "animat.replication_store.manifest"
# Per decompressed stream of a packed run without a manifest (a run's checkpoint is a few MB).
MAX_UNPACKED_BYTES = 4 << 30
_CHUNK = 1 << 16
_BEST_NAME = re.compile(r"gen_[0-9]+\.json")
# What unpacking writes from each compressed file.
_GUNZIPPED = {"history.csv.gz": "history.csv", "checkpoint.json.gz": "checkpoint.json"}


class StoreError(ValueError):
    """A run that cannot be packed or unpacked as it is; the message names the run and the file."""


def _digest(data: bytes) -> Dict[str, object]:
    return {"sha256": hashlib.sha256(data).hexdigest(), "size": len(data)}


def _gzip_bytes(data: bytes) -> bytes:
    buf = io.BytesIO()
    with gzip.GzipFile(fileobj=buf, mode="wb", compresslevel=9, mtime=0, filename="") as f:
        f.write(data)
    return buf.getvalue()


def _sync_dir(path: Path) -> None:
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _write_atomically(path: Path, data: bytes) -> None:
    """``path`` holds either its old content or ``data``, never a part: a unique temporary file in the same
    directory, fsync, rename."""
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        os.fchmod(fd, path.stat().st_mode & 0o7777 if path.exists() else 0o666 & ~_umask())  # mkstemp's is 0600
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _write_if_changed(path: Path, data: bytes) -> None:
    if path.is_file() and path.read_bytes() == data:
        return
    _write_atomically(path, data)


class _Sink:
    """Collects a decompressed stream (in memory, or into a file when ``path`` is given) with its sha256 and
    size, refusing to go past ``limit`` bytes."""

    def __init__(self, where: str, limit: int, path: Optional[Path] = None):
        self.where, self.limit, self.path = where, limit, path
        self.sha, self.size = hashlib.sha256(), 0
        self.parts: List[bytes] = []
        self.file = open(path, "xb") if path is not None else None

    def write(self, data: bytes) -> None:
        self.size += len(data)
        if self.size > self.limit:
            raise StoreError(f"{self.where}: expands past {self.limit} bytes; refused (corrupt, or a gzip bomb)")
        self.sha.update(data)
        if self.file is not None:
            self.file.write(data)
        else:
            self.parts.append(data)

    def close(self) -> None:
        if self.file is not None and not self.file.closed:
            self.file.flush()
            os.fsync(self.file.fileno())
            self.file.close()

    def digest(self) -> Dict[str, object]:
        return {"sha256": self.sha.hexdigest(), "size": self.size}

    def data(self) -> bytes:
        return b"".join(self.parts)


def _gunzip(src: Path, sink: _Sink, where: str) -> Dict[str, object]:
    """Decompress the single-member gzip file ``src`` into ``sink`` chunk by chunk (memory bounded), checking
    its CRC-32 and length (zlib does, at the end of the stream), that it is complete and that nothing follows
    it. Returns the sha256 and size of ``src`` itself."""
    d = zlib.decompressobj(16 + zlib.MAX_WBITS)
    sha, size = hashlib.sha256(), 0
    with open(src, "rb") as f:
        while chunk := f.read(_CHUNK):
            sha.update(chunk)
            size += len(chunk)
            if d.eof:
                raise StoreError(f"{where}: bytes after the end of the gzip stream (corrupt)")
            buf = chunk
            while True:
                try:
                    out = d.decompress(buf, _CHUNK)
                except zlib.error as e:
                    raise StoreError(f"{where}: corrupt gzip stream ({e})") from None
                sink.write(out)
                buf = d.unconsumed_tail
                if d.eof:
                    if buf or d.unused_data:
                        raise StoreError(f"{where}: bytes after the end of the gzip stream (corrupt)")
                    break
                if not buf and len(out) < _CHUNK:  # input used up and no output pending
                    break
    if not d.eof:
        raise StoreError(f"{where}: the gzip stream ends early (truncated)")
    return {"sha256": sha.hexdigest(), "size": size}


def _gunzip_bytes(src: Path, where: str) -> bytes:
    sink = _Sink(where, MAX_UNPACKED_BYTES)
    _gunzip(src, sink, where)
    return sink.data()


def _file_digest(path: Path, sink: Optional[_Sink] = None) -> Dict[str, object]:
    sha, size = hashlib.sha256(), 0
    with open(path, "rb") as f:
        while chunk := f.read(_CHUNK):
            sha.update(chunk)
            size += len(chunk)
            if sink is not None:
                sink.write(chunk)
    return {"sha256": sha.hexdigest(), "size": size}


def _tar_best(members: Sequence[Tuple[str, bytes]]) -> bytes:
    raw = io.BytesIO()
    with tarfile.open(fileobj=raw, mode="w", format=tarfile.PAX_FORMAT) as tar:
        for name, data in members:
            info = tarfile.TarInfo(f"best/{name}")
            info.size, info.mtime, info.mode, info.uid, info.gid, info.uname, info.gname = (
                len(data),
                0,
                0o644,
                0,
                0,
                "",
                "",
            )
            tar.addfile(info, io.BytesIO(data))
    return raw.getvalue()


def _fnv1a(data: bytes) -> int:
    h = 0xCBF29CE484222325
    for c in data:
        h = ((h ^ c) * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return h


def _checkpoint_generation(text: bytes, where: str) -> int:
    """The generation of a checkpoint that passes the engine's structural checks (JSON, checksum, format, a
    history ending at its generation, a population); StoreError naming ``where`` otherwise. The engine checks
    more on restore (the config's identity, the meaning of every field)."""
    try:
        outer = json.loads(text)
    except (ValueError, RecursionError) as e:
        raise StoreError(f"{where}: not valid JSON (truncated?): {e}") from None
    if not (
        isinstance(outer, dict) and isinstance(outer.get("payload"), str) and isinstance(outer.get("checksum"), str)
    ):
        raise StoreError(f"{where}: not an animat checkpoint (no checksum and payload)")
    body = outer["payload"].encode("utf-8")
    if f"{_fnv1a(body):016x}" != outer["checksum"]:
        raise StoreError(f"{where}: checksum {outer['checksum']} does not match its content ({_fnv1a(body):016x})")
    try:
        p = json.loads(body)
    except (ValueError, RecursionError) as e:
        raise StoreError(f"{where}: payload is not valid JSON: {e}") from None
    if not isinstance(p, dict) or p.get("format") != "animat.checkpoint":
        fmt = p.get("format") if isinstance(p, dict) else None
        raise StoreError(f"{where}: not an animat checkpoint (format {fmt!r})")
    gen, hist, pop = p.get("generation"), p.get("history"), p.get("population")
    if not isinstance(gen, int) or isinstance(gen, bool) or gen < 0:
        raise StoreError(f"{where}: no generation")
    if not isinstance(hist, list) or not hist or not isinstance(hist[-1], dict):
        raise StoreError(f"{where}: no history")
    if hist[-1].get("generation") != gen:
        raise StoreError(
            f"{where}: generation {gen} does not match its history, which ends at {hist[-1].get('generation')}"
        )
    if not isinstance(pop, list) or not pop:
        raise StoreError(f"{where}: no population")
    return gen


def _history_generation(data: bytes, where: str) -> int:
    """The last generation of a history.csv with a header, complete rows of as many fields and the
    generations 0, 1, 2, ... in order; StoreError naming the line otherwise."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise StoreError(f"{where}: not UTF-8 text ({e})") from None
    if not text:
        raise StoreError(f"{where}: empty")
    if not text.endswith("\n"):
        raise StoreError(f"{where}: the last line is incomplete (no newline; truncated?)")
    lines = text.split("\n")[:-1]
    header = lines[0].split(",")
    if header[0] != "generation":
        raise StoreError(f"{where}: line 1 is not the header (generation,...)")
    if len(lines) < 2:
        raise StoreError(f"{where}: no generation")
    for n, line in enumerate(lines[1:], start=2):
        fields = line.split(",")
        if len(fields) != len(header):
            raise StoreError(f"{where} line {n}: {len(fields)} fields, the header has {len(header)}")
        if fields[0] != str(n - 2):
            raise StoreError(f"{where} line {n}: generation {fields[0]!r}, expected {n - 2}")
    return len(lines) - 2


#: how the engine's stop reason for the paper's stall rule begins ("no improvement for ...")
STALLED = "no improvement"


def _derived_stop(config: Path, history_lines: List[str]) -> str:
    """The stop rule the history shows as reached (the engine's wording), else "in progress"."""
    try:
        evo = tomllib.loads(config.read_text()).get("evolution", {})
    except (OSError, tomllib.TOMLDecodeError):
        return "in progress"
    rows = [ln.split(",") for ln in history_lines[1:]]
    if not rows:
        return "in progress"
    cap, stall = int(evo.get("generations", 0)), int(evo.get("stall_generations", 0))
    last = int(rows[-1][0])
    if cap > 0 and last >= cap:
        return f"generation cap evolution.generations = {cap} reached"
    best = [float(r[1]) for r in rows]
    improved = max((int(r[0]) for r, b, prev in zip(rows[1:], best[1:], best[:-1]) if b > prev), default=0)
    if stall > 0 and last - improved >= stall:
        return f"no improvement for evolution.stall_generations = {stall} generations"
    return "in progress"


def is_packed_run(path: Path) -> bool:
    """Whether ``path`` holds a packed run (its config and checkpoint)."""
    return (path / "config.toml").is_file() and (path / "checkpoint.json.gz").is_file()


def _packed_generation(dest: Path) -> Optional[Tuple[int, str]]:
    """The generation of the run packed at ``dest`` and the file that gives it (its checkpoint; its status.json
    when the checkpoint does not read); None when nothing is packed there. StoreError when files are there but
    neither tells a generation: what is there is not replaced unseen."""
    if not dest.is_dir() or not any(dest.iterdir()):
        return None
    why = []
    ckpt = dest / "checkpoint.json.gz"
    try:
        return _checkpoint_generation(_gunzip_bytes(ckpt, str(ckpt)), str(ckpt)), "checkpoint.json.gz"
    except (OSError, StoreError) as e:
        why.append(str(e))
    status = dest / "status.json"
    try:
        gen = json.loads(status.read_text()).get("generation")
        if isinstance(gen, int) and not isinstance(gen, bool):
            return gen, "status.json"
        why.append(f"{status}: no generation")
    except (OSError, ValueError, AttributeError) as e:
        why.append(f"{status}: {e}")
    raise StoreError(
        f"{dest}: holds files but no readable packed run ({'; '.join(why)}); refusing to pack over it "
        f"(move it away first)"
    )


def _prepare_pack(run_dir: Path, dest: Path, stop_reason: Optional[str]) -> Dict[str, bytes]:
    """Every file of the packed run (manifest.json included), after checking that the run restores and is
    not behind what ``dest`` holds; StoreError naming the run and the file otherwise. Writes nothing."""
    for need in ("config.toml", "history.csv"):
        if not (run_dir / need).is_file():
            raise StoreError(f"{run_dir / need}: missing; refusing to pack {run_dir}")
    config = (run_dir / "config.toml").read_bytes()
    try:
        tomllib.loads(config.decode("utf-8"))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as e:
        raise StoreError(f"{run_dir / 'config.toml'}: not a TOML config ({e}); refusing to pack {run_dir}") from None
    history = (run_dir / "history.csv").read_bytes()
    last_row = _history_generation(history, str(run_dir / "history.csv"))
    if (run_dir / "checkpoint.json").is_file():
        ckpt_path = run_dir / "checkpoint.json"
        ckpt = ckpt_path.read_bytes()
    elif (run_dir / "checkpoint.json.gz").is_file():
        ckpt_path = run_dir / "checkpoint.json.gz"
        ckpt = _gunzip_bytes(ckpt_path, str(ckpt_path))
    else:
        raise StoreError(f"{run_dir}: no checkpoint.json(.gz); refusing to pack it")
    generation = _checkpoint_generation(ckpt, str(ckpt_path))
    if last_row < generation:
        raise StoreError(
            f"{run_dir / 'history.csv'}: ends at generation {last_row}, before the checkpoint's "
            f"{generation}; refusing to pack {run_dir}"
        )
    best_dir = run_dir / "best"
    if not best_dir.is_dir():
        raise StoreError(f"{best_dir}: missing (the lineage of best individuals); refusing to pack {run_dir}")
    best = []
    for f in sorted(p for p in best_dir.iterdir() if _BEST_NAME.fullmatch(p.name)):
        data = f.read_bytes()
        try:
            if not isinstance(json.loads(data), dict):
                raise ValueError("not a JSON object")
        except (ValueError, RecursionError) as e:
            raise StoreError(f"{f}: not a JSON genome record ({e}); refusing to pack {run_dir}") from None
        best.append((f.name, data))
    if not best:
        raise StoreError(f"{best_dir}: no gen_*.json (the lineage of best individuals); refusing to pack {run_dir}")
    old = _packed_generation(dest)
    if old is not None:
        ours, ours_from = (generation, ckpt_path.name) if old[1] == "checkpoint.json.gz" else (last_row, "history.csv")
        if ours < old[0]:
            raise StoreError(
                f"{run_dir}: at generation {ours} ({ours_from}), behind the run packed in {dest} at "
                f"generation {old[0]} ({old[1]}); refusing to replace it"
            )
    lines = [ln for ln in history.decode().splitlines() if ln.strip()]
    try:
        old_status = json.loads((dest / "status.json").read_text()) if (dest / "status.json").is_file() else {}
    except (OSError, ValueError):
        old_status = {}
    if not isinstance(old_status, dict):
        old_status = {}
    if stop_reason is None:  # unchanged since the last packing: keep its reason; else derive it
        stop_reason = (
            old_status.get("stop_reason", "in progress")
            if old_status.get("generation") == last_row
            else _derived_stop(run_dir / "config.toml", lines)
        )
    status = {"generation": last_row, "stop_reason": stop_reason}
    tar = _tar_best(best)
    files = {
        "config.toml": config,
        "history.csv.gz": _gzip_bytes(history),
        "best.tar.gz": _gzip_bytes(tar),
        "checkpoint.json.gz": _gzip_bytes(ckpt),
        "status.json": (json.dumps(status, indent=1, sort_keys=True) + "\n").encode(),
    }
    if (run_dir / "resume.log").is_file():
        files["resume.log"] = (run_dir / "resume.log").read_bytes()
    gunzipped = {"history.csv.gz": history, "best.tar.gz": tar, "checkpoint.json.gz": ckpt}
    packed = {}
    for name, data in files.items():
        packed[name] = _digest(data)
        if name in gunzipped:
            packed[name]["gunzipped"] = _digest(gunzipped[name])
    unpacked = {
        "config.toml": _digest(config),
        "history.csv": _digest(history),
        "checkpoint.json": _digest(ckpt),
        "status.json": _digest(files["status.json"]),
    }
    unpacked.update({f"best/{name}": _digest(data) for name, data in best})
    if "resume.log" in files:
        unpacked["resume.log"] = _digest(files["resume.log"])
    manifest = {"format": MANIFEST_FORMAT, "version": 1, "packed": packed, "unpacked": unpacked}
    files[MANIFEST] = (json.dumps(manifest, indent=1, sort_keys=True) + "\n").encode()
    return files


def _write_pack(dest: Path, files: Dict[str, bytes]) -> Path:
    dest.mkdir(parents=True, exist_ok=True)
    # The manifest last: a pack cut short leaves content the old manifest does not match, which unpack reports.
    for name in sorted(files, key=lambda n: (n == MANIFEST, n == "status.json", n)):
        _write_if_changed(dest / name, files[name])
    _sync_dir(dest)
    return dest


def pack_run(run_dir: Path, dest: Path, stop_reason: Optional[str] = None) -> Path:
    """Pack the run directory ``run_dir`` (config.toml, history.csv, best/, checkpoint.json or
    checkpoint.json.gz, optional resume.log) into ``dest`` with its manifest; returns ``dest``. ``stop_reason``
    goes to status.json (default: the one already there if the run has not moved since, else "in progress").
    Raises StoreError, writing nothing, when the run would not restore or is behind the run packed in ``dest``
    (see the module docstring)."""
    run_dir, dest = Path(run_dir), Path(dest)
    return _write_pack(dest, _prepare_pack(run_dir, dest, stop_reason))


def _is_digest(e: object) -> bool:
    return (
        isinstance(e, dict)
        and isinstance(e.get("sha256"), str)
        and re.fullmatch(r"[0-9a-f]{64}", e["sha256"]) is not None
        and isinstance(e.get("size"), int)
        and not isinstance(e.get("size"), bool)
        and e["size"] >= 0
    )


def _read_manifest(packed: Path) -> dict:
    path = packed / MANIFEST
    if path.stat().st_size > 64 << 20:
        raise StoreError(f"{path}: {path.stat().st_size} bytes, too large for a manifest")
    try:
        m = json.loads(path.read_bytes())
    except (ValueError, RecursionError) as e:
        raise StoreError(f"{path}: not valid JSON ({e})") from None
    ok = (
        isinstance(m, dict)
        and m.get("format") == MANIFEST_FORMAT
        and m.get("version") == 1
        and isinstance(m.get("packed"), dict)
        and isinstance(m.get("unpacked"), dict)
        and all(_is_digest(e) for e in m["packed"].values())
        and all(_is_digest(e) for e in m["unpacked"].values())
        and all(_is_digest(m["packed"][n].get("gunzipped")) for n in m["packed"] if n.endswith(".gz"))
    )
    if not ok:
        raise StoreError(f"{path}: not a manifest of format {MANIFEST_FORMAT} version 1")
    return m


def _check_digest(where: str, what: str, got: Dict[str, object], want: Dict[str, object]) -> None:
    if got["size"] != want["size"]:
        raise StoreError(f"{where}: {what}size {got['size']} bytes, the manifest says {want['size']}")
    if got["sha256"] != want["sha256"]:
        raise StoreError(f"{where}: {what}sha256 {got['sha256']} does not match the manifest's {want['sha256']}")


def _stage(packed: Path, staging: Path) -> Dict[str, Path]:
    """Verify the packed run ``packed`` and write the files unpacking installs into ``staging``; returns
    ``{path in the run directory: staged file}``. StoreError naming the run and the file on any mismatch."""
    manifest = _read_manifest(packed) if (packed / MANIFEST).is_file() else None
    present = [n for n in PACKED_FILES + OPTIONAL_FILES if (packed / n).is_file()]
    for need in ("config.toml", "history.csv.gz", "best.tar.gz", "checkpoint.json.gz"):
        if need not in present:
            raise StoreError(f"{packed / need}: missing from the packed run {packed}")
    if manifest is not None:
        for name in sorted(set(manifest["packed"]) - set(present)):
            raise StoreError(f"{packed / name}: listed in {MANIFEST} but missing")
        for name in sorted(set(present) - set(manifest["packed"])):
            raise StoreError(f"{packed / name}: not listed in {MANIFEST}")
    staged: Dict[str, Path] = {}
    (staging / "best").mkdir()
    for name in present:
        src, where = packed / name, str(packed / name)
        want = manifest["packed"][name] if manifest is not None else None
        if want is not None:
            _check_digest(where, "", _file_digest(src), want)
        rel = _GUNZIPPED.get(name, "best.tar" if name == "best.tar.gz" else name)
        gunzip = name.endswith(".gz")
        want_out = (want["gunzipped"] if gunzip else want) if want is not None else None
        limit = MAX_UNPACKED_BYTES if want_out is None else min(want_out["size"], MAX_UNPACKED_BYTES)
        sink = _Sink(where, limit, staging / rel)
        try:
            if gunzip:
                _gunzip(src, sink, where)
            else:
                _file_digest(src, sink)
        finally:
            sink.close()
        if want_out is not None:
            _check_digest(where, "decompressed " if gunzip else "", sink.digest(), want_out)
        staged[rel] = staging / rel
    tar_path = staged.pop("best.tar")
    where = str(packed / "best.tar.gz")
    try:
        with tarfile.open(tar_path, mode="r:") as tar:
            for m in tar:
                base = m.name[len("best/") :] if m.name.startswith("best/") else ""
                if not m.isfile() or not _BEST_NAME.fullmatch(base):
                    raise StoreError(f"{where}: unexpected member {m.name!r}")
                if f"best/{base}" in staged:
                    raise StoreError(f"{where}: member {m.name!r} appears twice")
                member = tar.extractfile(m)
                if member is None:
                    raise StoreError(f"{where}: cannot read member {m.name!r}")
                sink = _Sink(f"{where} member {m.name}", MAX_UNPACKED_BYTES, staging / "best" / base)
                try:
                    while chunk := member.read(_CHUNK):
                        sink.write(chunk)
                finally:
                    sink.close()
                if sink.size != m.size:
                    raise StoreError(f"{where}: member {m.name!r} holds {sink.size} bytes, its header says {m.size}")
                staged[f"best/{base}"] = staging / "best" / base
    except tarfile.TarError as e:
        raise StoreError(f"{where}: not a readable tar archive ({e})") from None
    tar_path.unlink()
    if manifest is not None:
        want_files = manifest["unpacked"]
        for rel in sorted(set(want_files) - set(staged)):
            raise StoreError(f"{packed}: {rel} is listed in {MANIFEST} but not in the packed files")
        for rel in sorted(set(staged) - set(want_files)):
            raise StoreError(f"{packed}: {rel} is in the packed files but not listed in {MANIFEST}")
        for rel, path in staged.items():
            _check_digest(f"{packed}: {rel}", "", _file_digest(path), want_files[rel])
    return staged


def _compare(a: Path, b: Path) -> str:
    """``"equal"`` when the files hold the same bytes, ``"prefix"`` when ``a`` is a strict beginning of ``b``
    (what a write cut short leaves), else ``"other"``."""
    if a.stat().st_size > b.stat().st_size:
        return "other"
    with open(a, "rb") as fa, open(b, "rb") as fb:
        while True:
            ca = fa.read(_CHUNK)
            cb = fb.read(len(ca)) if ca else fb.read(1)
            if not ca:
                return "equal" if not cb else "prefix"
            if ca != cb:
                return "other"


def _install(staged: Dict[str, Path], run_dir: Path, only: Optional[set]) -> bool:
    """Rename the staged files into ``run_dir`` (those in ``only`` when given; each only where it differs),
    the checkpoint last: a run directory with a checkpoint has all its other files."""
    changed = False
    for rel in sorted(staged, key=lambda r: (r == "checkpoint.json", r)):
        if only is not None and rel not in only:
            continue
        target = run_dir / rel
        if target.is_file() and _compare(target, staged[rel]) == "equal":
            continue
        target.parent.mkdir(parents=True, exist_ok=True)
        os.replace(staged[rel], target)
        changed = True
    if changed:
        _sync_dir(run_dir / "best")
        _sync_dir(run_dir)
    return changed


def _mkdirs(path: Path) -> List[Path]:
    """mkdir -p; returns the directories it created, outermost first."""
    missing = []
    while not path.exists():
        missing.append(path)
        path = path.parent
    for d in reversed(missing):
        d.mkdir(exist_ok=True)
    return list(reversed(missing))


def _unpack_one(packed: Path, run_dir: Path) -> bool:
    """Bring ``run_dir`` to the packed run ``packed``, or leave it when it holds a run that is further on;
    returns whether a file was written. A checkpoint.json that is a strict beginning of the packed one was
    left by an unpack cut short: the run is unpacked again. Files missing next to a checkpoint equal to the
    packed one, or cut short, are restored; other differing files are the work copy's and are kept."""
    created = _mkdirs(run_dir.parent)
    for stale in run_dir.parent.glob(f".{run_dir.name}.unpack-*"):  # left by an unpack that was killed
        shutil.rmtree(stale, ignore_errors=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{run_dir.name}.unpack-", dir=run_dir.parent))
    installing = False
    try:
        staged = _stage(packed, staging)
        ckpt = run_dir / "checkpoint.json"
        only = None
        if ckpt.exists():
            state = _compare(ckpt, staged["checkpoint.json"])
            if state == "equal":
                only = {
                    rel
                    for rel, path in staged.items()
                    if not (run_dir / rel).is_file() or _compare(run_dir / rel, path) == "prefix"
                }
            elif state == "other":
                try:
                    ours = _checkpoint_generation(ckpt.read_bytes(), str(ckpt))
                except StoreError as e:
                    raise StoreError(
                        f"{e}; nor is it part of the packed run {packed}: move {run_dir} away to unpack it"
                    ) from None
                theirs = _checkpoint_generation(
                    staged["checkpoint.json"].read_bytes(), str(packed / "checkpoint.json.gz")
                )
                if ours < theirs:
                    raise StoreError(
                        f"{ckpt}: at generation {ours}, behind the packed run {packed} at generation "
                        f"{theirs}: move {run_dir} away to unpack it"
                    )
                return False  # a work directory is newer than the repository's copy until it is packed
        installing = True
        return _install(staged, run_dir, only)
    except OSError as e:
        raise OSError(
            e.errno,
            f"unpacking {packed} into {run_dir}: {e.strerror or e}" + (f" ({e.filename})" if e.filename else ""),
        ) from e
    finally:
        shutil.rmtree(staging, ignore_errors=True)
        if not installing:
            for d in reversed(created):
                try:
                    d.rmdir()
                except OSError:
                    break


def unpack_run(packed: Path, run_dir: Path) -> Path:
    """Unpack a packed run into ``run_dir`` as the runner writes it (config.toml, history.csv, best/,
    checkpoint.json, resume.log; and status.json, which the runner ignores), ready for ``animat_evolve --resume``
    / ``python -m animat experiment``, after verifying it (see the module docstring): StoreError naming the run
    and the file, and nothing written, when it does not verify. Refuses to overwrite a run directory that
    already holds a checkpoint."""
    packed, run_dir = Path(packed), Path(run_dir)
    if not is_packed_run(packed):
        raise FileNotFoundError(f"unpack_run: {packed} is not a packed run (config.toml, checkpoint.json.gz)")
    if (run_dir / "checkpoint.json").exists():
        raise FileExistsError(f"unpack_run: {run_dir} already holds a run (checkpoint.json)")
    _unpack_one(packed, run_dir)
    return run_dir


def packed_runs(root: Path) -> Dict[str, List[Path]]:
    """``{env: [run_<i> dirs in index order]}`` of the packed runs under ``root``."""
    out: Dict[str, List[Path]] = {}
    for env in sorted(p for p in Path(root).iterdir() if p.is_dir()):
        runs = sorted(
            (p for p in env.glob("run_*") if p.name[4:].isdigit() and is_packed_run(p)), key=lambda p: int(p.name[4:])
        )
        if runs:
            out[env.name] = runs
    return out


def unpack_tree(root: Path, work: Path) -> List[Path]:
    """Unpack every packed run ``root/<env>/run_<i>`` into ``work/<env>/run_<i>``, verifying each. A work
    directory that already equals its packed run is left as it is; one further on than its packed run is kept
    (a work directory is newer than the repository's copy until it is packed); what an unpack cut short left
    is repaired. Returns the directories written to. A run that does not verify, or a work directory behind
    its packed run or with a damaged checkpoint, is not unpacked; the others are, then StoreError lists every
    such run (its ``done`` attribute holds the directories written to)."""
    done, errors = [], []
    for env, runs in packed_runs(root).items():
        for p in runs:
            target = Path(work) / env / p.name
            try:
                if _unpack_one(p, target):
                    done.append(target)
            except (StoreError, OSError) as e:
                errors.append(str(e))
    if errors:
        err = StoreError(f"{len(errors)} run(s) not unpacked:\n" + "\n".join(errors))
        err.done = done  # type: ignore[attr-defined]
        raise err
    return done


def _stop_reasons(env_dir: Path) -> Dict[int, Tuple[int, str]]:
    """Each run's (generation, stop reason) as ``env_dir/summary.json`` records them."""
    f = env_dir / "summary.json"
    if not f.is_file():
        return {}
    return {
        int(r["index"]): (int(r["generations"]), str(r["stop_reason"]))
        for r in json.loads(f.read_text()).get("runs", [])
    }


def _history_lines(run: Path) -> List[str]:
    """The non-empty lines of ``run/history.csv``, header first."""
    return [ln for ln in (run / "history.csv").read_text().splitlines() if ln.strip()]


def _last_generation(lines: Sequence[str]) -> Optional[int]:
    """The generation of the last row of a history's lines; None when it has no row."""
    return int(lines[-1].split(",")[0]) if len(lines) > 1 else None


def _last_history_generation(run: Path) -> Optional[int]:
    try:
        return _last_generation(_history_lines(run))
    except (OSError, ValueError):
        return None


def pack_tree(work: Path, root: Path) -> List[Path]:
    """Pack every run ``work/<env>/run_<i>`` with a checkpoint into ``root/<env>/run_<i>`` (stop reasons from
    ``work/<env>/summary.json`` when the experiment wrote one and it records the generation the run's history
    ends at: a session stopped before it wrote its summary leaves an earlier session's there, whose reason is
    not this one's; the reason is then derived from the history). Returns the packed directories. Every run is
    checked first: when one is refused (see ``pack_run``), StoreError lists each refused run and no file is
    written."""
    plans, errors = [], []
    for env in sorted(p for p in Path(work).iterdir() if p.is_dir()):
        reasons = _stop_reasons(env)
        for run in sorted(env.glob("run_*")):
            if run.name[4:].isdigit() and (run / "checkpoint.json").is_file():
                dest = Path(root) / env.name / run.name
                try:
                    recorded = reasons.get(int(run.name[4:]))
                    reason = recorded[1] if recorded and recorded[0] == _last_history_generation(run) else None
                    plans.append((dest, _prepare_pack(run, dest, reason)))
                except (StoreError, OSError) as e:
                    errors.append(str(e))
    if errors:
        raise StoreError(f"{len(errors)} run(s) refused, nothing packed:\n" + "\n".join(errors))
    return [_write_pack(dest, files) for dest, files in plans]


def next_round_cap(work: Path, envs: Sequence[str], runs: int, generations: int, round_size: int) -> int:
    """Breadth-first growth (``ANIMAT_REPLICATION_ROUND`` of replication.sh): the generation cap of
    the next round, ``round_size`` generations past the least advanced run that is still open, at most
    ``generations``; -1 when every run is finished. A run is open when it has not reached ``generations``
    and has not stopped by the stall rule of its config; a run not started yet counts as generation 0."""
    if round_size < 1:
        raise ValueError(f"next_round_cap: round_size must be >= 1, got {round_size}")
    lowest: Optional[int] = None
    for env in envs:
        for i in range(runs):
            run = Path(work) / env / f"run_{i}"
            last = 0
            if (run / "history.csv").is_file():
                lines = _history_lines(run)
                last = _last_generation(lines) or 0
                if STALLED in _derived_stop(run / "config.toml", lines):
                    continue
            if last >= generations:
                continue
            lowest = last if lowest is None else min(lowest, last)
    return -1 if lowest is None else min(lowest + round_size, generations)


def growth(root: Path) -> Dict[str, List[Tuple[str, int, str]]]:
    """``{env: [(run name, last generation, stop reason)]}`` of the packed runs under ``root``, from their
    status.json: how far a study has grown, without unpacking it."""
    out: Dict[str, List[Tuple[str, int, str]]] = {}
    for env, runs in packed_runs(root).items():
        rows = []
        for run in runs:
            status = json.loads((run / "status.json").read_text())
            rows.append((run.name, int(status["generation"]), str(status.get("stop_reason", ""))))
        out[env] = rows
    return out


def _span(values: Sequence[int]) -> str:
    return f"{min(values)}" if min(values) == max(values) else f"{min(values)}-{max(values)}"


def growth_lines(root: Path) -> List[str]:
    """One line per environment: where its runs stand, and which runs the stall rule stopped where."""
    lines = []
    for env, rows in growth(root).items():
        stalled = [(name, g) for name, g, why in rows if STALLED in why]
        others = [g for _, g, why in rows if STALLED not in why]
        parts = [f"{env}: {len(rows)} run{'s' if len(rows) != 1 else ''}"]
        if others:
            parts.append(f"{len(others)} at generation {_span(others)}")
        if stalled:
            parts.append(
                f"{len(stalled)} stopped by the stall rule: " + ", ".join(f"{name} at {g}" for name, g in stalled)
            )
        lines.append("; ".join(parts))
    return lines


def _wall_seconds(run: Path) -> List[Tuple[int, float]]:
    """(generation, history column ``wall_seconds``) of every row of a packed run's history."""
    text = gzip.decompress((run / "history.csv.gz").read_bytes()).decode()
    lines = [ln for ln in text.splitlines() if ln.strip()]
    header = lines[0].split(",")
    if "wall_seconds" not in header:
        raise StoreError(f"{run / 'history.csv.gz'}: no column wall_seconds")
    g, w = header.index("generation"), header.index("wall_seconds")
    return [(int(c[g]), float(c[w])) for c in (ln.split(",") for ln in lines[1:])]


def pace(root: Path, last: int = 50, until: Optional[int] = None, target: int = 2000) -> List[str]:
    """What growing the packed runs under ``root`` to generation ``target`` costs, at the pace of each run's
    ``last`` generations up to generation ``until`` (default: its last). A generation's cost is the rise of
    the history's ``wall_seconds`` (cumulative over resumes; one run is one process on one core); each run's
    pace is the median over its window, so a generation slowed by other work on the machine moves it less
    than a mean. One line per environment (the median and range of its runs' paces, the generations left
    and their core-hours: runs the stall rule stopped have none left), then the total."""
    if last < 1 or target < 1:
        raise ValueError(f"pace: last and target must be >= 1, got {last}, {target}")
    lines, total = [], 0.0
    for env, runs in packed_runs(root).items():
        paces, ends, left, hours = [], [], 0, 0.0
        for run in runs:
            rows = [(g, w) for g, w in _wall_seconds(run) if until is None or g <= until]
            window = rows[-(last + 1) :]
            steps = [(b - a) / (gb - ga) for (ga, a), (gb, b) in zip(window, window[1:]) if gb > ga]
            if not steps:
                raise StoreError(f"{run}: fewer than two generations up to {until}")
            paces.append(statistics.median(steps))
            ends.append(window[-1][0])
            status = json.loads((run / "status.json").read_text())
            if STALLED not in str(status.get("stop_reason", "")):
                gens = max(0, target - int(status["generation"]))
                left += gens
                hours += gens * paces[-1] / 3600
        total += hours
        lines.append(
            f"{env}: {len(runs)} run{'s' if len(runs) != 1 else ''}, median {statistics.median(paces):.1f} s a "
            f"generation (runs {min(paces):.1f}-{max(paces):.1f}) over the {last} generations up to {_span(ends)}; "
            f"{left} generations left to {target}: {hours:.1f} core-hours"
        )
    lines.append(f"all: {total:.1f} core-hours to generation {target}")
    return lines


def main(argv: Optional[Sequence[str]] = None) -> int:
    p = argparse.ArgumentParser(
        prog="replication_store.py",
        description="Pack evolution runs into the repository (data/replication, ...), or unpack them.",
    )
    sub = p.add_subparsers(dest="command", required=True)
    u = sub.add_parser("unpack", help="unpack DATA/<env>/run_<i> into WORK/<env>/run_<i>")
    u.add_argument("data", type=Path)
    u.add_argument("work", type=Path)
    k = sub.add_parser("pack", help="pack WORK/<env>/run_<i> into DATA/<env>/run_<i>")
    k.add_argument("work", type=Path)
    k.add_argument("data", type=Path)
    c = sub.add_parser("next-cap", help="print the generation cap of the next breadth-first round (-1: all finished)")
    c.add_argument("work", type=Path)
    c.add_argument("--envs", nargs="+", required=True)
    c.add_argument("--runs", type=int, required=True)
    c.add_argument("--generations", type=int, required=True)
    c.add_argument("--round", type=int, required=True, dest="round_size")
    st = sub.add_parser("status", help="print how far the packed runs under DATA have grown, per environment")
    st.add_argument("data", type=Path)
    pc = sub.add_parser("pace", help="print what growing the packed runs under DATA to --target generations costs")
    pc.add_argument("data", type=Path)
    pc.add_argument("--last", type=int, default=50, help="generations each run's pace is the median over (50)")
    pc.add_argument("--until", type=int, default=None, help="the window ends at this generation (default: the last)")
    pc.add_argument("--target", type=int, default=2000, help="the generation every open run grows to (2000)")
    args = p.parse_args(argv)
    if args.command == "pace":
        if not args.data.is_dir():
            print(f"replication_store: {args.data}: no such directory", file=sys.stderr)
            return 1
        try:
            print("\n".join(pace(args.data, args.last, args.until, args.target)))
        except (StoreError, ValueError, OSError) as e:
            print(f"replication_store: error: {e}", file=sys.stderr)
            return 1
        return 0
    if args.command == "status":
        if not args.data.is_dir():
            print(f"replication_store: {args.data}: no such directory", file=sys.stderr)
            return 1
        print("\n".join(growth_lines(args.data)) or f"{args.data}: no packed runs")
        return 0
    if args.command == "next-cap":
        print(next_round_cap(args.work, args.envs, args.runs, args.generations, args.round_size))
        return 0
    if args.command == "unpack":
        if not args.data.is_dir():
            print(f"replication_store: {args.data}: no such directory (nothing to resume)", file=sys.stderr)
            return 0
        try:
            done = unpack_tree(args.data, args.work)
        except StoreError as e:
            print(f"unpacked {len(getattr(e, 'done', []))} run(s) into {args.work}", file=sys.stderr)
            print(f"replication_store: error: {e}", file=sys.stderr)
            return 1
        print(f"unpacked {len(done)} run(s) into {args.work}", file=sys.stderr)
    else:
        try:
            done = pack_tree(args.work, args.data)
        except (StoreError, OSError) as e:
            print(f"replication_store: error: {e}", file=sys.stderr)
            return 1
        print(f"packed {len(done)} run(s) into {args.data}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
