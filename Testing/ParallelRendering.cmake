# The Cloud representation rendered by several pvbatch ranks (issue 18, label mpi):
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
