# ctest fixture: install the build tree into a fresh PREFIX and check the layout.
#   cmake -DBUILD_DIR=... -DPREFIX=... -DLIBDIR=lib -DSONAME=libcurvetet.so.X -DBINDIR=bin
#         -DVERSION=X.Y.Z -DCLI=ON|OFF -DREADELF=/usr/bin/readelf [-DVTK=ON] [-DMESHLAB=ON]
#         -P install_prefix.cmake
file(REMOVE_RECURSE "${PREFIX}")
execute_process(COMMAND "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${PREFIX}"
                OUTPUT_QUIET COMMAND_ERROR_IS_FATAL ANY)
set(_vtk_files "")
if(VTK)
  set(_vtk_files "${LIBDIR}/libcurvetet_vtk.so" "include/vtkCurveTetFilter.h"
                 "${LIBDIR}/cmake/CurveTet/CurveTetVTKTargets.cmake")
endif()
if(MESHLAB)
  # MeshLab's plugin folder under the prefix (/usr: where Debian's MeshLab looks).
  file(GLOB_RECURSE _plugin RELATIVE "${PREFIX}" "${PREFIX}/*/libfilter_curvetet.so")
  if(NOT _plugin MATCHES "^lib/([a-z0-9_]+-linux-gnu/)?meshlab/plugins/libfilter_curvetet.so$")
    message(FATAL_ERROR "the MeshLab plugin is not in <prefix>/lib/<multiarch>/meshlab/plugins: '${_plugin}'")
  endif()
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
# The command-line tool, installed and runnable (unless CURVETET_BUILD_CLI is OFF).
set(_stripped "${LIBDIR}/libcurvetet.a" "${LIBDIR}/${SONAME}")
if(CLI)
  execute_process(COMMAND "${PREFIX}/${BINDIR}/curvetet" --version
                  OUTPUT_VARIABLE _cli_version RESULT_VARIABLE _cli_rc)
  if(NOT _cli_rc EQUAL 0 OR NOT _cli_version MATCHES "curvetet ${VERSION}")
    message(FATAL_ERROR "${BINDIR}/curvetet --version: exit ${_cli_rc}, '${_cli_version}' "
                        "(expected curvetet ${VERSION})")
  endif()
  list(APPEND _stripped "${BINDIR}/curvetet")
elseif(EXISTS "${PREFIX}/${BINDIR}/curvetet")
  message(FATAL_ERROR "${BINDIR}/curvetet is installed although CURVETET_BUILD_CLI is OFF")
endif()
# Installed without debug info (cmake/CurveTetInstall.cmake strips it).
if(NOT READELF)
  message(FATAL_ERROR "install_prefix.cmake needs READELF (binutils' readelf)")
endif()
foreach(f IN LISTS _stripped)
  execute_process(COMMAND "${READELF}" --section-headers --wide "${PREFIX}/${f}"
                  OUTPUT_VARIABLE _sections RESULT_VARIABLE _rc)
  if(NOT _rc EQUAL 0 OR NOT _sections MATCHES "\\.text")
    message(FATAL_ERROR "readelf cannot read ${f} (exit ${_rc})")
  endif()
  if(_sections MATCHES "\\] +\\.debug_(info|line) ") # DWARF (not .debug_gdb_scripts)
    message(FATAL_ERROR "${f} is installed with debug info (it should be stripped)")
  endif()
endforeach()
# The shared library a host process loads stays small.
file(SIZE "${PREFIX}/${LIBDIR}/${SONAME}" _so_size)
if(_so_size GREATER_EQUAL 5000000)
  message(FATAL_ERROR "${LIBDIR}/${SONAME} is ${_so_size} bytes installed (budget: under 5 MB)")
endif()
if(NOT IS_SYMLINK "${PREFIX}/${LIBDIR}/libcurvetet.so")
  message(FATAL_ERROR "${LIBDIR}/libcurvetet.so should be a symlink to ${SONAME}")
endif()
file(READ_SYMLINK "${PREFIX}/${LIBDIR}/libcurvetet.so" _target)
if(NOT _target STREQUAL SONAME)
  message(FATAL_ERROR "${LIBDIR}/libcurvetet.so points to ${_target}, not ${SONAME}")
endif()
message(STATUS "installed into ${PREFIX}")
