#!/usr/bin/env bash
# Fuzzes the case parser and the mesh generator with libFuzzer (fuzz/fuzz_case.cpp) for a given
# time, under AddressSanitizer and UndefinedBehaviorSanitizer.
#
#   scripts/fuzz.sh [SECONDS] [extra libFuzzer flags...]     (default 600 s)
#
# Seeds: every case file in cases/ and tests/data/. The growing corpus is kept in
# build-fuzz/corpus (reused by the next run); crashes, timeouts and out-of-memory inputs go to
# build-fuzz/artifacts/. Add a reproducer to tests/host/test_fuzz.cpp when fixing one.
# Needs clang with libFuzzer (Debian 12: clang libclang-rt-14-dev; installed when missing).
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
seconds=${1:-600}
shift || true
build=${FRACTA_FUZZ_BUILD_DIR:-$repo/build-fuzz}

say() { printf '[fuzz] %s\n' "$*" >&2; }

if ! command -v clang++ >/dev/null || ! dpkg-query -W -f='${Status}' libclang-rt-14-dev 2>/dev/null |
  grep -q 'install ok installed'; then
  [ "$(id -u)" = 0 ] || { say "install clang and libclang-rt-14-dev (needs root)"; exit 1; }
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
    clang libclang-rt-14-dev >/dev/null
fi

if [ ! -f "$build/CMakeCache.txt" ]; then
  CXX=clang++ cmake -S "$repo/fuzz" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
fi
cmake --build "$build" --target fuzz_case >/dev/null

mkdir -p "$build/corpus" "$build/artifacts" "$build/seeds"
find "$repo/cases" "$repo/tests/data" -name '*.toml' -exec cp {} "$build/seeds/" \;

say "fuzzing for ${seconds} s (corpus $build/corpus, findings in $build/artifacts)"
# 10 s per input and 2 GB: a slower or larger input is a finding (check_memory should have
# refused it). Inputs up to 16 kB: larger than any real case file.
ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:halt_on_error=1} \
UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1} \
  "$build/fuzz_case" "$build/corpus" "$build/seeds" -max_total_time="$seconds" -timeout=10 \
  -rss_limit_mb=2048 -max_len=16384 -dict="$repo/fuzz/case.dict" \
  -artifact_prefix="$build/artifacts/" -print_final_stats=1 "$@"
