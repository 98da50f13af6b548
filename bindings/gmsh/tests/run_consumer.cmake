# ctest gmsh_consumer: build examples/ against the installed PREFIX with
# find_package(CurveTet COMPONENTS Gmsh), run the C++ example, and the Python example
# with the installed curvetet_gmsh.py (which finds the installed library by itself).
#   cmake -DSOURCE=... -DWORK=... -DPREFIX=... -DLIBDIR=... -DGENERATOR=... -DCXX_COMPILER=...
#         -DPYTHON=... -P run_consumer.cmake
foreach(f "${LIBDIR}/libcurvetet_gmsh.so" "include/curvetet_gmsh.hpp" "share/curvetet/python/curvetet_gmsh.py"
        "share/curvetet/python/curvetet_lib.py")
  if(NOT EXISTS "${PREFIX}/${f}")
    message(FATAL_ERROR "install lacks ${f}")
  endif()
endforeach()
file(REMOVE_RECURSE "${WORK}")
execute_process(
  COMMAND "${CMAKE_COMMAND}" -S "${SOURCE}" -B "${WORK}" -G "${GENERATOR}"
          "-DCMAKE_PREFIX_PATH=${PREFIX}" -DCMAKE_BUILD_TYPE=Release "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}"
  OUTPUT_QUIET COMMAND_ERROR_IS_FATAL ANY)
execute_process(COMMAND "${CMAKE_COMMAND}" --build "${WORK}" OUTPUT_QUIET COMMAND_ERROR_IS_FATAL ANY)

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${ARGN} failed (${rc}):\n${out}\n${err}")
  endif()
  message(STATUS "${out}")
endfunction()

run("${WORK}/mesh_box_sphere" "${WORK}/box_sphere_cpp.msh")
if(PYTHON)
  # No CURVETET_LIBRARY: the module must find the library of its own install prefix.
  run("${CMAKE_COMMAND}" -E env --unset=CURVETET_LIBRARY
      "PYTHONPATH=${PREFIX}/share/curvetet/python"
      "${PYTHON}" "${SOURCE}/mesh_box_sphere.py" "${WORK}/box_sphere_py.msh")
endif()
foreach(f box_sphere_cpp.msh box_sphere_py.msh)
  if(NOT EXISTS "${WORK}/${f}" AND (PYTHON OR f STREQUAL "box_sphere_cpp.msh"))
    message(FATAL_ERROR "${f} was not written")
  endif()
endforeach()
