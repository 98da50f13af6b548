# Build the Rust library with cargo and expose it as imported targets, in the build tree:
#   CurveTet::curvetet         the shared library (libcurvetet.so, SONAME libcurvetet.so.<abi>)
#   CurveTet::curvetet_static  the static library, with the system libraries it needs
# Both carry the include directory of curvetet.h. The library files are copied from cargo's
# target directory into <build>/lib (the shared one under its SONAME, plus the
# libcurvetet.so link), which is also what gets installed, and the command-line tool into
# <build>/bin/curvetet (CURVETET_EXECUTABLE, installed into <prefix>/bin; the option
# CURVETET_BUILD_CLI=OFF leaves it out).

if(NOT CMAKE_SYSTEM_NAME STREQUAL "Linux")
  message(FATAL_ERROR "curvetet's CMake build supports Linux only for now (library names, SONAME, system libraries)")
endif()

find_program(CARGO_EXECUTABLE cargo HINTS "$ENV{CARGO_HOME}/bin" "$ENV{HOME}/.cargo/bin" REQUIRED)
find_program(RUSTC_EXECUTABLE rustc HINTS "$ENV{CARGO_HOME}/bin" "$ENV{HOME}/.cargo/bin" REQUIRED)

if(DEFINED ENV{CARGO_TARGET_DIR} AND NOT "$ENV{CARGO_TARGET_DIR}" STREQUAL "")
  set(_curvetet_default_target_dir "$ENV{CARGO_TARGET_DIR}")
else()
  set(_curvetet_default_target_dir "${CMAKE_BINARY_DIR}/cargo")
endif()
set(CURVETET_CARGO_TARGET_DIR "${_curvetet_default_target_dir}" CACHE PATH
    "cargo's target directory (default: $CARGO_TARGET_DIR, else <build>/cargo)")

# The shared library's ABI version, as build.rs sets the SONAME: the major version, or
# 0.minor before 1.0.
if(PROJECT_VERSION_MAJOR EQUAL 0)
  set(CURVETET_ABI_VERSION "0.${PROJECT_VERSION_MINOR}")
else()
  set(CURVETET_ABI_VERSION "${PROJECT_VERSION_MAJOR}")
endif()
set(CURVETET_SONAME "libcurvetet.so.${CURVETET_ABI_VERSION}")

# System libraries a Rust static library needs. rustc prints them with
# --print native-static-libs; asking cargo (`cargo rustc -- --print native-static-libs`)
# would recompile the whole crate with different flags, so we ask rustc about an empty
# static library instead: the set comes from Rust's std, and curvetet's dependencies are
# pure Rust (they add none; the static link tests would fail if one did). Linux fallback:
# the set rustc has printed for years.
if(NOT DEFINED CACHE{CURVETET_NATIVE_STATIC_LIBS})
  set(_probe_dir "${CMAKE_BINARY_DIR}/native-static-libs-probe")
  file(MAKE_DIRECTORY "${_probe_dir}")
  file(WRITE "${_probe_dir}/probe.rs" "")
  execute_process(
    COMMAND "${RUSTC_EXECUTABLE}" --crate-type staticlib --crate-name probe
            --print native-static-libs -o "${_probe_dir}/libprobe.a" "${_probe_dir}/probe.rs"
    RESULT_VARIABLE _probe_rc OUTPUT_VARIABLE _probe_out ERROR_VARIABLE _probe_err)
  string(REGEX MATCH "native-static-libs: ([^\n]*)" _probe_match "${_probe_out}${_probe_err}")
  set(_libs "")
  if(_probe_rc EQUAL 0 AND CMAKE_MATCH_1)
    separate_arguments(_flags UNIX_COMMAND "${CMAKE_MATCH_1}")
    foreach(_f IN LISTS _flags)
      if(_f MATCHES "^-l(.+)$")
        list(APPEND _libs "${CMAKE_MATCH_1}")
      endif()
    endforeach()
  endif()
  if(NOT _libs)
    message(WARNING "rustc --print native-static-libs failed; using the usual Linux set")
    set(_libs gcc_s util rt pthread m dl c)
  endif()
  set(CURVETET_NATIVE_STATIC_LIBS "${_libs}" CACHE STRING
      "System libraries the static curvetet library needs (from rustc --print native-static-libs)")
  file(REMOVE_RECURSE "${_probe_dir}")
endif()
message(STATUS "curvetet: static library needs: ${CURVETET_NATIVE_STATIC_LIBS}")

# The command-line tool needs the cargo feature `cli` (on by default: its argument parser
# and progress bar); the C library is built without it (--no-default-features), so that it
# compiles none of the tool's crates. The two builds use two target directories: cargo
# keeps one copy of a package's cdylib/staticlib per target directory, and building the
# library with and without the feature (the tool's build and `cargo test` build it with)
# in one directory would compile it again at every switch.
set(_cargo_lib_target_dir "${CURVETET_CARGO_TARGET_DIR}/no-default-features")
set(_cargo_out "${_cargo_lib_target_dir}/release")
set(CURVETET_LIBRARY_DIR "${CMAKE_BINARY_DIR}/lib")
set(CURVETET_STATIC_LIBRARY "${CURVETET_LIBRARY_DIR}/libcurvetet.a")
set(CURVETET_SHARED_LIBRARY "${CURVETET_LIBRARY_DIR}/${CURVETET_SONAME}")
set(CURVETET_SHARED_LINK "${CURVETET_LIBRARY_DIR}/libcurvetet.so")
set(CURVETET_EXECUTABLE "${CMAKE_BINARY_DIR}/bin/curvetet")
file(MAKE_DIRECTORY "${CURVETET_LIBRARY_DIR}" "${CMAKE_BINARY_DIR}/bin")

option(CURVETET_BUILD_CLI "Build and install the command-line tool (bin/curvetet)" ON)

set(_cargo_build "${CARGO_EXECUTABLE}" build --release --quiet
                 --manifest-path "${PROJECT_SOURCE_DIR}/Cargo.toml")
set(_cli_commands "")
set(_cli_byproducts "")
if(CURVETET_BUILD_CLI)
  set(_cli_commands
    COMMAND "${CMAKE_COMMAND}" -E env "CARGO_TARGET_DIR=${CURVETET_CARGO_TARGET_DIR}"
            ${_cargo_build} --bin curvetet
    COMMAND "${CMAKE_COMMAND}" -E copy_if_different "${CURVETET_CARGO_TARGET_DIR}/release/curvetet"
            "${CURVETET_EXECUTABLE}")
  set(_cli_byproducts "${CURVETET_EXECUTABLE}")
endif()

# Always ask cargo (it knows the Rust dependencies exactly and does nothing when the
# library is up to date); copy only when the files changed, so C targets relink only then.
add_custom_target(curvetet_cargo ALL
  COMMAND "${CMAKE_COMMAND}" -E env "CARGO_TARGET_DIR=${_cargo_lib_target_dir}"
          ${_cargo_build} --lib --no-default-features
  COMMAND "${CMAKE_COMMAND}" -E copy_if_different "${_cargo_out}/libcurvetet.a" "${CURVETET_STATIC_LIBRARY}"
  COMMAND "${CMAKE_COMMAND}" -E copy_if_different "${_cargo_out}/libcurvetet.so" "${CURVETET_SHARED_LIBRARY}"
  COMMAND "${CMAKE_COMMAND}" -E create_symlink "${CURVETET_SONAME}" "${CURVETET_SHARED_LINK}"
  ${_cli_commands}
  BYPRODUCTS "${CURVETET_STATIC_LIBRARY}" "${CURVETET_SHARED_LIBRARY}" "${CURVETET_SHARED_LINK}"
             ${_cli_byproducts}
  WORKING_DIRECTORY "${PROJECT_SOURCE_DIR}"
  COMMENT "cargo build --release (curvetet: the library without default features, the tool)"
  USES_TERMINAL
  VERBATIM)

add_library(curvetet SHARED IMPORTED GLOBAL)
set_target_properties(curvetet PROPERTIES
  IMPORTED_LOCATION "${CURVETET_SHARED_LIBRARY}"
  IMPORTED_SONAME "${CURVETET_SONAME}"
  INTERFACE_INCLUDE_DIRECTORIES "${PROJECT_SOURCE_DIR}/include")
add_dependencies(curvetet curvetet_cargo)
add_library(CurveTet::curvetet ALIAS curvetet)

add_library(curvetet_static STATIC IMPORTED GLOBAL)
set_target_properties(curvetet_static PROPERTIES
  IMPORTED_LOCATION "${CURVETET_STATIC_LIBRARY}"
  IMPORTED_LINK_INTERFACE_LANGUAGES "C"
  INTERFACE_INCLUDE_DIRECTORIES "${PROJECT_SOURCE_DIR}/include"
  INTERFACE_LINK_LIBRARIES "${CURVETET_NATIVE_STATIC_LIBS}")
add_dependencies(curvetet_static curvetet_cargo)
add_library(CurveTet::curvetet_static ALIAS curvetet_static)
