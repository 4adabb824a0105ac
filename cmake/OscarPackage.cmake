# The installed package: find_package(oscar) gives oscar::framework, oscar::types,
# oscar::run_main, oscar::testing, the IDL generator and oscar_add_module().
include(CMakePackageConfigHelpers)

install(TARGETS oscar_types oscar_framework oscar_run_main oscar_testing oscar_command_line
  EXPORT oscarTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/framework/include/oscar DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT oscarTargets NAMESPACE oscar:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/oscar)

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/oscarConfig.cmake.in
  ${PROJECT_BINARY_DIR}/oscarConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/oscar)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/oscarConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES
  ${PROJECT_BINARY_DIR}/oscarConfig.cmake
  ${PROJECT_BINARY_DIR}/oscarConfigVersion.cmake
  ${PROJECT_SOURCE_DIR}/cmake/OscarIdl.cmake
  ${PROJECT_SOURCE_DIR}/cmake/OscarModule.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/oscar)
