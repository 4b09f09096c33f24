#!/usr/bin/env bash
# The paper's whole study: 4 environments x 10 runs, resumable, then the replication report.
#
#   scripts/paper_study.sh --np 2    [--runs 10] [--out runs/paper] [-- EXTRA...]   # one machine, one MPI job
#   scripts/paper_study.sh --slurm   [--runs 10] [--out runs/paper] [-- EXTRA...]   # a Slurm array + a report job
#
# EXTRA goes to `python -m animat experiment` (e.g. --wall-seconds 3600, --generations 300, --set KEY=VALUE).
# Interrupted, cancelled or out of time? Run the same command again: every run resumes from its
# checkpoint and finished runs stop at once. The report is OUT/replication.md (figures in OUT/images/).
# docs/cluster.md explains both modes; --task I and --report are the steps the Slurm jobs run.
set -euo pipefail
cd "$(dirname "$0")/.."
MODE="" NP=2 RUNS=10 OUT=runs/paper TASK=""
EXTRA=()
while (($#)); do
  case "$1" in
    --np) MODE=mpi NP=$2; shift 2 ;;
    --slurm) MODE=slurm; shift ;;
    --task) MODE=task TASK=$2; shift 2 ;;
    --report) MODE=report; shift ;;
    --runs) RUNS=$2; shift 2 ;;
    --out) OUT=$2; shift 2 ;;
    --) shift; EXTRA=("$@"); break ;;
    *) echo "paper_study: unknown argument '$1' (see the header of $0)" >&2; exit 2 ;;
  esac
done
[[ -n "$MODE" ]] || { sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }

# The paper's four environments (§6), named as studies/replication/replication_report.py expects.
ENVS=(dn0.5=configs/paper_dn0.5.toml dn2=configs/paper_dn2.toml dn10=configs/paper_dn10.toml
      dn0.2_64cells=configs/paper_dn0.2_64cells.toml)
PY=${ANIMAT_PYTHON:-.venv/bin/python}
export PYTHONPATH=${ANIMAT_PYTHONPATH:-$PWD/build/python}
experiment() { "$PY" -m animat experiment "${ENVS[@]}" --runs "$RUNS" --out "$OUT" "$@" "${EXTRA[@]}"; }
report() {
  experiment --quiet  # every run is finished: each stops at once; writes OUT/<env>/summary.{json,md}
  "$PY" studies/replication/replication_report.py --runs "$OUT" --doc "$OUT/replication.md" --discussion "$OUT/discussion.md"
}

case "$MODE" in
  mpi)
    [[ -n "${ANIMAT_PYTHONPATH:-}" ]] || { scripts/setup.sh; scripts/build.sh >/dev/null; }
    mkdir -p "$OUT"; git rev-parse HEAD > "$OUT/commit.txt" 2>/dev/null || true
    ROOT_OK=(); [[ $(id -u) -ne 0 ]] || ROOT_OK=(--allow-run-as-root)
    # Runs are dealt round-robin to the ranks; each rank's runs use its share of the cores.
    mpirun "${ROOT_OK[@]}" --oversubscribe --bind-to none -np "$NP" -x PYTHONPATH \
      "$PY" -m animat experiment "${ENVS[@]}" --runs "$RUNS" --out "$OUT" --mpi "${EXTRA[@]}"
    report ;;
  slurm)
    [[ -n "${ANIMAT_PYTHONPATH:-}" ]] || { scripts/setup.sh; scripts/build.sh >/dev/null; }
    mkdir -p "$OUT"; git rev-parse HEAD > "$OUT/commit.txt" 2>/dev/null || true
    TASKS=$(( ${#ENVS[@]} * RUNS ))
    ARGS=(--runs "$RUNS" --out "$OUT" -- "${EXTRA[@]}")
    job=$(sbatch --parsable --array="0-$((TASKS - 1))" --output="$OUT/slurm-%A_%a.out" \
      scripts/cluster/paper_study.sbatch "${ARGS[@]}")
    report_job=$(sbatch --parsable --dependency="afterok:${job%%;*}" --output="$OUT/slurm-report-%j.out" \
      scripts/cluster/paper_report.sbatch "${ARGS[@]}")
    echo "paper_study: array job $job ($TASKS runs), report job $report_job (after all runs succeed): $OUT/replication.md"
    echo "paper_study: if runs ran out of time, run the same command again: they resume" ;;
  task)
    experiment --index "$TASK" --threads "${SLURM_CPUS_PER_TASK:-0}" ;;
  report)
    report ;;
esac
