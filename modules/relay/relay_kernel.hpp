#pragma once

#include <memory>
#include <string>

#include <oscar/cue_types.hpp>
#include <oscar/kernel.hpp>

namespace oscar::modules {

/// Forwards every cue of a standard type, appending its own stamp to the header: the smallest
/// fusing module (seed 004 Abb. 3, footnote 2: fusing modules extend the stamp sequence).
class Relay final : public Kernel {
 public:
  struct Params {
    std::string type = "Bool";  ///< Bool, LineSeg3DSeq or GvImage
    void describe(ParamSpec& spec);
  };
  explicit Relay(KernelSetup& setup);
  ~Relay() override;
  void process(Cycle& cycle) override;
  void stub(Cycle& cycle) override;
  struct Ports;  // typed handles for the chosen type

 private:
  Params params_;
  std::unique_ptr<Ports> ports_;
};

}  // namespace oscar::modules
