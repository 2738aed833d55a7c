#!/bin/bash
# Makes (once) and caches a minimal Debian root with only Python — none of the libraries TopStoc
# builds against (no TetGen, libgomp, OpenMesh, Blender) — for the install tests.
#
#   tests/install/minimal_root.sh SUITE              prints the root's path (bookworm or trixie)
#   tests/install/minimal_root.sh SUITE run DIR CMD  runs CMD (bash) inside it with DIR at /work
#
# The root is ${TOPSTOC_CACHE:-/var/cache/topstoc}/minimal-SUITE-root (debootstrap --variant=minbase
# plus python3 and python3-venv, ~300 MB, ~3 min once). Commands run through scripts/in_root.sh
# (private mounts, clean environment); write under /work, so the cached root stays as made.
set -u
SUITE=${1:?usage: minimal_root.sh bookworm|trixie [run DIR CMD]}
CACHE=${TOPSTOC_CACHE:-/var/cache/topstoc}
ROOTFS=$CACHE/minimal-$SUITE-root

make_root() {
  command -v debootstrap >/dev/null ||
    { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -q debootstrap >/dev/null; } || return 1
  local tmp=$ROOTFS.partial log=$CACHE/minimal-$SUITE-root.log
  rm -rf "$tmp"; mkdir -p "$CACHE"
  echo "== making a minimal Debian $SUITE root in $ROOTFS (once; ~3 min)" >&2
  debootstrap --variant=minbase "$SUITE" "$tmp" http://deb.debian.org/debian >"$log" 2>&1 ||
    { tail -20 "$log" >&2; return 1; }
  cp /etc/resolv.conf "$tmp/etc/resolv.conf"
  chroot "$tmp" /bin/bash -c "apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -q \
    --no-install-recommends python3 python3-venv >/dev/null && apt-get clean" >>"$log" 2>&1 ||
    { echo "error: could not install python3 in the $SUITE root (see $log)" >&2; return 1; }
  mv "$tmp" "$ROOTFS"
}

[ -d "$ROOTFS" ] || make_root || exit 1
[ "${2:-}" = run ] || { echo "$ROOTFS"; exit 0; }
dir=${3:?work dir}; shift 3
exec "$(dirname "$0")/../../scripts/in_root.sh" "$ROOTFS" "$dir" "$@"
