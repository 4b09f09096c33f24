"""The replication study's runs, kept in the repository (issue 19): pack a run directory into
``data/replication/<env>/run_<i>/`` and unpack it again to resume it.

A packed run holds what is needed to check and to continue it, compressed:

- ``config.toml``: the resolved config the run was last run with (plain text, a few KB);
- ``history.csv.gz``: one row per generation;
- ``best.tar.gz``: the lineage of best individuals (``best/gen_*.json``);
- ``checkpoint.json.gz``: the population, random state and history to resume from;
- ``resume.log`` when the run was resumed with other caps;
- ``status.json``: the stop reason of its last session (``"in progress"`` when unknown) and the
  last generation.

Packing is deterministic (sorted members, fixed times and owners, gzip without a time stamp), so
packing an unchanged run gives the same bytes and git sees no change. Command line::

    python -m animat.replication_store unpack data/replication runs/replication   # into work dirs
    python -m animat.replication_store pack runs/replication data/replication     # back into the repository
"""
from __future__ import annotations

import argparse
import gzip
import io
import json
import shutil
import sys
import tarfile
import tomllib
from pathlib import Path
from typing import Dict, List, Optional, Sequence

__all__ = ["PACKED_FILES", "pack_run", "unpack_run", "pack_tree", "unpack_tree", "packed_runs", "is_packed_run",
           "main"]

PACKED_FILES = ("config.toml", "history.csv.gz", "best.tar.gz", "checkpoint.json.gz", "status.json")


def _gzip_bytes(data: bytes) -> bytes:
    buf = io.BytesIO()
    with gzip.GzipFile(fileobj=buf, mode="wb", compresslevel=9, mtime=0, filename="") as f:
        f.write(data)
    return buf.getvalue()


def _write_if_changed(path: Path, data: bytes) -> None:
    if path.is_file() and path.read_bytes() == data:
        return
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_bytes(data)
    tmp.replace(path)


def _tar_best(best: Path) -> bytes:
    raw = io.BytesIO()
    with tarfile.open(fileobj=raw, mode="w", format=tarfile.PAX_FORMAT) as tar:
        for f in sorted(best.glob("gen_*.json")):
            data = f.read_bytes()
            info = tarfile.TarInfo(f"best/{f.name}")
            info.size, info.mtime, info.mode, info.uid, info.gid, info.uname, info.gname = len(data), 0, 0o644, 0, 0, "", ""
            tar.addfile(info, io.BytesIO(data))
    return _gzip_bytes(raw.getvalue())


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


def pack_run(run_dir: Path, dest: Path, stop_reason: Optional[str] = None) -> Path:
    """Pack the run directory ``run_dir`` (config.toml, history.csv, best/, checkpoint.json or
    checkpoint.json.gz, optional resume.log) into ``dest``; returns ``dest``. ``stop_reason`` goes to
    status.json (default: the one already there if the run has not moved since, else "in progress")."""
    run_dir, dest = Path(run_dir), Path(dest)
    for need in ("config.toml", "history.csv"):
        if not (run_dir / need).is_file():
            raise FileNotFoundError(f"pack_run: {run_dir / need} is missing")
    if (run_dir / "checkpoint.json").is_file():
        ckpt = _gzip_bytes((run_dir / "checkpoint.json").read_bytes())
    elif (run_dir / "checkpoint.json.gz").is_file():
        ckpt = _gzip_bytes(gzip.decompress((run_dir / "checkpoint.json.gz").read_bytes()))
    else:
        raise FileNotFoundError(f"pack_run: {run_dir} has no checkpoint.json(.gz)")
    dest.mkdir(parents=True, exist_ok=True)
    history = (run_dir / "history.csv").read_bytes()
    lines = [ln for ln in history.decode().splitlines() if ln.strip()]
    last = int(lines[-1].split(",")[0]) if len(lines) > 1 else -1
    old = {}
    if (dest / "status.json").is_file():
        old = json.loads((dest / "status.json").read_text())
    if stop_reason is None:  # unchanged since the last packing: keep its reason; else derive it
        stop_reason = (old.get("stop_reason", "in progress") if old.get("generation") == last
                       else _derived_stop(run_dir / "config.toml", lines))
    status = {"generation": last, "stop_reason": stop_reason}
    _write_if_changed(dest / "config.toml", (run_dir / "config.toml").read_bytes())
    _write_if_changed(dest / "history.csv.gz", _gzip_bytes(history))
    _write_if_changed(dest / "best.tar.gz", _tar_best(run_dir / "best"))
    _write_if_changed(dest / "checkpoint.json.gz", ckpt)
    _write_if_changed(dest / "status.json", (json.dumps(status, indent=1, sort_keys=True) + "\n").encode())
    if (run_dir / "resume.log").is_file():
        _write_if_changed(dest / "resume.log", (run_dir / "resume.log").read_bytes())
    return dest


def unpack_run(packed: Path, run_dir: Path) -> Path:
    """Unpack a packed run into ``run_dir`` as the runner writes it (config.toml, history.csv, best/,
    checkpoint.json, resume.log; and status.json, which the runner ignores), ready for ``animat_evolve --resume`` / ``python -m animat experiment``.
    Refuses to overwrite a run directory that already holds a checkpoint."""
    packed, run_dir = Path(packed), Path(run_dir)
    if not is_packed_run(packed):
        raise FileNotFoundError(f"unpack_run: {packed} is not a packed run (config.toml, checkpoint.json.gz)")
    if (run_dir / "checkpoint.json").exists():
        raise FileExistsError(f"unpack_run: {run_dir} already holds a run (checkpoint.json)")
    run_dir.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(packed / "config.toml", run_dir / "config.toml")
    (run_dir / "history.csv").write_bytes(gzip.decompress((packed / "history.csv.gz").read_bytes()))
    (run_dir / "best").mkdir(exist_ok=True)
    with tarfile.open(packed / "best.tar.gz", mode="r:gz") as tar:
        for m in tar.getmembers():
            name = Path(m.name)
            if not m.isfile() or name.parent != Path("best") or not name.name.startswith("gen_"):
                raise ValueError(f"unpack_run: unexpected member {m.name!r} in {packed / 'best.tar.gz'}")
            member = tar.extractfile(m)
            if member is None:
                raise ValueError(f"unpack_run: cannot read {m.name!r} in {packed / 'best.tar.gz'}")
            data = member.read()
            (run_dir / "best" / name.name).write_bytes(data)
    for extra in ("resume.log", "status.json"):
        if (packed / extra).is_file():
            shutil.copyfile(packed / extra, run_dir / extra)
    (run_dir / "checkpoint.json").write_bytes(gzip.decompress((packed / "checkpoint.json.gz").read_bytes()))
    return run_dir


def packed_runs(root: Path) -> Dict[str, List[Path]]:
    """``{env: [run_<i> dirs in index order]}`` of the packed runs under ``root``."""
    out: Dict[str, List[Path]] = {}
    for env in sorted(p for p in Path(root).iterdir() if p.is_dir()):
        runs = sorted((p for p in env.glob("run_*") if p.name[4:].isdigit() and is_packed_run(p)),
                      key=lambda p: int(p.name[4:]))
        if runs:
            out[env.name] = runs
    return out


def unpack_tree(root: Path, work: Path) -> List[Path]:
    """Unpack every packed run ``root/<env>/run_<i>`` into ``work/<env>/run_<i>`` unless that already holds a
    checkpoint (a work directory is newer than the repository's copy until it is packed). Returns the
    directories unpacked."""
    done = []
    for env, runs in packed_runs(root).items():
        for p in runs:
            target = Path(work) / env / p.name
            if (target / "checkpoint.json").exists():
                continue
            done.append(unpack_run(p, target))
    return done


def _stop_reasons(env_dir: Path) -> Dict[int, str]:
    f = env_dir / "summary.json"
    if not f.is_file():
        return {}
    return {int(r["index"]): str(r["stop_reason"]) for r in json.loads(f.read_text()).get("runs", [])}


def pack_tree(work: Path, root: Path) -> List[Path]:
    """Pack every run ``work/<env>/run_<i>`` with a checkpoint into ``root/<env>/run_<i>`` (stop reasons from
    ``work/<env>/summary.json`` when the experiment wrote one). Returns the packed directories."""
    done = []
    for env in sorted(p for p in Path(work).iterdir() if p.is_dir()):
        reasons = _stop_reasons(env)
        for run in sorted(env.glob("run_*")):
            if run.name[4:].isdigit() and (run / "checkpoint.json").is_file():
                done.append(pack_run(run, Path(root) / env.name / run.name, reasons.get(int(run.name[4:]))))
    return done


def next_round_cap(work: Path, envs: Sequence[str], runs: int, generations: int, round_size: int) -> int:
    """Breadth-first growth (``ANIMAT_REPLICATION_ROUND`` of scripts/replication.sh): the generation cap of
    the next round, ``round_size`` generations past the least advanced run that is still open, at most
    ``generations``; -1 when every run is finished. A run is open when it has not reached ``generations``
    and has not stopped by the stall rule of its config; a run not started yet counts as generation 0."""
    if round_size < 1:
        raise ValueError(f"next_round_cap: round_size must be >= 1, got {round_size}")
    lowest: Optional[int] = None
    for env in envs:
        for i in range(runs):
            run = Path(work) / env / f"run_{i}"
            history = run / "history.csv"
            last = 0
            if history.is_file():
                lines = [ln for ln in history.read_text().splitlines() if ln.strip()]
                last = int(lines[-1].split(",")[0]) if len(lines) > 1 else 0
                if "no improvement" in _derived_stop(run / "config.toml", lines):
                    continue
            if last >= generations:
                continue
            lowest = last if lowest is None else min(lowest, last)
    return -1 if lowest is None else min(lowest + round_size, generations)


def main(argv: Optional[Sequence[str]] = None) -> int:
    p = argparse.ArgumentParser(prog="python -m animat.replication_store",
                                description="Pack replication runs into data/replication, or unpack them.")
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
    args = p.parse_args(argv)
    if args.command == "next-cap":
        print(next_round_cap(args.work, args.envs, args.runs, args.generations, args.round_size))
        return 0
    if args.command == "unpack":
        if not args.data.is_dir():
            print(f"replication_store: {args.data}: no such directory (nothing to resume)", file=sys.stderr)
            return 0
        done = unpack_tree(args.data, args.work)
        print(f"unpacked {len(done)} run(s) into {args.work}", file=sys.stderr)
    else:
        done = pack_tree(args.work, args.data)
        print(f"packed {len(done)} run(s) into {args.data}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
