#!/usr/bin/env bash
# CUDA portability check, compile only (these machines have nvcc but no GPU):
#  1. builds Kokkos 3.4.1 with CUDA (sm_80, CUDA lambdas) + Serial from Debian's Trilinos source
#     package, with the CUDA 13 fixes of scripts/patches/, into a prefix (once: a stamp that
#     names the patches and the nvcc version makes a second run skip it);
#  2. compiles every kernel of src/kernels (one unit per header, cuda/kernels_*.cpp) and the
#     host sources that only launch kernels with nvcc_wrapper for sm_80 (cuda/CMakeLists.txt).
# Any error fails the check, and so does any warning of nvcc or the host compiler (nvcc only
# warns about some device bugs, e.g. a host function called from a host-device one).
#
# Environment:
#   CUDA_ROOT             CUDA toolkit (default /usr/local/cuda)
#   FRACTA_PREFIX         where the Kokkos goes (default /opt/fracta, as scripts/setup.sh)
#   FRACTA_CUDA_BUILD_DIR build directory of the kernel units (default <repo>/build-cuda)
#   FRACTA_CUDA_CHECK_TESTS=1 also compile the kernel tests (tests/kernels/*.cpp)
# Needs g++, cmake, ninja-build and dpkg-dev (scripts/setup.sh installs them).
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
prefix=${FRACTA_PREFIX:-/opt/fracta}
kokkos_prefix=$prefix/kokkos-3.4.1-cuda
cuda_root=${CUDA_ROOT:-/usr/local/cuda}
build_dir=${FRACTA_CUDA_BUILD_DIR:-$repo/build-cuda}
jobs=$(nproc)

say() { printf '[cuda_check] %s\n' "$*" >&2; }
now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }'; }

nvcc=$cuda_root/bin/nvcc
if [ ! -x "$nvcc" ]; then
  say "no nvcc at $nvcc (set CUDA_ROOT): cannot check"
  exit 1
fi
for tool in cmake ninja g++ patch; do
  command -v "$tool" >/dev/null || { say "$tool is missing: run scripts/setup.sh first"; exit 1; }
done
export PATH=$cuda_root/bin:$PATH
export CUDA_ROOT=$cuda_root  # nvcc_wrapper takes nvcc from there

# --- 1. Kokkos with CUDA --------------------------------------------------------------------
t0=$(now)
# shellcheck source=scripts/kokkos_source.sh
. "$repo/scripts/kokkos_source.sh"
fracta_kokkos_cuda "$repo" "$prefix" "$kokkos_prefix" AMPERE80 sm_80
kokkos_seconds=$(elapsed "$t0")

# --- 2. fracta's kernels, compile only ------------------------------------------------------
t1=$(now)
mkdir -p "$build_dir"
with_tests=OFF
if [ "${FRACTA_CUDA_CHECK_TESTS:-0}" = 1 ]; then with_tests=ON; fi
if [ ! -f "$build_dir/CMakeCache.txt" ]; then
  cmake -S "$repo/cuda" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DKokkos_ROOT="$kokkos_prefix" -DCMAKE_CXX_COMPILER="$kokkos_prefix/bin/nvcc_wrapper" \
    -DFRACTA_CUDA_CHECK_TESTS="$with_tests" \
    >"$build_dir/configure.log" 2>&1 || { cat "$build_dir/configure.log" >&2; exit 1; }
else
  cmake "$build_dir" -DFRACTA_CUDA_CHECK_TESTS="$with_tests" >"$build_dir/configure.log" 2>&1 ||
    { cat "$build_dir/configure.log" >&2; exit 1; }
fi
sed -n 's/^-- fracta CUDA check: /[cuda_check] /p' "$build_dir/configure.log" >&2
log=$build_dir/build.log
# Rebuild everything: the warnings of units compiled by an earlier run must be seen again.
ninja -C "$build_dir" -t clean >/dev/null
status=0
ninja -C "$build_dir" -k 0 -j "$jobs" >"$log" 2>&1 || status=$?
kernel_seconds=$(elapsed "$t1")

# Every diagnostic fails the check, including warnings inside Kokkos' headers: they are
# instantiated with fracta's functors, and the log of a clean build has none.
diagnostics=$(grep -E '(warning|error)[ #:]' "$log" | sort -u || true)
units=$(grep -c -E '^\[[0-9]+/[0-9]+\] Building CXX' "$log" || true)
# Failed: units that did not compile, plus the files that warnings point at.
failed=$(grep -c '^FAILED:' "$log" || true)
warned=$(printf '%s\n' "$diagnostics" | grep -E 'warning[ #:]' | sed -E 's/[(:].*//' | sort -u | grep -c . || true)
failed=$((failed + warned > units ? units : failed + warned))
say "Kokkos step ${kokkos_seconds} s, kernel compile step ${kernel_seconds} s ($units units, log: $log)"
if [ "$status" != 0 ] || [ -n "$diagnostics" ]; then
  if [ -n "$diagnostics" ]; then printf '%s\n' "$diagnostics" | head -60 >&2; fi
  say "FAILED: fracta's kernels are not CUDA-clean (full log: $log)"
  # The plain summary line CI reads (one per compiled unit).
  echo "cuda_check: $((units - failed)) passed, $failed failed"
  exit 1
fi
say "passed: every kernel compiles for CUDA sm_80 without warnings"
echo "cuda_check: $units passed, 0 failed"
