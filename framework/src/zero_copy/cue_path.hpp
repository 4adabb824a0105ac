#pragma once
/// @file Which path the cues of one connection take: in place through shared memory, or
/// serialized through DDS (docs/zero_copy.md).

#include <string>

#include "oscar/cue.hpp"

namespace oscar::zero_copy {

enum class CuePath {
  kZeroCopy,   ///< the consumer reads the producer's cue in an iceoryx chunk
  kSerialized  ///< CDR through DDS (shared-memory transport on one host, UDP across hosts)
};

/// The path of one connection and, for the serialized path, why it is not zero-copy.
struct CuePathChoice {
  CuePath path = CuePath::kSerialized;
  std::string reason{};  ///< empty for kZeroCopy
};

/// What decides a connection's path.
struct ConnectionFacts {
  std::string source{};        ///< the producer's output, "<kernel>/<channel>"
  std::string type_name{};     ///< its cue type, e.g. "oscar::GvImage"
  bool type_is_plain = false;  ///< fixed-size members only (Fast DDS's is_plain())
  bool producer_on_this_host = false;
  bool roudi_running = false;
};

/// Zero-copy when the type is plain, the producer on this host and RouDi there; else serialized
/// with the first reason that rules zero-copy out. Logs one line for a serialized choice.
CuePathChoice choose_cue_path(const ConnectionFacts& facts);

/// The facts of a connection from `source` of cue type `type`: plainness as its CueMemory says
/// (Fast DDS's is_plain()), RouDi as roudi_running() finds it.
ConnectionFacts connection_facts(const std::string& source, const CueTypeInfo& type,
                                 bool producer_on_this_host);

}  // namespace oscar::zero_copy
