#!/usr/bin/env bash
# Grow a replication study's runs on another x86-64 Linux machine that has nothing installed (a
# cluster node, a lent many-core machine), one animat_evolve process per run, then bring them back.
#
#   studies/replication/grow_elsewhere.sh bundle WORK BUNDLE   # here: WORK = runs/replication_regime
#   BUNDLE/grow.sh SECONDS OUT                                  # there: every run for SECONDS
#   studies/replication/grow_elsewhere.sh unbundle OUT/runs.tar.gz WORK   # here again
#
# `bundle` copies build/animat_evolve, every shared library it loads and the loader itself into
# BUNDLE (about 14 MB), with the run directories of WORK as runs.tar.gz and grow.sh. There, grow.sh
# resumes every run with `animat_evolve --resume RUN --generations CAP --threads 1` under
# `timeout -s INT SECONDS` (each writes the checkpoint of its last complete generation) and writes
# OUT/runs.tar.gz. All runs go at once, so the machine's cores share them evenly: breadth first.
# `animat_evolve --resume` continues a run bit for bit as `python -m animat experiment` does (only
# the wall-clock column of history.csv differs). After `unbundle`, pack the study as usual
# (replication_store.py pack WORK DATA, or replication.sh, which unpacks only what is newer).
set -euo pipefail
cd "$(dirname "$0")/../.."
case "${1:-}" in
  bundle)
    work=$2 bundle=$3
    mkdir -p "$bundle/bin" "$bundle/lib"
    cp build/animat_evolve "$bundle/bin/"
    ldd build/animat_evolve | awk '/=>/ {print $3}' | xargs -I{} cp -L {} "$bundle/lib/"
    cp -L "$(ldd build/animat_evolve | awk '/ld-linux/ {print $1}')" "$bundle/lib/"
    envs=$(cd "$work" && ls -d */ | tr -d / | grep -v '^report$')
    # shellcheck disable=SC2086
    tar czf "$bundle/runs.tar.gz" -C "$work" $envs
    cat > "$bundle/grow.sh" <<'GROW'
#!/usr/bin/env bash
# Resume every run of runs.tar.gz for $1 seconds (generation cap ${CAP:-1000}); write $2/runs.tar.gz.
set -u
T=$1 OUT=$2 CAP=${CAP:-1000}
here=$(cd "$(dirname "$0")" && pwd)
evolve=("$here/lib/$(basename "$(ls "$here"/lib/ld-linux*)")" --library-path "$here/lib" "$here/bin/animat_evolve")
work=$(mktemp -d) && tar xzf "$here/runs.tar.gz" -C "$work" || exit 3
"${evolve[@]}" --help > /dev/null || { echo "grow.sh: the bundled animat_evolve does not start" >&2; exit 3; }
mkdir -p "$work/logs" "$OUT"
for run in "$work"/*/run_*/; do
  run=${run%/}
  log="$work/logs/$(basename "$(dirname "$run")")_$(basename "$run").log"
  timeout -s INT "$T" "${evolve[@]}" --resume "$run" --generations "$CAP" --threads 1 \
    --set evolution.wall_seconds=0 --quiet > "$log" 2>&1 &
done
wait
for run in "$work"/*/run_*/; do echo "${run#"$work"/} generation $(tail -n 1 "$run/history.csv" | cut -d, -f1)"; done
tar czf "$OUT/runs.tar.gz" -C "$work" $(cd "$work" && ls -d */ | tr -d / | grep -v '^logs$')
GROW
    chmod +x "$bundle/grow.sh"
    du -sh "$bundle"
    ;;
  unbundle)
    tar xzf "$2" -C "$3"
    echo "unbundled into $3; now: replication_store.py pack $3 DATA"
    ;;
  *)
    sed -n 2,16p "$0" >&2
    exit 2
    ;;
esac
