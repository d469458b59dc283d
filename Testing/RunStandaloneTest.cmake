# Installs the Nimbus build tree into a scratch prefix, then configures, builds and
# runs Testing/Standalone against it with find_package(Nimbus).
#   cmake -DNIMBUS_BUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... -DGENERATOR=... -P RunStandaloneTest.cmake
foreach (var NIMBUS_BUILD_DIR SOURCE_DIR WORK_DIR GENERATOR)
  if (NOT DEFINED ${var})
    message(FATAL_ERROR "RunStandaloneTest.cmake: ${var} is not set")
  endif ()
endforeach ()

function (run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result)
  if (NOT result EQUAL 0)
    string(REPLACE ";" " " command "${ARGN}")
    message(FATAL_ERROR "failed (${result}): ${command}")
  endif ()
endfunction ()

file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/install")
run("${CMAKE_COMMAND}" --install "${NIMBUS_BUILD_DIR}" --prefix "${prefix}")
run("${CMAKE_COMMAND}" -S "${SOURCE_DIR}" -B "${WORK_DIR}/build" -G "${GENERATOR}"
  "-DCMAKE_PREFIX_PATH=${prefix}" -DCMAKE_BUILD_TYPE=Release)
run("${CMAKE_COMMAND}" --build "${WORK_DIR}/build")
run("${WORK_DIR}/build/nimbus-standalone-app")
message(STATUS "standalone app built and ran against ${prefix}")
