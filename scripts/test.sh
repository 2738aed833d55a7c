#!/bin/bash
# Runs every test: the C++ engine (tests/native, ctest; and built for Windows, run under Wine), the
# Python API (plain python3 and NumPy 2), the batch on Dask, a short fuzzing pass, the add-on
# inside Debian's Blender 3.4 (legacy add-on) and as an extension in PyPI's bpy 4.2 (.venv), 4.5
# LTS and 5.0 (CPython 3.11) and 5.2 LTS (CPython 3.13, in a Debian 13 root), the real GUI under
# Xvfb in Blender 3.4 and Debian 13's Blender 4.3, and (as root) the release wheels and extension
# installed in bare roots and Linux aarch64 under QEMU. Installs what is missing first; the bpy
# venvs, the pipeline venv, the Wine prefix and the Debian roots are cached outside the checkout
# in ${TOPSTOC_CACHE:-/var/cache/topstoc} (the first run downloads ~4 GB). Runs the suites in two
# lanes at once and prints each suite's wall and CPU time. Exit code 0 only if every suite passed.
set -o pipefail
source "$(dirname "$0")/common.sh"
ensure_packages $RUNTIME_PACKAGES $TEST_PACKAGES || exit 1
build || exit 1

# A venv on top of the system site packages (numpy, scipy, gudhi, pytest from Debian) that adds
# the peers only PyPI has: bpy 4.2 (Blender 4.2 LTS as a module, CPython 3.11) and pymeshlab.
# numpy stays below 2 there (Blender 4.2 ships numpy 1.26); NumPy 2 gets its own venv below.
VENV=.venv
if [ ! -x $VENV/bin/python ] || ! $VENV/bin/python -c "import bpy, pymeshlab" 2>/dev/null; then
  echo "== preparing $VENV (bpy 4.2, pymeshlab from PyPI; first run downloads ~600 MB)"
  /usr/bin/python3 -m venv --system-site-packages $VENV &&
    $VENV/bin/pip install -q --disable-pip-version-check "bpy==4.2.*" "pymeshlab==2023.12.post3" "numpy<2" ||
    echo "warning: could not prepare $VENV; suites that need bpy 4.x or pymeshlab will fail" >&2
fi

# A plain venv with NumPy 2 from PyPI (and a scipy built for it): pip users get NumPy 2 by default,
# and the module is built with Debian's pybind11 2.10, which predates it.
VENV2=.venv-numpy2
if [ ! -x $VENV2/bin/python ] || ! $VENV2/bin/python -c "import numpy, scipy, gudhi, pytest; assert numpy.__version__ >= '2'" 2>/dev/null; then
  echo "== preparing $VENV2 (numpy 2, scipy, gudhi, pytest from PyPI)"
  /usr/bin/python3 -m venv $VENV2 &&
    $VENV2/bin/pip install -q --disable-pip-version-check "numpy>=2,<3" scipy gudhi pytest ||
    echo "warning: could not prepare $VENV2; the NumPy 2 suite will fail" >&2
fi

# The batch at studio scale (tests/pipeline): dask.distributed, tqdm and openjd-cli from PyPI, in a
# venv cached outside the checkout (system site packages: numpy, pytest from Debian).
PIPELINE_VENV=${TOPSTOC_CACHE:-/var/cache/topstoc}/venv-pipeline
if [ ! -x $PIPELINE_VENV/bin/python ] || ! $PIPELINE_VENV/bin/python -c "import distributed, tqdm" 2>/dev/null ||
   [ ! -x $PIPELINE_VENV/bin/openjd ]; then
  echo "== preparing $PIPELINE_VENV (dask, distributed, tqdm, openjd-cli from PyPI)"
  mkdir -p "$(dirname $PIPELINE_VENV)" && /usr/bin/python3 -m venv --system-site-packages $PIPELINE_VENV &&
    $PIPELINE_VENV/bin/pip install -q --disable-pip-version-check dask distributed tqdm openjd-cli ||
    echo "warning: could not prepare $PIPELINE_VENV; the pipeline suite will fail" >&2
fi

# PyPI's bpy versions under test (pinned; the newest of each line when this was written).
BPY_311=(4.5.15 5.0.1)   # Blender 4.5 LTS and 5.0: CPython 3.11, venvs on this host
BPY_313=5.2.3            # Blender 5.2 LTS: CPython 3.13, which Debian 12 lacks: Debian 13 root
CACHE=${TOPSTOC_CACHE:-/var/cache/topstoc}

# Suites run in two lanes at once, as the machine has two cores and most suites use one: the host
# lane (engine, Python API, batch, Blender 3.4) prints as it goes; the other lane (bpy 4.2 and the
# later bpy, both GUIs, the Debian 13 root and the release files) writes to a log printed at the
# end. Both GUIs share a lane (two Xvfb would race for one display), and every user of the Debian
# 13 root is in that lane too (one overlay over the root at a time).
LOGS=$(mktemp -d)
FAILED=$LOGS/failed
: >"$FAILED"
run() {  # run NAME COMMAND...: prints the suite's wall time and the cores it kept busy
  local name=$1 start=$SECONDS cpu; shift
  echo "== $name"
  # A suite that hangs (a Blender that never exits) fails after 40 minutes instead of stalling CI.
  local times=$LOGS/cpu.$BASHPID  # one file per lane
  local verdict=passed
  /usr/bin/time -q -o "$times" -f "%U %S" timeout -k 30 2400 "$@" || { verdict=FAILED; echo "$name" >>"$FAILED"; }
  local wall=$((SECONDS - start))
  cpu=$(awk -v wall=$wall 'END {printf "%.0f s CPU, %.1f cores", $1 + $2, ($1 + $2) / (wall ? wall : 1)}' "$times")
  echo "== $name: $verdict ($wall s, $cpu)" | tee -a "$LOGS/summary"
}
PYTEST_ARGS=(-q -p no:cacheprovider)

host_lane() {
  run "C++ engine (doctest, ctest)" /usr/bin/ctest --test-dir build --output-on-failure
  run "engine and Python API (python3 + pymeshlab)" $VENV/bin/python -m pytest "${PYTEST_ARGS[@]}" tests/python
  # Under NumPy 2 the suite less its long engine checks (marked heavy: peer comparisons, the stress
  # pass, seeds and thread counts), whose arrays cross the API the same way as in the tests kept.
  run "Python API with NumPy 2 (PyPI)" $VENV2/bin/python -m pytest "${PYTEST_ARGS[@]}" -m "not heavy" tests/python
  run "batch on Dask and OpenJD (venv-pipeline)" env PATH="$PIPELINE_VENV/bin:$PATH" \
    $PIPELINE_VENV/bin/python -m pytest "${PYTEST_ARGS[@]}" tests/pipeline
  # Fuzz targets (clang, ASan + UBSan): every kept input once, then 5 s of new inputs per target.
  # Long runs: scripts/fuzz.sh SECONDS. The Python suite under ASan + UBSan: scripts/sanitize.sh.
  run "fuzzing, short pass (scripts/fuzz.sh 5)" scripts/fuzz.sh 5
  # The engine for Windows x64 (mingw-w64, static): its doctest binary under Wine, and its
  # command-line driver's files byte-compared with this build's (scripts/windows_test.sh).
  run "C++ engine under Wine (mingw-w64)" scripts/windows_test.sh
  [ -d tests/blender ] || return 0
  run "add-on in Blender $(blender -v 2>/dev/null | head -1 | awk '{print $2}')" \
    blender -b --factory-startup --python-exit-code 1 --python-expr \
    "import sys, pytest; sys.exit(pytest.main(['-q', '-p', 'no:cacheprovider', 'tests/blender']))"
}

other_lane() {
  [ -d tests/blender ] && bpy_suites
  [ -d tests/gui ] && run "real Blender GUI under Xvfb" $VENV/bin/python -m pytest "${PYTEST_ARGS[@]}" tests/gui
  if [ "$(id -u)" != 0 ]; then
    echo "== skipped: bpy $BPY_313, Blender 4.3, release files and Linux aarch64 (chroot and binfmt_misc need root: run as root)"
    return 0
  fi
  debian13_suites
  release_suites
}

bpy_suites() {
  run "add-on as an extension in Blender 4.2 (bpy)" env TOPSTOC_BPY=1 $VENV/bin/python -m pytest "${PYTEST_ARGS[@]}" tests/blender
  # The later Blenders test the add-on's interface to them: the long engine and shading checks
  # (marked heavy) run in 3.4 and 4.2 only.
  local version venv
  for version in "${BPY_311[@]}"; do
    venv=$CACHE/venvs/bpy-$version
    if scripts/bpy_venv.sh "$venv" "$version" /usr/bin/python3; then
      run "add-on as an extension in Blender $version (bpy)" env TOPSTOC_BPY=1 $venv/bin/python -m pytest "${PYTEST_ARGS[@]}" -m "not heavy" tests/blender
    else
      echo "bpy $version venv" >>"$FAILED"
    fi
  done
}

# Debian 13 root (made once, cached): CPython 3.13 for bpy 5.2 and a real Blender 4.3 for the GUI.
# Toolchain, the cp313 test build (build-trixie/) and the venv go into the root's "test" layer.
debian13_suites() {
  local in_root=(env TOPSTOC_ROOT_LAYER=test scripts/debian13_root.sh run)
  echo "== preparing the Debian 13 root (toolchain, cp313 build, bpy $BPY_313)"
  if ! "${in_root[@]}" "scripts/debian13_prepare.sh $BPY_313"; then
    echo "Debian 13 root" >>"$FAILED"; return 0
  fi
  local python=/opt/venvs/bpy-$BPY_313/bin/python
  [ -d tests/blender ] && run "add-on as an extension in Blender $BPY_313 (bpy, CPython 3.13, Debian 13 root)" \
    "${in_root[@]}" "TOPSTOC_BPY=1 TOPSTOC_BUILD=/opt/project/build-trixie $python -m pytest ${PYTEST_ARGS[*]} -m 'not heavy' tests/blender"
  [ -d tests/gui ] && run "real Blender 4.3 GUI under Xvfb (Debian 13 root)" \
    "${in_root[@]}" "TOPSTOC_BLENDER=/usr/bin/blender TOPSTOC_BUILD=/opt/project/build-trixie $python -m pytest ${PYTEST_ARGS[*]} tests/gui"
  return 0
}

# The release files as users get them (the roots are entered with chroot): the wheels (x86-64 and
# arm64, zig) and the extension zips are built (scripts/build_wheels.sh, build_extension.sh),
# checked (tags, symbol versions) and installed in cached minimal Debian 12/13 roots without the
# build's libraries and in Debian 13's Blender 4.3. Then the macOS link check, then Linux aarch64
# under QEMU user emulation in a cached arm64 Debian 12 root: the cross-built C++ tests and driver,
# then the aarch64 wheel from dist/ and part of tests/python (scripts/aarch64_test.sh).
release_suites() {
  run "release wheels and extension zips" bash -c "scripts/build_wheels.sh && scripts/build_extension.sh"
  run "install tests (wheel checks, bare Debian roots, Blender 4.3 extension, Blender 3.4 legacy zip)" \
    /usr/bin/python3 -m pytest "${PYTEST_ARGS[@]}" tests/install
  run "macOS arm64 and x86_64 module link (zig, scripts/build_macos.sh)" \
    bash -c "scripts/build_macos.sh && /usr/bin/python3 -m pytest ${PYTEST_ARGS[*]} tests/cross -k 'not windows and not aarch64'"
  run "Python API on Linux aarch64 under QEMU" scripts/aarch64_test.sh
}

other_lane >"$LOGS/other.log" 2>&1 &
other=$!
trap 'kill 0' INT TERM  # an interrupted run stops both lanes
host_lane
echo "== waiting for the other lane (bpy 4.2-5.0, GUIs, Debian 13 root, release files)"
wait $other
echo "== the other lane's output"
cat "$LOGS/other.log"
echo "== every suite"
cat "$LOGS/summary"
if [ -s "$FAILED" ]; then
  echo "FAILED: $(paste -sd, "$FAILED")"
  exit 1
fi
echo "all test suites passed"
