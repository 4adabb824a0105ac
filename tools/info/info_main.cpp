// `oscar info FILE`: topics, types, message counts, time range, compression and size of an MCAP
// file; a file without summary (a killed recorder) is scanned, and the output says so.
#include <ctime>
#include <string>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

#include "oscar/mcap/reader.hpp"

namespace {

std::string utc(std::uint64_t ns) {
  const std::time_t s = static_cast<std::time_t>(ns / 1'000'000'000);
  std::tm tm{};
  gmtime_r(&s, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
  return fmt::format("{}.{:09}Z", buf, ns % 1'000'000'000);
}

std::string size(std::uint64_t bytes) {
  if (bytes >= 1 << 20) return fmt::format("{:.1f} MiB", bytes / 1048576.0);
  if (bytes >= 1 << 10) return fmt::format("{:.1f} KiB", bytes / 1024.0);
  return fmt::format("{} B", bytes);
}

void print(const std::string& path, const oscar::mcap::FileInfo& info) {
  const auto& st = info.statistics;
  fmt::print("file:        {} ({}, {} bytes)\n", path, size(info.file_size), info.file_size);
  fmt::print("library:     {}{}\n", info.library,
             info.profile.empty() ? "" : ", profile " + info.profile);
  fmt::print("summary:     {}\n", info.from_summary ? "yes" : "none (" + *info.recovery + ")");
  std::string compression;
  for (const auto& c : info.compressions) {
    compression += (compression.empty() ? "" : ", ") + (c.empty() ? std::string("none") : c);
  }
  fmt::print("messages:    {} in {} chunks (compression: {})\n", st.message_count, st.chunk_count,
             compression.empty() ? "-" : compression);
  if (st.message_count > 0) {
    const double seconds = (st.message_end_time - st.message_start_time) / 1e9;
    fmt::print("time range:  {} .. {} ({:.3f} s)\n", utc(st.message_start_time),
               utc(st.message_end_time), seconds);
  }
  fmt::print("channels:    {}\n", info.channels.size());
  std::size_t topic_width = 5, type_width = 4;
  for (const auto& [id, c] : info.channels) {
    topic_width = std::max(topic_width, c.topic.size());
    const auto s = info.schemas.find(c.schema_id);
    if (s != info.schemas.end()) type_width = std::max(type_width, s->second.name.size());
  }
  fmt::print("  {:<{}}  {:<{}}  {:>9}  {}\n", "topic", topic_width, "type", type_width, "messages",
             "encoding");
  for (const auto& [id, c] : info.channels) {
    const auto s = info.schemas.find(c.schema_id);
    const auto n = st.channel_message_counts.find(id);
    fmt::print("  {:<{}}  {:<{}}  {:>9}  {}{}\n", c.topic, topic_width,
               s == info.schemas.end() ? "-" : s->second.name, type_width,
               n == st.channel_message_counts.end() ? 0 : n->second, c.message_encoding,
               s == info.schemas.end() ? "" : " / " + s->second.encoding);
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Summarises an MCAP file: topics, types, counts, time range, compression, size"};
  app.name("oscar info");
  std::string path;
  app.add_option("FILE", path, "MCAP file")->required();
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  try {
    oscar::mcap::Reader reader(path);
    print(path, reader.info());
    return 0;
  } catch (const std::exception& e) {
    fmt::print(stderr, "oscar info: {}\n", e.what());
    return 1;
  }
}
