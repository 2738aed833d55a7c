# Mirrors addon/ into the staging folder (build/python/topstoc) and puts the extension manifest
# next to __init__.py. Everything but the compiled module is replaced, so files deleted from
# addon/ never linger in the staged package.
file(GLOB_RECURSE old_files RELATIVE "${DST}" "${DST}/*")
foreach(f IN LISTS old_files)
  if(NOT f MATCHES "^_topstoc.*\\.so$")
    file(REMOVE "${DST}/${f}")
  endif()
endforeach()
file(COPY "${SRC}/" DESTINATION "${DST}" PATTERN "__pycache__" EXCLUDE PATTERN "*.pyc" EXCLUDE)
file(COPY "${MANIFEST}" DESTINATION "${DST}")
