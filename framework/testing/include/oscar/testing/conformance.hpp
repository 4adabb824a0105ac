#pragma once
/// @file The conformance suite every kernel passes (docs/kernels.md): construction has no side
/// effects, port names are unique, stub() writes every output, process() survives empty
/// inputs, neither writes to a parameter, and parameters round-trip through YAML.

#include <string>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

namespace oscar::conformance {

/// Runs every conformance check on a kernel type with the given parameters.
void expect_kernel_conformance(const std::string& type, const YAML::Node& params = {});

}  // namespace oscar::conformance

/// Defines a test `KernelConformance.<Name>` running the suite for a kernel type.
#define OSCAR_KERNEL_CONFORMANCE_TEST(NAME, TYPE, PARAMS_YAML)                      \
  TEST(KernelConformance, NAME) {                                                   \
    ::oscar::conformance::expect_kernel_conformance(TYPE, YAML::Load(PARAMS_YAML)); \
  }
