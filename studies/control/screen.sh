#!/usr/bin/env bash
# Freshly evolved GRN-control bests (docs/control.md, "The controller's schedule under refinement"):
# short chemotaxis runs of configs/chemotaxis.toml in both actuation modes, whose every lineage best
# studies/worlds/refinement.py then re-swims at dt, dt/16 and dt/32. Keeps each run's config,
# history and lineage in studies/control/screen/<mode>_<guard>_seed<seed>/. Idempotent: a run
# already kept is skipped, one left unfinished in runs/control_screen/ is resumed.
#
#   studies/control/screen.sh
#   SCREEN_ACTUATION=direct SCREEN_SEEDS="1 2 3 4" studies/control/screen.sh
#
# Grid (environment variables, space-separated): SCREEN_ACTUATION (control.actuation: direct,
# amplitude), SCREEN_GUARD (evaluation.reference_check), SCREEN_REPEATS (evaluation.repeats;
# names carry r<K> unless it is 1), SCREEN_SEEDS; SCREEN_POPULATION, SCREEN_GENERATIONS.
set -euo pipefail
cd "$(dirname "$0")/../.."
source studies/evolve_kept.sh
EXE=${ANIMAT_EVOLVE_EXE:-build/animat_evolve}
ACTUATION=${SCREEN_ACTUATION:-"direct amplitude"}
GUARD=${SCREEN_GUARD:-"record"}
REPEATS=${SCREEN_REPEATS:-"1"}
SEEDS=${SCREEN_SEEDS:-"1 2 3"}
POP=${SCREEN_POPULATION:-60}
GENS=${SCREEN_GENERATIONS:-40}
KEEP=studies/control/screen
WORK=runs/control_screen
mkdir -p "$KEEP" "$WORK"

for mode in $ACTUATION; do for r in $REPEATS; do for guard in $GUARD; do for seed in $SEEDS; do
  name="${mode}"
  [[ "$r" == 1 ]] || name+="_r${r}"
  name+="_${guard}_seed${seed}"
  [[ -f "$KEEP/$name/history.csv" ]] && continue
  evolve_kept "$name" "$KEEP/$name" "$WORK/$name" "$GENS" lineage \
    --config configs/chemotaxis.toml --set "control.actuation=$mode" \
    --set "evolution.population=$POP" --set "evaluation.reference_check=$guard" --seed "$seed" \
    $([[ "$r" == 1 ]] || echo --set "evaluation.repeats=$r")
done; done; done; done
