# Cross-compiling for Linux aarch64 with Debian's g++-aarch64-linux-gnu (glibc 2.36): the
# engine's C++ tests and command-line driver, run in the arm64 Debian root under QEMU user
# emulation (scripts/aarch64_test.sh). Dependencies are looked up under CMAKE_FIND_ROOT_PATH (the
# prefix cmake/deps installed into) and the cross toolchain's own folders, never the host's /usr.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
list(APPEND CMAKE_FIND_ROOT_PATH /usr/aarch64-linux-gnu /usr/lib/gcc-cross/aarch64-linux-gnu/12)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
