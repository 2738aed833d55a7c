#!/bin/bash
# Builds the engine and the Python module with AddressSanitizer + UndefinedBehaviorSanitizer
# (gcc, -DTOPSTOC_SANITIZE=ON, in build-asan/) and runs the Python test suite against it.
# Python itself is not instrumented, so the ASan runtime is preloaded. Leak detection is off:
# CPython keeps its objects alive until exit by design. Any ASan or UBSan report stops the run.
#
#   scripts/sanitize.sh [PYTEST ARGS...]      default: tests/python
# Suppressions (third-party code only, named): tests/sanitizers/{asan,ubsan}.supp.
set -o pipefail
source "$(dirname "$0")/common.sh"
ensure_packages $RUNTIME_PACKAGES $TEST_PACKAGES || exit 1
BUILD=${TOPSTOC_ASAN_BUILD:-build-asan}
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
mkdir -p "$BUILD"
echo "== building $BUILD (ASan + UBSan)"
/usr/bin/cmake -S . -B "$BUILD" -DTOPSTOC_SANITIZE=ON -DTOPSTOC_PEERS=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "${launcher[@]}" >"$BUILD/configure.log" 2>&1 || { cat "$BUILD/configure.log"; exit 1; }
/usr/bin/cmake --build "$BUILD" -j"$(nproc)" >"$BUILD/build.log" 2>&1 ||
  { grep -E -B2 -A6 "error" "$BUILD/build.log" | head -60; exit 1; }

ASAN_RUNTIME=$(g++ -print-file-name=libasan.so)
export LD_PRELOAD=$ASAN_RUNTIME
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1:halt_on_error=1:suppressions=$ROOT/tests/sanitizers/asan.supp
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1:suppressions=$ROOT/tests/sanitizers/ubsan.supp
export TOPSTOC_BUILD=$ROOT/$BUILD PYTHONPATH=$ROOT/$BUILD/python  # conftest.py and subprocesses
[ $# -eq 0 ] && set -- tests/python
echo "== tests under ASan + UBSan: $*"
/usr/bin/python3 -m pytest -q -p no:cacheprovider "$@"
