#!/usr/bin/env bash
# Runs the FE step benchmark with 1 and 2 OpenMP threads and prints element-steps/s and the
# 2-thread speed-up. Usage: bench/run_fe_bench.sh [build-dir]
set -euo pipefail
build=${1:-$(dirname "$0")/../build}
out=$(mktemp -d)
for t in 1 2; do
  OMP_NUM_THREADS=$t OMP_PROC_BIND=spread OMP_PLACES=threads "$build/bench/bench_fe" \
    --benchmark_min_time=0.5 --benchmark_format=json >"$out/t$t.json" 2>/dev/null
done
/usr/bin/python3 - "$out" <<'PY'
import json, sys, os
d = sys.argv[1]
rows = {}
for t in (1, 2):
    for b in json.load(open(os.path.join(d, f"t{t}.json")))["benchmarks"]:
        key = (int(b["elements"]), b["label"])
        rows.setdefault(key, {})[t] = b["element_steps_per_s"]
print(f"{'elements':>10} {'material':>12} {'1 thread (M el-steps/s)':>24} {'2 threads':>10} {'speed-up':>9}")
for (n, label), r in sorted(rows.items()):
    print(f"{n:>10} {label:>12} {r[1]/1e6:>24.2f} {r[2]/1e6:>10.2f} {r[2]/r[1]:>9.2f}")
PY
