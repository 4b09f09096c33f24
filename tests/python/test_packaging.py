"""The installed package holds the library only: study code lives under studies/, not in python/animat.

The wheel packs python/animat (pyproject.toml, ``wheel.packages``) and the development stage
build/python/animat mirrors it (CMake target ``animat_python_stage``, which also removes staged modules
the source no longer has). A new module in the package must be added to LIBRARY_MODULES on purpose:
study code (scripts, reports, reference data for checks) goes to studies/<study>/ instead.

The wheel of scripts/wheel.sh, installed into a fresh virtualenv, works on its own: only with
ANIMAT_TEST_WHEEL set (the path of a built wheel, or 1 to build one: a whole compile, ~10 minutes
on 2 cores), since a wheel build is too slow for every test run.
"""

import importlib.util
import os
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import pytest

import animat

ROOT = Path(__file__).resolve().parents[2]
SOURCE = ROOT / "python" / "animat"

#: Every Python module the package ships.
LIBRARY_MODULES = {
    "__init__",
    "__main__",
    "animation",
    "cli",
    "control",
    "evolution",
    "experiment",
    "explore",
    "locomotion",
    "moo",
    "pipeline",
    "plot",
    "pool",
    "protrusion",
    "qd",
    "run",
    "shape",
    "trajectory",
}
#: Data files the package ships next to its modules (read through ``Path(__file__).with_name``).
PACKAGE_DATA = {
    "explore_template.html",  # the page of `animat explore` (animat/explore.py)
    "default_swimmer.json",  # the body SwimEnv swims when given none (animat/control.py)
}
#: Study modules that live under studies/ (and must stay out of the package).
STUDY_MODULES = {
    "replication_store": ROOT / "studies" / "replication" / "replication_store.py",
    "replication_stats": ROOT / "studies" / "replication" / "replication_stats.py",
    "known_swimmers": ROOT / "studies" / "locomotion" / "known_swimmers.py",
}


def _modules(package_dir: Path) -> set:
    return {p.stem for p in package_dir.glob("*.py")}


def test_the_package_source_holds_exactly_the_library_modules():
    assert _modules(SOURCE) == LIBRARY_MODULES
    # Besides the modules: the typing marker, the data files of PACKAGE_DATA, and the compiled extension
    # (ignored by git) where linked.
    others = {p.name for p in SOURCE.iterdir() if p.suffix != ".py" and p.name != "__pycache__"}
    assert {n for n in others if not n.startswith("_core")} == {"py.typed"} | PACKAGE_DATA


def test_the_package_data_is_staged_and_read_from_the_package():
    # The wheel packs every file of python/animat; the development stage copies python/animat/* (not
    # subfolders): so the data files sit next to the modules, and the modules find them there.
    staged = Path(animat.__file__).resolve().parent
    for name in PACKAGE_DATA:
        assert (staged / name).is_file(), f"{name} is not staged next to the modules in {staged}"
    from animat import explore

    assert explore.TEMPLATE.parent == staged and explore.TEMPLATE.name in PACKAGE_DATA


def test_the_imported_package_holds_exactly_the_library_modules():
    # build/python/animat (the stage) or python/animat: what the tests import is what a wheel installs.
    assert _modules(Path(animat.__file__).resolve().parent) == LIBRARY_MODULES


def test_study_modules_are_under_studies_and_not_importable_from_the_package():
    for name, path in STUDY_MODULES.items():
        assert path.is_file(), path
        assert importlib.util.find_spec(f"animat.{name}") is None, name


def test_the_wheel_packs_only_python_animat():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert project["tool"]["scikit-build"]["wheel"]["packages"] == ["python/animat"]


def _wheel() -> Path:
    """The wheel ANIMAT_TEST_WHEEL names, or one built by scripts/wheel.sh when it is 1."""
    given = os.environ["ANIMAT_TEST_WHEEL"]
    if given != "1":
        return Path(given)
    subprocess.run([str(ROOT / "scripts" / "wheel.sh")], check=True)
    version = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    return max((ROOT / "dist").glob(f"animat-{version}-*.whl"), key=lambda p: p.stat().st_mtime)


@pytest.mark.skipif(
    not os.environ.get("ANIMAT_TEST_WHEEL"), reason="set ANIMAT_TEST_WHEEL=1 (builds the wheel) or =PATH.whl"
)
def test_the_wheel_installs_into_a_fresh_venv_and_evaluates_as_the_build_does(tmp_path):
    wheel = _wheel()
    names = zipfile.ZipFile(wheel).namelist()
    package = {n.removeprefix("animat/") for n in names if n.startswith("animat/")}
    assert {m + ".py" for m in LIBRARY_MODULES} | PACKAGE_DATA | {"py.typed", "_core.pyi"} <= package
    assert any(n.startswith("_core.") and n.endswith(".so") for n in package)
    assert {f"configs/{c}.toml" for c in animat.paper_configs()} <= package
    assert any(n.endswith(".data/scripts/animat_evolve") for n in names)
    assert not [n for n in names if n.startswith(("studies/", "tests/"))]

    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    python = venv / "bin" / "python"
    subprocess.run([str(python), "-m", "pip", "install", "-q", "--disable-pip-version-check", str(wheel)], check=True)
    # Outside the source tree and without PYTHONPATH: only the installed package can be imported.
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "ANIMAT_EVOLVE_EXE")}
    script = (
        "import animat\n"
        "config = animat.load_config('paper_dn10')\n"
        "genome, tries = animat.Genome.random_viable(seed=42, config=config)\n"
        "print(animat.__file__)\n"
        "print(animat.evaluate(genome, config).fitness.hex())\n"
    )
    r = subprocess.run([str(python), "-c", script], cwd=tmp_path, env=env, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    where, fitness = r.stdout.split()
    assert Path(where).is_relative_to(venv)
    config = animat.load_config("paper_dn10")
    genome, _ = animat.Genome.random_viable(seed=42, config=config)
    assert float.fromhex(fitness) == animat.evaluate(genome, config).fitness
    # The two commands: animat_evolve and animat, on the venv's PATH.
    for command in (["animat_evolve", "--print-config"], ["animat", "evolve", "--print-config"]):
        r = subprocess.run(
            [str(venv / "bin" / command[0]), *command[1:]], cwd=tmp_path, env=env, capture_output=True, text=True
        )
        assert r.returncode == 0, r.stderr
        assert "[evolution]" in r.stdout
