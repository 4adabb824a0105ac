// The C++ side of the MCAP interop test: `write FILE zstd|lz4|none` writes a known recording
// with oscar::mcap; `summary FILE` reads any MCAP file with oscar::mcap's reader and prints what
// it holds in the same JSON form as mcap_interop.js, so run.sh can compare the two.
#include <cstring>
#include <map>

#include <fmt/format.h>

#include "oscar/mcap/reader.hpp"
#include "oscar/mcap/writer.hpp"

namespace {
using namespace oscar::mcap;

// {"schemas":2,"channels":3,"messages":N,"sum":S,"topics":{"a":n,...}} (topics sorted).
void print_summary(std::size_t schemas, std::size_t channels, std::uint64_t messages,
                   std::uint64_t sum, const std::map<std::string, std::uint64_t>& topics) {
  std::string t;
  for (const auto& [topic, n] : topics)
    t += fmt::format("{}\"{}\":{}", t.empty() ? "" : ",", topic, n);
  fmt::print("{{\"schemas\":{},\"channels\":{},\"messages\":{},\"sum\":{},\"topics\":{{{}}}}}\n",
             schemas, channels, messages, sum, t);
}

int write(const std::string& path, const std::string& compression) {
  WriterOptions o;
  o.compression = parse_compression(compression);
  o.chunk_size_bytes = 4096;
  Writer w(path, o);
  const auto a = w.add_schema("oscar::Bool", "omgidl", {'s', 't', 'r', 'u', 'c', 't'});
  const auto b = w.add_schema("oscar::GvImage", "omgidl", {'m', 'o', 'd'});
  const std::uint16_t ch[] = {w.add_channel(a, "oscar/cue/a/out", "cdr", {{"kernel", "a"}}),
                              w.add_channel(a, "oscar/cue/b/out", "cdr", {}),
                              w.add_channel(b, "oscar/cue/c/out", "cdr", {{"qos", "reliable"}})};
  for (std::uint32_t i = 0; i < 1000; ++i) {
    std::vector<std::uint8_t> p(16 + i % 200);
    for (std::size_t k = 0; k < p.size(); ++k) p[k] = static_cast<std::uint8_t>(i * 31 + k);
    w.write({ch[i % 3], i, 1000 + 10 * std::uint64_t{i}, 500 + i, p});
  }
  w.close();
  return 0;
}

int summary(const std::string& path) {
  Reader r(path);
  std::uint64_t messages = 0, sum = 0;
  std::map<std::string, std::uint64_t> topics;
  const auto scan = r.read_messages([&](const Channel& c, const MessageView& m) {
    ++messages;
    ++topics[c.topic];
    for (const auto x : m.data) sum += x;
  });
  if (!scan.complete) {
    fmt::print(stderr, "{}: data section incomplete\n", path);
    return 1;
  }
  const auto info = r.info();
  if (!info.from_summary || info.statistics.message_count != messages) {
    fmt::print(stderr, "{}: summary missing or its statistics disagree with the data\n", path);
    return 1;
  }
  print_summary(info.schemas.size(), info.channels.size(), messages, sum, topics);
  return 0;
}
}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc == 4 && std::strcmp(argv[1], "write") == 0) return write(argv[2], argv[3]);
    if (argc == 3 && std::strcmp(argv[1], "summary") == 0) return summary(argv[2]);
    fmt::print(stderr, "usage: oscar-mcap-interop write FILE zstd|lz4|none | summary FILE\n");
    return 2;
  } catch (const std::exception& e) {
    fmt::print(stderr, "oscar-mcap-interop: {}\n", e.what());
    return 1;
  }
}
