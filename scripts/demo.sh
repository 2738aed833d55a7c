#!/bin/bash
# The main job: decimate a bundled real mesh (the CGAL Chinese dragon, 20k triangles) inside
# Blender in background mode with TopStoc's one-click operator; writes out/demo/ (a .blend
# with both objects, the decimated .obj, and a PNG render of both) and prints one line.
set -eo pipefail
source "$(dirname "$0")/common.sh"
ensure_packages $RUNTIME_PACKAGES
build
mkdir -p out/demo
blender -b --factory-startup --python-exit-code 1 --python scripts/demo_blender.py -- \
  --input tests/data/genus0/cgal_ChineseDragon-10kv.off --ratio 0.05 --output out/demo 2>&1 |
  grep -E "^(TopStoc|Error|error|Traceback)|Error:" || true
test -f out/demo/summary.txt && cat out/demo/summary.txt
