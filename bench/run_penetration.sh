#!/usr/bin/env bash
# The throughput benchmark: bench/penetration at refinement levels 1, 2, 4, 8
# (cell size 0.4 mm / level; level 8 has 1.17e6 nodes), each level in its own process (so the
# peak RSS is that level's) with OMP_NUM_THREADS=1 and 2. Prints the table and writes
# bench/results/penetration.{csv,json}.
# Usage: bench/run_penetration.sh [build-dir] [levels (default "1 2 4 8")] [results-dir]
# Environment: PENETRATION_ARGS adds arguments to every run (e.g. "--warmup 10");
# PENETRATION_PAUSE (s, default 30) is the pause before each run of level 4 or 8: on the VMs
# we measure on, a run that starts right after another has released its 0.6-2.3 GB is up to
# 25% slower (level 8, 2 threads: 15.8-16.6 steps/s right after the 1-thread run, 21.1-23.1
# after 30 s; its set-up also takes twice as long), while the host takes the memory back.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
levels=${2:-"1 2 4 8"}
results=${3:-$root/bench/results}
mkdir -p "$results"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$root"
for level in $levels; do
  for t in 1 2; do
    echo "penetration: level $level, $t thread(s)" >&2
    if [ "$level" -ge 4 ]; then sleep "${PENETRATION_PAUSE:-30}"; fi
    # shellcheck disable=SC2086
    OMP_NUM_THREADS=$t OMP_PROC_BIND=spread OMP_PLACES=threads "$build/bench/penetration" \
      --level "$level" --json "$tmp/l${level}_t$t.json" ${PENETRATION_ARGS:-} >/dev/null
  done
done
/usr/bin/python3 "$root/bench/penetration_table.py" "$tmp" "$results"
