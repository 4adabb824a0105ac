#pragma once
/// @file This process's DDS domain for tests, declared outside oscar::testing so that code in
/// namespace oscar which says `testing::` for GoogleTest can include it.

namespace oscar {

/// A DDS domain held for this process until it ends (oscar::testing::FreeDomain): the first free
/// one from `first` down, the same for every call. Tests run in parallel (ctest -j) never share
/// one, and none takes the domain of a system booted on this machine.
/// @throws std::runtime_error if every domain is taken; std::invalid_argument if `first` is not
/// 1 to 232.
int process_test_domain(int first);

}  // namespace oscar
