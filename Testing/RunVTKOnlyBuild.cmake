# Proves the VTK-only configuration: configures and builds Nimbus with
# -DNIMBUS_USE_PARAVIEW=OFF against a plain VTK config directory (ParaView's
# bundled VTK here), checks that no plugin was built, and imports the Python
# bindings from that build.
#   cmake -DSOURCE_DIR=... -DWORK_DIR=... -DVTK_DIR=... -DGENERATOR=... -DPYTHON=... -P RunVTKOnlyBuild.cmake
include("${CMAKE_CURRENT_LIST_DIR}/ScriptHelpers.cmake")
nimbus_require_variables(RunVTKOnlyBuild.cmake SOURCE_DIR WORK_DIR VTK_DIR GENERATOR PYTHON)

set(build "${WORK_DIR}/build")
nimbus_run("${CMAKE_COMMAND}" -S "${SOURCE_DIR}" -B "${build}" -G "${GENERATOR}"
  -DNIMBUS_USE_PARAVIEW=OFF "-DVTK_DIR=${VTK_DIR}" -DBUILD_TESTING=OFF
  -DCMAKE_BUILD_TYPE=Release)
nimbus_run("${CMAKE_COMMAND}" --build "${build}")

file(GLOB_RECURSE plugins "${build}/*/Nimbus.so")
if (plugins)
  message(FATAL_ERROR "the VTK-only build produced a ParaView plugin: ${plugins}")
endif ()
file(GLOB python_dirs "${build}/lib/python3*/site-packages")
if (NOT python_dirs)
  message(FATAL_ERROR "the VTK-only build produced no Python package")
endif ()
nimbus_run("${CMAKE_COMMAND}" -E env "PYTHONPATH=${python_dirs}"
  "${PYTHON}" -c "import nimbus; s = nimbus.vtkNimbusMetaballCloudSource(); s.SetDimensions(16, 16, 12); s.Update(); n = s.GetOutput().GetNumberOfPoints(); assert n == 16 * 16 * 12, n; print('VTK-only nimbus OK:', n, 'points')")
