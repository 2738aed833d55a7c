# Cross-compiling for Windows x64 with Debian's mingw-w64 (g++-mingw-w64-x86-64-posix: the posix
# thread model, which has std::thread and std::mutex). Everything links statically, so the
# .exe files need no DLL next to them; tests run under Wine (CMAKE_CROSSCOMPILING_EMULATOR).
# Dependencies are looked up only under CMAKE_FIND_ROOT_PATH (pass -DCMAKE_FIND_ROOT_PATH=PREFIX,
# the prefix cmake/deps installed into), never in the host's /usr.
set(CMAKE_SYSTEM_NAME Windows)
set(CMAKE_SYSTEM_PROCESSOR x86_64)
set(CMAKE_C_COMPILER x86_64-w64-mingw32-gcc-posix)
set(CMAKE_CXX_COMPILER x86_64-w64-mingw32-g++-posix)
set(CMAKE_RC_COMPILER x86_64-w64-mingw32-windres)
set(CMAKE_EXE_LINKER_FLAGS_INIT "-static")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
find_program(TOPSTOC_WINE NAMES wine64 wine PATHS /usr/lib/wine NO_CMAKE_FIND_ROOT_PATH)
if(TOPSTOC_WINE)
  set(CMAKE_CROSSCOMPILING_EMULATOR ${TOPSTOC_WINE})
endif()
