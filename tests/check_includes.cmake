# Fails when a source file under DIR includes a header matching FORBIDDEN
# (a regular expression on the quoted or bracketed name). Keeps the layers
# apart: the editor model (editor/app) and the view data (render/view) are
# built and tested without GL, SDL, ImGui or the renderer.
#   cmake -DDIR=editor/app -DFORBIDDEN="^(render/|GL/|SDL|imgui)" -P check_includes.cmake
get_filename_component(DIR "${DIR}" ABSOLUTE)
file(GLOB_RECURSE sources "${DIR}/*.cpp" "${DIR}/*.hpp")
if(NOT sources)
  message(FATAL_ERROR "${DIR}: no source files (wrong folder?)")
endif()
set(bad "")
foreach(source IN LISTS sources)
  file(STRINGS "${source}" includes REGEX "^[ \t]*#[ \t]*include[ \t]*[<\"]")
  foreach(line IN LISTS includes)
    string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*[<\"]([^>\"]*)[>\"].*" "\\1" header "${line}")
    if(header MATCHES "${FORBIDDEN}")
      file(RELATIVE_PATH rel "${DIR}" "${source}")
      string(APPEND bad "\n  ${rel}: #include \"${header}\"")
    endif()
  endforeach()
endforeach()
if(bad)
  message(FATAL_ERROR "${DIR} must not include headers matching ${FORBIDDEN}:${bad}")
endif()
list(LENGTH sources count)
message(STATUS "${DIR}: ${count} files, none includes ${FORBIDDEN}")
