"""The experiment runner and the paper's environment configs."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

import animat

ROOT = Path(__file__).resolve().parents[2]

TINY = """
[evaluation]
steps = 200
[evolution]
population = 8
generations = 2
"""


@pytest.mark.parametrize(
    "name,dn,cells",
    [("paper_dn0.5", 0.5, 32), ("paper_dn2", 2.0, 32), ("paper_dn10", 10.0, 32), ("paper_dn0.2_64cells", 0.2, 64)],
)
def test_paper_configs_hold_the_paper_settings(name, dn, cells):
    c = animat.load_config(str(ROOT / "configs" / f"{name}.toml"))
    assert c["scene.drag_normal"] == dn
    assert c["scene.drag_tangential"] == pytest.approx(dn / 200)
    assert c["development.max_cells"] == cells
    assert c["evaluation.steps"] == 4000
    assert c["evolution.population"] == 100
    assert c["evolution.crossover_fraction"] == 0.2
    assert (c["evolution.tournament_p_start"], c["evolution.tournament_p_end"]) == (0.8, 1.0)
    assert c["evolution.tournament_ramp_generations"] == 1000
    assert c["evolution.stall_generations"] == 500
    assert c["development.steps"] == 400


@pytest.mark.parametrize("env, damping", [("dn0.5", 0.25), ("dn2", 0.25), ("dn10", 0.25), ("dn0.2_64cells", 0.5)])
def test_regime_presets_are_the_paper_environments_with_their_two_values(env, damping):
    paper = animat.load_config(str(ROOT / "configs" / f"paper_{env}.toml"))
    regime = animat.load_config(str(ROOT / "configs" / f"regime_{env}.toml"))
    changed = {key: regime[key] for key in paper.keys() if regime[key] != paper[key]}
    assert changed == {"scene.spring_damping": damping, "evaluation.reference_check": "select"}
    assert paper["scene.spring_damping"] == 4.0 and paper["evaluation.reference_check"] == "record"


@pytest.mark.parametrize("env", ["dn0.5", "dn2", "dn10", "dn0.2_64cells"])
def test_fixed_stream_presets_are_the_regime_presets_with_one_jitter_stream(env):
    regime = animat.load_config(str(ROOT / "configs" / f"regime_{env}.toml"))
    fixed = animat.load_config(str(ROOT / "configs" / f"regime_fixed_{env}.toml"))
    changed = {key: fixed[key] for key in regime.keys() if fixed[key] != regime[key]}
    assert changed == {"development.jitter_stream": "fixed"}
    assert regime["development.jitter_stream"] == "genome"


@pytest.mark.parametrize("env, damping", [("dn0.5", None), ("dn10", None), ("dn0.2_64cells", 1.0)])
def test_long_replication_presets_select_at_dt4_with_the_reference_at_dt16(env, damping):
    fixed = animat.load_config(str(ROOT / "configs" / f"regime_fixed_{env}.toml"))
    dt4 = animat.load_config(str(ROOT / "configs" / f"regime_dt4_{env}.toml"))
    changed = {key: dt4[key] for key in fixed.keys() if dt4[key] != fixed[key]}
    expected = {"physics.substeps": 4, "evaluation.reference_substeps": 4, "evolution.generations": 5000}
    if damping is not None:
        expected["scene.spring_damping"] = damping
    assert changed == expected
    # the same reference step as the fixed-stream preset's: dt/16
    assert fixed["physics.substeps"] * fixed["evaluation.reference_substeps"] == 16
    assert dt4["physics.substeps"] * dt4["evaluation.reference_substeps"] == 16


def test_experiment_runs_seeds_resumes_and_summarises(tmp_path):
    cfg = tmp_path / "tiny.toml"
    cfg.write_text(TINY)
    out = tmp_path / "exp"
    records = animat.run_experiment(str(cfg), runs=2, out=str(out), parallel=2, threads=2)
    assert [r.seed for r in records] == [1, 2]
    assert all(r.generations == 2 for r in records)
    summary = json.loads((out / "summary.json").read_text())
    assert [r["best"] for r in summary["runs"]] == [r.best for r in records]
    assert summary["best_fitness"]["median"] == pytest.approx(sum(r.best for r in records) / 2)
    assert "median best fitness" in (out / "summary.md").read_text()
    assert (out / "run_0" / "history.csv").exists() and (out / "run_1" / "history.csv").exists()
    # Interrupted or finished, a rerun resumes each run: with a higher cap it continues them.
    more = animat.run_experiment(str(cfg), runs=2, out=str(out), generations=3, threads=2)
    assert all(r.generations == 3 for r in more)
    # A straight 3-generation run of seed 1 gives the same history: resume is exact.
    c = animat.load_config(str(cfg))
    c["evolution.generations"] = 3
    straight = animat.evolve(c)
    assert straight.history[-1].best == more[0].best
    # A round with a lower cap (a study grown breadth first) leaves the runs that are ahead untouched.
    files = ("config.toml", "history.csv", "checkpoint.json", "resume.log")  # resume.log: from the cap 2 -> 3
    before = {f: (out / "run_0" / f).read_bytes() for f in files}
    lower = animat.run_experiment(str(cfg), runs=2, out=str(out), generations=1, threads=2)
    assert [(r.generations, r.best) for r in lower] == [(r.generations, r.best) for r in more]
    assert {f: (out / "run_0" / f).read_bytes() for f in files} == before
    assert lower[0].stop_reason == "already at generation 3, past the cap 1"


def test_study_names_packaged_configs_and_files_by_their_whole_name(tmp_path):
    # A dot in the name is part of it: paper_dn0.5 and paper_dn0.2_64cells are two environments.
    out = tmp_path / "study"
    tiny = ["evolution.population=8", "evaluation.steps=200"]
    by_env = animat.run_study(
        ["paper_dn0.5", "paper_dn0.2_64cells"], runs=1, out=str(out), generations=1, overrides=tiny, threads=2
    )
    assert list(by_env) == ["paper_dn0.5", "paper_dn0.2_64cells"]
    for name, drag in (("paper_dn0.5", 0.5), ("paper_dn0.2_64cells", 0.2)):
        assert json.loads((out / name / "summary.json").read_text())["config"] == name
        assert animat.load_config(str(out / name / "run_0" / "config.toml"))["scene.drag_normal"] == drag
    # A file is named by its file name less .toml, the same name as the packaged config it copies.
    copy = tmp_path / "paper_dn0.5.toml"
    copy.write_text((ROOT / "configs" / "paper_dn0.5.toml").read_text())
    index = animat.run_study(
        [str(copy), "paper_dn2"], runs=1, out=str(tmp_path / "files"), index=[0], overrides=tiny, generations=1
    )
    assert list(index) == ["paper_dn0.5", "paper_dn2"]
    assert (tmp_path / "files" / "paper_dn0.5" / "run_0" / "history.csv").is_file()


def test_experiment_command_line(tmp_path):
    cfg = tmp_path / "tiny.toml"
    cfg.write_text(TINY)
    out = tmp_path / "cli"
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "animat",
            "experiment",
            str(cfg),
            "--runs",
            "1",
            "--out",
            str(out),
            "--set",
            "scene.drag_normal=3",
            "--quiet",
        ],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 0, r.stderr
    assert "median best fitness" in r.stdout
    assert animat.load_config(str(out / "run_0" / "config.toml"))["scene.drag_normal"] == 3.0
    bad = subprocess.run(
        [
            sys.executable,
            "-m",
            "animat",
            "experiment",
            str(cfg),
            "--runs",
            "1",
            "--out",
            str(out),
            "--set",
            "scene.drag_nromal=3",
        ],
        capture_output=True,
        text=True,
    )
    assert bad.returncode == 1
    assert "unknown key 'scene.drag_nromal'" in bad.stderr
