#pragma once
/// @file Reader: validates an MCAP file (magic, record lengths, CRCs) and reads its messages,
/// using the summary section when there is one and recovering by a scan when there is not.

#include <functional>
#include <optional>
#include <set>
#include <string>

#include "oscar/mcap/records.hpp"

namespace oscar::mcap {

/// What a file holds: from its summary section, or counted by a scan if it has none.
struct FileInfo {
  std::string profile;
  std::string library;
  std::uint64_t file_size = 0;
  std::map<std::uint16_t, Schema> schemas;
  std::map<std::uint16_t, Channel> channels;
  Statistics statistics;               ///< message/chunk counts, time range, per-channel counts
  std::set<std::string> compressions;  ///< of the chunks ("" = uncompressed)
  bool from_summary = false;
  /// Set when the file did not end properly: why, and up to which byte it was read.
  std::optional<std::string> recovery;
};

/// What a scan of the data section saw.
struct ScanResult {
  std::uint64_t messages = 0;
  std::uint64_t chunks = 0;
  bool complete = false;  ///< reached the Data End record
  /// Set if the data section ends early (a writer that was killed): where and why.
  std::optional<std::string> truncation;
};

class Reader {
 public:
  /// Maps the file and checks the leading magic and header; reads and checks the footer and
  /// summary if the file ends with the closing magic.
  /// @throws std::runtime_error if the file cannot be opened; FormatError if it is no MCAP
  ///         file or its footer or summary is corrupt.
  explicit Reader(const std::string& path);
  ~Reader();
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;

  /// True if a footer with a (CRC-checked) summary section was found.
  bool has_summary() const { return summary_.has_value(); }
  /// Why the summary could not be used, if it could not (e.g. no footer: the writer was killed).
  const std::optional<std::string>& missing_summary() const { return missing_summary_; }

  using MessageFn = std::function<void(const Channel&, const MessageView&)>;
  /// Reads every record of the data section in file order, checking record lengths, chunk CRCs
  /// and the data section CRC, and calls `fn` for every message. A data section cut short is
  /// reported in the result (not thrown) if the file has no footer: that is a killed writer.
  /// @throws FormatError for anything malformed.
  ScanResult read_messages(const MessageFn& fn);

  /// The file's contents in summary: from the summary section if there is one, otherwise by
  /// scanning (FileInfo::recovery then says so).
  /// @throws FormatError as read_messages().
  FileInfo info();

  const std::string& path() const { return path_; }

 private:
  void read_footer();
  void read_summary(std::uint64_t start, std::uint64_t end);
  void fail(std::uint64_t offset, const std::string& what) const;
  /// Reads `n` bytes at `at` into `out` with pread(); false if that fails.
  bool read_at(std::uint64_t at, std::uint64_t n, std::vector<std::uint8_t>& out) const;

  std::string path_;
  const std::uint8_t* data_ = nullptr;
  std::uint64_t size_ = 0;
  int fd_ = -1;  ///< chunks are read with pread(), not through the mapping (read_messages)
  std::uint64_t header_end_ = 0;
  std::string profile_, library_;
  bool has_footer_ = false;
  std::uint64_t data_end_ = 0;  ///< where the data section must end (summary or footer start)
  std::optional<FileInfo> summary_;
  std::optional<std::string> missing_summary_;
  std::map<std::uint16_t, Schema> schemas_;
  std::map<std::uint16_t, Channel> channels_;
  std::set<std::string> compressions_;
};

}  // namespace oscar::mcap
