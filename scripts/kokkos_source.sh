# shellcheck shell=bash
# Kokkos 3.4.1 source, shared by scripts/setup.sh (OpenMP build) and scripts/cuda_check.sh
# (CUDA build). Source this file, then call
#   fracta_kokkos_source CACHE_DIR DEST_DIR
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
