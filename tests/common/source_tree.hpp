#pragma once

// Where tests and benchmarks find the checkout's files and the build tree's. The two paths are
// compiled into one small generated file (source_tree.cpp.in), not passed as compile
// definitions: an absolute path on the compiler's command line made every object of the target
// a compiler-cache miss in another clone, so CI recompiled those test programs on every run.

#include <string>
#include <string_view>

namespace oscar::testing {

/// The checkout's file or folder at `relative`, e.g. source_path("config/demo-local.yaml").
std::string source_path(std::string_view relative = {});

/// The build tree's file or folder at `relative`, e.g. build_path("lib/oscar/test_plugins").
std::string build_path(std::string_view relative = {});

}  // namespace oscar::testing
