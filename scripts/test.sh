#!/bin/bash
# Runs every test: C++ engine and Python API (plain python3), the add-on inside Debian's
# Blender 3.4, the add-on as an extension in Blender 4.2+ (PyPI's bpy in .venv), and the real
# GUI under Xvfb. Installs what is missing first. Exit code 0 only if every suite passed.
set -o pipefail
source "$(dirname "$0")/common.sh"
ensure_packages $RUNTIME_PACKAGES $TEST_PACKAGES || exit 1
build || exit 1

# A venv on top of the system site packages (numpy, scipy, gudhi, pytest from Debian) that adds
# the peers only PyPI has: bpy 4.2 (Blender 4.2 LTS as a module, CPython 3.11) and pymeshlab.
# numpy stays below 2 (pybind11 2.10 predates numpy 2; Blender 4.2 ships numpy 1.26).
VENV=.venv
if [ ! -x $VENV/bin/python ] || ! $VENV/bin/python -c "import bpy, pymeshlab" 2>/dev/null; then
  echo "== preparing $VENV (bpy 4.2, pymeshlab from PyPI; first run downloads ~600 MB)"
  /usr/bin/python3 -m venv --system-site-packages $VENV &&
    $VENV/bin/pip install -q --disable-pip-version-check "bpy==4.2.*" "pymeshlab==2023.12.post3" "numpy<2" ||
    echo "warning: could not prepare $VENV; suites that need bpy 4.x or pymeshlab will fail" >&2
fi

failed=()
run() {  # run NAME COMMAND...
  local name=$1; shift
  echo "== $name"
  if "$@"; then echo "== $name: passed"; else echo "== $name: FAILED"; failed+=("$name"); fi
}
PYTEST_ARGS=(-q -p no:cacheprovider)
run "engine and Python API (python3 + pymeshlab)" $VENV/bin/python -m pytest "${PYTEST_ARGS[@]}" tests/python
if [ -d tests/blender ]; then
  run "add-on in Blender $(blender -v 2>/dev/null | head -1 | awk '{print $2}')" \
    blender -b --factory-startup --python-exit-code 1 --python-expr \
    "import sys, pytest; sys.exit(pytest.main(['-q', '-p', 'no:cacheprovider', 'tests/blender']))"
  run "add-on as an extension in Blender 4.2 (bpy)" env TOPSTOC_BPY=1 $VENV/bin/python -m pytest "${PYTEST_ARGS[@]}" tests/blender
fi
if [ -d tests/gui ]; then
  run "real Blender GUI under Xvfb" $VENV/bin/python -m pytest "${PYTEST_ARGS[@]}" tests/gui
fi

if [ ${#failed[@]} -gt 0 ]; then
  echo "FAILED: ${failed[*]}"
  exit 1
fi
echo "all test suites passed"
