#pragma once
// Per-output sequence counters in a memory-mapped file, so a restarted module continues its
// channels' numbering where the killed incarnation stopped (consumers see a gap for the
// outage, never a number twice). Stores into a shared mapping survive the process's death.

#include <cstdint>
#include <string>

namespace oscar::internal {

class SequenceStore {
 public:
  /// Maps (creating if needed) `<dir>/<module>.seq`. @throws std::runtime_error naming the file.
  SequenceStore(const std::string& dir, const std::string& module);
  ~SequenceStore();
  SequenceStore(const SequenceStore&) = delete;
  SequenceStore& operator=(const SequenceStore&) = delete;

  /// The counter of an output ("<kernel>/<channel>"), found or added.
  /// @throws std::runtime_error when the file has no room for another output.
  std::uint64_t* counter(const std::string& address);

  struct Record;  ///< one output's slot in the file (64 bytes)

 private:
  std::string path_;
  Record* records_ = nullptr;
};

}  // namespace oscar::internal
