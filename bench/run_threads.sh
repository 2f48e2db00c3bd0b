#!/usr/bin/env bash
# Runs one benchmark program with 1 and 2 OpenMP threads and prints its rate counter
# `items_per_s` (the benchmark's label says which items) and the 2-thread speed-up.
# Usage: bench/run_threads.sh PROGRAM [build-dir] [extra benchmark args]
set -euo pipefail
prog=$1
build=${2:-$(dirname "$0")/../build}
shift $(( $# >= 2 ? 2 : 1 ))
out=$(mktemp -d)
for t in 1 2; do
  OMP_NUM_THREADS=$t OMP_PROC_BIND=spread OMP_PLACES=threads "$build/bench/$prog" \
    --benchmark_min_time=0.5 --benchmark_format=json "$@" >"$out/t$t.json" 2>/dev/null
done
/usr/bin/python3 - "$out" <<'PY'
import json, sys, os
d = sys.argv[1]
rows, order = {}, []
for t in (1, 2):
    for b in json.load(open(os.path.join(d, f"t{t}.json")))["benchmarks"]:
        key = (b["run_name"], b.get("label", ""))
        if key not in rows:
            order.append(key)
        rows.setdefault(key, {})[t] = b["items_per_s"]
print(f"{'benchmark':<48} {'unit':<22} {'1 thread (M)':>13} {'2 threads (M)':>14} {'speed-up':>9}")
for key in order:
    r = rows[key]
    print(f"{key[0]:<48} {key[1]:<22} {r[1]/1e6:>13.2f} {r[2]/1e6:>14.2f} {r[2]/r[1]:>9.2f}")
PY
