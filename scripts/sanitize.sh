#!/usr/bin/env bash
# Builds the asan preset (AddressSanitizer + UndefinedBehaviorSanitizer, RelWithDebInfo, in
# build-asan/) and runs the test suite under it (all but the tests of 3 s or more in Release,
# below): any sanitizer report fails the run.
#
#   scripts/sanitize.sh            asan preset (Kokkos from scripts/setup.sh)
#   scripts/sanitize.sh --bounds   also the debug-bounds preset: Debug with Kokkos bounds checks
#                                  (builds the debug Kokkos once: scripts/setup.sh --kokkos-debug)
#
# No suppression file: the suite runs clean without one. Kokkos, HDF5 and libgomp are not
# instrumented (only our code is), so their internals are not checked, but every access of our
# code to their memory is.
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$repo"
say() { printf '[sanitize] %s\n' "$*" >&2; }

bounds=0
for arg in "$@"; do
  case $arg in
    --bounds) bounds=1 ;;
    *) say "unknown option $arg (known: --bounds)"; exit 2 ;;
  esac
done

export OMP_NUM_THREADS=${OMP_NUM_THREADS:-2} OMP_PROC_BIND=spread OMP_PLACES=threads
# halt_on_error: the first report fails the test that caused it (with its name in the log).
# detect_leaks: our code owns no raw allocations; a leak is a bug.
export ASAN_OPTIONS=${ASAN_OPTIONS:-halt_on_error=1:abort_on_error=1:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}

# The presets name /opt/fracta's Kokkos; KOKKOS_ROOT or FRACTA_PREFIX (as for setup.sh) override.
prefix=${FRACTA_PREFIX:-/opt/fracta}
[ -n "${KOKKOS_ROOT:-}" ] || [ -f "$prefix/kokkos-3.4.1-openmp/.fracta-stamp" ] || bash scripts/setup.sh
start=$SECONDS
[ -f build-asan/CMakeCache.txt ] ||
  cmake --preset asan -DKokkos_ROOT="${KOKKOS_ROOT:-$prefix/kokkos-3.4.1-openmp}" >/dev/null
mkdir -p build-asan
cmake --build --preset asan >build-asan/build.log 2>&1 ||
  { tail -80 build-asan/build.log >&2; say "build failed (full log: build-asan/build.log)"; exit 1; }
say "asan build: $((SECONDS - start)) s"
start=$SECONDS
# The tests that take 3 s or more in Release (some ten times that here) are left to the Release
# suite: they run, for longer, scenes whose kernels and code paths shorter tests run here too
# (the kernel tests of bonds, cohesive softening, contact and friction; the lattice, output and
# checkpoint tests below 3 s). The rest, about 45 s of the Release suite's 300, is sanitized.
long_tests='^(BrazilianDisc|KalthoffWinkler|GlassBranching|PerturbedLattice|OutputCost|Memory'
long_tests+='|HjcConcrete|CrackGrowth|ContactFriction)\.'
long_tests+='|^LatticeFailure\.(Weibull|Cohesive|RateDependent|UniaxialTension)'
long_tests+='|^LatticeEnergy\.CellTerm|^Extremes\.(MillionStep|PaperPlate)'
long_tests+='|^Checkpoint\.SigkillLeaves|^Scripts\.ReadEveryFrameStorage|BarFragmentation.*/e100$'
ctest --preset asan -j1 -E "$long_tests"
say "asan tests: $((SECONDS - start)) s"

if [ $bounds = 1 ]; then
  [ -f "$prefix/kokkos-3.4.1-openmp-debug/.fracta-stamp" ] ||
    FRACTA_BUILD_DIR=$repo/build-debug-bounds bash scripts/setup.sh --kokkos-debug
  start=$SECONDS
  [ -f build-debug-bounds/CMakeCache.txt ] ||
    cmake --preset debug-bounds -DKokkos_ROOT="$prefix/kokkos-3.4.1-openmp-debug" >/dev/null
  cmake --build --preset debug-bounds >build-debug-bounds/build.log 2>&1 ||
    { tail -80 build-debug-bounds/build.log >&2; say "build failed (build-debug-bounds/build.log)"; exit 1; }
  ctest --preset debug-bounds -j1
  say "debug-bounds build and tests: $((SECONDS - start)) s"
fi
