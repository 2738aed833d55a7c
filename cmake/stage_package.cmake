# Mirrors addon/ into the staging folder (build/python/topstoc) and puts the extension manifest
# next to __init__.py. Everything but the compiled module is replaced, so files deleted from
# addon/ never linger in the staged package.
file(GLOB_RECURSE old_files RELATIVE "${DST}" "${DST}/*")
foreach(f IN LISTS old_files)
  if(NOT f MATCHES "^_topstoc.*\\.so$")
    file(REMOVE "${DST}/${f}")
  endif()
endforeach()
# Folders addon/ no longer has (a module moved elsewhere) go too, not to linger empty in the zips.
file(GLOB_RECURSE old_dirs LIST_DIRECTORIES true RELATIVE "${DST}" "${DST}/*")
foreach(d IN LISTS old_dirs)
  if(IS_DIRECTORY "${DST}/${d}" AND NOT EXISTS "${SRC}/${d}")
    file(REMOVE_RECURSE "${DST}/${d}")
  endif()
endforeach()
file(COPY "${SRC}/" DESTINATION "${DST}" PATTERN "__pycache__" EXCLUDE PATTERN "*.pyc" EXCLUDE)
# The staged package carries its compiled module itself, so its manifest drops the release's
# `wheels = [...]` (the topstoc_native wheels only scripts/build_extension.sh packs).
file(READ "${MANIFEST}" manifest)
string(FIND "${manifest}" "\nwheels = [" start)
if(start GREATER -1)
  string(SUBSTRING "${manifest}" ${start} -1 tail)
  string(FIND "${tail}" "]\n" length)
  math(EXPR cut "${length} + 2")
  string(SUBSTRING "${tail}" ${cut} -1 rest)
  string(SUBSTRING "${manifest}" 0 ${start} head)
  set(manifest "${head}\n${rest}")
endif()
file(WRITE "${DST}/blender_manifest.toml" "${manifest}")
