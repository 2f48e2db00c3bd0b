#!/usr/bin/env bash
# The device run, for a machine with an NVIDIA GPU (docs/development.md, "The device run"):
#  1. the CPU build (scripts/setup.sh, build/), for the comparison;
#  2. Kokkos 3.4.1 with CUDA for the GPU's architecture (once, as scripts/cuda_check.sh builds
#     it) and fracta with it in build-gpu/: fracta, its tests and its benchmarks. The compiler
#     stays g++; Kokkos' launcher sends the units that use Kokkos to nvcc_wrapper, so the case
#     parser (toml++, which nvcc's front end rejects) is compiled by g++;
#  3. the test suite on the GPU (the device path's tolerances, as CI runs them on the CPU);
#  4. bench/penetration at levels 1, 4 and 8 on the GPU and on the CPU (all cores);
#  5. the paper's penetration scene to 20 us on both, and the largest distance between their node positions;
# then prints one table. Without a GPU (or with FRACTA_DEVICE_RUN_BUILD_ONLY=1) it stops after
# step 2: that much is checked on machines without one.
#
# Environment:
#   CUDA_ROOT                    CUDA toolkit (default /usr/local/cuda)
#   KOKKOS_ROOT                  a CUDA Kokkos to use instead of building 3.4.1 (needed for
#                                compute capability 9.0 and later, which Kokkos 3.4.1 lacks)
#   FRACTA_PREFIX                where the Kokkos goes (default /opt/fracta)
#   FRACTA_GPU_BUILD_DIR         the GPU build (default <repo>/build-gpu)
#   FRACTA_DEVICE_RUN_BUILD_ONLY=1  build, run nothing
#   FRACTA_CUDA_ARCH             Kokkos architecture option and sm name when no GPU tells it
#                                (default "AMPERE80 sm_80")
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
prefix=${FRACTA_PREFIX:-/opt/fracta}
cuda_root=${CUDA_ROOT:-/usr/local/cuda}
build=${FRACTA_GPU_BUILD_DIR:-$repo/build-gpu}
build_only=${FRACTA_DEVICE_RUN_BUILD_ONLY:-0}
jobs=$(nproc)
say() { printf '[device_run] %s\n' "$*" >&2; }
now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.0f", b - a }'; }
t_start=$(now)

if [ ! -x "$cuda_root/bin/nvcc" ]; then
  say "no nvcc at $cuda_root/bin/nvcc (set CUDA_ROOT)"
  exit 1
fi
export PATH=$cuda_root/bin:$PATH
export CUDA_ROOT=$cuda_root

# --- 0. The GPU and its architecture -------------------------------------------------------
gpu=none
capability=
if command -v nvidia-smi >/dev/null && nvidia-smi -L >/dev/null 2>&1; then
  gpu=$(nvidia-smi --query-gpu=name --format=csv,noheader | head -1)
  capability=$(nvidia-smi --query-gpu=compute_cap --format=csv,noheader | head -1 | tr -d ' ')
fi
if [ "$gpu" = none ]; then
  say "no NVIDIA GPU found (nvidia-smi): building only"
  build_only=1
  read -r arch sm <<<"${FRACTA_CUDA_ARCH:-AMPERE80 sm_80}"
else
  say "GPU: $gpu, compute capability $capability"
  # Kokkos 3.4.1 aborts at start-up when the binary's major version differs from the device's,
  # and it knows no architecture after Ampere (8.x).
  case $capability in
    7.5) arch=TURING75 sm=sm_75 ;;
    8.0) arch=AMPERE80 sm=sm_80 ;;
    8.*) arch=AMPERE86 sm=sm_86 ;;
    *)
      if [ -z "${KOKKOS_ROOT:-}" ]; then
        say "Kokkos 3.4.1 cannot run on compute capability $capability: set KOKKOS_ROOT to a"
        say "Kokkos 4.x or 5.x built with CUDA for it (e.g. -DKokkos_ARCH_HOPPER90=ON)"
        exit 1
      fi
      arch= sm=sm_${capability/./}
      ;;
  esac
fi

# --- 1. The CPU build -------------------------------------------------------------------------
if [ "$build_only" != 1 ]; then
  bash "$repo/scripts/setup.sh"
fi

# --- 2. Kokkos with CUDA and fracta with it ---------------------------------------------------
t0=$(now)
if [ -n "${KOKKOS_ROOT:-}" ]; then
  kokkos_root=$KOKKOS_ROOT
  say "using the Kokkos given by KOKKOS_ROOT=$kokkos_root"
else
  kokkos_root=$prefix/kokkos-3.4.1-cuda
  [ "$sm" = sm_80 ] || kokkos_root=$prefix/kokkos-3.4.1-cuda-$sm
  # shellcheck source=scripts/kokkos_source.sh
  . "$repo/scripts/kokkos_source.sh"
  fracta_kokkos_cuda "$repo" "$prefix" "$kokkos_root" "$arch" "$sm"
fi
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$repo" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DKokkos_ROOT="$kokkos_root" \
    >"$build.configure.log" 2>&1 || { cat "$build.configure.log" >&2; exit 1; }
  rm -f "$build.configure.log"
fi
cmake --build "$build" -j "$jobs" >"$build/build.log" 2>&1 ||
  { grep -E 'error|FAILED' "$build/build.log" | head -40 >&2; say "GPU build failed (log: $build/build.log)"; exit 1; }
build_seconds=$(elapsed "$t0")
say "built $build in ${build_seconds} s"
if [ "$build_only" = 1 ]; then
  say "build only: done in $(elapsed "$t_start") s"
  exit 0
fi
"$build/fracta" info >&2

# --- 3. The suite on the GPU -------------------------------------------------------------------
t1=$(now)
suite=passed
ctest --test-dir "$build" --output-on-failure >"$build/ctest.log" 2>&1 || suite=FAILED
suite_line=$(grep -E 'tests passed' "$build/ctest.log" || echo "no summary")
suite_seconds=$(elapsed "$t1")

# --- 4. Throughput, GPU against CPU -----------------------------------------------------------
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for level in 1 4 8; do
  steps=200
  [ "$level" = 8 ] && steps=50
  "$build/bench/penetration" --level "$level" --steps "$steps" --json "$out/gpu_$level.json" >/dev/null
  OMP_NUM_THREADS=$jobs OMP_PROC_BIND=spread OMP_PLACES=threads \
    "$repo/build/bench/penetration" --level "$level" --steps "$steps" \
    --json "$out/cpu_$level.json" >/dev/null
done

# --- 5. The paper's penetration scene on both, frames compared -----------------------------------
for side in gpu cpu; do
  exe=$build/fracta
  [ "$side" = cpu ] && exe=$repo/build/fracta
  OMP_NUM_THREADS=$jobs OMP_PROC_BIND=spread OMP_PLACES=threads "$exe" run \
    "$repo/cases/penetration.toml" -o "$out/main_$side.h5" --set simulation.end_time=20e-6 \
    >/dev/null
done

/usr/bin/python3 - "$out" "$gpu" "$jobs" "$suite" "$suite_line" "$build_seconds" \
  "$suite_seconds" "$(elapsed "$t_start")" <<'EOF'
import json, sys
import h5py
import numpy as np
out, gpu, jobs, suite, suite_line, build_s, suite_s, total_s = sys.argv[1:]
print(f"fracta device run on {gpu} (CPU: {jobs} threads)")
print(f"build {build_s} s; suite on the GPU: {suite} ({suite_line}, {suite_s} s); total {total_s} s")
print(f"{'level':>5} {'nodes':>9} {'CPU steps/s':>12} {'GPU steps/s':>12} {'GPU/CPU':>8}"
      f" {'GPU entity-steps/s':>19}")
for level in (1, 4, 8):
    c = json.load(open(f"{out}/cpu_{level}.json"))
    g = json.load(open(f"{out}/gpu_{level}.json"))
    print(f"{level:>5} {g['nodes']:>9} {c['steps_per_s']:>12.1f} {g['steps_per_s']:>12.1f}"
          f" {g['steps_per_s'] / c['steps_per_s']:>8.2f} {g['entity_steps_per_s']:>19.3e}")
with h5py.File(f"{out}/main_gpu.h5") as a, h5py.File(f"{out}/main_cpu.h5") as b:
    n = min(a["frames"].attrs["count"], b["frames"].attrs["count"])
    xa = a[f"frames/{n - 1}/node_position"][:]
    xb = b[f"frames/{n - 1}/node_position"][:]
    t = a[f"frames/{n - 1}/time"][()]
    d = float(np.max(np.linalg.norm(xa - xb, axis=1)))
    print(f"penetration scene at t = {float(np.ravel(t)[0]) * 1e6:.1f} us: largest GPU-CPU node distance"
          f" {d:.3e} m")
EOF
[ "$suite" = passed ]
