#!/usr/bin/env bash
# Issue 10: evolve the paper's four environments (§6), RUNS seeds each, then write docs/replication.md.
#   scripts/replication.sh [WALL_SECONDS_PER_RUN]      (default 5400)
# All 4 x RUNS runs go at once, one thread each (they share the machine's cores); each stops at its
# wall-clock budget, at the paper's stall rule, or at ANIMAT_REPLICATION_GENERATIONS if set.
# Interrupted? Run it again: every run resumes from its checkpoint.
set -euo pipefail
cd "$(dirname "$0")/.."
WALL=${1:-5400}
RUNS=${ANIMAT_REPLICATION_RUNS:-3}
OUT=${ANIMAT_REPLICATION_OUT:-runs/replication}
PY_PATH=${ANIMAT_PYTHONPATH:-build/python}
if [[ -z "${ANIMAT_PYTHONPATH:-}" ]]; then
  scripts/setup.sh
  scripts/build.sh
fi
GEN_ARGS=()
if [[ -n "${ANIMAT_REPLICATION_GENERATIONS:-}" ]]; then GEN_ARGS=(--generations "$ANIMAT_REPLICATION_GENERATIONS"); fi
mkdir -p "$OUT"
git rev-parse HEAD > "$OUT/commit.txt" 2>/dev/null || true
pids=()
for env in dn0.5 dn2 dn10 dn0.2_64cells; do
  PYTHONPATH="$PY_PATH" .venv/bin/python -m animat experiment "configs/paper_$env.toml" --runs "$RUNS" \
    --parallel "$RUNS" --threads "$RUNS" --wall-seconds "$WALL" "${GEN_ARGS[@]}" --out "$OUT/$env" \
    > "$OUT/$env.log" 2>&1 &
  pids+=($!)
done
status=0
for p in "${pids[@]}"; do wait "$p" || status=1; done
if [[ $status -ne 0 ]]; then echo "replication: a run failed; see $OUT/*.log" >&2; exit 1; fi
PYTHONPATH="$PY_PATH" .venv/bin/python scripts/replication_report.py --runs "$OUT" --doc docs/replication.md
