# Makes a cached Debian root with debootstrap; sourced, not run (scripts/debian13_root.sh,
# scripts/arm64_root.sh, tests/install/minimal_root.sh):
#
#   make_debian_root ROOTFS SUITE ARCH "PACKAGES" LOG
#
# debootstrap --variant=minbase SUITE for ARCH (a foreign ARCH runs under QEMU user emulation:
# call enable_qemu first) into ROOTFS.partial, then PACKAGES (--no-install-recommends), and only
# then the rename to ROOTFS: an interrupted run leaves no half-made root behind. The host's DNS
# settings and local CA certificates are copied in so that apt and pip work inside. Needs root.

ensure_debootstrap() {
  command -v debootstrap >/dev/null ||
    { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -q debootstrap >/dev/null; }
}

make_debian_root() {
  local rootfs=$1 suite=$2 arch=$3 packages=$4 log=$5 tmp=$1.partial
  export PATH=$PATH:/usr/sbin:/sbin  # debootstrap and chroot, whatever PATH the caller had
  ensure_debootstrap || return 1
  rm -rf "$tmp"; mkdir -p "$(dirname "$rootfs")"
  echo "== making a Debian $suite $arch root in $rootfs (once; minutes)" >&2
  debootstrap --variant=minbase --arch="$arch" "$suite" "$tmp" http://deb.debian.org/debian >"$log" 2>&1 ||
    { tail -20 "$log" >&2; return 1; }
  cp /etc/resolv.conf "$tmp/etc/resolv.conf"
  local certificates=true  # nothing to add unless the host has local CA certificates
  if ls /usr/local/share/ca-certificates/*.crt >/dev/null 2>&1; then
    mkdir -p "$tmp/usr/local/share/ca-certificates"
    cp /usr/local/share/ca-certificates/*.crt "$tmp/usr/local/share/ca-certificates/"
    certificates="{ ! command -v update-ca-certificates || update-ca-certificates; }"
  fi
  chroot "$tmp" /bin/bash -c "apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -q \
    --no-install-recommends $packages && apt-get clean && $certificates" >>"$log" 2>&1 ||
    { echo "error: could not install $packages in the $suite $arch root (see $log)" >&2; return 1; }
  mv "$tmp" "$rootfs"
}

# Lets this machine run ARCH (e.g. aarch64) binaries: Debian's qemu-user-static registered with
# binfmt_misc (flag F: the emulator is opened now, so chroots need no copy of it).
enable_qemu() {
  local arch=$1
  export PATH=$PATH:/usr/sbin:/sbin
  command -v update-binfmts >/dev/null && [ -x /usr/bin/qemu-$arch-static ] ||
    { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -q qemu-user-static binfmt-support >/dev/null; } ||
    return 1
  [ -e /proc/sys/fs/binfmt_misc/register ] || mount -t binfmt_misc binfmt_misc /proc/sys/fs/binfmt_misc || return 1
  grep -qx enabled "/proc/sys/fs/binfmt_misc/qemu-$arch" 2>/dev/null || update-binfmts --enable "qemu-$arch" || return 1
  grep -qx enabled "/proc/sys/fs/binfmt_misc/qemu-$arch"
}
