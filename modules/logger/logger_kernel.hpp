#pragma once

#include <chrono>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <oscar/kernel.hpp>
#include <oscar/mcap/writer.hpp>

namespace oscar::modules {

/// Records every cue that reaches its inputs into an MCAP file, in the format `oscar record`
/// writes (seed 004 §3: generic data loggers hung onto input and output channels;
/// docs/recording.md).
class Logger final : public Kernel {
 public:
  struct Params {
    std::string file;                  ///< the MCAP file (required)
    std::string inputs;                ///< "name:Type, name:Type" (Type: a standard cue type)
    std::string compression = "zstd";  ///< zstd, lz4 or none
    std::chrono::nanoseconds flush_every{std::chrono::seconds(1)};  ///< oldest unwritten cue
    void describe(ParamSpec& spec);
  };
  /// One declared input: its name and cue type.
  struct InputSpec {
    std::string name, type;
  };
  /// Parses the `inputs` parameter. @throws std::invalid_argument naming the bad entry.
  static std::vector<InputSpec> parse_inputs(const std::string& text);

  explicit Logger(KernelSetup& setup);
  ~Logger() override;
  void process(Cycle& cycle) override;
  /// Nothing to make up: a logger has no outputs, so stub mode records as process() does.
  void stub(Cycle& cycle) override;
  void on_deactivate() override;

  struct Port;  // a typed input and how to serialise its cues

 private:
  void open();
  std::uint16_t channel(const std::string& source, const std::string& type);

  Params params_;
  std::vector<std::unique_ptr<Port>> ports_;
  std::unique_ptr<mcap::Writer> writer_;
  std::map<std::string, std::uint16_t> channels_;  // by topic
  std::map<std::string, std::uint16_t> schemas_;   // by type name
  Stamp unflushed_since_ = 0;                      // cycle time of the oldest unwritten cue
};

}  // namespace oscar::modules
