#!/usr/bin/env bash
# Calibration screen (docs/regime.md): evolves short runs at every point of a factorial over the
# constants the paper leaves open, at d_N = 0.5 and d_N = 10, and keeps each run's compact results
# (config, history, final best) in studies/regime/screen/. Idempotent: a run already kept is skipped,
# one left unfinished in runs/screen/ is resumed.
#
#   studies/regime/screen.sh            # every point, one run at a time
#   SCREEN_JOBS=2 studies/regime/screen.sh
#
# Grid (environment variables, space-separated): SCREEN_ENVS, SCREEN_GROWTH, SCREEN_DAMPING,
# SCREEN_STIFFNESS, SCREEN_SEEDS; SCREEN_POPULATION, SCREEN_GENERATIONS; SCREEN_GUARD (the exploit
# guard, evaluation.reference_check: "record" by default; "select" adds "_select" to the names);
# SCREEN_SUBSTEPS (physics.substeps, the step's refinement: 1 by default; N > 1 adds "_sN");
# SCREEN_REPEATS (evaluation.repeats: 1 by default; K > 1 adds "_rK") and SCREEN_STATISTIC
# (evaluation.repeat_statistic: mean by default; min adds "_min"); SCREEN_FREQUENCY_MAX
# (development.frequency_max: 6 by default; F adds "_fF").
# Growth: "paper" (any cell divides along its orientation), "tipsN" (a cell divides only while it
# touches at most N cells, its daughter placed outward: development.division_max_contacts = N,
# development.division_axis = "outward"). Run names carry the growth unless it is "paper".
set -euo pipefail
cd "$(dirname "$0")/../.."
source studies/evolve_kept.sh
EXE=${ANIMAT_EVOLVE_EXE:-build/animat_evolve}
ENVS=${SCREEN_ENVS:-"dn0.5 dn10"}
GROWTH=${SCREEN_GROWTH:-"paper"}
GUARD=${SCREEN_GUARD:-record}
SUBSTEPS=${SCREEN_SUBSTEPS:-1}
REPEATS=${SCREEN_REPEATS:-1}
STATISTIC=${SCREEN_STATISTIC:-mean}
FREQUENCY_MAX=${SCREEN_FREQUENCY_MAX:-6}
DAMPING=${SCREEN_DAMPING:-"4 1 0.25"}
STIFFNESS=${SCREEN_STIFFNESS:-"100 30"}
SEEDS=${SCREEN_SEEDS:-"1 2"}
POP=${SCREEN_POPULATION:-60}
GENS=${SCREEN_GENERATIONS:-100}
JOBS=${SCREEN_JOBS:-1}
KEEP=studies/regime/screen
WORK=runs/screen
mkdir -p "$KEEP" "$WORK"

one() {  # env growth damping stiffness seed
  set -euo pipefail
  local env=$1 growth=$2 c=$3 k=$4 seed=$5
  local name="${env}_c${c}_k${k}_seed${seed}" grow=()
  if [[ "$growth" =~ ^tips([0-9]+)$ ]]; then
    name="${env}_${growth}_c${c}_k${k}_seed${seed}"
    grow=(--set "development.division_max_contacts=${BASH_REMATCH[1]}"
          --set "development.division_axis=outward")
  elif [[ "$growth" != paper ]]; then
    echo "screen: unknown growth '$growth' (expected paper or tipsN)" >&2
    return 1
  fi
  local guard=(--set "evaluation.reference_check=$GUARD")
  [[ "$GUARD" == record ]] || name="${name%_seed*}_${GUARD}_seed${seed}"
  [[ "$SUBSTEPS" == 1 ]] || name="${name%_seed*}_s${SUBSTEPS}_seed${seed}"
  [[ "$REPEATS" == 1 ]] || name="${name%_seed*}_r${REPEATS}_seed${seed}"
  [[ "$STATISTIC" == mean ]] || name="${name%_seed*}_${STATISTIC}_seed${seed}"
  [[ "$FREQUENCY_MAX" == 6 ]] || name="${name%_seed*}_f${FREQUENCY_MAX}_seed${seed}"
  [[ -f "$KEEP/$name/best_genome.json" ]] && return 0
  evolve_kept "$name" "$KEEP/$name" "$WORK/$name" "$GENS" final \
    --config "configs/paper_${env}.toml" --set "evolution.population=$POP" \
    --set "scene.spring_damping=$c" --set "scene.spring_stiffness=$k" "${grow[@]}" "${guard[@]}" \
    --set "physics.substeps=$SUBSTEPS" --set "evaluation.repeats=$REPEATS" \
    --set "evaluation.repeat_statistic=$STATISTIC" \
    --set "development.frequency_max=$FREQUENCY_MAX" --seed "$seed"
}
export -f one evolve_kept
export EXE POP GENS KEEP WORK GUARD SUBSTEPS REPEATS STATISTIC FREQUENCY_MAX
points=()
for env in $ENVS; do for g in $GROWTH; do for c in $DAMPING; do for k in $STIFFNESS; do
  for s in $SEEDS; do points+=("$env $g $c $k $s"); done
done; done; done; done
printf '%s\n' "${points[@]}" | xargs -P "$JOBS" -L 1 bash -c 'one "$@"' _
