"""animat_evolve's MAP-Elites with the default descriptors (search.descriptors = elongation,
protrusions), which the engine measures during each evaluation: every elite of the checkpoint carries
the shape animat.shape gives its genome, and sits in the grid cell of those descriptors.
Skipped when ANIMAT_EVOLVE_EXE is not set (scripts/test.sh sets it)."""

import json
import os
import subprocess

import numpy as np
import pytest

import animat
from animat import shape
from animat.locomotion import MODES

EXE = os.environ.get("ANIMAT_EVOLVE_EXE")

pytestmark = pytest.mark.skipif(not EXE or not os.path.exists(EXE), reason="ANIMAT_EVOLVE_EXE not set")

SMALL = ["--set", "search.algorithm=map_elites", "--set", "search.batch=6", "--set", "evaluation.steps=40"]


def test_map_elites_runs_with_the_default_descriptors_and_each_elite_has_its_genomes_shape(tmp_path):
    out = tmp_path / "run"
    r = subprocess.run(
        [EXE, *SMALL, "--seed", "4", "--generations", "2", "--threads", "1", "--quiet", "--out", str(out)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr
    config = animat.load_config(out / "config.toml")
    assert list(config["search.descriptors"]) == ["elongation", "protrusions"]
    payload = json.loads(json.loads((out / "checkpoint.json").read_text())["payload"])
    elites = payload["elites"]
    assert len(elites) >= 2
    bins = [int(b) for b in config["search.bins"]] * (3 - len(config["search.bins"]))  # one count for both
    edges = [np.linspace(1.0, 4.0, bins[0] + 1), np.linspace(0.0, 8.0, bins[1] + 1)]
    for elite in elites:
        genome = animat.Genome.from_json(json.dumps(elite["genome"]))
        want = shape.genome_shape(genome, config)
        got = elite["result"]
        assert got["viable"] and want is not None
        assert got["elongation"] == want.elongation
        assert got["protrusions"] == want.protrusion_count
        assert got["symmetric_pair"] == int(want.symmetric_pair)
        assert got["concavity"] == want.concavity
        assert got["frequency"] == float(np.median(animat.develop(genome, config).frequency))
        # the grid cell of (elongation in [1, 4), protrusions in [0, 8)), values outside clipped
        column, row = (
            int(np.clip(np.searchsorted(e, x, side="right") - 1, 0, len(e) - 2))
            for e, x in zip(edges, (want.elongation, want.protrusion_count))
        )
        assert elite["cell"] == column * bins[1] + row


def test_map_elites_with_locomotion_classifies_each_elites_own_swim(tmp_path):
    """search.descriptors = locomotion, cells: each elite carries the mode that animat.classify_locomotion
    gives its genome, measured during its evaluation (no second swim)."""
    out = tmp_path / "run"
    r = subprocess.run(
        [
            EXE,
            *SMALL[:4],
            "--set",
            "evaluation.steps=240",
            "--set",
            'search.descriptors=["locomotion","cells"]',
            "--set",
            "search.bins=[6,16]",
            "--seed",
            "4",
            "--generations",
            "1",
            "--threads",
            "1",
            "--quiet",
            "--out",
            str(out),
        ],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr
    config = animat.load_config(out / "config.toml")
    elites = json.loads(json.loads((out / "checkpoint.json").read_text())["payload"])["elites"]
    assert elites
    for elite in elites:
        genome = animat.Genome.from_json(json.dumps(elite["genome"]))
        want = MODES.index(animat.classify_locomotion(genome, config).mode)
        assert elite["result"]["locomotion"] == want
