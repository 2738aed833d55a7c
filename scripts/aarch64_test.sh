#!/bin/bash
# The Linux aarch64 suite (scripts/test.sh, as root), run on this x86-64 machine under QEMU user
# emulation with the cached arm64 Debian 12 root (scripts/arm64_root.sh):
# 1. the engine's C++ tests and command-line driver cross-built (scripts/cross_build.sh aarch64):
#    the doctest summary, and the driver's files compared with this machine's byte for byte
#    (tests/cross -k aarch64);
# 2. the aarch64 cp311 wheel (dist/ from scripts/build_wheels.sh, or TOPSTOC_AARCH64_WHEEL)
#    installed into a venv in the root: tests/install/wheel_check.py, then the Python API tests
#    in PYTHON_TESTS below, less DESELECT (emulation is 10-30x slower, so not all of
#    tests/python: the engine's guarantees, the prepared mesh, sampling and the file formats, about
#    5 minutes here; test_native_import.py needs a build tree, not an installed wheel).
set -u -o pipefail
source "$(dirname "$0")/common.sh"  # cd to the checkout
PYTHON_TESTS="tests/python/test_mesh.py tests/python/test_io.py tests/python/test_sampling.py
  tests/python/test_guarantees.py"
# Deselected besides the stress pass: the random surfaces past the first 8 manifold and 6 pinched
# seeds (the same code paths again; the native suite runs them all, tests/cross compares files).
DESELECT="--deselect tests/python/test_guarantees.py::test_stress_pass_finds_nothing"
for seed in $(seq 8 39); do DESELECT+=" --deselect 'tests/python/test_guarantees.py::test_random_manifolds_keep_every_guarantee[$seed]'"; done
for seed in $(seq 6 29); do DESELECT+=" --deselect 'tests/python/test_guarantees.py::test_random_pinched_surfaces_keep_every_fan[$seed]'"; done
ROOTFS=$(scripts/arm64_root.sh) || exit 1

scripts/cross_build.sh aarch64 || exit 1
echo "== C++ tests (doctest) under QEMU: build-aarch64/tests/native/topstoc_tests"
# Natively only: the pool's CPU-budget case (under emulation the process CPU clock also counts
# QEMU's own translation and signal work, not the workers' sleeping), and the three long checks of
# the collapses' batches on needle strips and fans (42 of the suite's 52 s natively, about 20
# minutes under QEMU). Those compare runs on one machine (resumed against fresh, one thread
# against two); the driver's files below are compared with this machine's byte for byte.
LONG_NATIVE="workers sleep between calls*,a state kept where a capped run's tail starts*"
LONG_NATIVE+=",a collapse at a fan's centre is checked before*,tied collapses on a flat strip of needles*"
QEMU_LD_PREFIX=$ROOTFS build-aarch64/tests/native/topstoc_tests --test-case-exclude="$LONG_NATIVE" |
  grep -v '^\[doctest\] run with' || exit 1
echo "== the aarch64 driver against this machine's driver (tests/cross)"
/usr/bin/python3 -m pytest -q -p no:cacheprovider tests/cross -k aarch64 || exit 1

WHEEL=${TOPSTOC_AARCH64_WHEEL:-$(ls dist/topstoc-*-cp311-cp311-*aarch64.whl 2>/dev/null | head -1)}
[ -f "$WHEEL" ] || { echo "error: no topstoc cp311 aarch64 wheel in dist/ (scripts/build_wheels.sh)" >&2; exit 1; }
# The root sees only this folder: the wheel and the tests (their meshes included), no build tree.
WORK=build-aarch64/wheel-test
rm -rf "$WORK"; mkdir -p "$WORK"
cp "$WHEEL" "$WORK/"
cp -r tests "$WORK/tests"
echo "== $(basename "$WHEEL") in the arm64 root: install check and $(echo $PYTHON_TESTS | wc -w) test files"
scripts/arm64_root.sh run "$WORK" "
  python3 -m venv --system-site-packages /work/venv &&
  /work/venv/bin/pip install -q --no-index --no-deps /work/$(basename "$WHEEL") &&
  /work/venv/bin/python /work/tests/install/wheel_check.py &&
  TOPSTOC_BUILD=/work/no-build /work/venv/bin/python -m pytest -q -p no:cacheprovider $(echo $PYTHON_TESTS) $DESELECT"
