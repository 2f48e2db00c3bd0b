#!/usr/bin/env bash
# Regenerates every benchmark table and plot and the tables of docs/performance.md:
#   1. bench/run_penetration.sh   throughput, levels 1 2 4 8, 1 and 2 threads
#   2. bench/paper_efficiency     the paper's Table 3 and Fig. 8, the adaptive/FE ratio and
#                                 phase tables, with 1 and 2 threads
#   3. bench/tradeoff.py          the speed-accuracy studies (1 thread), CSV + PNG
#   4. bench/output_cost.py       wall time per frame and bytes per node and frame
#   5. bench/update_docs.py       the tables of docs/performance.md
# About 18 minutes on 2 idle cores. Run it on an otherwise idle machine: the wall times are the
# measurement. Results go to bench/results/ (text logs beside the CSV/JSON/PNG).
# Usage: [STATUS="text shown in the doc"] bench/run_all.sh [build-dir]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
status=${STATUS:-"measured by bench/run_all.sh on $(date -u +%Y-%m-%d)"}
results=$root/bench/results
mkdir -p "$results"
cd "$root"
start=$(date +%s)

cmake --build "$build" --target fracta penetration paper_efficiency >/dev/null

echo "== 1/5 penetration throughput" >&2
bench/run_penetration.sh "$build" "1 2 4 8" "$results" | tee "$results/penetration.txt"

echo "== 2/5 paper efficiency (Table 3, Fig. 8, adaptive vs FE)" >&2
for t in 1 2; do
  OMP_NUM_THREADS=$t OMP_PROC_BIND=spread OMP_PLACES=threads "$build/bench/paper_efficiency" \
    --cases "$root/cases" --json "$results/paper_efficiency_t$t.json" |
    tee "$results/paper_efficiency_t$t.txt"
done

echo "== 3/5 speed-accuracy studies" >&2
/usr/bin/python3 bench/tradeoff.py --fracta "$build/fracta" --out "$results" |
  tee "$results/tradeoff.txt"

echo "== 4/5 output cost" >&2
/usr/bin/python3 bench/output_cost.py --fracta "$build/fracta" --out "$results" |
  tee "$results/output_cost.txt"

echo "== 5/5 docs/performance.md" >&2
/usr/bin/python3 bench/update_docs.py --results "$results" --status "$status"
echo "run_all: done in $(( $(date +%s) - start )) s" >&2
