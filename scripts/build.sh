#!/usr/bin/env bash
# Configures and builds animat (library, CLI, tests, Python module) into build/; with
# ANIMAT_TARGETS="t1 t2", only those targets (scripts/demo.sh builds what it runs).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${ANIMAT_BUILD_DIR:-build}
JOBS=${ANIMAT_JOBS:-$(nproc)}
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DANIMAT_BUILD_TESTS=ON -DANIMAT_BUILD_PYTHON=ON -DANIMAT_BUILD_BENCH="${ANIMAT_BUILD_BENCH:-OFF}" \
  -DANIMAT_WITH_MPI="${ANIMAT_WITH_MPI:-ON}" \
  -DPython_EXECUTABLE="$PWD/.venv/bin/python" "$@" >/dev/null
read -r -a targets <<<"${ANIMAT_TARGETS:-}"
cmake --build "$BUILD_DIR" -j "$JOBS" ${targets[@]:+--target "${targets[@]}"}
