# ctest fixture: install the build tree into a fresh PREFIX and check the layout.
#   cmake -DBUILD_DIR=... -DPREFIX=... -DLIBDIR=lib -DSONAME=libcurvetet.so.X [-DVTK=ON]
#         -P install_prefix.cmake
file(REMOVE_RECURSE "${PREFIX}")
execute_process(COMMAND "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${PREFIX}"
                OUTPUT_QUIET COMMAND_ERROR_IS_FATAL ANY)
set(_vtk_files "")
if(VTK)
  set(_vtk_files "${LIBDIR}/libcurvetet_vtk.so" "include/vtkCurveTetFilter.h"
                 "${LIBDIR}/cmake/CurveTet/CurveTetVTKTargets.cmake")
endif()
foreach(f ${_vtk_files}
    "${LIBDIR}/libcurvetet.a"
    "${LIBDIR}/${SONAME}"
    "${LIBDIR}/libcurvetet.so"
    "include/curvetet.h"
    "${LIBDIR}/cmake/CurveTet/CurveTetConfig.cmake"
    "${LIBDIR}/cmake/CurveTet/CurveTetConfigVersion.cmake"
    "${LIBDIR}/pkgconfig/curvetet.pc")
  if(NOT EXISTS "${PREFIX}/${f}")
    message(FATAL_ERROR "install lacks ${f}")
  endif()
endforeach()
if(NOT IS_SYMLINK "${PREFIX}/${LIBDIR}/libcurvetet.so")
  message(FATAL_ERROR "${LIBDIR}/libcurvetet.so should be a symlink to ${SONAME}")
endif()
file(READ_SYMLINK "${PREFIX}/${LIBDIR}/libcurvetet.so" _target)
if(NOT _target STREQUAL SONAME)
  message(FATAL_ERROR "${LIBDIR}/libcurvetet.so points to ${_target}, not ${SONAME}")
endif()
message(STATUS "installed into ${PREFIX}")
