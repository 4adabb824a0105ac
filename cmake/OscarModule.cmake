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
