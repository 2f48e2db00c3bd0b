# shellcheck shell=bash
# Kokkos 3.4.1 source, shared by scripts/setup.sh (OpenMP build), scripts/cuda_check.sh and
# scripts/device_run.sh (CUDA builds). Source this file, then call
#   fracta_kokkos_source CACHE_DIR DEST_DIR
# or, for a CUDA Kokkos (below),
#   fracta_kokkos_cuda REPO PREFIX KOKKOS_PREFIX ARCH SM
# It downloads Debian's trilinos 13.2.0-4 source package into CACHE_DIR once (apt-get source,
# as root), checks the orig tarball's sha256 and unpacks its standalone Kokkos
# (packages/kokkos) into DEST_DIR. Needs dpkg-dev (apt-get source) and a deb-src entry, which
# it adds when missing (mirroring the configured Debian sources: no host is named here).

fracta_kokkos_source() {
  local src_cache=$1 dest=$2
  local tarball=$src_cache/trilinos_13.2.0.orig.tar.gz
  local want_sha=0ddb47784ba7b8a6b9a07a4822b33be508feb4ccd54301b2a5d10c9e54524b90
  mkdir -p "$src_cache" "$dest"
  if [ ! -f "$tarball" ] || [ "$(sha256sum "$tarball" | cut -d' ' -f1)" != "$want_sha" ]; then
    chown _apt:root "$src_cache" 2>/dev/null || true  # apt-get source downloads as _apt
    if ! apt-get source --download-only --print-uris trilinos=13.2.0-4 >/dev/null 2>&1; then
      if [ -f /etc/apt/sources.list.d/debian.sources ]; then
        sed 's/^Types: deb$/Types: deb-src/' /etc/apt/sources.list.d/debian.sources \
          >/etc/apt/sources.list.d/fracta-deb-src.sources
      elif [ -f /etc/apt/sources.list ]; then
        sed -n 's/^deb /deb-src /p' /etc/apt/sources.list >/etc/apt/sources.list.d/fracta-deb-src.list
      fi
      apt-get update -qq
    fi
    (cd "$src_cache" && apt-get source --download-only -qq trilinos=13.2.0-4 >/dev/null)
    local got_sha
    got_sha=$(sha256sum "$tarball" | cut -d' ' -f1)
    if [ "$got_sha" != "$want_sha" ]; then
      printf 'trilinos tarball hash mismatch: %s (want %s)\n' "$got_sha" "$want_sha" >&2
      return 1
    fi
  fi
  tar xzf "$tarball" -C "$dest" --strip-components=3 --wildcards '*/packages/kokkos/*'
}

# Builds Kokkos 3.4.1 with CUDA (CUDA lambdas, architecture option Kokkos_ARCH_<ARCH>, e.g.
# AMPERE80, named SM in the stamp, e.g. sm_80) and Serial into KOKKOS_PREFIX, with the CUDA 13
# fixes of REPO/scripts/patches/, from the source cached under PREFIX/src. Once: a stamp that
# names the architecture, the patches and the nvcc version makes a later call return at once.
# Needs nvcc on PATH and CUDA_ROOT set (nvcc_wrapper takes nvcc from there).
fracta_kokkos_cuda() {
  local repo=$1 prefix=$2 kokkos_prefix=$3 arch=$4 sm=$5
  local patches=("$repo"/scripts/patches/kokkos-3.4.1-cuda13-*.patch)
  local nvcc_version stamp_want
  nvcc_version=$(nvcc --version | sed -n 's/.*release \([0-9.]*\).*/\1/p')
  stamp_want="kokkos 3.4.1 cuda+serial $sm nvcc $nvcc_version patches $(cat "${patches[@]}" | sha256sum | cut -c1-16)"
  if [ -f "$kokkos_prefix/.fracta-stamp" ] && [ "$(cat "$kokkos_prefix/.fracta-stamp")" = "$stamp_want" ]; then
    printf '[kokkos] Kokkos with CUDA (%s) already installed in %s\n' "$sm" "$kokkos_prefix" >&2
    return 0
  fi
  printf '[kokkos] building Kokkos 3.4.1 (CUDA %s + Serial) into %s (several minutes, once)\n' \
    "$sm" "$kokkos_prefix" >&2
  local work
  work=$(mktemp -d)
  fracta_kokkos_source "$prefix/src" "$work/kokkos" || { rm -rf "$work"; return 1; }
  # Idempotent: a patch that reverses cleanly is already in (a reused source tree).
  local p
  for p in "${patches[@]}"; do
    if ! patch -d "$work/kokkos" -p1 -R --dry-run -s -f <"$p" >/dev/null 2>&1; then
      patch -d "$work/kokkos" -p1 -s -f <"$p" || { printf '[kokkos] patch failed: %s\n' "$p" >&2; rm -rf "$work"; return 1; }
    fi
  done
  rm -rf "$kokkos_prefix"
  if ! cmake -S "$work/kokkos" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_CXX_STANDARD=17 -DCMAKE_CXX_EXTENSIONS=OFF \
    -DCMAKE_CXX_COMPILER="$work/kokkos/bin/nvcc_wrapper" \
    -DCMAKE_INSTALL_PREFIX="$kokkos_prefix" -DKokkos_ENABLE_SERIAL=ON \
    -DKokkos_ENABLE_CUDA=ON -DKokkos_ENABLE_CUDA_LAMBDA=ON "-DKokkos_ARCH_$arch=ON" \
    >"$work/configure.log" 2>&1; then
    tail -50 "$work/configure.log" >&2
    rm -rf "$work"
    return 1
  fi
  if ! cmake --build "$work/build" -j "$(nproc)" >"$work/build.log" 2>&1; then
    grep -E 'error|Error' "$work/build.log" | head -40 >&2
    rm -rf "$work"
    return 1
  fi
  cmake --install "$work/build" >/dev/null
  printf '%s\n' "$stamp_want" >"$kokkos_prefix/.fracta-stamp"
  rm -rf "$work"
  printf '[kokkos] Kokkos with CUDA installed\n' >&2
}
