#include "test_kernels.hpp"

#include "oscar/kernel_registry.hpp"

OSCAR_REGISTER_KERNEL(oscar::test::Counter, "test_counter")
OSCAR_REGISTER_KERNEL(oscar::test::Wisher, "test_wisher")
OSCAR_REGISTER_KERNEL(oscar::test::Collect, "test_collect")
OSCAR_REGISTER_KERNEL(oscar::test::RawCollect, "test_raw_collect")
OSCAR_REGISTER_KERNEL(oscar::test::Lines, "test_lines")
OSCAR_REGISTER_KERNEL(oscar::test::Merge, "test_merge")
OSCAR_REGISTER_KERNEL(oscar::test::CollectImage, "test_gv")
OSCAR_REGISTER_KERNEL(oscar::test::Failing, "test_failing")
OSCAR_REGISTER_KERNEL(oscar::test::Emitter, "test_emitter")
OSCAR_REGISTER_KERNEL(oscar::test::ReliableCollect, "test_reliable_collect")
OSCAR_REGISTER_KERNEL(oscar::test::Prefetching, "test_prefetching")
OSCAR_REGISTER_KERNEL(oscar::test::Commanded, "test_commanded")
