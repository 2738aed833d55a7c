#!/bin/bash
# Runs inside the Debian 13 root (scripts/debian13_root.sh run, with TOPSTOC_ROOT_LAYER=test so
# nothing lands in the base root): installs Debian 13's toolchain and the engine's -dev libraries
# if missing, builds the CPython 3.13 module into build-trixie/ (test-only; ccache kept in the
# layer makes later runs cheap), and makes or keeps the bpy 5.2 venv in /opt/venvs.
set -u
source "$(dirname "$0")/common.sh"
BPY_313=${1:?usage: debian13_prepare.sh BPY_VERSION}
export CCACHE_DIR=/var/cache/ccache
# python3-numpy: Debian 13's own Blender 4.3 (GUI suite) runs the system CPython 3.13, and a
# minimal root does not have numpy, which the add-on needs.
ensure_packages cmake make g++ ccache pybind11-dev libopenmesh-dev libtet1.5-dev libphat-dev python3-numpy || exit 1
build build-trixie -DTOPSTOC_PEERS=OFF || exit 1
scripts/bpy_venv.sh "/opt/venvs/bpy-$BPY_313" "$BPY_313" /usr/bin/python3
