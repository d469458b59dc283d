# Configures, builds and runs Testing/Sanitizers: the plain-C++ cores and their unit tests
# under AddressSanitizer and UndefinedBehaviorSanitizer. Any report fails.
#   cmake -DSOURCE_DIR=<repo>/Testing/Sanitizers -DWORK_DIR=... -DGENERATOR=... -P RunSanitizers.cmake
include("${CMAKE_CURRENT_LIST_DIR}/ScriptHelpers.cmake")
nimbus_require_variables(RunSanitizers.cmake SOURCE_DIR WORK_DIR GENERATOR)

set(build "${WORK_DIR}/build")
nimbus_run("${CMAKE_COMMAND}" -S "${SOURCE_DIR}" -B "${build}" -G "${GENERATOR}")
nimbus_run("${CMAKE_COMMAND}" --build "${build}")
set(ENV{ASAN_OPTIONS} "halt_on_error=1:abort_on_error=0:detect_leaks=1:strict_string_checks=1")
set(ENV{UBSAN_OPTIONS} "halt_on_error=1:print_stacktrace=1")
include(ProcessorCount)
ProcessorCount(cores)
if (cores LESS 1)
  set(cores 1)
endif ()
nimbus_run("${CMAKE_CTEST_COMMAND}" --test-dir "${build}" --output-on-failure
  --parallel ${cores})
message(STATUS "Nimbus cores passed under AddressSanitizer and UndefinedBehaviorSanitizer")
