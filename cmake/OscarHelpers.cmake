# Build helpers shared by every folder: warnings, sanitizers, libraries, tests, executables.

# Sanitizer builds compile at -O1 with line tables only (-g1): enough for symbolized reports, and
# half the compile time of -O2 -g. UBSan's null and alignment checks are left out: they instrument
# every pointer access in Fast DDS's header templates and made a translation unit 2.5x slower to
# compile; a null access still faults and ASan reports it with its stack, and x86 tolerates
# misalignment.
if(OSCAR_SANITIZE STREQUAL "address")
  add_compile_options(-O1 -g1 -fsanitize=address,undefined -fno-sanitize=null,alignment
                      -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
elseif(OSCAR_SANITIZE STREQUAL "thread")
  add_compile_options(-O1 -g1 -fsanitize=thread -fno-omit-frame-pointer)
  add_link_options(-fsanitize=thread)
elseif(NOT OSCAR_SANITIZE STREQUAL "")
  message(FATAL_ERROR "OSCAR_SANITIZE='${OSCAR_SANITIZE}': use '', 'address' or 'thread'")
endif()

# With debug information ccache keys every object on the compiler's working directory too, unless
# the debug information names paths relative to the checkout: then a clone at another path (CI's)
# reuses the objects of this one.
if(NOT OSCAR_SANITIZE STREQUAL "" OR CMAKE_BUILD_TYPE MATCHES "Deb")
  add_compile_options(-fdebug-prefix-map=${PROJECT_SOURCE_DIR}=.)
endif()

# Warnings for OSCAR's own code (generated and third-party code is compiled without them).
function(oscar_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow)
  if(OSCAR_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

# oscar_add_library(NAME <name> ALIAS <ns::name> SOURCES ... [PUBLIC ...] [PRIVATE ...] [EXPORT])
# A library with include/ as its public include directory.
function(oscar_add_library)
  cmake_parse_arguments(A "SHARED;EXPORT" "NAME;ALIAS" "SOURCES;PUBLIC;PRIVATE" ${ARGN})
  if(A_SHARED)
    add_library(${A_NAME} SHARED ${A_SOURCES})
  else()
    add_library(${A_NAME} STATIC ${A_SOURCES})
  endif()
  if(A_ALIAS)
    add_library(${A_ALIAS} ALIAS ${A_NAME})
  endif()
  target_include_directories(${A_NAME} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(${A_NAME} PUBLIC ${A_PUBLIC} PRIVATE ${A_PRIVATE})
  oscar_warnings(${A_NAME})
endfunction()

# oscar_add_executable(NAME <name> SOURCES ... [LIBS ...]): a program in build/bin.
function(oscar_add_executable)
  cmake_parse_arguments(A "" "NAME" "SOURCES;LIBS" ${ARGN})
  add_executable(${A_NAME} ${A_SOURCES})
  target_link_libraries(${A_NAME} PRIVATE ${A_LIBS})
  oscar_warnings(${A_NAME})
endfunction()

# oscar_add_test(NAME <name> SOURCES ... [LIBS ...] [LABELS ...] [TIMEOUT s] [SERIAL test...])
# One GoogleTest executable per folder, each test registered with gtest_discover_tests. Tests run
# in parallel (ctest -j) on domains of their own (test_domain()); the SERIAL ones run alone,
# for what they look at is the whole machine (e.g. every system booted on it).
function(oscar_add_test)
  cmake_parse_arguments(A "" "NAME;TIMEOUT" "SOURCES;LIBS;LABELS;SERIAL" ${ARGN})
  if(NOT OSCAR_BUILD_TESTS)
    return()
  endif()
  if(NOT A_TIMEOUT)
    set(A_TIMEOUT 120)
  endif()
  add_executable(${A_NAME} ${A_SOURCES})
  set_target_properties(${A_NAME} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests)
  target_link_libraries(${A_NAME} PRIVATE ${A_LIBS} GTest::gtest GTest::gtest_main GTest::gmock)
  oscar_warnings(${A_NAME})
  gtest_discover_tests(${A_NAME}
    DISCOVERY_TIMEOUT 60
    PROPERTIES TIMEOUT ${A_TIMEOUT})
  # Labels and the environment are set by a file ctest reads after the discovered tests:
  # gtest_discover_tests flattens list-valued PROPERTIES, so "LABELS unit;swarm" there became
  # LABELS=unit plus a property named "swarm", and `ctest -L swarm` missed every unit test.
  # OSCAR_BIN_DIR is where oscar::testing::SystemUnderTest finds oscar-boot.
  set(label_file "${CMAKE_CURRENT_BINARY_DIR}/${A_NAME}_labels.cmake")
  file(WRITE "${label_file}"
       "if(${A_NAME}_TESTS)\n"
       "  set_tests_properties(\${${A_NAME}_TESTS} PROPERTIES LABELS \"${A_LABELS}\"\n"
       "    ENVIRONMENT \"OSCAR_BUILD_DIR=${PROJECT_BINARY_DIR};OSCAR_BIN_DIR=${PROJECT_BINARY_DIR}/bin\")\n"
       "endif()\n")
  foreach(test ${A_SERIAL})
    file(APPEND "${label_file}"
         "list(FIND ${A_NAME}_TESTS \"${test}\" serial_index)\n"
         "if(NOT serial_index EQUAL -1)\n"
         "  set_tests_properties(\"${test}\" PROPERTIES RUN_SERIAL TRUE)\n"
         "endif()\n")
  endforeach()
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES "${label_file}")
endfunction()
