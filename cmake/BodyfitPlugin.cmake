# bodyfit_add_plugin(<name> <sources...>)
# Builds a velocity-model plugin as a MODULE library named bodyfit_<name>.so, linked against the
# core, placed where the driver searches for plugins and installed with it. The same function is
# exported in bodyfitConfig.cmake so third parties build plugins out of tree with one call.
#
# Installed plugins find libbodyfit_core from their own location: their RUNPATH is $ORIGIN followed
# by the way from the plugin directory to the library directory ($ORIGIN/../.. for
# <libdir>/bodyfit/plugins), so any program may dlopen them, and a moved prefix keeps working. Out
# of tree the directory of the installed libbodyfit_core is added too (INSTALL_RPATH_USE_LINK_PATH,
# unless it is a system directory), for a plugin installed to another prefix than bodyfit's.
#
# With no build type (CMAKE_BUILD_TYPE empty on a single-configuration generator) CMake compiles
# with no optimisation at all; the plugin then gets the Release flags (CMAKE_CXX_FLAGS_RELEASE).
# An explicit build type (Debug, RelWithDebInfo...) is used as given.
function(bodyfit_add_plugin name)
  set(target bodyfit_plugin_${name})
  add_library(${target} MODULE ${ARGN})
  if(TARGET bodyfit_core)
    target_link_libraries(${target} PRIVATE bodyfit_core)
    set(in_tree TRUE)
  else()
    target_link_libraries(${target} PRIVATE bodyfit::bodyfit_core)
    set(in_tree FALSE)
  endif()
  set_target_properties(${target} PROPERTIES
    PREFIX "" OUTPUT_NAME "bodyfit_${name}"
    CXX_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON)
  target_compile_options(${target} PRIVATE -Wall -Wextra)

  separate_arguments(release_flags UNIX_COMMAND "${CMAKE_CXX_FLAGS_RELEASE}")
  if(release_flags)
    target_compile_options(${target} PRIVATE "$<$<CONFIG:>:${release_flags}>")
  endif()

  if(DEFINED BODYFIT_PLUGIN_BUILD_DIR)
    set_target_properties(${target} PROPERTIES LIBRARY_OUTPUT_DIRECTORY ${BODYFIT_PLUGIN_BUILD_DIR})
  endif()
  if(DEFINED BODYFIT_PLUGIN_INSTALL_DIR)
    include(GNUInstallDirs)
    cmake_path(ABSOLUTE_PATH BODYFIT_PLUGIN_INSTALL_DIR BASE_DIRECTORY "${CMAKE_INSTALL_PREFIX}"
               NORMALIZE OUTPUT_VARIABLE plugin_dir)
    cmake_path(ABSOLUTE_PATH CMAKE_INSTALL_LIBDIR BASE_DIRECTORY "${CMAKE_INSTALL_PREFIX}"
               NORMALIZE OUTPUT_VARIABLE lib_dir)
    file(RELATIVE_PATH to_libdir "${plugin_dir}" "${lib_dir}")
    string(REGEX REPLACE "/+$" "" to_libdir "${to_libdir}")  # "../../" -> "../.."
    if(to_libdir STREQUAL "")
      set(rpath "$ORIGIN")
    else()
      set(rpath "$ORIGIN/${to_libdir}")
    endif()
    set_target_properties(${target} PROPERTIES INSTALL_RPATH "${rpath}")
    if(NOT in_tree)
      set_target_properties(${target} PROPERTIES INSTALL_RPATH_USE_LINK_PATH ON)
    endif()
    install(TARGETS ${target} LIBRARY DESTINATION ${BODYFIT_PLUGIN_INSTALL_DIR})
  endif()
endfunction()
