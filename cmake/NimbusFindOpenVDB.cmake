# Finds OpenVDB (Debian: libopenvdb-dev) for the Nimbus::IOOpenVDB module and defines
#   NIMBUS_HAVE_OPENVDB        TRUE when the headers, the library and its TBB and Imath
#                              configs were found (the module's vtk.module CONDITION)
#   nimbus_openvdb_modules     Nimbus::IOOpenVDB, or empty (for REQUEST_MODULES / plugin)
#   NimbusOpenVDB::openvdb     imported target: libopenvdb + TBB + Imath (+ Boost headers)
#
# OpenVDB's own FindOpenVDB.cmake (in <libdir>/cmake/OpenVDB) also asks for
# boost_iostreams, which Debian's libopenvdb-dev does not depend on; the headers only
# need TBB, Imath (half) and header-only Boost, so this finds exactly those.
# -DNIMBUS_WITH_OPENVDB=OFF skips the module.
option(NIMBUS_WITH_OPENVDB "Build the OpenVDB reader and writer (needs libopenvdb-dev)" ON)
set(NIMBUS_HAVE_OPENVDB FALSE)
set(nimbus_openvdb_modules)
if (NIMBUS_WITH_OPENVDB)
  find_path(NIMBUS_OPENVDB_INCLUDE_DIR openvdb/openvdb.h)
  find_library(NIMBUS_OPENVDB_LIBRARY openvdb)
  find_package(TBB CONFIG QUIET)
  find_package(Imath CONFIG QUIET)
  find_package(Boost QUIET)
  mark_as_advanced(NIMBUS_OPENVDB_INCLUDE_DIR NIMBUS_OPENVDB_LIBRARY)
  set(nimbus_openvdb_missing)
  foreach (what IN ITEMS NIMBUS_OPENVDB_INCLUDE_DIR NIMBUS_OPENVDB_LIBRARY TBB_FOUND Imath_FOUND Boost_FOUND)
    if (NOT ${what})
      list(APPEND nimbus_openvdb_missing ${what})
    endif ()
  endforeach ()
  if (nimbus_openvdb_missing)
    message(STATUS "Nimbus: OpenVDB reader/writer SKIPPED (not found: ${nimbus_openvdb_missing}; "
      "install libopenvdb-dev, or scripts/setup.sh does)")
  else ()
    file(STRINGS "${NIMBUS_OPENVDB_INCLUDE_DIR}/openvdb/version.h" nimbus_openvdb_version_line
      REGEX "define OPENVDB_LIBRARY_VERSION_STRING")
    string(REGEX MATCH "\"[^\"]*\"" NIMBUS_OPENVDB_VERSION "${nimbus_openvdb_version_line}")
    message(STATUS "Nimbus: OpenVDB ${NIMBUS_OPENVDB_VERSION} found: building Nimbus::IOOpenVDB")
    if (NOT TARGET NimbusOpenVDB::openvdb)
      add_library(NimbusOpenVDB::openvdb UNKNOWN IMPORTED)
      set_target_properties(NimbusOpenVDB::openvdb PROPERTIES
        IMPORTED_LOCATION "${NIMBUS_OPENVDB_LIBRARY}"
        INTERFACE_INCLUDE_DIRECTORIES "${NIMBUS_OPENVDB_INCLUDE_DIR}"
        INTERFACE_LINK_LIBRARIES "TBB::tbb;Imath::Imath;Boost::headers")
    endif ()
    set(NIMBUS_HAVE_OPENVDB TRUE)
    set(nimbus_openvdb_modules Nimbus::IOOpenVDB)
  endif ()
else ()
  message(STATUS "Nimbus: OpenVDB reader/writer SKIPPED (NIMBUS_WITH_OPENVDB=OFF)")
endif ()
