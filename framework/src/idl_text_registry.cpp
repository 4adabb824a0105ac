#include <mutex>

#include "oscar/idl_texts.hpp"

namespace oscar {
namespace {
struct Registered {
  std::mutex mutex;
  std::map<std::string, std::string> texts;
};
Registered& registered() {
  static Registered r;
  return r;
}
}  // namespace

void register_idl_texts(const std::map<std::string, std::string>& texts) {
  auto& r = registered();
  std::lock_guard lock(r.mutex);
  for (const auto& [name, text] : texts) r.texts[name] = text;
}

std::optional<std::string> find_idl_text(const std::string& type) {
  if (const auto own = idl_texts().find(type); own != idl_texts().end()) return own->second;
  auto& r = registered();
  std::lock_guard lock(r.mutex);
  const auto it = r.texts.find(type);
  return it == r.texts.end() ? std::nullopt : std::optional(it->second);
}

}  // namespace oscar
