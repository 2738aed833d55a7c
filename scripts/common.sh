# Shared by scripts/demo.sh and scripts/test.sh: install what is missing, build, find tools.
# Sourced, not run. Works as root or with sudo on Debian 12.

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$ROOT"
# ccache keys paths inside the checkout relative to it, so a fresh clone anywhere reuses the
# compiles of earlier ones; its files live with the test caches (the engine is built about ten
# times per test run: host, Windows, fuzzing, wheels, macOS, aarch64).
export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$ROOT}
if [ -z "${CCACHE_DIR:-}" ]; then  # ccache's own default where the cache folder is not writable
  _ccache_dir=${TOPSTOC_CACHE:-/var/cache/topstoc}/ccache
  mkdir -p "$_ccache_dir" 2>/dev/null && [ -w "$_ccache_dir" ] && export CCACHE_DIR=$_ccache_dir
  unset _ccache_dir
fi

# Debian packages: the build and runtime, then peers and tools used by tests and benchmarks.
RUNTIME_PACKAGES="blender cmake g++ make pybind11-dev libopenmesh-dev libtet1.5-dev libphat-dev
  python3 python3-dev python3-numpy python3-pytest"
TEST_PACKAGES="libmeshoptimizer-dev libcgal-dev python3-gudhi python3-scipy python3-venv xvfb
  xauth git ca-certificates doctest-dev ccache time"

as_root() {
  if [ "$(id -u)" = 0 ]; then "$@";
  elif command -v sudo >/dev/null; then sudo "$@";
  else echo "error: need root or sudo to run: $*" >&2; return 1; fi
}

# Installs the given Debian packages that are not installed yet.
ensure_packages() {
  local missing=()
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "== installing Debian packages: ${missing[*]}"
  as_root env DEBIAN_FRONTEND=noninteractive apt-get update -q >/dev/null &&
    as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}" >/dev/null
}

# Builds the module against /usr/bin/python3 and stages DIR/python/topstoc: build [DIR [CMAKE_ARGS...]]
# (DIR defaults to build; the Debian 13 root builds its CPython 3.13 module into build-trixie).
build() {
  local dir=${1:-build}; [ $# -gt 0 ] && shift
  echo "== building (cmake -S . -B $dir && cmake --build $dir)"
  mkdir -p "$dir"
  local launcher=()  # ccache, when installed, makes rebuilds in other clones cheap
  command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  /usr/bin/cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" "$@" >"$dir/configure.log" 2>&1 ||
    { cat "$dir/configure.log"; return 1; }
  /usr/bin/cmake --build "$dir" -j"$(nproc)" >"$dir/build.log" 2>&1 ||
    { grep -E -B2 -A6 "error" "$dir/build.log" | head -60; return 1; }
  test -f "$dir/python/topstoc/__init__.py" && ls "$dir"/python/topstoc/_topstoc*.so >/dev/null
}
