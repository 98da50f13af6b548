# ctest vtk_consumer: configure and build this folder against the installed PREFIX with
# find_package(CurveTet COMPONENTS VTK), then mesh an STL with it.
#   cmake -DSOURCE=... -DWORK=... -DPREFIX=... -DGENERATOR=... -DCXX_COMPILER=...
#         -DVTK_DIR=... -DSTL=surface.stl -P run_consumer.cmake
file(REMOVE_RECURSE "${WORK}")
execute_process(
  COMMAND "${CMAKE_COMMAND}" -S "${SOURCE}" -B "${WORK}" -G "${GENERATOR}"
          "-DCMAKE_PREFIX_PATH=${PREFIX}" -DCMAKE_BUILD_TYPE=Release
          "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}" "-DVTK_DIR=${VTK_DIR}"
  OUTPUT_QUIET COMMAND_ERROR_IS_FATAL ANY)
execute_process(COMMAND "${CMAKE_COMMAND}" --build "${WORK}" OUTPUT_QUIET COMMAND_ERROR_IS_FATAL ANY)
execute_process(COMMAND "${WORK}/mesh_stl" "${STL}" "${WORK}/volume.vtu"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT EXISTS "${WORK}/volume.vtu")
  message(FATAL_ERROR "mesh_stl failed (${rc}):\n${out}\n${err}")
endif()
message(STATUS "${out}")
# The program links the installed filter library (found through PREFIX's CMake package).
find_program(READELF readelf)
if(READELF)
  execute_process(COMMAND "${READELF}" -d "${WORK}/mesh_stl" OUTPUT_VARIABLE dyn)
  if(NOT dyn MATCHES "NEEDED[^\n]*libcurvetet_vtk\\.so" OR NOT dyn MATCHES "PATH[^\n]*${PREFIX}")
    message(FATAL_ERROR "mesh_stl does not load libcurvetet_vtk.so from ${PREFIX}:\n${dyn}")
  endif()
endif()
