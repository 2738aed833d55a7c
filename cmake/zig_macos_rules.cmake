# Loaded as CMAKE_USER_MAKE_RULES_OVERRIDE by scripts/build_macos.sh: zig 0.15's Mach-O linker
# crashes (segmentation fault) linking with -bundle, so the macOS module is linked as a dynamic
# library (MH_DYLIB), which CPython's dlopen loads as it loads a bundle.
set(CMAKE_SHARED_MODULE_CREATE_CXX_FLAGS "-shared -Wl,-headerpad_max_install_names")
