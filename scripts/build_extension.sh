#!/bin/bash
# Packs the Blender extension (Blender 4.2+) with a real Blender's own tools, one zip per platform
# (blender --command extension build --split-platforms):
#   dist/topstoc-VERSION-linux_x64.zip, dist/topstoc-VERSION-linux_arm64.zip
# Each holds the add-on package without a binary plus its platform's wheels/topstoc_native-*.whl
# (CPython 3.11 and 3.13, from scripts/build_wheels.sh); Blender installs the wheel matching its
# Python and the add-on imports topstoc_native._topstoc (addon/core/support/native.py). The
# Blender is Debian 13's 4.3 in the cached root (scripts/debian13_root.sh), run through
# scripts/in_root.sh.
set -eu -o pipefail
cd "$(dirname "$0")/.."
ls dist/topstoc_native-*-cp311-*.whl dist/topstoc_native-*-cp313-*.whl >/dev/null 2>&1 || scripts/build_wheels.sh

# The wheels the manifest names must be exactly the ones built.
listed=$(sed -n 's|.*"\./wheels/\([^"]*\.whl\)".*|\1|p' blender_manifest.toml | sort)
built=$(cd dist && ls topstoc_native-*.whl | sort)
[ "$listed" = "$built" ] || { echo "error: blender_manifest.toml lists\n$listed\nbut dist/ holds\n$built" >&2; exit 1; }

STAGE=build/extension/topstoc
rm -rf build/extension; mkdir -p "$STAGE/wheels" build/extension/out
cp -r addon/. "$STAGE/"
find "$STAGE" -name __pycache__ -prune -exec rm -rf {} + ; rm -f "$STAGE"/_topstoc*.so
cp blender_manifest.toml "$STAGE/"
cp dist/topstoc_native-*.whl "$STAGE/wheels/"

TRIXIE=$(scripts/debian13_root.sh)
scripts/in_root.sh "$TRIXIE" "$PWD" "
  blender --version | head -1 &&
  blender --factory-startup --command extension validate build/extension/topstoc &&
  blender --factory-startup --command extension build --split-platforms \
    --source-dir build/extension/topstoc --output-dir build/extension/out &&
  for zip in build/extension/out/*.zip; do blender --factory-startup --command extension validate \$zip; done &&
  for zip in build/extension/out/*.zip; do echo \$zip; python3 -m zipfile -l \$zip | grep '\.whl'; done"
ls build/extension/out/*-linux_x64.zip build/extension/out/*-linux_arm64.zip >/dev/null
cp build/extension/out/*.zip dist/
ls -la dist/*.zip
