#!/bin/bash
# The Windows x64 suite (scripts/test.sh): builds the engine, its C++ tests and the command-line
# driver with mingw-w64 (scripts/cross_build.sh windows), runs the doctest binary under Wine and
# compares the Windows driver's output with the Linux build's, byte for byte (tests/cross).
# Needs the Linux build (build/, scripts/common.sh's build) for the comparison.
set -u -o pipefail
source "$(dirname "$0")/common.sh"  # cd to the checkout
scripts/cross_build.sh windows || exit 1
export WINEPREFIX=${TOPSTOC_CACHE:-/var/cache/topstoc}/wine-prefix WINEDEBUG=-all
echo "== C++ tests (doctest) under Wine: build-windows/tests/native/topstoc_tests.exe"
# A time limit, so that a hang fails the suite instead of stalling it.
timeout 600 /usr/lib/wine/wine64 build-windows/tests/native/topstoc_tests.exe | tr -d '\r' |
  grep -v '^\[doctest\] run with' || exit 1
echo "== the Windows driver against the Linux driver (tests/cross)"
/usr/bin/python3 -m pytest -q -p no:cacheprovider tests/cross -k windows
