#!/usr/bin/env bash
# README command 1: set up, build, and run animat_evolve on its embedded default config as a short
# demo (the paper's d_N = 2, 32-cell setting, capped at a few generations), then draw the result.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
# Only what the demo runs: the CLI and the Python module (the tests are scripts/test.sh's).
ANIMAT_TARGETS="animat_evolve _core animat_python_stage" scripts/build.sh
OUT=${ANIMAT_DEMO_OUT:-runs/demo}
GENERATIONS=${ANIMAT_DEMO_GENERATIONS:-25}
rm -rf "$OUT"
./build/animat_evolve --generations "$GENERATIONS" --out "$OUT" "$@"
if [[ -f python/animat/__main__.py ]]; then
  echo
  echo "== Drawing the best swimmer of $OUT =="
  PYTHONPATH=build/python .venv/bin/python -m animat show "$OUT"
  PYTHONPATH=build/python .venv/bin/python -m animat animate "$OUT"
  PYTHONPATH=build/python .venv/bin/python -m animat explore "$OUT"
  echo "Open $OUT/explore.html in a browser (offline): the curves, lineage, genealogy and the best's swim."
fi
