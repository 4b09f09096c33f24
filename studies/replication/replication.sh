#!/usr/bin/env bash
# Grow the replication study of the paper's four environments (§6) and rewrite docs/replication.md
# from it. Run from anywhere; it works in the repository root.
#   studies/replication/replication.sh [SESSION_SECONDS]      (default 5400)
#
# The study lives in the repository, in data/replication/<env>/run_<i>/ (config.toml, history.csv.gz,
# best.tar.gz, checkpoint.json.gz, status.json, manifest.json: replication_store.py here). A session
#  1. unpacks every packed run into a work directory (runs/replication/<env>/run_<i>, kept when it is
#     already there and newer),
#  2. resumes them, and starts the runs not started yet, with `python -m animat experiment` (run i of an
#     environment has seed evolution.seed + i), PARALLEL runs at a time, one thread each; every run stops
#     at the generation cap (1000, ANIMAT_REPLICATION_GENERATIONS) or the paper's stall rule (500
#     generations without improvement, in the configs); the session stops every run still going after
#     SESSION_SECONDS (SIGINT: each writes the checkpoint of its last complete generation),
#  3. packs every run back into data/replication (commit it: the study grows across sessions),
#  4. rewrites docs/replication.md from data/replication alone (replication_report.py here).
# Runs 0-4 of every environment were made before the [evaluation] objective keys existed; they resume
# since run_identity() leaves keys added later out of the hash while they hold their default
# (late_keys() in src/evolution.cpp).
# ANIMAT_REPLICATION_INDEX="1 2 3" restricts step 2 to those runs of the study (env-major: run i of the
# e-th environment of dn0.5, dn2, dn10, dn0.2_64cells is e * RUNS + i).
# ANIMAT_REPLICATION_ROUND=150 grows the study breadth first: step 2 runs in rounds, each taking every
# open run to ROUND generations past the least advanced one (replication_store.py
# next-cap), so that a short session leaves the runs at comparable lengths instead of finishing the
# first few. Default 0: every run straight to the cap. (With an INDEX, the rounds stop as soon as the
# least advanced run is one outside it.)
# ANIMAT_REPLICATION_PRESET=regime grows the same study at the regime presets (configs/regime_<env>.toml,
# docs/regime.md) instead of the paper's environments (configs/paper_<env>.toml, the default "paper"),
# in the environments the preset has (regime: all four); ANIMAT_REPLICATION_PRESET=regime_fixed grows
# it at configs/regime_fixed_<env>.toml (the regime presets with development.jitter_stream = "fixed"),
# and ANIMAT_REPLICATION_PRESET=regime_dt4 at configs/regime_dt4_<env>.toml (the long replication:
# selection at dt/4, the reference at dt/16, cap 5000; three environments).
# Give each its own ANIMAT_REPLICATION_DATA, _OUT, _DOC and _IMAGES (the page's figures, default
# docs/images/replication).
# The paper's discussion (docs/notes/replication_discussion.md) and the controlled runs' section are
# written for the paper preset only.
set -euo pipefail
# One brace group, read whole before anything runs: editing this file while a session runs (for
# hours) cannot change what the running session does.
{
cd "$(dirname "$0")/../.."
HERE=studies/replication
SESSION=${1:-5400}
RUNS=${ANIMAT_REPLICATION_RUNS:-10}
GENERATIONS=${ANIMAT_REPLICATION_GENERATIONS:-1000}
DATA=${ANIMAT_REPLICATION_DATA:-data/replication}
WORK=${ANIMAT_REPLICATION_OUT:-runs/replication}
PARALLEL=${ANIMAT_REPLICATION_PARALLEL:-$(nproc)}
DOC=${ANIMAT_REPLICATION_DOC:-docs/replication.md}
PRESET=${ANIMAT_REPLICATION_PRESET:-paper}
IMAGES=${ANIMAT_REPLICATION_IMAGES:-docs/images/replication}
ENVS=()
for env in dn0.5 dn2 dn10 dn0.2_64cells; do
  [[ -f "configs/${PRESET}_${env}.toml" ]] && ENVS+=("$env")
done
(( ${#ENVS[@]} > 0 )) || { echo "replication: no configs/${PRESET}_<env>.toml" >&2; exit 2; }
PY_PATH=${ANIMAT_PYTHONPATH:-build/python}
if [[ -z "${ANIMAT_PYTHONPATH:-}" ]]; then
  scripts/setup.sh
  scripts/build.sh
fi
PY=(env PYTHONPATH="$PY_PATH" .venv/bin/python)
INDEX_ARGS=()
for i in ${ANIMAT_REPLICATION_INDEX:-}; do INDEX_ARGS+=(--index "$i"); done

mkdir -p "$WORK"
"${PY[@]}" "$HERE/replication_store.py" unpack "$DATA" "$WORK"
git rev-parse HEAD > "$WORK/commit.txt" 2>/dev/null || true
rm -f "$WORK"/*/summary.json  # stop reasons of this session only (an --index session writes none)
: > "$WORK/experiment.log"
ROUND=${ANIMAT_REPLICATION_ROUND:-0}
START=$SECONDS
# One call of the runner up to generation cap $1, within what is left of the session's budget.
# --wall-seconds 0: no cumulative budget (evolution.wall_seconds counts over resumes); the session's
# budget is the SIGINT that `timeout` sends when it is spent.
experiment() {
  local left=$(( SESSION - (SECONDS - START) ))
  (( left > 0 )) || return 124
  local env configs=()
  for env in "${ENVS[@]}"; do configs+=("$env=configs/${PRESET}_${env}.toml"); done
  timeout -s INT "$left" "${PY[@]}" -m animat experiment "${configs[@]}" \
    --runs "$RUNS" --parallel "$PARALLEL" --threads "$PARALLEL" --generations "$1" --wall-seconds 0 \
    "${INDEX_ARGS[@]}" --out "$WORK" >> "$WORK/experiment.log" 2>&1
}
status=0
if (( ROUND > 0 )); then
  previous=""
  while :; do
    cap=$("${PY[@]}" "$HERE/replication_store.py" next-cap "$WORK" --envs "${ENVS[@]}" --runs "$RUNS" \
          --generations "$GENERATIONS" --round "$ROUND")
    # Every run finished, or the last round did not move the least advanced run (a failed run).
    [[ "$cap" == "-1" || "$cap" == "$previous" ]] && break
    previous=$cap
    echo "replication: round to generation $cap" >&2
    experiment "$cap" || { status=$?; break; }
  done
else
  experiment "$GENERATIONS" || status=$?
fi
if [[ $status -ne 0 && $status -ne 124 && $status -ne 130 ]]; then
  echo "replication: the experiment failed (exit $status); see $WORK/experiment.log; packing what ran" >&2
fi
"${PY[@]}" "$HERE/replication_store.py" pack "$WORK" "$DATA"
CAUSES=${ANIMAT_REPLICATION_CAUSES:-data/replication_causes}  # the controlled runs, packed; their section if present
REPORT_ARGS=(--images "$IMAGES")
if [[ "$PRESET" == paper ]]; then
  [[ -d "$CAUSES" ]] && REPORT_ARGS+=(--causes "$CAUSES")
else
  REPORT_ARGS+=(--discussion "$WORK/no_discussion.md")  # a file that does not exist: no discussion
fi
"${PY[@]}" "$HERE/replication_report.py" --data "$DATA" --doc "$DOC" "${REPORT_ARGS[@]}"
if [[ $status -ne 0 && $status -ne 124 && $status -ne 130 ]]; then exit 1; fi
exit
}
