#!/usr/bin/env bash
# Builds the binary wheel dist/animat-<version>-<python tag>-linux_x86_64.whl with the project's own
# build (scikit-build-core and nanobind from .venv, no download): the Python package, the compiled
# module animat._core and its stub, the packaged configs, the `animat` command and animat_evolve.
# `pip install dist/animat-*.whl` then installs animat without compiling, on a machine with the same
# Python version and the Debian 12 libraries the wheel links (README.md, "A prebuilt wheel").
#
#   scripts/wheel.sh                   # ANIMAT_JOBS=N caps the compile jobs (default: every core)
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
JOBS=${ANIMAT_JOBS:-$(nproc)}
# --no-build-isolation: the build requirements of pyproject.toml are those of .venv (requirements-dev.txt).
CMAKE_BUILD_PARALLEL_LEVEL=$JOBS .venv/bin/python -m pip wheel . -w dist --no-deps --no-build-isolation \
  --disable-pip-version-check
ls -l dist/animat-*.whl
