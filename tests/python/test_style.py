"""The code style stays applied: ``ruff check`` and ``ruff format --check`` ([tool.ruff] in
pyproject.toml) on the tracked Python, ``clang-format --dry-run -Werror`` (.clang-format) on the tracked
C++, each over the folders its config names.

The tools are the virtualenv's (.venv/bin, next to this interpreter), pinned in requirements-dev.txt
because another version formats differently; scripts/setup.sh installs them. A test skips only when its
tool is not installed there (or when the sources are not a git checkout). To fix a failure, run
``.venv/bin/ruff format FILE``, ``.venv/bin/ruff check --fix FILE`` or ``.venv/bin/clang-format -i FILE``.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path
from typing import List

import pytest

ROOT = Path(__file__).resolve().parents[2]
VENV_BIN = Path(sys.executable).parent

PYTHON_DIRS = ["python", "tests", "bench", "examples", "scripts", "studies"]
CPP_DIRS = ["src", "include", "bindings", "tests/cpp", "bench", "examples"]
CPP_SUFFIXES = (".cpp", ".hpp", ".h", ".inc")

# C++ files clang-format does not check, each with its reason.
CLANG_FORMAT_EXCEPTIONS = {
    # Frozen data: run identity scheme 1 hashed this text; never reformatted (also in
    # .clang-format-ignore, so that clang-format -i skips it).
    "src/run_identity_v1_comments.inc",
}


def _tool(name: str) -> Path:
    exe = VENV_BIN / name
    if not exe.exists():
        pytest.skip(f"{name} is not installed in {VENV_BIN} (requirements-dev.txt; scripts/setup.sh installs it)")
    pinned = re.search(rf"^{re.escape(name)}==(\S+)", (ROOT / "requirements-dev.txt").read_text(), flags=re.MULTILINE)
    assert pinned, f"requirements-dev.txt pins no {name}"
    version = subprocess.run([str(exe), "--version"], capture_output=True, text=True, check=True).stdout
    assert pinned.group(1) in version.split(), (
        f"{exe} is {version.strip()!r}, requirements-dev.txt pins {pinned.group(1)}: re-run scripts/setup.sh"
    )
    return exe


def _tracked(dirs: List[str], suffixes: tuple) -> List[str]:
    try:
        out = subprocess.run(["git", "ls-files", "-z", "--", *dirs], cwd=ROOT, capture_output=True, check=True)
    except (OSError, subprocess.CalledProcessError):
        pytest.skip("not a git checkout: the tracked files are unknown")
    files = sorted({f for f in out.stdout.decode().split("\0") if f.endswith(suffixes)})
    assert files, f"no tracked {suffixes} files under {dirs}"
    return files


def _run(cmd: List[str]) -> subprocess.CompletedProcess:
    return subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)


def test_ruff_check_passes():
    ruff = _tool("ruff")
    p = _run([str(ruff), "check", "--force-exclude", "--no-cache", *_tracked(PYTHON_DIRS, (".py", ".pyi"))])
    assert p.returncode == 0, p.stdout + p.stderr


def test_ruff_format_is_applied():
    ruff = _tool("ruff")
    p = _run([str(ruff), "format", "--check", "--force-exclude", "--no-cache", *_tracked(PYTHON_DIRS, (".py", ".pyi"))])
    assert p.returncode == 0, p.stdout + p.stderr


def test_clang_format_is_applied():
    clang_format = _tool("clang-format")
    tracked = _tracked(CPP_DIRS, CPP_SUFFIXES)
    stale = CLANG_FORMAT_EXCEPTIONS - set(_tracked(["."], CPP_SUFFIXES))
    assert not stale, f"CLANG_FORMAT_EXCEPTIONS names files that are not tracked: {sorted(stale)}"
    files = [f for f in tracked if f not in CLANG_FORMAT_EXCEPTIONS]
    p = _run([str(clang_format), "--dry-run", "-Werror", *files])
    assert p.returncode == 0, p.stderr[-20000:]
