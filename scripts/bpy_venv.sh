#!/bin/bash
# Makes (or keeps) a venv holding PyPI's bpy (Blender as a Python module) for the add-on suites:
#
#   scripts/bpy_venv.sh DIR VERSION PYTHON
#
# DIR is reused when healthy (bpy VERSION, numpy, scipy and pytest import); otherwise it is made
# again from scratch with PYTHON (first run downloads ~400 MB). Only what the suites need beyond
# bpy's own dependencies is added: pytest, and scipy (tests/reference.py). Runs on the host
# (CPython 3.11: bpy 4.x, 5.0) and inside the Debian 13 root (CPython 3.13: bpy 5.1+).
set -u
dir=$1 version=$2 python=$3
healthy() {
  "$1/bin/python" -c "import bpy, numpy, scipy, pytest, sys
sys.exit(bpy.app.version_string.split()[0] != '$version')" >/dev/null 2>&1
}
healthy "$dir" && exit 0
echo "== preparing $dir (bpy $version from PyPI)"
rm -rf "$dir" "$dir.partial"
mkdir -p "$(dirname "$dir")"
"$python" -m venv "$dir.partial" &&
  "$dir.partial/bin/python" -m pip install -q --disable-pip-version-check "bpy==$version" pytest scipy &&
  healthy "$dir.partial" && mv "$dir.partial" "$dir" ||
  { echo "error: could not prepare $dir (bpy $version)" >&2; rm -rf "$dir.partial"; exit 1; }
