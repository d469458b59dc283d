# style.ClangFormat: every C++ file of the project is formatted as .clang-format says
# (VTK's style). Fails with the list of files to run `clang-format -i` on.
#   cmake -DSOURCE_DIR=<repo> -DCLANG_FORMAT=<clang-format> -P CheckFormat.cmake
if (NOT CLANG_FORMAT)
  message(FATAL_ERROR "clang-format was not found: install it (scripts/setup.sh does) and "
    "configure again.")
endif ()
find_package(Git QUIET)
set(files)
if (GIT_FOUND AND EXISTS "${SOURCE_DIR}/.git")
  execute_process(COMMAND "${GIT_EXECUTABLE}" ls-files -- "*.h" "*.cxx"
    WORKING_DIRECTORY "${SOURCE_DIR}" OUTPUT_VARIABLE listed RESULT_VARIABLE status)
  if (status EQUAL 0)
    string(REGEX REPLACE "\n$" "" listed "${listed}")
    string(REPLACE "\n" ";" files "${listed}")
  endif ()
endif ()
if (NOT files)
  # Not a git checkout: every C++ file outside build folders.
  file(GLOB_RECURSE files RELATIVE "${SOURCE_DIR}" "${SOURCE_DIR}/*.h" "${SOURCE_DIR}/*.cxx")
  list(FILTER files EXCLUDE REGEX "(^|/)build[^/]*/")
endif ()
set(unformatted)
foreach (file IN LISTS files)
  execute_process(COMMAND "${CLANG_FORMAT}" --dry-run --Werror "${file}"
    WORKING_DIRECTORY "${SOURCE_DIR}" RESULT_VARIABLE status OUTPUT_QUIET ERROR_QUIET)
  if (NOT status EQUAL 0)
    list(APPEND unformatted "${file}")
  endif ()
endforeach ()
list(LENGTH files checked)
if (unformatted)
  list(JOIN unformatted "\n  " shown)
  message(FATAL_ERROR "Not formatted as .clang-format says (run clang-format -i on them):\n  "
    "${shown}")
endif ()
message(STATUS "clang-format: ${checked} files formatted as .clang-format says")
