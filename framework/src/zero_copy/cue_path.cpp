#include "zero_copy/cue_path.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "zero_copy/roudi.hpp"

namespace oscar::zero_copy {

CuePathChoice choose_cue_path(const ConnectionFacts& facts) {
  CuePathChoice choice;
  if (!facts.type_is_plain)
    choice.reason = fmt::format(
        "cue type {} is not plain (it holds unbounded sequences or strings; a plain form has "
        "fixed-size members only, see idl/oscar/plain_cues.idl)",
        facts.type_name);
  else if (!facts.producer_on_this_host)
    choice.reason =
        "no process of this host offers it in shared memory (the producer runs on another host, "
        "has not started yet, or has no RouDi)";
  else if (!facts.roudi_running)
    choice.reason = "no RouDi runs on this host (iceoryx's daemon, iox-roudi)";
  else
    choice.path = CuePath::kZeroCopy;
  if (choice.path == CuePath::kSerialized)
    spdlog::info("cues of {} go serialized, not zero-copy: {}", facts.source, choice.reason);
  return choice;
}

ConnectionFacts connection_facts(const std::string& source, const CueTypeInfo& type,
                                 bool producer_on_this_host) {
  ConnectionFacts facts;
  facts.source = source;
  facts.type_name = type.name;
  facts.type_is_plain = type.memory.plain;
  facts.producer_on_this_host = producer_on_this_host;
  facts.roudi_running = producer_on_this_host && facts.type_is_plain && roudi_running();
  return facts;
}

}  // namespace oscar::zero_copy
