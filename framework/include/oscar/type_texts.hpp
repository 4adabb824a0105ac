#pragma once
/// @file Types OSCAR does not define, described on the wire: a module built with IDL of its own
/// (oscar_add_module(... IDL ...)) announces the IDL text of each such type its ports use on
/// `oscar/types`, and OSCAR's tools (echo, record, the Foxglove bridge) read those announcements
/// to decode its cues and requests without its code (docs/kernels.md, "Types of your own").

#include <chrono>
#include <condition_variable>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <oscar/type_texts.h>
#include <oscar/type_textsPubSubTypes.h>

#include "oscar/topic_io.hpp"
#include "oscar/topics.hpp"

namespace oscar {

struct KernelPorts;

namespace topics {
/// One sample per module whose ports use types OSCAR does not define, written when it starts
/// (state class: a tool that starts later gets it). Part of the topic catalogue (topics.hpp).
TopicSpec<ModuleTypes, ModuleTypesPubSubType> module_types();
}  // namespace topics

/// The types the ports of `kernels` use (outputs, typed inputs, command requests) that OSCAR
/// does not define and whose IDL text this process has registered (find_idl_text()), by name.
std::map<std::string, std::string> own_type_texts(const std::vector<const KernelPorts*>& kernels);

using TypeTextsWriter = TopicWriter<ModuleTypes, ModuleTypesPubSubType>;

/// Announces `texts` (the IDL text of each type, by name) as `module`'s on oscar/types, once;
/// nullptr, and no writer, if there are none.
/// @throws std::runtime_error if DDS refuses the writer (e.g. the identity's permissions).
std::unique_ptr<TypeTextsWriter> announce_type_texts(
    DdsParticipant& participant, const std::string& module,
    const std::map<std::string, std::string>& texts);

/// The IDL texts of types OSCAR does not define, as a running system's modules announce them.
/// Thread-safe.
class AnnouncedTypes {
 public:
  /// Called on a DDS thread for each type whose text arrives new or changed.
  using OnText = std::function<void(const std::string& type, const std::string& idl)>;

  explicit AnnouncedTypes(DdsParticipant& participant, OnText on_text = {});
  AnnouncedTypes(const AnnouncedTypes&) = delete;
  AnnouncedTypes& operator=(const AnnouncedTypes&) = delete;

  /// The IDL text of `type`: OSCAR's own, else one announced, else one registered in this
  /// process; nullopt if none.
  std::optional<std::string> idl_text(const std::string& type) const;
  /// idl_text(type), waiting up to `timeout` for an announcement to bring it.
  std::optional<std::string> wait_for(const std::string& type,
                                      std::chrono::milliseconds timeout) const;
  /// Every text announced so far, by type.
  std::map<std::string, std::string> announced() const;

 private:
  void on_sample(const ModuleTypes& sample);

  OnText on_text_;
  mutable std::mutex mutex_;
  mutable std::condition_variable arrived_;
  std::map<std::string, std::string> texts_;
  // Last: deleted first, so no DDS thread calls on_sample() on a half-destroyed object.
  std::unique_ptr<TopicReader<ModuleTypes, ModuleTypesPubSubType>> reader_;
};

}  // namespace oscar
