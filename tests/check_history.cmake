# Fails when a source, script or document names a calendar date (year,
# month and day joined by hyphens) or a tracker entry by its number: comments say why
# the code is as it is and docs say what it does today, so neither refers
# to when it changed.
# docs/measured/ is left out: the benchmarks write those tables and date
# them. Run from the source root:
#   cmake -DROOT=. -P tests/check_history.cmake
get_filename_component(ROOT "${ROOT}" ABSOLUTE)
file(GLOB_RECURSE files RELATIVE "${ROOT}"
  "${ROOT}/engine/*" "${ROOT}/editor/*" "${ROOT}/bench/*.cpp" "${ROOT}/bench/*.hpp"
  "${ROOT}/bench/*.sh" "${ROOT}/bench/CMakeLists.txt" "${ROOT}/tests/*.cpp" "${ROOT}/tests/*.hpp"
  "${ROOT}/tests/*.sh" "${ROOT}/tests/*.cmake" "${ROOT}/tests/*.py" "${ROOT}/tests/*.txt"
  "${ROOT}/tests/*.dict" "${ROOT}/shaders/*" "${ROOT}/docs/*.md" "${ROOT}/.ci/*")
list(APPEND files README.md CMakeLists.txt)
list(FILTER files EXCLUDE REGEX "^(tests/data/|tests/fuzz/corpus/|docs/measured/)")
if(NOT files)
  message(FATAL_ERROR "${ROOT}: no files to check (wrong folder?)")
endif()
# Assembled from parts, so that this file does not match itself.
set(digit "[0-9]")
set(date "[12]${digit}${digit}${digit}-[01]${digit}-[0-3]${digit}")
set(tracked "ss")
set(issue "[Ii]${tracked}ue #?${digit}")
set(bad "")
foreach(file IN LISTS files)
  file(STRINGS "${ROOT}/${file}" lines REGEX "${date}|${issue}")
  foreach(line IN LISTS lines)
    string(STRIP "${line}" line)
    string(APPEND bad "\n  ${file}: ${line}")
  endforeach()
endforeach()
if(bad)
  message(FATAL_ERROR "dates or issue numbers in code or docs (say why, in the present tense):${bad}")
endif()
list(LENGTH files count)
message(STATUS "${count} files, no date or issue number")
