#!/bin/bash
# Builds the engine for Windows x64 with Debian's mingw-w64 into build-windows/: the C++ tests
# (topstoc_tests.exe, doctest) and the command-line driver (topstoc_decimate.exe), linked
# statically (no DLL to ship), for running under Wine (scripts/windows_test.sh).
#
# TetGen is compiled from Debian's source package and PHAT's headers come from Debian's
# libphat-dev (scripts/fetch_deps.py, cmake/deps); doctest's header and CMake files are the
# host's (doctest-dev: one platform-independent header). They are installed once into
# ${TOPSTOC_CACHE:-/var/cache/topstoc}/mingw-prefix, the only place the cross build looks
# (cmake/toolchains/mingw-w64-x86_64.cmake), and reused until the pins in fetch_deps.py change.
set -eu -o pipefail
source "$(dirname "$0")/common.sh"  # cd to the checkout; ensure_packages
ensure_packages g++-mingw-w64-x86-64-posix wine64 doctest-dev cmake make python3

CACHE=${TOPSTOC_CACHE:-/var/cache/topstoc}
PREFIX=$CACHE/mingw-prefix
TOOLCHAIN=$PWD/cmake/toolchains/mingw-w64-x86_64.cmake
OUT=build-windows
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
mkdir -p "$OUT"

# --- dependencies, once per pin set ------------------------------------------------------------
stamp="$(sha256sum scripts/fetch_deps.py cmake/deps/CMakeLists.txt "$TOOLCHAIN" | sha256sum | cut -c1-16)"
if [ "$(cat "$PREFIX/.stamp" 2>/dev/null)" != "$stamp" ]; then
  echo "== building TetGen for Windows into $PREFIX (once)"
  rm -rf "$PREFIX" "$CACHE/mingw-deps-build"
  python3 scripts/fetch_deps.py "$CACHE/deps-src" >/dev/null
  cmake -S cmake/deps -B "$CACHE/mingw-deps-build" -DCMAKE_TOOLCHAIN_FILE="$TOOLCHAIN" \
    -DTOPSTOC_DEPS_SOURCES="$CACHE/deps-src" -DCMAKE_INSTALL_PREFIX="$PREFIX" "${launcher[@]}" \
    >"$OUT/deps.log" 2>&1 &&
    cmake --build "$CACHE/mingw-deps-build" -j2 >>"$OUT/deps.log" 2>&1 &&
    cmake --install "$CACHE/mingw-deps-build" >>"$OUT/deps.log" 2>&1 ||
    { tail -30 "$OUT/deps.log"; exit 1; }
  mkdir -p "$PREFIX/include" "$PREFIX/lib/cmake"
  cp -r /usr/include/doctest "$PREFIX/include/"
  cp -r /usr/lib/cmake/doctest "$PREFIX/lib/cmake/"
  # Debian's doctestTargets.cmake names /usr outright: point it at the copy.
  sed -i "s|_IMPORT_PREFIX \"/usr\"|_IMPORT_PREFIX \"$PREFIX\"|" "$PREFIX/lib/cmake/doctest/doctestTargets.cmake"
  grep -q "_IMPORT_PREFIX \"$PREFIX\"" "$PREFIX/lib/cmake/doctest/doctestTargets.cmake"
  echo "$stamp" >"$PREFIX/.stamp"
fi

# --- the engine, its tests and the driver ------------------------------------------------------
echo "== building for Windows x64 (mingw-w64) in $OUT"
cmake -S . -B "$OUT" -DCMAKE_TOOLCHAIN_FILE="$TOOLCHAIN" -DCMAKE_FIND_ROOT_PATH="$PREFIX" \
  -DCMAKE_BUILD_TYPE=Release -DTOPSTOC_PYTHON=OFF -DTOPSTOC_PEERS=OFF -DTOPSTOC_TESTS=ON "${launcher[@]}" \
  >"$OUT/configure.log" 2>&1 || { tail -30 "$OUT/configure.log"; exit 1; }
cmake --build "$OUT" -j2 >"$OUT/build.log" 2>&1 || { grep -E -B2 -A8 "error" "$OUT/build.log" | head -80; exit 1; }
ls "$OUT/tests/native/topstoc_tests.exe" "$OUT/topstoc_decimate.exe"
