# Installs the Nimbus build tree into a scratch prefix, then configures, builds and
# runs Testing/Standalone against it with find_package(Nimbus).
#   cmake -DNIMBUS_BUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... -DGENERATOR=... -P RunStandaloneTest.cmake
include("${CMAKE_CURRENT_LIST_DIR}/ScriptHelpers.cmake")
nimbus_require_variables(RunStandaloneTest.cmake NIMBUS_BUILD_DIR SOURCE_DIR WORK_DIR GENERATOR)

file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/install")
nimbus_run("${CMAKE_COMMAND}" --install "${NIMBUS_BUILD_DIR}" --prefix "${prefix}")
nimbus_run("${CMAKE_COMMAND}" -S "${SOURCE_DIR}" -B "${WORK_DIR}/build" -G "${GENERATOR}"
  "-DCMAKE_PREFIX_PATH=${prefix}" -DCMAKE_BUILD_TYPE=Release)
nimbus_run("${CMAKE_COMMAND}" --build "${WORK_DIR}/build")
nimbus_run("${WORK_DIR}/build/nimbus-standalone-app")
message(STATUS "standalone app built and ran against ${prefix}")
