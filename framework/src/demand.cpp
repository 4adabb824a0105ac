#include "oscar/demand.hpp"

#include <cstdio>
#include <cstdlib>

namespace oscar::internal {

void demand_failed(std::string_view condition, std::string_view message,
                   std::source_location where) {
  std::fprintf(stderr, "OSCAR_DEMAND failed: %.*s\n  %.*s\n  at %s:%u in %s\n",
               static_cast<int>(condition.size()), condition.data(),
               static_cast<int>(message.size()), message.data(), where.file_name(), where.line(),
               where.function_name());
  std::abort();
}

}  // namespace oscar::internal
