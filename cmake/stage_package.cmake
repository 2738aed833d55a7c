# Mirrors addon/ into the staging folder (build/python/topstoc) and puts the extension manifest
# next to __init__.py. Files addon/ no longer has are removed, so none lingers in the staged
# package; the others are copied only where they changed (file(COPY) skips a file of the same
# timestamp), so staging an unchanged tree again touches nothing: a test that packs the zips
# while other suites import the staged package (scripts/test.sh runs two lanes) cannot race them.
file(GLOB_RECURSE old_files RELATIVE "${DST}" "${DST}/*")
foreach(f IN LISTS old_files)
  if(NOT f MATCHES "^_topstoc.*\\.so$" AND NOT f STREQUAL "blender_manifest.toml" AND
     (NOT EXISTS "${SRC}/${f}" OR f MATCHES "(^|/)__pycache__/|\\.pyc$"))
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
set(old_manifest "")
if(EXISTS "${DST}/blender_manifest.toml")
  file(READ "${DST}/blender_manifest.toml" old_manifest)
endif()
if(NOT old_manifest STREQUAL manifest)
  file(WRITE "${DST}/blender_manifest.toml" "${manifest}")
endif()
