# TetGen compiled from its source folder TOPSTOC_TETGEN_SOURCE (tetgen.h, tetgen.cxx,
# predicates.cxx; scripts/fetch_deps.py fetches them for the zig builds) into a static
# library linked into the module, so a wheel needs no libtet beside it.
add_library(tet STATIC ${TOPSTOC_TETGEN_SOURCE}/tetgen.cxx ${TOPSTOC_TETGEN_SOURCE}/predicates.cxx)
target_compile_definitions(tet PUBLIC TETLIBRARY)
target_compile_options(tet PRIVATE -w)  # third-party code: its warnings are not ours to fix
set_target_properties(tet PROPERTIES CXX_VISIBILITY_PRESET hidden)
set(TETGEN_INCLUDE_DIR ${TOPSTOC_TETGEN_SOURCE})
set(TETGEN_LIBRARY tet)
