# oscar_add_module(NAME <type> SOURCES <kernel sources...> [TEST <test sources...>] [LIBS <libs...>]
#                  [IDL <idl files...>])
# Builds a module type: the plugin liboscar_kernel_<type>.so that oscar-run loads, a stand-alone
# runner oscar-module-<type> (oscar-run with the kernel linked in), and, when TEST is given and
# testing is on, its unit test. Works in this repository and against an installed OSCAR.
function(oscar_add_module)
  cmake_parse_arguments(A "" "NAME" "SOURCES;TEST;TEST_LIBS;LIBS;IDL" ${ARGN})
  if(NOT A_NAME MATCHES "^[A-Za-z_][A-Za-z0-9_]*$")
    message(FATAL_ERROR "oscar_add_module: NAME '${A_NAME}' must be an identifier")
  endif()
  set(objects oscar_kernel_${A_NAME}_objects)
  add_library(${objects} OBJECT ${A_SOURCES})
  target_link_libraries(${objects} PUBLIC oscar::framework ${A_LIBS})
  target_include_directories(${objects} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR})
  set_target_properties(${objects} PROPERTIES POSITION_INDEPENDENT_CODE ON)  # for the plugin
  if(A_IDL)
    oscar_generate_idl(${objects} IDL ${A_IDL} SUBDIR ${A_NAME})
  endif()
  if(COMMAND oscar_warnings)
    oscar_warnings(${objects})
  endif()

  add_library(oscar_kernel_${A_NAME} MODULE $<TARGET_OBJECTS:${objects}>)
  target_link_libraries(oscar_kernel_${A_NAME} PRIVATE ${objects})
  set_target_properties(oscar_kernel_${A_NAME} PROPERTIES
    PREFIX "lib" OUTPUT_NAME oscar_kernel_${A_NAME}
    LIBRARY_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/lib/oscar/plugins)

  add_executable(oscar-module-${A_NAME} $<TARGET_OBJECTS:${objects}>)
  target_link_libraries(oscar-module-${A_NAME} PRIVATE ${objects} oscar::run_main)
  set_target_properties(oscar-module-${A_NAME} PROPERTIES
    RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bin)

  if(A_TEST AND (OSCAR_BUILD_TESTS OR NOT DEFINED OSCAR_BUILD_TESTS))
    find_package(GTest REQUIRED)
    include(GoogleTest)
    add_executable(oscar_kernel_${A_NAME}_test ${A_TEST} $<TARGET_OBJECTS:${objects}>)
    target_link_libraries(oscar_kernel_${A_NAME}_test PRIVATE ${objects} oscar::testing ${A_TEST_LIBS}
                          GTest::gtest GTest::gtest_main GTest::gmock)
    if(COMMAND oscar_warnings)
      oscar_warnings(oscar_kernel_${A_NAME}_test)
    endif()
    gtest_discover_tests(oscar_kernel_${A_NAME}_test DISCOVERY_TIMEOUT 60
      PROPERTIES LABELS "unit" TIMEOUT 120)
  endif()

  if(NOT OSCAR_OUT_OF_TREE)
    install(TARGETS oscar_kernel_${A_NAME} LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}/oscar/plugins)
    install(TARGETS oscar-module-${A_NAME} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  endif()
endfunction()

# oscar_add_system_test(NAME <test> SOURCES <sources...> SYSTEM <system.yaml> [LIBS <libs...>]
#                       [LABELS <labels...>] [TIMEOUT <seconds>] [DEPENDS <targets...>])
# A GoogleTest program whose tests boot a whole system (oscar::testing::BootedSystem,
# docs/testing.md), each test registered with ctest under LABELS (default "system") and TIMEOUT
# (default 120 s). BootedSystem::boot() without a file boots SYSTEM; the tests find OSCAR's
# programs ($OSCAR_BIN_DIR) and the plugins this project builds ($OSCAR_PLUGIN_PATH). DEPENDS
# names targets to build first (in the OSCAR repository: the plugins the system loads).
function(oscar_add_system_test)
  cmake_parse_arguments(A "" "NAME;SYSTEM;TIMEOUT" "SOURCES;LIBS;LABELS;DEPENDS" ${ARGN})
  if(NOT A_NAME MATCHES "^[A-Za-z_][A-Za-z0-9_]*$")
    message(FATAL_ERROR "oscar_add_system_test: NAME '${A_NAME}' must be an identifier")
  endif()
  if(NOT A_SOURCES)
    message(FATAL_ERROR "oscar_add_system_test(${A_NAME}): SOURCES is missing")
  endif()
  if(NOT A_SYSTEM)
    message(FATAL_ERROR "oscar_add_system_test(${A_NAME}): SYSTEM (the system file) is missing")
  endif()
  get_filename_component(system "${A_SYSTEM}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  if(NOT EXISTS "${system}")
    message(FATAL_ERROR "oscar_add_system_test(${A_NAME}): SYSTEM file '${system}' does not exist")
  endif()
  if(DEFINED OSCAR_BUILD_TESTS AND NOT OSCAR_BUILD_TESTS)
    return()
  endif()
  if(NOT A_LABELS)
    set(A_LABELS system)
  endif()
  if(NOT A_TIMEOUT)
    set(A_TIMEOUT 120)
  endif()
  if(OSCAR_OUT_OF_TREE)
    set(programs "${OSCAR_BIN_DIR}")
  else()
    set(programs "${PROJECT_BINARY_DIR}/bin")
  endif()
  find_package(GTest REQUIRED)
  include(GoogleTest)
  add_executable(${A_NAME} ${A_SOURCES})
  target_link_libraries(${A_NAME} PRIVATE oscar::testing ${A_LIBS} GTest::gtest GTest::gtest_main
                        GTest::gmock)
  if(COMMAND oscar_warnings)
    oscar_warnings(${A_NAME})
  endif()
  if(NOT OSCAR_OUT_OF_TREE)
    add_dependencies(${A_NAME} oscar-boot oscar-registry oscar-monitor oscar-run)
  endif()
  if(A_DEPENDS)
    add_dependencies(${A_NAME} ${A_DEPENDS})
  endif()
  gtest_discover_tests(${A_NAME} DISCOVERY_TIMEOUT 60 PROPERTIES TIMEOUT ${A_TIMEOUT})
  # Labels and environment by a file ctest reads after the discovered tests (list-valued
  # PROPERTIES of gtest_discover_tests are flattened).
  set(file "${CMAKE_CURRENT_BINARY_DIR}/${A_NAME}_properties.cmake")
  file(WRITE "${file}"
       "if(${A_NAME}_TESTS)\n"
       "  set_tests_properties(\${${A_NAME}_TESTS} PROPERTIES LABELS \"${A_LABELS}\"\n"
       "    ENVIRONMENT \"OSCAR_BIN_DIR=${programs};OSCAR_TEST_SYSTEM=${system};"
       "OSCAR_PLUGIN_PATH=${CMAKE_BINARY_DIR}/lib/oscar/plugins\")\n"
       "endif()\n")
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES "${file}")
endfunction()
