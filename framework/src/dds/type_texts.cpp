#include "oscar/type_texts.hpp"

#include "oscar/idl_texts.hpp"
#include "oscar/kernel.hpp"

namespace oscar {

namespace topics {
TopicSpec<ModuleTypes, ModuleTypesPubSubType> module_types() {
  // Each such module has a writer of its own that keeps its one sample.
  return {"oscar/types", qos::state_writer(1), qos::state_reader(64)};
}
}  // namespace topics

std::map<std::string, std::string> own_type_texts(const std::vector<const KernelPorts*>& kernels) {
  std::map<std::string, std::string> out;
  const auto add = [&](const std::string& type) {
    if (idl_texts().contains(type) || out.contains(type)) return;
    if (auto text = find_idl_text(type)) out.emplace(type, std::move(*text));
  };
  for (const auto* ports : kernels) {
    for (const auto& o : ports->outputs) add(o->type().name);
    for (const auto& i : ports->inputs) {
      if (!i->takes_any_type()) add(i->type().name);
    }
    for (const auto& c : ports->commands) add(c->type().name);
  }
  return out;
}

std::unique_ptr<TypeTextsWriter> announce_type_texts(
    DdsParticipant& participant, const std::string& module,
    const std::map<std::string, std::string>& texts) {
  if (texts.empty()) return nullptr;
  ModuleTypes announcement;
  announcement.module_name(module);
  for (const auto& [name, idl] : texts) {
    TypeText t;
    t.name(name);
    t.idl(idl);
    announcement.types().push_back(std::move(t));
  }
  auto writer = std::make_unique<TypeTextsWriter>(participant, topics::module_types());
  writer->write(announcement);
  return writer;
}

AnnouncedTypes::AnnouncedTypes(DdsParticipant& participant, OnText on_text)
    : on_text_(std::move(on_text)),
      reader_(std::make_unique<TopicReader<ModuleTypes, ModuleTypesPubSubType>>(
          participant, topics::module_types(),
          [this](const ModuleTypes& s, const eprosima::fastdds::dds::SampleInfo&) {
            on_sample(s);
          })) {}

void AnnouncedTypes::on_sample(const ModuleTypes& sample) {
  std::vector<std::pair<std::string, std::string>> changed;
  {
    std::lock_guard lock(mutex_);
    for (const auto& t : sample.types()) {
      // OSCAR's own types are never taken from the wire.
      if (t.name().empty() || idl_texts().contains(t.name())) continue;
      auto& text = texts_[t.name()];
      if (text == t.idl()) continue;
      text = t.idl();
      changed.emplace_back(t.name(), t.idl());
    }
  }
  if (changed.empty()) return;
  arrived_.notify_all();
  if (on_text_) {
    for (const auto& [type, idl] : changed) on_text_(type, idl);
  }
}

std::optional<std::string> AnnouncedTypes::idl_text(const std::string& type) const {
  if (const auto own = idl_texts().find(type); own != idl_texts().end()) return own->second;
  {
    std::lock_guard lock(mutex_);
    if (const auto it = texts_.find(type); it != texts_.end()) return it->second;
  }
  return find_idl_text(type);
}

std::optional<std::string> AnnouncedTypes::wait_for(const std::string& type,
                                                    std::chrono::milliseconds timeout) const {
  if (auto text = idl_text(type)) return text;
  std::unique_lock lock(mutex_);
  arrived_.wait_for(lock, timeout, [&] { return texts_.contains(type); });
  const auto it = texts_.find(type);
  return it == texts_.end() ? std::nullopt : std::optional(it->second);
}

std::map<std::string, std::string> AnnouncedTypes::announced() const {
  std::lock_guard lock(mutex_);
  return texts_;
}

}  // namespace oscar
