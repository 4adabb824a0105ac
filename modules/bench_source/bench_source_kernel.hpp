#pragma once

#include <memory>
#include <string>

#include <oscar/cue_types.hpp>
#include <oscar/kernel.hpp>

namespace oscar::modules {

/// Publishes one cue of a seed-004 benchmark type per cycle (Abb. 8): Bool, LineSeg3DSeq with
/// `lines` lines, or a dx x dy GvImage. Sequence numbers let sinks count gaps.
class BenchSource final : public Kernel {
 public:
  struct Params {
    std::string type = "Bool";
    int lines = 100;
    int dx = 768;
    int dy = 576;
    std::int64_t count = 0;  ///< stop after this many cues; 0 = never
    void describe(ParamSpec& spec);
  };
  explicit BenchSource(KernelSetup& setup);
  ~BenchSource() override;
  void process(Cycle& cycle) override;
  void stub(Cycle& cycle) override;
  struct Ports;

 private:
  Params params_;
  std::unique_ptr<Ports> ports_;
  std::int64_t sent_ = 0;
};

}  // namespace oscar::modules
