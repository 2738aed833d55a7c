#!/bin/bash
# Makes every file a user downloads, in dist/, on a Debian 12 machine (run as root; a user with
# sudo is re-run under sudo, since the Debian 13 root needs debootstrap and chroot):
#   topstoc-VERSION-cp311-cp311-manylinux_2_28_{x86_64,aarch64}.whl, ...-cp313-...  pip (scripts/build_wheels.sh)
#   topstoc_native-VERSION-cp3XX-...whl                         the extension's engine wheels
#   topstoc-VERSION-linux_{x64,arm64}.zip                       Blender 4.2+ (scripts/build_extension.sh)
#   topstoc-VERSION-legacy-addon.zip                            Blender 3.4-4.1 with CPython 3.11
# The legacy zip holds the engine built on this machine (it needs this system's TetGen).
set -eu -o pipefail
cd "$(dirname "$0")/.."
if [ "$(id -u)" != 0 ]; then
  command -v sudo >/dev/null || { echo "error: scripts/release.sh needs root or sudo" >&2; exit 1; }
  exec sudo --preserve-env=TOPSTOC_CACHE,SOURCE_DATE_EPOCH "$0" "$@"
fi
VERSION=$(sed -n 's/^version = "\(.*\)"/\1/p' pyproject.toml | head -1)

scripts/build_wheels.sh      # empties dist/, then writes the eight wheels
scripts/build_extension.sh   # packs the extension zip with Blender 4.3's own tools

source scripts/common.sh     # ensure_packages, build (the engine for this machine's CPython 3.11)
ensure_packages g++ cmake make pybind11-dev libopenmesh-dev libtet1.5-dev libphat-dev python3-dev python3-numpy
build
/usr/bin/cmake --build build --target addon_zip >/dev/null
cp build/dist/topstoc-addon.zip "dist/topstoc-$VERSION-legacy-addon.zip"

echo "== dist/"
ls -l dist/
