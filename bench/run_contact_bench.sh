#!/usr/bin/env bash
# Runs the contact benchmark with 1 and 2 OpenMP threads and prints (1) the contact throughput
# (pre-search + forces, disc-steps/s) on 10^4..10^6 discs and (2) the Fig. 8 analogue: ms per
# 1000 steps for the all-pairs traversal, the binned search every step and the binned search
# with a Verlet skin. Usage: bench/run_contact_bench.sh [build-dir]
set -euo pipefail
build=${1:-$(dirname "$0")/../build}
out=$(mktemp -d)
for t in 1 2; do
  OMP_NUM_THREADS=$t OMP_PROC_BIND=spread OMP_PLACES=threads "$build/bench/bench_contact" \
    --benchmark_format=json >"$out/t$t.json" 2>/dev/null
done
/usr/bin/python3 - "$out" <<'PY'
import json, sys, os
d = sys.argv[1]
step, fig8 = {}, {}
for t in (1, 2):
    for b in json.load(open(os.path.join(d, f"t{t}.json")))["benchmarks"]:
        n = int(b["discs"])
        if b["name"].startswith("BM_ContactStep"):
            step.setdefault(n, {})[t] = b
        else:
            fig8.setdefault((n, b["label"]), {})[t] = b
print("Contact step (search + forces + integration), binned search with skin 0.1 r")
print(f"{'discs':>9} {'candidates':>11} {'rebuilds/step':>14} {'1 thread (M disc-steps/s)':>26} {'2 threads':>10} {'speed-up':>9}")
for n, r in sorted(step.items()):
    a, b = r[1]["disc_steps_per_s"], r[2]["disc_steps_per_s"]
    print(f"{n:>9} {int(r[1]['candidates']):>11} {r[1]['rebuilds_per_step']:>14.3f} {a/1e6:>26.2f} {b/1e6:>10.2f} {b/a:>9.2f}")
print()
print("Fig. 8 analogue: time per 1000 steps (ms) = measured time per step x 1000")
modes = ["all-pairs", "binned", "binned+skin"]
ns = sorted({n for n, _ in fig8})
print(f"{'discs':>9} " + " ".join(f"{m + ' ' + str(t) + 't':>17}" for m in modes for t in (1, 2)))
for n in ns:
    cells = []
    for m in modes:
        for t in (1, 2):
            r = fig8.get((n, m), {}).get(t)
            cells.append(f"{r['ms_per_1000_steps']:>17.1f}" if r else f"{'-':>17}")
    print(f"{n:>9} " + " ".join(cells))
PY
