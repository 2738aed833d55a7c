#!/bin/bash
# Runs a command in a new mount namespace, so that the mounts it makes vanish when it ends and
# parallel runs never see each other's:
#
#   scripts/private_mounts.sh COMMAND [ARG ...]
#
# On a normal system unshare makes every mount of the namespace private. Inside a chroot (a
# fresh Debian root made with debootstrap, as ../shared/tools/fresh-debian.sh runs the Quick
# start) "/" is not a mount point and that step fails with "cannot change root filesystem
# propagation". There the namespace keeps the propagation it inherits, which is as private only
# when no mount seen here is shared: checked (in /proc), else an error names the problem (a
# shared mount would carry our mounts out to the host).
if unshare --mount --propagation private true 2>/dev/null; then
  exec unshare --mount --propagation private "$@"
fi
if [ ! -r /proc/self/mountinfo ]; then
  echo "error: no private mount namespace in this chroot ('/' is not a mount point), and /proc is not" \
       "mounted to check that its mounts are private: mount /proc in the chroot first" >&2
  exit 1
fi
if grep -q ' shared:' /proc/self/mountinfo; then
  echo "error: no private mount namespace in this chroot ('/' is not a mount point), and some of its" \
       "mounts are shared (our mounts would reach the host): make them private (mount --make-rprivate)" >&2
  exit 1
fi
exec unshare --mount --propagation unchanged "$@"
