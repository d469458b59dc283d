# The Cloud representation rendered by several pvbatch ranks (docs/parallel.md, label mpi):
# the picture of 2 and 4 ranks against one rank's, within the bounds measured in
# docs/parallel.md, and the air and the ground drawn once (an empty cloud, to 1 level).
# Needs ParaView's pvbatch and an MPI launcher; without either the tests are left out.
find_program(NIMBUS_PVBATCH pvbatch HINTS "${ParaView_PREFIX_PATH}/bin")
find_program(NIMBUS_MPIEXEC NAMES mpiexec mpirun)
if (NOT NIMBUS_PVBATCH OR NOT NIMBUS_MPIEXEC)
  message(STATUS "Nimbus: no pvbatch or mpiexec; the parallel rendering tests are left out")
  return ()
endif ()
# Open MPI refuses root without these, and 4 ranks on 2 cores need --oversubscribe
# (given through the environment, which Open MPI reads as its MCA parameters).
set(nimbus_mpi_environment
  "OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMPI_MCA_rmaps_base_oversubscribe=1")
foreach (ranks 2 4)
  add_test(NAME mpi.CloudRepresentation.${ranks}
    COMMAND "${with_display}" "${Python3_EXECUTABLE}"
      "${CMAKE_CURRENT_SOURCE_DIR}/Python/TestParallelCloud.py"
      --mpiexec "${NIMBUS_MPIEXEC}" --pvbatch "${NIMBUS_PVBATCH}"
      --plugin $<TARGET_FILE:Nimbus> --ranks ${ranks}
      --output-dir "${output_dir}/ParallelCloud${ranks}")
  set_tests_properties(mpi.CloudRepresentation.${ranks} PROPERTIES
    LABELS mpi TIMEOUT 600 ENVIRONMENT "${nimbus_mpi_environment}" ${pvpython_lock})
endforeach ()

# The Cloud representation of every Nimbus source and reader (metaball cloud, cloud
# automaton, image cloud, smoke, OpenVDB reader, a .vti), each producing its own pieces,
# on the first render of a view whose camera the script set: the picture of N ranks
# against one rank's, the air and the ground drawn (TestParallelSources.py, 32-point data).
# mpi.CloudSources: on X (with-display.sh), every source on 2 ranks and the metaball cloud
# on 4. mpi.CloudSources.offscreen: no X (DISPLAY removed, NIMBUS_OFFSCREEN=egl,
# --force-offscreen-rendering), every source on 2 ranks and the metaball cloud on 8. One
# rank is each test's reference. About 20 s each on 2 idle cores (docs/parallel.md). A
# pvbatch run that has not finished after 120 s is stopped (its whole process group) and
# fails: a hang is a failure, well within the test's TIMEOUT.
foreach (mode IN ITEMS x offscreen)
  if (mode STREQUAL "x")
    set(name mpi.CloudSources)
    set(launcher "${with_display}")
    set(options --runs 2:all 4:metaball)
  else ()
    set(name mpi.CloudSources.offscreen)
    set(launcher)
    set(options --runs 2:all 8:metaball --offscreen)
  endif ()
  add_test(NAME ${name}
    COMMAND ${launcher} "${Python3_EXECUTABLE}"
      "${CMAKE_CURRENT_SOURCE_DIR}/Python/TestParallelSources.py"
      --mpiexec "${NIMBUS_MPIEXEC}" --pvbatch "${NIMBUS_PVBATCH}"
      --plugin $<TARGET_FILE:Nimbus> ${options} --timeout 120
      --output-dir "${output_dir}/ParallelSources-${mode}")
  set_tests_properties(${name} PROPERTIES
    LABELS mpi TIMEOUT 420 ENVIRONMENT "PYTHONPATH=${python_dir};${nimbus_mpi_environment}"
    ${pvpython_lock})
endforeach ()
