"""The installed package holds the library only: study code lives under studies/, not in python/animat.

The wheel packs python/animat (pyproject.toml, ``wheel.packages``) and the development stage
build/python/animat mirrors it (CMake target ``animat_python_stage``, which also removes staged modules
the source no longer has). A new module in the package must be added to LIBRARY_MODULES on purpose:
study code (scripts, reports, reference data for checks) goes to studies/<study>/ instead.
"""

import importlib.util
import tomllib
from pathlib import Path

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
PACKAGE_DATA = {"explore_template.html"}  # the page of `animat explore` (animat/explore.py)
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
