# bodyfit_add_plugin(<name> <sources...>)
# Builds a velocity-model plugin as a MODULE library named bodyfit_<name>.so, linked against the
# core, placed where the driver searches for plugins and installed with it. The same function is
# exported in bodyfitConfig.cmake so third parties build plugins out of tree with one call.
function(bodyfit_add_plugin name)
  set(target bodyfit_plugin_${name})
  add_library(${target} MODULE ${ARGN})
  if(TARGET bodyfit_core)
    target_link_libraries(${target} PRIVATE bodyfit_core)
  else()
    target_link_libraries(${target} PRIVATE bodyfit::bodyfit_core)
  endif()
  set_target_properties(${target} PROPERTIES
    PREFIX "" OUTPUT_NAME "bodyfit_${name}"
    CXX_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON)
  target_compile_options(${target} PRIVATE -Wall -Wextra)
  if(DEFINED BODYFIT_PLUGIN_BUILD_DIR)
    set_target_properties(${target} PROPERTIES LIBRARY_OUTPUT_DIRECTORY ${BODYFIT_PLUGIN_BUILD_DIR})
  endif()
  if(DEFINED BODYFIT_PLUGIN_INSTALL_DIR)
    install(TARGETS ${target} LIBRARY DESTINATION ${BODYFIT_PLUGIN_INSTALL_DIR})
  endif()
endfunction()
