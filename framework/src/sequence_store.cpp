#include "sequence_store.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include <fmt/format.h>

namespace oscar::internal {
namespace {
constexpr std::size_t kRecords = 64;
}

struct SequenceStore::Record {
  char address[56];  // NUL-terminated "<kernel>/<channel>"; empty = free
  std::uint64_t seq;
};
static_assert(sizeof(SequenceStore::Record) == 64);

SequenceStore::SequenceStore(const std::string& dir, const std::string& module)
    : path_(dir + "/" + module + ".seq") {
  const int fd = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  const std::size_t bytes = kRecords * sizeof(Record);
  if (fd < 0 || ftruncate(fd, static_cast<off_t>(bytes)) != 0) {
    const int err = errno;
    if (fd >= 0) ::close(fd);
    throw std::runtime_error(
        fmt::format("{}: cannot keep sequence numbers: {}", path_, std::strerror(err)));
  }
  void* map = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  ::close(fd);
  if (map == MAP_FAILED) {
    throw std::runtime_error(fmt::format("{}: cannot map: {}", path_, std::strerror(errno)));
  }
  records_ = static_cast<Record*>(map);
}

SequenceStore::~SequenceStore() {
  if (records_) munmap(records_, kRecords * sizeof(Record));
}

std::uint64_t* SequenceStore::counter(const std::string& address) {
  if (address.size() >= sizeof(Record::address)) {
    throw std::runtime_error(fmt::format("{}: output name '{}' is longer than {} characters", path_,
                                         address, sizeof(Record::address) - 1));
  }
  for (std::size_t i = 0; i < kRecords; ++i) {
    auto& r = records_[i];
    if (r.address[0] == '\0') {
      std::memcpy(r.address, address.c_str(), address.size() + 1);
      r.seq = 0;
      return &r.seq;
    }
    if (address == r.address) return &r.seq;
  }
  throw std::runtime_error(fmt::format("{}: more than {} outputs", path_, kRecords));
}

}  // namespace oscar::internal
