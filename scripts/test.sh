#!/usr/bin/env bash
# README command 2: set up, build, and run every test (C++ then Python).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
BUILD_DIR=${ANIMAT_BUILD_DIR:-build}
echo "== C++ tests (ctest) =="
ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$(nproc)"
echo "== Python tests (pytest) =="
# ANIMAT_TEST_MPI=1: the MPI tests (tests/python/test_mpi.py) fail, not skip, without mpirun or an MPI build.
ANIMAT_TEST_MPI="${ANIMAT_TEST_MPI:-$([[ "${ANIMAT_WITH_MPI:-ON}" == "OFF" ]] && echo 0 || echo 1)}" \
ANIMAT_EVOLVE_EXE="$PWD/$BUILD_DIR/animat_evolve" PYTHONPATH="$PWD/$BUILD_DIR/python" \
  .venv/bin/python -m pytest -q tests/python
# Sanitizers, ThreadSanitizer and time-boxed fuzzers: always in CI, on request locally.
if [[ "${CI:-}" == "true" || "${ANIMAT_RELIABILITY:-0}" == "1" ]]; then
  if [[ -x scripts/reliability.sh ]]; then
    echo "== Reliability: sanitizers and fuzzers =="
    scripts/reliability.sh
  fi
fi
