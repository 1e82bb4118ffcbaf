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
