#!/bin/bash
# Builds the engine and the Python module with AddressSanitizer + UndefinedBehaviorSanitizer
# (gcc, -DTOPSTOC_SANITIZE=ON, in build-asan/) and runs the Python test suite against it.
# Python itself is not instrumented, so the ASan runtime is preloaded. Leak detection is off:
# CPython keeps its objects alive until exit by design. Any ASan or UBSan report stops the run
# (a report in a test's subprocess fails that test) and fails the script. The whole tests/python
# takes about an hour on the shared 2-core machine (docs/robustness.md); pass test files to run
# fewer.
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

# The ASan runtime must come first; libstdc++ is preloaded too, because python3 does not link it:
# loaded later (with the module), ASan's __cxa_throw interceptor finds no real function and the
# first C++ exception aborts ("CHECK failed: asan_interceptors.cpp ... real___cxa_throw").
export LD_PRELOAD="$(g++ -print-file-name=libasan.so) $(g++ -print-file-name=libstdc++.so)"
# Sanitizer reports are written to file descriptor 2, which pytest's default capture would keep
# (and lose, when the report ends the process): --capture=sys leaves fd 2 to the terminal, and
# the whole output is kept in $BUILD/sanitize.log.
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1:halt_on_error=1:suppressions=$ROOT/tests/sanitizers/asan.supp
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1:suppressions=$ROOT/tests/sanitizers/ubsan.supp
export TOPSTOC_BUILD=$ROOT/$BUILD PYTHONPATH=$ROOT/$BUILD/python  # conftest.py and subprocesses
[ $# -eq 0 ] && set -- tests/python
LOG=$ROOT/$BUILD/sanitize.log
echo "== tests under ASan + UBSan: $* (load: $(cut -d' ' -f1-3 /proc/loadavg); output also in $LOG)"
start=$(date +%s)
/usr/bin/python3 -m pytest -q -p no:cacheprovider --capture=sys "$@" 2>&1 | tee "$LOG"
status=$?
echo "== exit status $status after $(( $(date +%s) - start )) s (load: $(cut -d' ' -f1-3 /proc/loadavg))" | tee -a "$LOG"
if grep -qE "ERROR: AddressSanitizer|runtime error:|AddressSanitizer: CHECK failed" "$LOG"; then
  echo "== sanitizer report(s) above (grep 'runtime error\|AddressSanitizer' $LOG)"
  exit 1
fi
exit $status
