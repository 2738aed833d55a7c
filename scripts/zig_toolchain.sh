# Cross builds with zig (PyPI's `ziglang`, pinned in scripts/build_wheels.sh's venv): the
# compilers and CPython's headers for a target, cached under ${TOPSTOC_CACHE:-/var/cache/topstoc}/cross
# so a warm run downloads and builds nothing twice. TetGen's sources and PHAT's headers come from
# scripts/fetch_deps.py (pinned SHA-256s), as for the cross builds and cibuildwheel.
# Sourced from the checkout, not run; needs ZIG (the zig binary). Used by scripts/build_wheels.sh
# and scripts/build_macos.sh.
#
#   zig_cmake_args TARGET   CMake arguments (array ZIG_CMAKE_ARGS) for a zig target such as
#                           x86_64-linux-gnu.2.28, aarch64-linux-gnu.2.28, aarch64-macos
#                           (TetGen compiled into the module, PHAT's headers)
#   python_include VER ARCH the folder holding pythonVER/ for Debian ARCH (amd64, arm64)

CROSS=${TOPSTOC_CACHE:-/var/cache/topstoc}/cross
DEPS=${TOPSTOC_CACHE:-/var/cache/topstoc}/deps-src  # scripts/fetch_deps.py's folder, shared with cross_build.sh
export ZIG_GLOBAL_CACHE_DIR=$CROSS/zig-cache  # zig's own libc++ and libc stubs, built once per target

zig_cmake_args() {
  local target=$1 dir=$CROSS/bin/$1 system processor
  mkdir -p "$dir"
  # One wrapper per tool: CMake and ccache take a compiler as a single executable. -mcpu=baseline:
  # the oldest CPU of the architecture, as Debian's own builds. -ffp-contract=off: no fused
  # multiply-add (aarch64 has it), so results equal x86-64's and TetGen's exact predicates stay exact.
  for tool in cc c++; do
    printf '#!/bin/sh\nexec "%s" %s -target %s -mcpu=baseline -ffp-contract=off "$@"\n' "$ZIG" "$tool" "$target" >"$dir/$tool.new"
  done
  for tool in ar ranlib; do printf '#!/bin/sh\nexec "%s" %s "$@"\n' "$ZIG" "$tool" >"$dir/$tool.new"; done
  for tool in cc c++ ar ranlib; do  # rewritten only when changed: ccache keys on the wrapper's mtime
    cmp -s "$dir/$tool.new" "$dir/$tool" && rm "$dir/$tool.new" || mv "$dir/$tool.new" "$dir/$tool"
    chmod +x "$dir/$tool"
  done
  python3 scripts/fetch_deps.py "$DEPS" >/dev/null || return 1
  case $target in *-macos*) system=Darwin ;; *-windows*) system=Windows ;; *) system=Linux ;; esac
  processor=${target%%-*}
  ZIG_CMAKE_ARGS=(-DCMAKE_SYSTEM_NAME=$system -DCMAKE_SYSTEM_PROCESSOR=$processor
    -DCMAKE_C_COMPILER="$dir/cc" -DCMAKE_CXX_COMPILER="$dir/c++"
    -DCMAKE_AR="$dir/ar" -DCMAKE_RANLIB="$dir/ranlib"
    # Nothing of the host's libraries or headers: every dependency is given by path.
    -DCMAKE_FIND_ROOT_PATH="$CROSS/none" -DCMAKE_FIND_ROOT_PATH_MODE_INCLUDE=ONLY
    -DCMAKE_FIND_ROOT_PATH_MODE_LIBRARY=ONLY -DCMAKE_FIND_ROOT_PATH_MODE_PACKAGE=ONLY
    -DTOPSTOC_TESTS=OFF -DTOPSTOC_PEERS=OFF -DTOPSTOC_TETGEN_SOURCE="$DEPS/tetgen" -DPHAT_INCLUDE_DIR="$DEPS/phat/include")
  command -v ccache >/dev/null && ZIG_CMAKE_ARGS+=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  return 0
}

# CPython's headers for a Debian architecture: libpythonVER-dev of Debian 12 (3.11) or 13
# (3.13), fetched by apt with a private state folder (arm64 needs no change to the host's dpkg).
# The headers are the same on every architecture except pyconfig.h, which Debian keeps in a
# multiarch folder: it is copied over the dispatching pyconfig.h.
python_include() {
  local version=$1 arch=$2 suite out=$CROSS/python/$1-$2 apt=$CROSS/apt
  [ "$version" = 3.11 ] && suite=bookworm || suite=trixie
  if [ ! -f "$out/include/python$version/Python.h" ]; then
    echo "== fetching libpython$version-dev:$arch from Debian $suite into $out" >&2
    mkdir -p "$apt/lists/partial" "$apt/cache/archives/partial" "$apt/debs"
    touch "$apt/status"
    printf 'deb [arch=amd64,arm64] http://deb.debian.org/debian %s main\n' bookworm trixie >"$apt/sources.list"
    local opts=(-o Dir::Etc::SourceList="$apt/sources.list" -o Dir::Etc::SourceParts=/nonexistent
      -o Dir::State::Lists="$apt/lists" -o Dir::Cache="$apt/cache" -o Dir::State::status="$apt/status"
      -o APT::Architectures::=arm64 -o Debug::NoLocking=1 -o APT::Sandbox::User=root -q)
    [ -n "$(ls "$apt/lists"/*trixie*arm64*Packages* 2>/dev/null)" ] || apt-get "${opts[@]}" update >/dev/null || return 1
    (cd "$apt/debs" && apt-get "${opts[@]}" download "libpython$version-dev:$arch/$suite" >/dev/null) || return 1
    local triplet deb
    deb=$(ls "$apt"/debs/libpython"$version"-dev_*_"$arch".deb | tail -1)
    [ "$arch" = arm64 ] && triplet=aarch64-linux-gnu || triplet=x86_64-linux-gnu
    rm -rf "$out"; mkdir -p "$out/deb" "$out/include"
    dpkg-deb -x "$deb" "$out/deb"
    mv "$out/deb/usr/include/python$version" "$out/include/"
    cp "$out/deb/usr/include/$triplet/python$version/pyconfig.h" "$out/include/python$version/pyconfig.h"
    rm -rf "$out/deb"
  fi
  echo "$out/include/python$version"
}
