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
# (scene.spring_stiffness; names carry it unless it is 100, the default), SCREEN_GUARD
# (evaluation.reference_check), SCREEN_SEEDS; SCREEN_POPULATION, SCREEN_GENERATIONS.
set -euo pipefail
cd "$(dirname "$0")/../.."
EXE=${ANIMAT_EVOLVE_EXE:-build/animat_evolve}
GRAVITY=${SCREEN_GRAVITY:-"1 4 10"}
STIFFNESS=${SCREEN_STIFFNESS:-"100"}
GUARD=${SCREEN_GUARD:-"record"}
SEEDS=${SCREEN_SEEDS:-"1 2 3"}
POP=${SCREEN_POPULATION:-100}
GENS=${SCREEN_GENERATIONS:-60}
JOBS=${SCREEN_JOBS:-1}
KEEP=studies/worlds/crawl_screen
WORK=runs/crawl_screen
mkdir -p "$KEEP" "$WORK"

one() {  # gravity stiffness guard seed
  set -euo pipefail
  local g=$1 k=$2 guard=$3 seed=$4
  local name="g${g}_${guard}_seed${seed}"
  [[ "$k" == 100 ]] || name="g${g}_k${k}_${guard}_seed${seed}"
  local keep="$KEEP/$name" work="$WORK/$name"
  [[ -f "$keep/history.csv" ]] && return 0
  if [[ -f "$work/checkpoint.json" ]]; then
    "$EXE" --resume "$work" --generations "$GENS" --threads 1 --quiet >/dev/null
  else
    rm -rf "$work"
    "$EXE" --config configs/crawl.toml --set "scene.gravity=$g" --set "scene.spring_stiffness=$k" \
      --set "evolution.population=$POP" \
      --set "evaluation.reference_check=$guard" --generations "$GENS" --threads 1 --seed "$seed" \
      --quiet --out "$work" >/dev/null
  fi
  local last
  last=$(tail -1 "$work/history.csv" | cut -d, -f1)
  if [[ "$last" != "$GENS" && ! -f "$work/stopped.txt" ]]; then
    echo "crawl_screen: $name stopped at generation $last, not kept" >&2
    return 1
  fi
  rm -rf "$keep.tmp"
  mkdir -p "$keep.tmp"
  cp "$work/config.toml" "$work/history.csv" "$keep.tmp/"
  cp -r "$work/best" "$keep.tmp/best"
  mv "$keep.tmp" "$keep"
  echo "crawl_screen: kept $name"
}
export -f one
export EXE GENS POP KEEP WORK

points=()
for g in $GRAVITY; do for k in $STIFFNESS; do for guard in $GUARD; do for seed in $SEEDS; do
  points+=("$g $k $guard $seed")
done; done; done; done
printf '%s\n' "${points[@]}" | xargs -P "$JOBS" -L 1 bash -c 'one "$@"' _
