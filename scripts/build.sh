#!/usr/bin/env bash
# Configures and builds animat (library, CLI, tests, Python module) into build/.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${ANIMAT_BUILD_DIR:-build}
JOBS=${ANIMAT_JOBS:-$(nproc)}
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DANIMAT_BUILD_TESTS=ON -DANIMAT_BUILD_PYTHON=ON -DANIMAT_BUILD_BENCH="${ANIMAT_BUILD_BENCH:-OFF}" \
  -DANIMAT_WITH_MPI="${ANIMAT_WITH_MPI:-ON}" \
  -DPython_EXECUTABLE="$PWD/.venv/bin/python" "$@" >/dev/null
cmake --build "$BUILD_DIR" -j "$JOBS"
