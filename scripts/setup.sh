#!/usr/bin/env bash
# fracta setup: installs what is missing on Debian 12, builds Kokkos 3.4.1 with OpenMP
# from Debian's Trilinos source package into a prefix (once), then configures and builds
# fracta into build/. Idempotent: a second run only rebuilds what changed.
#
# Environment:
#   KOKKOS_ROOT       use this Kokkos install (3.4 or 4.x, OpenMP or CUDA) instead of building one
#   FRACTA_PREFIX     where our Kokkos goes (default /opt/fracta)
#   FRACTA_BUILD_DIR  build directory (default <repo>/build)
#   FRACTA_BUILD_TYPE CMake build type (default Release)
#   FRACTA_KOKKOS_FLAVOR=debug (or the option --kokkos-debug): a Debug Kokkos with bounds
#                     checking (Kokkos_ENABLE_DEBUG, Kokkos_ENABLE_DEBUG_BOUNDS_CHECK) from the
#                     same source, in its own prefix kokkos-3.4.1-openmp-debug, and a Debug
#                     fracta in build-debug-bounds/ (the CMakePresets.json preset debug-bounds)
#   FRACTA_KOKKOS_FLAVOR=device (or the option --device-path): fracta built to take the device
#                     code path on the CPU (-DFRACTA_DEVICE_PATH=ON: atomic scatter, one lane per
#                     work item, LayoutLeft views) with the release Kokkos, in build-device/
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
flavor=${FRACTA_KOKKOS_FLAVOR:-release}
for arg in "$@"; do
  case $arg in
    --kokkos-debug) flavor=debug ;;
    --device-path) flavor=device ;;
    *) printf '[setup] unknown option %s (known: --kokkos-debug, --device-path)\n' "$arg" >&2; exit 2 ;;
  esac
done
prefix=${FRACTA_PREFIX:-/opt/fracta}
case $flavor in
  release)
    kokkos_prefix=$prefix/kokkos-3.4.1-openmp
    kokkos_flags=(-DCMAKE_BUILD_TYPE=Release)
    build_dir=${FRACTA_BUILD_DIR:-$repo/build}
    build_type=${FRACTA_BUILD_TYPE:-Release}
    fracta_flags=()
    ;;
  device)
    kokkos_prefix=$prefix/kokkos-3.4.1-openmp
    kokkos_flags=(-DCMAKE_BUILD_TYPE=Release)
    build_dir=${FRACTA_BUILD_DIR:-$repo/build-device}
    build_type=${FRACTA_BUILD_TYPE:-Release}
    fracta_flags=(-DFRACTA_DEVICE_PATH=ON -DFRACTA_BUILD_BENCH=OFF)  # the path is for the tests
    ;;
  debug)
    kokkos_prefix=$prefix/kokkos-3.4.1-openmp-debug
    kokkos_flags=(-DCMAKE_BUILD_TYPE=Debug -DKokkos_ENABLE_DEBUG=ON
      -DKokkos_ENABLE_DEBUG_BOUNDS_CHECK=ON)
    build_dir=${FRACTA_BUILD_DIR:-$repo/build-debug-bounds}
    build_type=${FRACTA_BUILD_TYPE:-Debug}
    fracta_flags=(-DFRACTA_BUILD_BENCH=OFF)  # the bounds check is for the tests
    ;;
  *) printf '[setup] FRACTA_KOKKOS_FLAVOR must be release, debug or device (got %s)\n' "$flavor" >&2; exit 2 ;;
esac
jobs=$(nproc)

say() { printf '[setup] %s\n' "$*" >&2; }

# --- 1. Debian packages -------------------------------------------------------------
packages=(g++ cmake make ninja-build pkg-config libeigen3-dev libhdf5-dev hdf5-tools
  libtomlplusplus-dev libcli11-dev libgtest-dev libgmock-dev libbenchmark-dev
  python3-h5py python3-matplotlib python3-numpy dpkg-dev ca-certificates)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" != 0 ]; then
    say "missing Debian packages: ${missing[*]}; run this script as root (or install them) first"
    exit 1
  fi
  say "installing ${missing[*]}"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# --- 2. Kokkos ----------------------------------------------------------------------
if [ -n "${KOKKOS_ROOT:-}" ]; then
  kokkos_root=$KOKKOS_ROOT
  say "using the Kokkos given by KOKKOS_ROOT=$kokkos_root"
elif [ -f "$kokkos_prefix/.fracta-stamp" ]; then
  kokkos_root=$kokkos_prefix
else
  kokkos_root=$kokkos_prefix
  say "building Kokkos 3.4.1 (OpenMP + Serial, ${kokkos_flags[0]#-DCMAKE_BUILD_TYPE=}) into $kokkos_prefix (about a minute, once)"
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
  # shellcheck source=scripts/kokkos_source.sh
  . "$repo/scripts/kokkos_source.sh"
  fracta_kokkos_source "$prefix/src" "$work"
  cmake -S "$work" -B "$work/build" -G Ninja "${kokkos_flags[@]}" \
    -DCMAKE_CXX_STANDARD=17 -DCMAKE_INSTALL_PREFIX="$kokkos_prefix" \
    -DKokkos_ENABLE_OPENMP=ON -DKokkos_ENABLE_SERIAL=ON >"$work/configure.log" 2>&1 ||
    { cat "$work/configure.log" >&2; exit 1; }
  cmake --build "$work/build" -j "$jobs" >"$work/build.log" 2>&1 || { tail -50 "$work/build.log" >&2; exit 1; }
  cmake --install "$work/build" >/dev/null
  date -u +%FT%TZ >"$kokkos_prefix/.fracta-stamp"
  say "Kokkos installed"
fi

# --- 3. fracta ----------------------------------------------------------------------
if [ ! -f "$build_dir/CMakeCache.txt" ]; then
  cmake -S "$repo" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE="$build_type" \
    -DKokkos_ROOT="$kokkos_root" ${fracta_flags[@]+"${fracta_flags[@]}"} >"$build_dir.configure.log" 2>&1 ||
    { cat "$build_dir.configure.log" >&2; exit 1; }
  rm -f "$build_dir.configure.log"
fi
log=$build_dir/build.log
cmake --build "$build_dir" -j "$jobs" >"$log" 2>&1 || { tail -80 "$log" >&2; say "build failed (full log: $log)"; exit 1; }
say "built $build_dir/fracta"
