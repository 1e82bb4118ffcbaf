include(CMakePackageConfigHelpers)
# The public headers only: the engine's (core/include) and the application library's (app/include);
# core/internal stays in the tree. config.hpp.in stays in the source tree, its config.hpp is installed.
foreach(part core app)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${part}/include/bodyfit DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
          FILES_MATCHING PATTERN "*.hpp" PATTERN "*.h")
endforeach()
install(FILES ${PROJECT_BINARY_DIR}/core/include/bodyfit/config.hpp DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/bodyfit)
install(FILES ${PROJECT_BINARY_DIR}/app/include/bodyfit/app/config.hpp
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/bodyfit/app)
install(EXPORT bodyfitTargets NAMESPACE bodyfit:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/bodyfit)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/bodyfitConfig.cmake.in
  ${PROJECT_BINARY_DIR}/bodyfitConfig.cmake INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/bodyfit)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/bodyfitConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/bodyfitConfig.cmake ${PROJECT_BINARY_DIR}/bodyfitConfigVersion.cmake
        ${PROJECT_SOURCE_DIR}/cmake/BodyfitPlugin.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/bodyfit)

# pkg-config files (for builds without CMake): the engine and the application library, relocatable
# (prefix from the .pc file's own place: <libdir>/pkgconfig), like the rest of an install.
foreach(dir LIBDIR INCLUDEDIR)
  if(IS_ABSOLUTE "${CMAKE_INSTALL_${dir}}")
    set(BODYFIT_PC_${dir} "${CMAKE_INSTALL_${dir}}")
  else()
    set(BODYFIT_PC_${dir} "\${prefix}/${CMAKE_INSTALL_${dir}}")
  endif()
endforeach()
set(BODYFIT_PC_PLUGINDIR "\${libdir}/bodyfit/plugins")
foreach(pc bodyfit bodyfit-app)
  configure_file(${PROJECT_SOURCE_DIR}/cmake/${pc}.pc.in ${PROJECT_BINARY_DIR}/${pc}.pc @ONLY)
  install(FILES ${PROJECT_BINARY_DIR}/${pc}.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
endforeach()

# What users need beside the programs: the example cases with their DEMs and parts, the fuel
# tables the fire model compiles in (to copy and edit), the example
# plugins (share/bodyfit, where `bodyfit --help` points), the manual and the licences
# (share/doc/bodyfit), the man page and the bash completion the driver writes of itself.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/meshes/cases ${PROJECT_SOURCE_DIR}/meshes/dem ${PROJECT_SOURCE_DIR}/meshes/parts
                  ${PROJECT_SOURCE_DIR}/examples
        DESTINATION ${CMAKE_INSTALL_DATADIR}/bodyfit)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/plugins/fire/fuels DESTINATION ${CMAKE_INSTALL_DATADIR}/bodyfit)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(FILES ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/LICENSE DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(FILES ${PROJECT_SOURCE_DIR}/plugins/thermal/LICENSE DESTINATION ${CMAKE_INSTALL_DOCDIR}
        RENAME LICENSE.thermal-plugin)
install(FILES ${PROJECT_BINARY_DIR}/share/man/man1/bodyfit.1 DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
install(FILES ${PROJECT_BINARY_DIR}/share/bash-completion/completions/bodyfit
        DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions)
