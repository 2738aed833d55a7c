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

source "$(dirname "$0")/../../scripts/debian_root.sh"  # make_debian_root
make_root() {
  make_debian_root "$ROOTFS" "$SUITE" "$(dpkg --print-architecture)" "python3 python3-venv" \
    "$CACHE/minimal-$SUITE-root.log"
}

[ -d "$ROOTFS" ] || make_root || exit 1
[ "${2:-}" = run ] || { echo "$ROOTFS"; exit 0; }
dir=${3:?work dir}; shift 3
exec "$(dirname "$0")/../../scripts/in_root.sh" "$ROOTFS" "$dir" "$@"
