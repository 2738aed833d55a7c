#!/bin/bash
# Runs a command inside a cached Debian root (chroot) with DIR bind-mounted at /work:
#
#   scripts/in_root.sh ROOTFS DIR 'COMMAND'
#
# The mounts (/proc, /sys, /dev, a fresh /tmp, DIR) live in a private mount namespace
# (scripts/private_mounts.sh): they vanish when the command ends and parallel runs never see each other's.
# The environment is clean (HOME=/work, TMPDIR=/work/tmp), so nothing of this host leaks in.
set -eu
rootfs=$(cd "${1:?rootfs}" && pwd); work=$(cd "${2:?dir}" && pwd); shift 2
mkdir -p "$rootfs/work" "$work/tmp"
exec "$(dirname "${BASH_SOURCE[0]}")/private_mounts.sh" /bin/bash -c '
  set -e; r=$1; w=$2; shift 2
  mount -t proc proc "$r/proc"; mount -t sysfs sys "$r/sys"; mount --rbind /dev "$r/dev"
  mount -t tmpfs tmpfs "$r/tmp"; mount --bind "$w" "$r/work"
  exec chroot "$r" /usr/bin/env -i HOME=/work TMPDIR=/work/tmp LANG=C.UTF-8 \
    PATH=/usr/local/bin:/usr/bin:/bin:/usr/sbin:/sbin /bin/bash -c "cd /work && $*"' _ "$rootfs" "$work" "$*"
