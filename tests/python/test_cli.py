"""animat_evolve command line through Python: --print-config output parses back to the same
config; --set/--config/--seed change it; bad options exit non-zero with a message on stderr.
Skipped when ANIMAT_EVOLVE_EXE is not set (scripts/test.sh sets it)."""

import os
import pathlib
import subprocess

import pytest

import animat

EXE = os.environ.get("ANIMAT_EVOLVE_EXE")
BAD = pathlib.Path(__file__).resolve().parent.parent / "bad_inputs"

pytestmark = pytest.mark.skipif(not EXE or not os.path.exists(EXE), reason="ANIMAT_EVOLVE_EXE not set")


def run(*args, cwd):
    # Run in a temporary directory so that nothing the program might write lands in the tree.
    return subprocess.run([EXE, *args], capture_output=True, text=True, cwd=cwd, timeout=120)


def test_print_config_parses_back_to_default(tmp_path):
    r = run("--print-config", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert animat.Config.from_toml(r.stdout, "stdout") == animat.Config()
    assert r.stdout == animat.Config().to_toml()


def test_set_and_options_are_reflected(tmp_path):
    r = run(
        "--print-config",
        "--set",
        "evolution.population=50",
        "--set",
        "grn.dt=0.025",
        "--seed",
        "99",
        "--generations",
        "3",
        "--threads",
        "1",
        cwd=tmp_path,
    )
    assert r.returncode == 0, r.stderr
    c = animat.Config.from_toml(r.stdout)
    expected = animat.Config(
        {"evolution": {"population": 50, "seed": 99, "generations": 3, "threads": 1}, "grn": {"dt": 0.025}}
    )
    assert c == expected


def test_config_file_then_set(tmp_path):
    base = animat.Config({"scene": {"drag_normal": 3.5}, "evolution": {"population": 60}})
    p = tmp_path / "run.toml"
    p.write_text(base.to_toml())
    r = run("--print-config", "--config", str(p), cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert animat.Config.from_toml(r.stdout) == base
    r = run("--print-config", "--config", str(p), "--set", "evolution.population=70", cwd=tmp_path)
    c = animat.Config.from_toml(r.stdout)
    assert c["evolution.population"] == 70 and c["scene.drag_normal"] == 3.5


@pytest.mark.parametrize(
    "args, fragments",
    [
        (["--bogus-option"], ["--bogus-option"]),
        (["--set", "genome.dimensons=3"], ["genome.dimensons", "did you mean 'dimensions'"]),
        (["--set", "evolution.population=0"], ["evolution.population", "out of range", "[2, 100000]"]),
        (["--set", "grn.dt=abc"], ["grn.dt=abc"]),
        (["--set", "grn.dt=nan"], ["grn.dt", "finite"]),
        (["--set", "nodot"], ["section.key=value"]),
        (["--log-level", "loud"], ["--log-level", "loud"]),
        (["--seed", "-1"], ["--seed"]),
        (["--threads", "5000"], ["evolution.threads"]),
        (["--config", "/nonexistent/animat.toml"], ["/nonexistent/animat.toml"]),
        (
            ["--config", str(BAD / "config_unknown_key.toml")],
            [f"{BAD / 'config_unknown_key.toml'}:6", "evolution.populaton", "did you mean 'population'"],
        ),
        (["--config", str(BAD / "config_dt_zero.toml")], [f"{BAD / 'config_dt_zero.toml'}:6", "grn.dt", "(0, 1]"]),
    ],
)
def test_bad_options_exit_nonzero_with_message(tmp_path, args, fragments):
    r = run("--print-config", *args, cwd=tmp_path)
    assert r.returncode != 0
    for f in fragments:
        assert f in r.stderr, r.stderr
    assert "[grn]" not in r.stdout


@pytest.mark.parametrize(
    "pair",
    [("evolution.elites=150", "evolution.population=200"), ("evolution.elites=30", "evolution.population=20")],
    ids=["valid", "invalid"],
)
def test_set_cross_key_checks_do_not_depend_on_the_flag_order(pair, tmp_path):
    a = run("--print-config", "--set", pair[0], "--set", pair[1], cwd=tmp_path)
    b = run("--print-config", "--set", pair[1], "--set", pair[0], cwd=tmp_path)
    assert (a.returncode, a.stdout, a.stderr) == (b.returncode, b.stdout, b.stderr)
    if pair[1].endswith("200"):
        assert a.returncode == 0, a.stderr
        c = animat.Config.from_toml(a.stdout)
        assert (c["evolution.elites"], c["evolution.population"]) == (150, 200)
        same = animat.Config()
        same.apply_overrides(list(reversed(pair)))
        assert same == c
    else:
        assert a.returncode == 2
        assert "evolution.elites = 30 must be smaller than evolution.population = 20" in a.stderr
        untouched = animat.Config()
        with pytest.raises(ValueError, match="must be smaller"):
            untouched.apply_overrides(list(pair))
        assert untouched == animat.Config()
