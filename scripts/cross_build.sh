#!/bin/bash
# Builds the engine's C++ tests (doctest) and the command-line driver for another platform with a
# Debian cross compiler, to run them where this machine can (scripts/windows_test.sh,
# scripts/aarch64_test.sh):
#
#   scripts/cross_build.sh windows   mingw-w64, static .exe files (no DLL to ship): build-windows/
#   scripts/cross_build.sh aarch64   g++-aarch64-linux-gnu (Debian 12's glibc): build-aarch64/
#
# TetGen is compiled from Debian's source package and PHAT's headers come from Debian's
# libphat-dev (scripts/fetch_deps.py, cmake/deps); doctest's header and CMake files are the
# host's (doctest-dev: one platform-independent header). They are installed once per target into
# ${TOPSTOC_CACHE:-/var/cache/topstoc}/TARGET-prefix, the only place the cross build looks
# (cmake/toolchains/), and reused until the pins in fetch_deps.py or the toolchain change.
set -eu -o pipefail
source "$(dirname "$0")/common.sh"  # cd to the checkout; ensure_packages
TARGET=${1:?usage: cross_build.sh windows|aarch64}
case $TARGET in
  windows) ensure_packages g++-mingw-w64-x86-64-posix wine64 doctest-dev cmake make python3
           TOOLCHAIN=$PWD/cmake/toolchains/mingw-w64-x86_64.cmake; EXE=.exe ;;
  aarch64) ensure_packages g++-aarch64-linux-gnu doctest-dev cmake make python3
           TOOLCHAIN=$PWD/cmake/toolchains/aarch64-linux-gnu.cmake; EXE= ;;
  *) echo "error: unknown target '$TARGET' (windows or aarch64)" >&2; exit 2 ;;
esac
CACHE=${TOPSTOC_CACHE:-/var/cache/topstoc}
PREFIX=$CACHE/$TARGET-prefix
OUT=build-$TARGET
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
mkdir -p "$OUT"

# --- dependencies, once per pin set ------------------------------------------------------------
stamp="$(sha256sum scripts/fetch_deps.py cmake/deps/CMakeLists.txt "$TOOLCHAIN" | sha256sum | cut -c1-16)"
if [ "$(cat "$PREFIX/.stamp" 2>/dev/null)" != "$stamp" ]; then
  echo "== building TetGen for $TARGET into $PREFIX (once)"
  rm -rf "$PREFIX" "$CACHE/$TARGET-deps-build"
  python3 scripts/fetch_deps.py "$CACHE/deps-src" >/dev/null
  cmake -S cmake/deps -B "$CACHE/$TARGET-deps-build" -DCMAKE_TOOLCHAIN_FILE="$TOOLCHAIN" \
    -DTOPSTOC_DEPS_SOURCES="$CACHE/deps-src" -DCMAKE_INSTALL_PREFIX="$PREFIX" "${launcher[@]}" \
    >"$OUT/deps.log" 2>&1 &&
    cmake --build "$CACHE/$TARGET-deps-build" -j2 >>"$OUT/deps.log" 2>&1 &&
    cmake --install "$CACHE/$TARGET-deps-build" >>"$OUT/deps.log" 2>&1 ||
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
echo "== building for $TARGET in $OUT"
cmake -S . -B "$OUT" -DCMAKE_TOOLCHAIN_FILE="$TOOLCHAIN" -DCMAKE_FIND_ROOT_PATH="$PREFIX" \
  -DCMAKE_BUILD_TYPE=Release -DTOPSTOC_PYTHON=OFF -DTOPSTOC_PEERS=OFF -DTOPSTOC_TESTS=ON "${launcher[@]}" \
  >"$OUT/configure.log" 2>&1 || { tail -30 "$OUT/configure.log"; exit 1; }
cmake --build "$OUT" -j2 >"$OUT/build.log" 2>&1 || { grep -E -B2 -A8 "error" "$OUT/build.log" | head -80; exit 1; }
ls "$OUT/tests/native/topstoc_tests$EXE" "$OUT/topstoc_decimate$EXE"
