# Sourced by the screens (studies/*/screen.sh, studies/worlds/crawl_screen.sh): one run evolved,
# or resumed from its checkpoint, and its compact results kept.
#
#   evolve_kept NAME KEEP WORK GENERATIONS lineage|final ARGS...
#
# Runs `$EXE ARGS... --out WORK` (or resumes WORK when it holds a checkpoint) to GENERATIONS, then
# copies config.toml, history.csv and either the whole lineage (best/) or the final best
# (best_genome.json) to KEEP, atomically: a kept folder is always complete. A run that ended before
# GENERATIONS without a stop record (stopped.txt) is not kept and fails.
evolve_kept() {
  local name=$1 keep=$2 work=$3 gens=$4 what=$5
  shift 5
  if [[ -f "$work/checkpoint.json" ]]; then
    "$EXE" --resume "$work" --generations "$gens" --threads 1 --quiet >/dev/null
  else
    rm -rf "$work"
    "$EXE" "$@" --generations "$gens" --threads 1 --quiet --out "$work" >/dev/null
  fi
  local last
  last=$(tail -n 1 "$work/history.csv" | cut -d, -f1)
  if [[ "$last" != "$gens" && ! -f "$work/stopped.txt" ]]; then
    echo "$name stopped at generation $last, not kept" >&2
    return 1
  fi
  rm -rf "$keep.tmp"
  mkdir -p "$keep.tmp"
  cp "$work/config.toml" "$work/history.csv" "$keep.tmp/"
  case "$what" in
    lineage) cp -r "$work/best" "$keep.tmp/best" ;;
    final) cp "$(ls "$work"/best/gen_*.json | sort | tail -n 1)" "$keep.tmp/best_genome.json" ;;
    *) echo "evolve_kept: keep 'lineage' or 'final', not '$what'" >&2; return 1 ;;
  esac
  rm -rf "$keep"
  mv "$keep.tmp" "$keep"
  echo "kept $name"
}
