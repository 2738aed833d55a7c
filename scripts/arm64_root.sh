#!/bin/bash
# Makes (once) and caches a Debian 12 arm64 root, run on this x86-64 machine through QEMU user
# emulation (Debian's qemu-user-static, binfmt_misc), for the Linux aarch64 suite
# (scripts/aarch64_test.sh):
#
#   scripts/arm64_root.sh                prints the root's path, creating it on first use
#   scripts/arm64_root.sh run DIR CMD    runs CMD (bash) inside it with DIR at /work
#
# The root is ${TOPSTOC_CACHE:-/var/cache/topstoc}/arm64-bookworm-root: debootstrap minbase plus
# Python and the test suite's Debian packages (numpy, pytest, scipy, gudhi; about 600 MB, ~15 min
# once: every package's scripts run emulated). Commands run through scripts/in_root.sh (private
# mounts, clean environment); write under /work, so the cached root stays as made. Needs root.
set -u
source "$(dirname "$0")/debian_root.sh"  # make_debian_root, enable_qemu
CACHE=${TOPSTOC_CACHE:-/var/cache/topstoc}
ROOTFS=$CACHE/arm64-bookworm-root
PACKAGES="python3 python3-venv python3-numpy python3-pytest python3-scipy python3-gudhi"

enable_qemu aarch64 || { echo "error: cannot run aarch64 programs here (qemu-user-static, binfmt_misc)" >&2; exit 1; }
[ -d "$ROOTFS" ] || make_debian_root "$ROOTFS" bookworm arm64 "$PACKAGES" "$CACHE/arm64-bookworm-root.log" || exit 1
[ "${1:-}" = run ] || { echo "$ROOTFS"; exit 0; }
dir=${2:?work dir}; shift 2
exec "$(dirname "$0")/in_root.sh" "$ROOTFS" "$dir" "$@"
