#!/bin/bash
# Compiles and links the engine's Python module for macOS arm64 and x86_64 with zig's clang and
# libc++ (a link check: nothing here runs macOS). The module is a Mach-O dynamic library (a bundle
# would be usual, but zig 0.15's linker crashes on -bundle: cmake/zig_macos_rules.cmake) whose
# CPython symbols stay undefined (`-undefined dynamic_lookup`, added by pybind11 on macOS, as every
# macOS extension module links), so no Python framework is needed at link time. Prints each
# link step's command and output; the bundles land in build/macos-ARCH/ and tests/cross checks them.
#
#   scripts/build_macos.sh [ARCH...]    aarch64 and x86_64 unless given
#
# CPython's headers: Debian's libpython3.11-dev of the same CPU (no macOS pyconfig.h is reachable
# here): enough for a compile and link check, not for a shipped wheel (the cibuildwheel workflow's).
set -eu -o pipefail
source "$(dirname "$0")/common.sh"  # cd to the checkout; ensure_packages
ensure_packages cmake make python3
VENV=${TOPSTOC_CACHE:-/var/cache/topstoc}/wheel-venv
export PATH=/usr/bin:/bin:$PATH  # Debian's cmake, as scripts/build_wheels.sh uses
"$VENV/bin/python" -c "import ziglang, pybind11" 2>/dev/null ||
  { echo "error: no ziglang/pybind11 in $VENV: run scripts/build_wheels.sh first" >&2; exit 1; }
ZIG=$("$VENV/bin/python" -c "import ziglang, os; print(os.path.join(os.path.dirname(ziglang.__file__), 'zig'))")
source scripts/zig_toolchain.sh

ARCHS=("$@"); [ $# -gt 0 ] || ARCHS=(aarch64 x86_64)
for arch in "${ARCHS[@]}"; do
  dir=build/macos-$arch debian_arch=amd64
  [ "$arch" = aarch64 ] && debian_arch=arm64  # the pyconfig.h of the same CPU (sizes, alignment)
  zig_cmake_args "$arch-macos.11.0"
  echo "== macOS $arch: zig c++ -target $arch-macos.11.0 -O0"
  # -O0: nothing built here runs, and an unoptimised build compiles every source and links every
  # reference (none inlined away) for about two thirds of -O3's compile time.
  cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS_RELEASE="-O0 -DNDEBUG" "${ZIG_CMAKE_ARGS[@]}" \
    -DCMAKE_USER_MAKE_RULES_OVERRIDE="$PWD/cmake/zig_macos_rules.cmake" \
    -DTOPSTOC_PYTHON_HEADERS_ONLY=ON -DPython_INCLUDE_DIR="$(python_include 3.11 $debian_arch)" \
    -DPYTHON_IS_DEBUG=OFF -DPYTHON_MODULE_DEBUG_POSTFIX= -DPYTHON_MODULE_EXTENSION=.cpython-311-darwin.so \
    -Dpybind11_DIR="$("$VENV/bin/python" -m pybind11 --cmakedir)" >"$dir.log" 2>&1 ||
    { tail -40 "$dir.log"; exit 1; }
  cmake --build "$dir" --target _topstoc -j2 >>"$dir.log" 2>&1 || { tail -40 "$dir.log"; exit 1; }
  # The link step again, verbosely: its command line and whatever the linker says.
  rm -f "$dir"/python/topstoc/_topstoc*.so
  cmake --build "$dir" --target _topstoc -- VERBOSE=1 2>&1 | grep -A20 -E "Linking CXX|c\+\+ .*-o python/topstoc" |
    grep -v "^gmake\|^\[" | sed 's/^/   /'
  ls -l "$dir"/python/topstoc/_topstoc*.so
done
