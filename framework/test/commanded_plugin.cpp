// The test_commanded kernel as a plugin, for oscar-run children of the integration tests.
#include "oscar/kernel_registry.hpp"
#include "test_kernels.hpp"

OSCAR_REGISTER_KERNEL(oscar::test::Commanded, "test_commanded")
