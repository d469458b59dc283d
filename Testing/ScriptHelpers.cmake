# Helpers shared by the cmake -P test scripts (RunStandaloneTest.cmake, RunVTKOnlyBuild.cmake,
# RunPhysicsStandalone.cmake, RunSanitizers.cmake).

# nimbus_require_variables(<script name> <var>...): stop with a message unless each -D<var> was given.
function (nimbus_require_variables script)
  foreach (var IN LISTS ARGN)
    if (NOT DEFINED ${var})
      message(FATAL_ERROR "${script}: ${var} is not set")
    endif ()
  endforeach ()
endfunction ()

# nimbus_run(<command> <arg>...): run a command, stop with its command line if it fails.
function (nimbus_run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result)
  if (NOT result EQUAL 0)
    string(REPLACE ";" " " command "${ARGN}")
    message(FATAL_ERROR "failed (${result}): ${command}")
  endif ()
endfunction ()
