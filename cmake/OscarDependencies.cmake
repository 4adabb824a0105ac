# Every dependency is found once, here. Odd ones are wrapped in imported targets.

find_package(Threads REQUIRED)
find_package(yaml-cpp REQUIRED)
find_package(CLI11 REQUIRED)
find_package(fmt REQUIRED)
find_package(spdlog REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(Boost 1.74 REQUIRED COMPONENTS graph)
find_package(tl-expected REQUIRED)

# Debian's OMPL 1.5 exports only variables (OMPL_INCLUDE_DIRS, OMPL_LIBRARIES), and its
# OMPL_LIBRARIES names libboost_filesystem.so, which only libboost-filesystem-dev provides.
# libompl.so records its own Boost dependencies, so linking it alone is enough.
find_package(ompl REQUIRED)
if(NOT TARGET oscar_deps::ompl)
  list(GET OMPL_LIBRARIES 0 OSCAR_OMPL_LIBRARY)
  add_library(oscar_deps::ompl INTERFACE IMPORTED)
  target_include_directories(oscar_deps::ompl SYSTEM INTERFACE ${OMPL_INCLUDE_DIRS})
  target_link_libraries(oscar_deps::ompl INTERFACE ${OSCAR_OMPL_LIBRARY} Boost::boost)
endif()

# GoogleTest also without the tests: oscar::testing (the kernel conformance suite and the
# booted-system fixture for modules' own tests) is part of the installed package.
find_package(GTest REQUIRED)
if(OSCAR_BUILD_TESTS)
  include(GoogleTest)
endif()

if(OSCAR_WITH_FRAMEWORK)
  # Fast DDS 2.9 as Debian ships it: the CMake package is fastrtps (targets fastrtps, fastcdr).
  find_package(fastcdr REQUIRED)
  find_package(fastrtps 2.9 REQUIRED)
  find_program(OSCAR_FASTDDSGEN fastddsgen REQUIRED)
  find_package(OpenCV 4 REQUIRED COMPONENTS core imgproc imgcodecs videoio)
  find_package(apriltag REQUIRED)
  # The keystore tool (oscar security) makes keys, certificates and S/MIME signatures with it;
  # modules read their trusted identities' certificates with it (dds/writer_identity.cpp).
  find_package(OpenSSL 3 REQUIRED COMPONENTS Crypto)
  find_package(PkgConfig REQUIRED)
  pkg_check_modules(ZSTD REQUIRED IMPORTED_TARGET libzstd)
  pkg_check_modules(LZ4 REQUIRED IMPORTED_TARGET liblz4)
  # The zero-copy path (docs/zero_copy.md) where Debian's libiceoryx-posh-dev is installed.
  find_package(iceoryx_posh CONFIG QUIET)
endif()
