#!/bin/bash
# Makes (once) and caches a Debian 13 "trixie" root for the suites that need CPython 3.13 or a
# newer real Blender than Debian 12's: Debian 13 has Python 3.13 and Blender 4.3.
#
#   scripts/debian13_root.sh            prints the root's path, creating it on first use
#   scripts/debian13_root.sh run CMD    runs CMD (bash) inside it, this checkout at /opt/project
#
# The root lives in ${TOPSTOC_CACHE:-/var/cache/topstoc}/trixie-root (about 1.5 GB, ~5 min to
# make), outside the checkout, so CI runs on fresh clones reuse it. Needs root and debootstrap.
set -u
export PATH=$PATH:/usr/sbin:/sbin  # debootstrap and chroot, whatever PATH the caller had
CACHE=${TOPSTOC_CACHE:-/var/cache/topstoc}
ROOTFS=$CACHE/trixie-root
PACKAGES="python3 python3-venv python3-dev blender xvfb xauth ca-certificates libgl1-mesa-dri"

source "$(dirname "${BASH_SOURCE[0]}")/debian_root.sh"  # make_debian_root
make_root() {
  make_debian_root "$ROOTFS" trixie "$(dpkg --print-architecture)" "$PACKAGES" "$CACHE/debootstrap.log"
}

# Runs a command inside the root with /proc, /sys, /dev and this checkout mounted. The mounts live
# in a private mount namespace (scripts/private_mounts.sh), so runs from several checkouts at
# once neither see nor unmount each other's /opt/project, and nothing stays mounted when the
# command ends.
# With TOPSTOC_ROOT_LAYER=NAME the root is seen through a writable overlay kept in
# $CACHE/trixie-NAME: what that run installs (compilers, -dev libraries, venvs) stays in the layer
# and the base root keeps none of the build's libraries (the install tests need such a root).
run_in_root() {
  local project; project=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
  local layer=""
  [ -n "${TOPSTOC_ROOT_LAYER:-}" ] && layer=$CACHE/trixie-$TOPSTOC_ROOT_LAYER
  mkdir -p "$ROOTFS/opt/project" ${layer:+"$layer/upper" "$layer/work" "$layer/merged"}
  ROOTFS=$ROOTFS LAYER=$layer PROJECT=$project "$project/scripts/private_mounts.sh" /bin/bash -c '
    root=$ROOTFS
    if [ -n "$LAYER" ]; then
      mount -t overlay overlay -o "lowerdir=$ROOTFS,upperdir=$LAYER/upper,workdir=$LAYER/work" \
        "$LAYER/merged" || exit 1
      root=$LAYER/merged
    fi
    mount -t proc proc "$root/proc" && mount -t sysfs sys "$root/sys" &&
    mount --rbind /dev "$root/dev" && mount --bind "$PROJECT" "$root/opt/project" || exit 1
    exec chroot "$root" /usr/bin/env -i HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
      LANG=C.UTF-8 /bin/bash -c "cd /opt/project && $1"' _ "$*"
}

[ -d "$ROOTFS" ] || make_root || exit 1
if [ "${1:-}" = run ]; then shift; run_in_root "$@"; else echo "$ROOTFS"; fi
