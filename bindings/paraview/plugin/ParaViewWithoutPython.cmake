# Lets paraview-dev's CMake package load, and a plugin build, without python3-paraview
# installed.
#
# On Debian 12, python3-paraview (pvpython, ParaView's Python modules) conflicts with
# python3-vtk9, which libvtk9-dev (bindings/vtk) depends on, so one system cannot have both.
# paraview-dev's exported-target files check that every imported file exists, among them
# those python3-paraview ships (its Python extension modules, bin/pvpython). A C++ filter
# plugin links none of them. For each exported-target file of the package with a missing
# imported file, this defines all of that file's targets as empty imported stand-ins
# beforehand, so the file skips itself (exported-target files return early when all their
# targets exist). With python3-paraview installed, nothing is defined.
#
# curvetet_paraview_stand_in_missing(<folder of paraview-config.cmake>)
function(curvetet_paraview_stand_in_missing pv_dir)
  file(GLOB _target_files "${pv_dir}/*-targets.cmake" "${pv_dir}/vtk/*-targets.cmake")
  foreach(_file IN LISTS _target_files)
    # The install prefix as the file computes it: its folder, then one level up per line
    # get_filename_component(_IMPORT_PREFIX "${_IMPORT_PREFIX}" PATH).
    get_filename_component(_prefix "${_file}" DIRECTORY)
    file(STRINGS "${_file}" _ups REGEX "^ *get_filename_component\\(_IMPORT_PREFIX \"\\\${_IMPORT_PREFIX}\" PATH\\)")
    foreach(_up IN LISTS _ups)
      get_filename_component(_prefix "${_prefix}" DIRECTORY)
    endforeach()
    string(REGEX REPLACE "\\.cmake$" "-*.cmake" _config_glob "${_file}")
    file(GLOB _config_files "${_config_glob}")
    set(_missing "")
    foreach(_config IN LISTS _config_files)
      file(STRINGS "${_config}" _checks REGEX "_cmake_import_check_files_for_")
      foreach(_check IN LISTS _checks)
        if(_check MATCHES "\"\\\${_IMPORT_PREFIX}([^\"]*)\"")
          if(NOT EXISTS "${_prefix}${CMAKE_MATCH_1}")
            list(APPEND _missing "${_prefix}${CMAKE_MATCH_1}")
          endif()
        endif()
      endforeach()
    endforeach()
    if(NOT _missing)
      continue()
    endif()
    file(STRINGS "${_file}" _line REGEX "^foreach\\(_cmake_expected_target IN ITEMS ")
    string(REGEX REPLACE "^foreach\\(_cmake_expected_target IN ITEMS (.*)\\)$" "\\1"
           _targets "${_line}")
    separate_arguments(_targets)
    foreach(_target IN LISTS _targets)
      if(NOT TARGET "${_target}")
        add_library("${_target}" INTERFACE IMPORTED)
      endif()
    endforeach()
    list(LENGTH _targets _n)
    list(GET _missing 0 _first)
    get_filename_component(_name "${_file}" NAME)
    message(STATUS "curvetet: ${_name}: ${_n} stand-in targets (missing: ${_first} "
                   "and others; python3-paraview not installed)")
  endforeach()
endfunction()

# python3-paraview also ships the wrapping hierarchy files of ParaView's VTK modules
# (lib/<multiarch>/vtk/hierarchy/ParaView/), which the client-server wrapping of a plugin
# reads. Without the package installed they are taken from a copy of it unpacked under
# <root> (scripts/fetch-paraview-python): each imported module's hierarchy file that is
# missing is looked up as <root><its path>.
#
# curvetet_paraview_hierarchy_from(<root>)
function(curvetet_paraview_hierarchy_from root)
  get_property(_targets DIRECTORY PROPERTY IMPORTED_TARGETS)
  set(_n 0)
  foreach(_target IN LISTS _targets)
    get_property(_file TARGET "${_target}" PROPERTY INTERFACE_vtk_module_hierarchy)
    if(_file AND NOT EXISTS "${_file}")
      if(NOT EXISTS "${root}${_file}")
        message(FATAL_ERROR "${_target}: no wrapping hierarchy file ${_file}, nor "
                            "'${root}${_file}': install python3-paraview, or unpack it with "
                            "scripts/fetch-paraview-python and set "
                            "CURVETET_PARAVIEW_PYTHON_ROOT to the folder it prints")
      endif()
      set_property(TARGET "${_target}" PROPERTY INTERFACE_vtk_module_hierarchy "${root}${_file}")
      math(EXPR _n "${_n} + 1")
    endif()
  endforeach()
  if(_n)
    message(STATUS "curvetet: ${_n} wrapping hierarchy files from ${root}")
  endif()
endfunction()
