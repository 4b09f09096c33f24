#!/usr/bin/env bash
# Crawl-world screen (docs/worlds.md, "Does the crawl ranking survive refinement?"): evolves short
# runs of configs/crawl.toml at every point of a grid over gravity and the exploit guard, and keeps
# each run's compact results (config, history, every lineage best) in studies/worlds/crawl_screen/.
# refinement.py then re-swims every lineage best at dt and dt/16. Idempotent: a run already kept is
# skipped, one left unfinished in runs/crawl_screen/ is resumed.
#
#   studies/worlds/crawl_screen.sh
#   SCREEN_GRAVITY="1 4" SCREEN_SEEDS="1 2 3" SCREEN_JOBS=2 studies/worlds/crawl_screen.sh
#
# Grid (environment variables, space-separated): SCREEN_GRAVITY (scene.gravity), SCREEN_STIFFNESS
# (scene.spring_stiffness; names carry it unless it is 100, the default), SCREEN_FREQUENCY_MAX
# (development.frequency_max; names carry it unless it is 6), SCREEN_AMPLITUDE_MAX
# (development.amplitude_max; names carry it unless it is 0.2), SCREEN_CONTACT
# (scene.ground_contact; names carry it unless it is impulse), SCREEN_GUARD
# (evaluation.reference_check), SCREEN_REPEATS (evaluation.repeats; names carry r<K> unless it is 1),
# SCREEN_STATISTIC (evaluation.repeat_statistic; names carry it unless it is mean), SCREEN_SEEDS;
# SCREEN_POPULATION, SCREEN_GENERATIONS.
set -euo pipefail
cd "$(dirname "$0")/../.."
source studies/evolve_kept.sh
EXE=${ANIMAT_EVOLVE_EXE:-build/animat_evolve}
GRAVITY=${SCREEN_GRAVITY:-"1 4 10"}
STIFFNESS=${SCREEN_STIFFNESS:-"100"}
FREQUENCY_MAX=${SCREEN_FREQUENCY_MAX:-"6"}
AMPLITUDE_MAX=${SCREEN_AMPLITUDE_MAX:-"0.2"}
CONTACT=${SCREEN_CONTACT:-"impulse"}
GUARD=${SCREEN_GUARD:-"record"}
REPEATS=${SCREEN_REPEATS:-"1"}
STATISTIC=${SCREEN_STATISTIC:-"mean"}
SEEDS=${SCREEN_SEEDS:-"1 2 3"}
POP=${SCREEN_POPULATION:-100}
GENS=${SCREEN_GENERATIONS:-60}
JOBS=${SCREEN_JOBS:-1}
KEEP=studies/worlds/crawl_screen
WORK=runs/crawl_screen
mkdir -p "$KEEP" "$WORK"

one() {  # gravity stiffness frequency_max amplitude_max contact repeats statistic guard seed
  set -euo pipefail
  local g=$1 k=$2 f=$3 a=$4 contact=$5 repeats=$6 statistic=$7 guard=$8 seed=$9
  local name="g${g}"
  [[ "$k" == 100 ]] || name+="_k${k}"
  [[ "$f" == 6 ]] || name+="_f${f}"
  [[ "$a" == 0.2 ]] || name+="_a${a}"
  [[ "$contact" == impulse ]] || name+="_${contact}"
  [[ "$repeats" == 1 ]] || name+="_r${repeats}"
  [[ "$statistic" == mean ]] || name+="_${statistic}"
  name+="_${guard}_seed${seed}"
  [[ -f "$KEEP/$name/history.csv" ]] && return 0
  evolve_kept "$name" "$KEEP/$name" "$WORK/$name" "$GENS" lineage \
    --config configs/crawl.toml --set "scene.gravity=$g" --set "scene.spring_stiffness=$k" \
    --set "development.frequency_max=$f" --set "development.amplitude_max=$a" \
    --set "scene.ground_contact=$contact" --set "evolution.population=$POP" \
    --set "evaluation.reference_check=$guard" --seed "$seed" \
    --set "evaluation.repeats=$repeats" \
    $([[ "$statistic" == mean ]] || echo --set "evaluation.repeat_statistic=$statistic")
}
export -f one evolve_kept
export EXE GENS POP KEEP WORK

points=()
for g in $GRAVITY; do for k in $STIFFNESS; do for f in $FREQUENCY_MAX; do for a in $AMPLITUDE_MAX; do
  for c in $CONTACT; do for r in $REPEATS; do for stat in $STATISTIC; do
    for guard in $GUARD; do for seed in $SEEDS; do
      points+=("$g $k $f $a $c $r $stat $guard $seed")
    done; done
  done; done; done
done; done; done; done
printf '%s\n' "${points[@]}" | xargs -P "$JOBS" -L 1 bash -c 'one "$@"' _
