#!/bin/bash
# The main job: decimate a bundled real mesh (the CGAL Chinese dragon, 20k triangles) inside
# Blender in background mode with TopStoc's Guided Decimate operator (head painted for more
# detail); writes out/demo/ (a .blend with both objects, the decimated .obj, a PNG render of
# both) and prints a one-line summary.
set -eo pipefail
source "$(dirname "$0")/common.sh"
ensure_packages $RUNTIME_PACKAGES
build
mkdir -p out/demo
log=out/demo/blender.log
if ! blender -b --factory-startup --python-exit-code 1 --python scripts/demo_blender.py -- \
    --input tests/data/genus0/cgal_ChineseDragon-10kv.off --ratio 0.05 --output out/demo >"$log" 2>&1; then
  echo "error: the demo failed in Blender; its output is in $log:" >&2
  grep -E "Error|error|Traceback" -A3 "$log" | head -30 >&2
  exit 1
fi
cat out/demo/summary.txt
