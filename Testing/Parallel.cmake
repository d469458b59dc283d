# Data-parallel tests (docs/parallel.md), label mpi: the field sources and the OpenVDB reader under
# MPI. Included at the end of Testing/CMakeLists.txt.
#
# mpi.Pieces.<N>: `mpiexec -n N pvbatch --symmetric TestParallelPieces.py`: every rank
#   produces its piece (0 and 1 ghost levels) of every source; rank 0 assembles them and
#   compares with the serial output bit for bit.
# mpi.ParaViewPieces.2: `mpiexec -n 2 pvbatch` (rank 0 the client): the plugin's metaball
#   cloud through paraview.simple; its data information over both ranks equals the serial
#   output's.
#
# Without mpiexec or pvbatch (or without the Python bindings) the tests are not added.
if (NOT NIMBUS_WRAP_PYTHON OR NOT NIMBUS_USE_PARAVIEW)
  message(STATUS "Nimbus: mpi tests off (they need the Python bindings and ParaView)")
  return()
endif ()
find_package(MPI QUIET COMPONENTS C)
if (MPIEXEC_EXECUTABLE)
  set(NIMBUS_MPIEXEC "${MPIEXEC_EXECUTABLE}")
else ()
  find_program(NIMBUS_MPIEXEC NAMES mpiexec mpirun)
endif ()
find_program(NIMBUS_PVBATCH pvbatch HINTS "${ParaView_PREFIX_PATH}/bin")
if (NOT NIMBUS_MPIEXEC OR NOT NIMBUS_PVBATCH)
  message(STATUS "Nimbus: mpi tests off (mpiexec: ${NIMBUS_MPIEXEC}, pvbatch: ${NIMBUS_PVBATCH})")
  return()
endif ()

# Open MPI refuses to run as root unless told, and more ranks than cores unless told.
set(nimbus_mpiexec_flags "")
set(nimbus_mpi_environment "")
execute_process(COMMAND "${NIMBUS_MPIEXEC}" --version OUTPUT_VARIABLE nimbus_mpi_version
  ERROR_QUIET)
if (nimbus_mpi_version MATCHES "Open MPI|OpenRTE")
  set(nimbus_mpiexec_flags --oversubscribe)
  set(nimbus_mpi_environment "OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1")
endif ()

foreach (ranks IN ITEMS 2 4)
  add_test(NAME mpi.Pieces.${ranks}
    COMMAND "${NIMBUS_MPIEXEC}" ${nimbus_mpiexec_flags} -n ${ranks}
      "${NIMBUS_PVBATCH}" --symmetric --force-offscreen-rendering
      "${CMAKE_CURRENT_SOURCE_DIR}/Python/TestParallelPieces.py"
      --output-dir "${output_dir}")
  # ranks > cores on small machines: one MPI test at a time, counted as `ranks` processors.
  set_tests_properties(mpi.Pieces.${ranks} PROPERTIES
    LABELS mpi TIMEOUT 300 PROCESSORS ${ranks} RESOURCE_LOCK mpi
    ENVIRONMENT "PYTHONPATH=${python_dir};${nimbus_mpi_environment}")
endforeach ()

add_test(NAME mpi.ParaViewPieces.2
  COMMAND "${with_display}" "${NIMBUS_MPIEXEC}" ${nimbus_mpiexec_flags} -n 2
    "${NIMBUS_PVBATCH}" --force-offscreen-rendering
    "${CMAKE_CURRENT_SOURCE_DIR}/Python/TestParallelParaView.py"
    --plugin $<TARGET_FILE:Nimbus>)
set_tests_properties(mpi.ParaViewPieces.2 PROPERTIES
  LABELS mpi TIMEOUT 300 PROCESSORS 2 RESOURCE_LOCK mpi
  ENVIRONMENT "PYTHONPATH=${python_dir};${nimbus_mpi_environment}")

# What a rank holds: mpi.PieceMemory.4 (TestParallelVdbMemory.py): every rank reads its piece
# of a 256^3 all-active .vdb (written by mpi.PieceMemory.Setup) and fails when its peak memory
# grows by more than its piece plus half the whole grid (a whole read, which the last rank also
# does as a check of the measurement and of its piece's values, grows it by the whole grid). The
# cloud automaton's ranks stepping only their slabs is checked by mpi.Pieces.* (its pieces
# against the serial output, 2 and 4 ranks, open and periodic sides).
if (NIMBUS_HAVE_OPENVDB)
  set(nimbus_vdb_memory_file "${output_dir}/parallel_vdb_memory.vdb")
  add_test(NAME mpi.PieceMemory.Setup
    COMMAND "${Python3_EXECUTABLE}" "${CMAKE_CURRENT_SOURCE_DIR}/Python/TestParallelVdbMemory.py"
      --write "${nimbus_vdb_memory_file}")
  set_tests_properties(mpi.PieceMemory.Setup PROPERTIES
    LABELS mpi TIMEOUT 60 FIXTURES_SETUP nimbus_vdb_memory
    ENVIRONMENT "PYTHONPATH=${python_dir}")
  add_test(NAME mpi.PieceMemory.4
    COMMAND "${NIMBUS_MPIEXEC}" ${nimbus_mpiexec_flags} -n 4
      "${NIMBUS_PVBATCH}" --symmetric --force-offscreen-rendering
      "${CMAKE_CURRENT_SOURCE_DIR}/Python/TestParallelVdbMemory.py"
      --read "${nimbus_vdb_memory_file}")
  set_tests_properties(mpi.PieceMemory.4 PROPERTIES
    LABELS mpi TIMEOUT 120 PROCESSORS 4 RESOURCE_LOCK mpi FIXTURES_REQUIRED nimbus_vdb_memory
    ENVIRONMENT "PYTHONPATH=${python_dir};${nimbus_mpi_environment}")
endif ()
