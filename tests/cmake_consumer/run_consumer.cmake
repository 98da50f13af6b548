# ctest: configure and build tests/cmake_consumer against the installed PREFIX with
# find_package(CurveTet), then run its programs on the sphere.
#   cmake -DSOURCE=... -DWORK=... -DPREFIX=... -DGENERATOR=... -DC_COMPILER=...
#         -DCXX_COMPILER=... -DVERSION=... -DDATA=... -P run_consumer.cmake
file(REMOVE_RECURSE "${WORK}")
execute_process(
  COMMAND "${CMAKE_COMMAND}" -S "${SOURCE}" -B "${WORK}" -G "${GENERATOR}"
          "-DCMAKE_PREFIX_PATH=${PREFIX}" -DCMAKE_BUILD_TYPE=Release
          "-DCMAKE_C_COMPILER=${C_COMPILER}" "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}"
          "-DCURVETET_EXPECTED_VERSION=${VERSION}"
  OUTPUT_QUIET COMMAND_ERROR_IS_FATAL ANY)
execute_process(COMMAND "${CMAKE_COMMAND}" --build "${WORK}" OUTPUT_QUIET COMMAND_ERROR_IS_FATAL ANY)

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${ARGN} failed (${rc}):\n${out}\n${err}")
  endif()
  message(STATUS "${out}")
endfunction()

run("${WORK}/mesh_surface" "${DATA}/sphere_p2.msh" "${WORK}/sphere_volume.msh")
run("${WORK}/mesh_surface_static" "${DATA}/sphere_p2.msh" "${WORK}/sphere_volume.vtu")
run("${WORK}/mesh_arrays" "${DATA}/sphere_p2.msh")
foreach(f sphere_volume.msh sphere_volume.vtu)
  if(NOT EXISTS "${WORK}/${f}")
    message(FATAL_ERROR "${f} was not written")
  endif()
endforeach()

# The shared build needs libcurvetet.so.<abi> at run time; the static one must not.
find_program(READELF readelf)
if(READELF)
  execute_process(COMMAND "${READELF}" -d "${WORK}/mesh_surface" OUTPUT_VARIABLE dyn)
  if(NOT dyn MATCHES "NEEDED[^\n]*libcurvetet\\.so\\.")
    message(FATAL_ERROR "mesh_surface does not need libcurvetet.so.<abi>:\n${dyn}")
  endif()
  execute_process(COMMAND "${READELF}" -d "${WORK}/mesh_surface_static" OUTPUT_VARIABLE dyn)
  if(dyn MATCHES "libcurvetet")
    message(FATAL_ERROR "mesh_surface_static depends on the shared library:\n${dyn}")
  endif()
endif()
