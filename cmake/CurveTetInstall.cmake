# Install layout (relative to the prefix; libdir is GNUInstallDirs' CMAKE_INSTALL_LIBDIR,
# "lib" for prefixes other than /usr):
#   bin/curvetet               (the command-line tool, unless CURVETET_BUILD_CLI is OFF)
#   lib/libcurvetet.a          (libraries and tool without debug info: strip --strip-debug)
#   lib/libcurvetet.so.<abi>   (the shared library, under its SONAME)
#   lib/libcurvetet.so         -> libcurvetet.so.<abi>
#   include/curvetet.h
#   lib/cmake/CurveTet/CurveTetConfig.cmake, CurveTetConfigVersion.cmake
#   lib/pkgconfig/curvetet.pc
include(CMakePackageConfigHelpers)

set(CURVETET_CMAKE_DIR "${CMAKE_INSTALL_LIBDIR}/cmake/CurveTet")

if(CURVETET_BUILD_CLI)
  install(PROGRAMS "${CURVETET_EXECUTABLE}" DESTINATION "${CMAKE_INSTALL_BINDIR}")
endif()
install(FILES "${CURVETET_STATIC_LIBRARY}" DESTINATION "${CMAKE_INSTALL_LIBDIR}")
install(FILES "${CURVETET_SHARED_LIBRARY}" DESTINATION "${CMAKE_INSTALL_LIBDIR}"
        PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE
                    WORLD_READ WORLD_EXECUTE)
install(FILES "${CURVETET_SHARED_LINK}" DESTINATION "${CMAKE_INSTALL_LIBDIR}") # a symlink
install(FILES "${PROJECT_SOURCE_DIR}/include/curvetet.h" DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}")

# The installed libraries and tool carry no debug info: cargo's release profile keeps line
# tables (debug = 1) for profilers and backtraces in the build tree, which makes the
# libraries several times larger than their code. `strip --strip-debug` keeps the symbol
# table (and so the exported C functions and readable profiles).
if(NOT CMAKE_STRIP)
  message(FATAL_ERROR "no strip program found (binutils): the installed libraries must be stripped")
endif()
set(_strip_files "${CMAKE_INSTALL_LIBDIR}/libcurvetet.a" "${CMAKE_INSTALL_LIBDIR}/${CURVETET_SONAME}")
if(CURVETET_BUILD_CLI)
  list(APPEND _strip_files "${CMAKE_INSTALL_BINDIR}/curvetet")
endif()
foreach(_f IN LISTS _strip_files)
  install(CODE "
    set(_file \"${_f}\")
    if(NOT IS_ABSOLUTE \"\${_file}\")
      set(_file \"\${CMAKE_INSTALL_PREFIX}/\${_file}\")
    endif()
    execute_process(COMMAND \"${CMAKE_STRIP}\" --strip-debug \"\$ENV{DESTDIR}\${_file}\"
                    COMMAND_ERROR_IS_FATAL ANY)")
endforeach()

configure_package_config_file(
  "${PROJECT_SOURCE_DIR}/cmake/CurveTetConfig.cmake.in"
  "${PROJECT_BINARY_DIR}/CurveTetConfig.cmake"
  INSTALL_DESTINATION "${CURVETET_CMAKE_DIR}"
  PATH_VARS CMAKE_INSTALL_INCLUDEDIR CMAKE_INSTALL_LIBDIR)
# Before 1.0 a minor release may change the ABI (the SONAME says so too).
if(PROJECT_VERSION_MAJOR EQUAL 0)
  set(_compat SameMinorVersion)
else()
  set(_compat SameMajorVersion)
endif()
write_basic_package_version_file(
  "${PROJECT_BINARY_DIR}/CurveTetConfigVersion.cmake"
  VERSION "${PROJECT_VERSION}" COMPATIBILITY ${_compat})
install(FILES "${PROJECT_BINARY_DIR}/CurveTetConfig.cmake"
              "${PROJECT_BINARY_DIR}/CurveTetConfigVersion.cmake"
        DESTINATION "${CURVETET_CMAKE_DIR}")

# pkg-config: paths relative to the .pc file (${pcfiledir}), so the prefix can move.
if(IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}" OR IS_ABSOLUTE "${CMAKE_INSTALL_INCLUDEDIR}")
  set(CURVETET_PC_PREFIX "${CMAKE_INSTALL_PREFIX}")
  set(CURVETET_PC_LIBDIR "${CMAKE_INSTALL_FULL_LIBDIR}")
  set(CURVETET_PC_INCLUDEDIR "${CMAKE_INSTALL_FULL_INCLUDEDIR}")
else()
  file(RELATIVE_PATH _up "/p/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/p")
  string(REGEX REPLACE "/$" "" _up "${_up}")
  set(CURVETET_PC_PREFIX "\${pcfiledir}/${_up}")
  set(CURVETET_PC_LIBDIR "\${prefix}/${CMAKE_INSTALL_LIBDIR}")
  set(CURVETET_PC_INCLUDEDIR "\${prefix}/${CMAKE_INSTALL_INCLUDEDIR}")
endif()
set(CURVETET_PC_LIBS_PRIVATE "")
foreach(_l IN LISTS CURVETET_NATIVE_STATIC_LIBS)
  string(APPEND CURVETET_PC_LIBS_PRIVATE " -l${_l}")
endforeach()
string(STRIP "${CURVETET_PC_LIBS_PRIVATE}" CURVETET_PC_LIBS_PRIVATE)
configure_file("${PROJECT_SOURCE_DIR}/cmake/curvetet.pc.in" "${PROJECT_BINARY_DIR}/curvetet.pc" @ONLY)
install(FILES "${PROJECT_BINARY_DIR}/curvetet.pc" DESTINATION "${CMAKE_INSTALL_LIBDIR}/pkgconfig")
