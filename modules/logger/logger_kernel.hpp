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
/// docs/recording.md). Its inputs take cues of any type (raw inputs): it stores each cue's
/// serialized form and the IDL text of the producer's type.
class Logger final : public Kernel {
 public:
  struct Params {
    std::string file;                  ///< the MCAP file (required)
    std::string inputs;                ///< "name, name": inputs to declare besides the wired ones
    std::string compression = "zstd";  ///< zstd, lz4 or none
    std::chrono::nanoseconds flush_every{std::chrono::seconds(1)};  ///< oldest unwritten cue
    void describe(ParamSpec& spec);
  };
  /// Parses the `inputs` parameter: input names separated by commas.
  /// @throws std::invalid_argument naming the bad entry.
  static std::vector<std::string> parse_inputs(const std::string& text);

  /// Declares one raw input per input the configuration names and per name in `inputs`.
  /// @throws std::invalid_argument without a file or without any input.
  explicit Logger(KernelSetup& setup);
  ~Logger() override;
  void process(Cycle& cycle) override;
  /// Nothing to make up: a logger has no outputs, so stub mode records as process() does.
  void stub(Cycle& cycle) override;
  void on_deactivate() override;

 private:
  void open();
  std::uint16_t channel(const RawCue& cue);

  Params params_;
  std::vector<Input<RawCue>*> inputs_;
  std::unique_ptr<mcap::Writer> writer_;
  std::map<std::string, std::uint16_t> channels_;  // by topic
  std::map<std::string, std::uint16_t> schemas_;   // by type name
  Stamp unflushed_since_ = 0;                      // cycle time of the oldest unwritten cue
};

}  // namespace oscar::modules
