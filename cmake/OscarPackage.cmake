# The installed package: find_package(oscar) gives oscar::framework, oscar::types,
# oscar::run_main, oscar::registry, oscar::testing (with the system-test fixture), the IDL
# generator, oscar_add_module() and oscar_add_system_test().
include(CMakePackageConfigHelpers)

install(TARGETS oscar_types oscar_plain_types oscar_framework oscar_run_main oscar_testing oscar_command_line
  oscar_registry
  EXPORT oscarTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/framework/include/oscar ${PROJECT_SOURCE_DIR}/registry/include/oscar
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT oscarTargets NAMESPACE oscar:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/oscar)
# The build tree is a package as well: -DCMAKE_PREFIX_PATH=<this build folder> finds it without
# an install (its targets point into the source and build trees).
export(EXPORT oscarTargets NAMESPACE oscar:: FILE ${PROJECT_BINARY_DIR}/oscarTargets.cmake)
configure_file(${PROJECT_SOURCE_DIR}/cmake/OscarIdl.cmake ${PROJECT_BINARY_DIR}/OscarIdl.cmake
  COPYONLY)
configure_file(${PROJECT_SOURCE_DIR}/cmake/OscarModule.cmake ${PROJECT_BINARY_DIR}/OscarModule.cmake
  COPYONLY)

file(WRITE ${PROJECT_BINARY_DIR}/oscarBuildTree.cmake
  "set(OSCAR_BIN_DIR \"${PROJECT_BINARY_DIR}/bin\")\n"
  "set(OSCAR_IDL_DIR \"${OSCAR_IDL_DIR}\")\n")
# Where a module's own IDL finds OSCAR's (#include "oscar/cue_header.idl").
set(OSCAR_INSTALL_IDL_DIR ${CMAKE_INSTALL_DATADIR}/oscar/idl)

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/oscarConfig.cmake.in
  ${PROJECT_BINARY_DIR}/oscarConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/oscar
  PATH_VARS CMAKE_INSTALL_BINDIR OSCAR_INSTALL_IDL_DIR)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/oscarConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES
  ${PROJECT_BINARY_DIR}/oscarConfig.cmake
  ${PROJECT_BINARY_DIR}/oscarConfigVersion.cmake
  ${PROJECT_SOURCE_DIR}/cmake/OscarIdl.cmake
  ${PROJECT_SOURCE_DIR}/cmake/OscarModule.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/oscar)
