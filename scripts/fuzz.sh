#!/bin/bash
# Builds the libFuzzer targets (tests/fuzz, clang, ASan + UBSan) and runs each for SECONDS
# (default 10): first every kept input (tests/fuzz/seeds and tests/fuzz/regressions) once,
# then new inputs. A crash, sanitizer report or failed check is saved as
# tests/fuzz/regressions/<target>/crash-<sha1> (commit it with the fix) and fails the script.
# The growing corpus is cached outside the checkout (${TOPSTOC_CACHE:-/var/cache/topstoc}/fuzz).
#
#   scripts/fuzz.sh [SECONDS] [TARGET...]     e.g. scripts/fuzz.sh 600 fuzz_read_ply
# Targets: fuzz_read_obj fuzz_read_ply fuzz_read_off fuzz_read_stl (reader, then writer ->
# reader round trip), fuzz_round_trip (any reader, then each other format's writer -> reader;
# the first byte picks the reader) and fuzz_decimate (Mesh + decimate on arbitrary arrays). One core.
set -o pipefail
source "$(dirname "$0")/common.sh"
SECONDS_EACH=${1:-10}
shift || true
TARGETS=("$@")
[ ${#TARGETS[@]} -eq 0 ] && TARGETS=(fuzz_read_obj fuzz_read_ply fuzz_read_off fuzz_read_stl fuzz_round_trip fuzz_decimate)
ensure_packages $RUNTIME_PACKAGES clang-14 libclang-rt-14-dev || exit 1

BUILD=${TOPSTOC_FUZZ_BUILD:-build-fuzz}
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
mkdir -p "$BUILD"
echo "== building fuzz targets in $BUILD (clang-14, ASan + UBSan)"
CC=clang-14 CXX=clang++-14 /usr/bin/cmake -S . -B "$BUILD" -DTOPSTOC_FUZZ=ON -DTOPSTOC_PEERS=OFF \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" >"$BUILD/configure.log" 2>&1 ||
  { cat "$BUILD/configure.log"; exit 1; }
/usr/bin/cmake --build "$BUILD" --target "${TARGETS[@]}" -j"$(nproc)" >"$BUILD/build.log" 2>&1 ||
  { grep -E -B2 -A6 "error" "$BUILD/build.log" | head -60; exit 1; }

CORPUS_ROOT=${TOPSTOC_CACHE:-/var/cache/topstoc}/fuzz
# Sanitizer reports abort the run; leak checks off (the readers own no global state, and
# libFuzzer's own leak detection needs ptrace, which containers often forbid).
export ASAN_OPTIONS=${ASAN_OPTIONS:-abort_on_error=1:detect_leaks=0:allocator_may_return_null=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export TOPSTOC_NUM_THREADS=1
failed=()
total=0
for target in "${TARGETS[@]}"; do
  name=${target#fuzz_}; name=${name#read_}
  seeds=tests/fuzz/seeds/$name; regressions=tests/fuzz/regressions/$name
  corpus=$CORPUS_ROOT/$target
  mkdir -p "$corpus" "$regressions" "$seeds"
  log=$BUILD/$target.log
  # Every kept input once (a regression that crashes again fails here, by name).
  if ! "$BUILD/fuzz/$target" -runs=0 "$regressions" "$seeds" >"$log.replay" 2>&1; then
    echo "== $target: a kept input fails again:"; grep -E "ERROR|SUMMARY|fuzz check|Running:" "$log.replay" | tail -5
    failed+=("$target"); continue
  fi
  "$BUILD/fuzz/$target" -max_total_time="$SECONDS_EACH" -timeout=20 -rss_limit_mb=2560 -max_len=8192 \
    -print_final_stats=1 -artifact_prefix="$regressions/" "$corpus" "$seeds" "$regressions" >"$log" 2>&1
  status=$?
  runs=$(grep -E "^stat::number_of_executed_units" "$log" | awk '{print $2}')
  total=$((total + ${runs:-0}))
  if [ $status -ne 0 ]; then
    echo "== $target: FAILED after ${runs:-?} executions:"
    grep -E "ERROR|SUMMARY|fuzz check|written|Test unit written" "$log" | head -8
    failed+=("$target")
  else
    echo "== $target: ${runs:-?} executions in ${SECONDS_EACH} s, no crash"
  fi
done
echo "== fuzzing: $total executions in total"
[ ${#failed[@]} -eq 0 ] || { echo "FAILED: ${failed[*]} (inputs kept in tests/fuzz/regressions)"; exit 1; }
