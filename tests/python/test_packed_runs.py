"""Packed runs (``data/README.md``: config.toml, history.csv.gz, best.tar.gz, checkpoint.json.gz,
status.json, manifest.json) read in place by :class:`animat.Run`, ``animat info`` and ``animat explore``:
the same history, lineage, config and checkpoint as the run directory ``replication_store.py unpack``
gives, every file checked against the manifest, and a clear error for a folder that is no run.
"""

from __future__ import annotations

import gzip
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import animat
from animat import explore

ROOT = Path(__file__).resolve().parents[2]
STUDY = ROOT / "data" / "replication_regime"
PACKED = STUDY / "dn0.5" / "run_0"
NO_MANIFEST = ROOT / "data" / "replication_causes" / "drag_tangential_x10" / "run_0"


def cli(*args, cwd=None):
    env = {**os.environ, "MPLBACKEND": "Agg"}
    command = [sys.executable, "-m", "animat", *map(str, args)]
    return subprocess.run(command, capture_output=True, text=True, env=env, cwd=cwd)


@pytest.fixture(scope="module")
def unpacked(tmp_path_factory):
    """The packed run unpacked by the store that packed it (studies/, not the package)."""
    import replication_store

    return replication_store.unpack_run(PACKED, tmp_path_factory.mktemp("unpacked") / "run_0")


def test_a_packed_run_reads_as_its_unpacked_run_directory(unpacked):
    packed, plain = animat.Run(PACKED), animat.Run(unpacked)
    assert packed.packed and not plain.packed
    status = json.loads((PACKED / "status.json").read_text())
    assert packed.generations == status["generation"] + 1 == plain.generations
    assert packed.generations > 500  # the study's runs ran to the stall or the cap, not 0 generations
    assert packed.history.tobytes() == plain.history.tobytes() and packed.history.dtype == plain.history.dtype
    lineage, expected = packed.best_genomes, plain.best_genomes
    manifest = json.loads((PACKED / "manifest.json").read_text())
    assert len(lineage) == len([k for k in manifest["unpacked"] if k.startswith("best/")]) == len(expected)
    for a, b in zip(lineage, expected):
        assert (a.generation, a.fitness, a.cell_count, a.id) == (b.generation, b.fitness, b.cell_count, b.id)
        assert a.genome.to_json() == b.genome.to_json()
        assert a.path == PACKED / "best.tar.gz" / "best" / b.path.name
    assert packed.best().fitness == pytest.approx(float(packed.history["best"][-1]))
    assert packed.config.to_toml() == plain.config.to_toml()
    assert packed.checkpoint == plain.checkpoint
    assert packed.status == status and plain.status is None


def test_a_packed_run_without_a_manifest_reads_by_its_gzip_checks():
    run = animat.Run(NO_MANIFEST)
    with gzip.open(NO_MANIFEST / "history.csv.gz", "rt") as f:
        rows = f.read().splitlines()
    assert run.packed and run.generations == len(rows) - 1 > 0
    assert run.best_genomes and run.best().generation <= int(run.history["generation"][-1])


def test_a_damaged_packed_run_is_refused_naming_the_file(tmp_path):
    bad = tmp_path / "run_0"
    shutil.copytree(PACKED, bad)
    data = bytearray((bad / "history.csv.gz").read_bytes())
    data[len(data) // 2] ^= 0xFF
    (bad / "history.csv.gz").write_bytes(bytes(data))
    with pytest.raises(ValueError, match=r"history.csv.gz: the sha256 of history.csv.gz"):
        animat.Run(bad).history
    (bad / "config.toml").write_text((PACKED / "config.toml").read_text() + "\n")
    with pytest.raises(ValueError, match=r"config.toml: config.toml is \d+ bytes, manifest.json says"):
        animat.Run(bad)
    shutil.copy(PACKED / "config.toml", bad / "config.toml")
    (bad / "best.tar.gz").unlink()
    with pytest.raises(FileNotFoundError, match=r"best.tar.gz: missing; .* part of a packed run"):
        animat.Run(bad)
    r = cli("info", bad)
    assert r.returncode == 1 and "best.tar.gz: missing" in r.stderr and r.stdout == ""


def test_a_folder_that_is_no_run_says_so_and_names_the_runs_below(tmp_path):
    with pytest.raises(FileNotFoundError, match=r"neither a run directory .* nor a packed run.*40 run\(s\) below"):
        animat.Run(STUDY)
    (tmp_path / "notes").mkdir()
    with pytest.raises(FileNotFoundError, match=r"notes/config.toml: missing; .* neither a run directory"):
        animat.Run(tmp_path / "notes")
    r = cli("info", STUDY)
    assert r.returncode == 1 and "animat explore" in r.stderr and "0 generation" not in r.stdout + r.stderr
    # a config.toml alone, no run writing there: not a run of 0 generations
    shutil.copy(PACKED / "config.toml", tmp_path / "notes" / "config.toml")
    with pytest.raises(FileNotFoundError, match=r"notes: holds config.toml but nothing of a run"):
        animat.Run(tmp_path / "notes")
    r = cli("info", tmp_path / "notes")
    assert r.returncode == 1 and "nothing of a run" in r.stderr and r.stdout == ""
    r = cli("explore", tmp_path / "notes", "--out", tmp_path / "page.html")
    assert r.returncode == 1 and "nothing of a run" in r.stderr and not (tmp_path / "page.html").exists()
    (tmp_path / "notes" / ".lock").write_text("")  # a run writing it, in its first moments: 0 generations
    assert animat.Run(tmp_path / "notes").generations == 0


def test_animat_info_reads_a_packed_run():
    r = cli("info", PACKED)
    assert r.returncode == 0, r.stderr
    status = json.loads((PACKED / "status.json").read_text())
    assert f"packed run {PACKED}: {status['generation'] + 1} generation(s) recorded" in r.stdout
    assert status["stop_reason"] in r.stdout


def test_explore_finds_the_forty_packed_runs_with_their_generations():
    refs = explore.find_runs([STUDY])
    assert len(refs) == 40 and {r.group for r in refs} == {"dn0.5", "dn2", "dn10", "dn0.2_64cells"}
    ref = next(r for r in refs if r.label == "dn0.5/run_0")
    data = explore.run_data(ref, frames=10, max_points=100)
    status = json.loads((PACKED / "status.json").read_text())
    assert data["summary"]["generations"] == status["generation"] + 1
    assert data["summary"]["stopped"] == status["stop_reason"]
    assert len(data["lineage"]) == len(animat.Run(PACKED).best_genomes) > 1
    assert data["swim"] is not None and data["swim"]["generation"] == data["lineage"][-1]["generation"]


def test_pages_and_figures_of_packed_runs_go_under_runs_not_into_data(tmp_path):
    before = sorted(p.name for p in PACKED.iterdir())
    r = cli("explore", PACKED, "--frames", 10, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    page = tmp_path / "runs" / "replication_regime" / "dn0.5" / "run_0" / "explore.html"
    assert r.stdout.strip() == str(Path("runs", "replication_regime", "dn0.5", "run_0", "explore.html"))
    assert page.is_file() and '"packed":true' in page.read_text()
    r = cli("show", PACKED, "--only", "phase_map", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "runs" / "replication_regime" / "dn0.5" / "run_0" / "figures" / "phase_map.png").is_file()
    r = cli("animate", PACKED, "--steps", 40, "--max-frames", 4, "--size", "80x60", "--no-progress", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == str(Path("runs", "replication_regime", "dn0.5", "run_0", "figures", "best.gif"))
    assert (tmp_path / "runs" / "replication_regime" / "dn0.5" / "run_0" / "figures" / "best.gif").is_file()
    assert sorted(p.name for p in PACKED.iterdir()) == before  # the packed run is read only
