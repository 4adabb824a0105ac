#pragma once
/// @file RawCue: a cue of a type the receiving kernel does not know at compile time, as a raw
/// input (KernelSetup::raw_input) receives it (docs/kernels.md, "Inputs of any type").

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "oscar/cue.hpp"

namespace oscar {

/// A cue as it travels on the wire: the producer's type name, its serialized form and its header,
/// read from that form (every cue type starts with its header).
struct RawCue {
  std::string type;               ///< the producer's DDS type name, e.g. "oscar::TagDetections"
  std::vector<std::uint8_t> cdr;  ///< encapsulation header and CDR, as a DDS reader gets them
  CueHeader cue_header;           ///< empty if `cdr` does not start with a readable header

  CueHeader& header() { return cue_header; }
  const CueHeader& header() const { return cue_header; }
};

/// The description raw inputs are declared with. Its name, "oscar::RawCue", is no DDS type: the
/// frame reads the producer's type (from its output in process, from discovery across processes).
const CueTypeInfo& raw_cue_type();

/// The RawCue of a cue of a type this process knows: its name, serialization and header.
std::shared_ptr<const RawCue> to_raw_cue(const CueTypeInfo& type, const void* cue);

}  // namespace oscar
