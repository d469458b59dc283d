# Proves that Nimbus::Physics needs no VTK: configures Physics/ on its own (VTK and
# ParaView may not even be looked for), builds it and its tests, runs them, and checks
# that the library links nothing of VTK.
#   cmake -DSOURCE_DIR=<repo>/Physics -DWORK_DIR=... -DGENERATOR=... -P RunPhysicsStandalone.cmake
include("${CMAKE_CURRENT_LIST_DIR}/ScriptHelpers.cmake")
nimbus_require_variables(RunPhysicsStandalone.cmake SOURCE_DIR WORK_DIR GENERATOR)

set(build "${WORK_DIR}/build")
nimbus_run("${CMAKE_COMMAND}" -S "${SOURCE_DIR}" -B "${build}" -G "${GENERATOR}"
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_DISABLE_FIND_PACKAGE_VTK=ON
  -DCMAKE_DISABLE_FIND_PACKAGE_ParaView=ON)
nimbus_run("${CMAKE_COMMAND}" --build "${build}")
nimbus_run("${CMAKE_CTEST_COMMAND}" --test-dir "${build}" --output-on-failure)

file(GLOB libraries "${build}/libNimbusPhysics.so*" "${build}/*/libNimbusPhysics.so*")
if (NOT libraries)
  message(FATAL_ERROR "the standalone Physics build produced no libNimbusPhysics")
endif ()
list(GET libraries 0 library)
execute_process(COMMAND ldd "${library}" OUTPUT_VARIABLE linked RESULT_VARIABLE status)
if (NOT status EQUAL 0)
  message(FATAL_ERROR "ldd ${library} failed")
endif ()
if (linked MATCHES "vtk|paraview")
  message(FATAL_ERROR "libNimbusPhysics links VTK or ParaView:\n${linked}")
endif ()
file(READ "${build}/CMakeCache.txt" cache)
if (cache MATCHES "VTK_DIR:PATH=/")
  message(FATAL_ERROR "the standalone Physics build looked for VTK")
endif ()
message(STATUS "Nimbus::Physics built and tested without VTK: ${library}")
