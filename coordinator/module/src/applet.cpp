#include "oscar/coordinator/applet.hpp"

#include <dlfcn.h>

#include <filesystem>
#include <mutex>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace oscar::coordinator {
namespace {

struct AppletType {
  internal::AppletFactory make;
  std::string source_file;
};

// Function-local statics: registration runs during static initialisation of other files.
std::map<std::string, AppletType>& types() {
  static std::map<std::string, AppletType> t;
  return t;
}
std::mutex& types_mutex() {
  static std::mutex m;
  return m;
}

const AppletType* find_type(const std::string& type) {
  std::lock_guard lock(types_mutex());
  const auto it = types().find(type);
  return it == types().end() ? nullptr : &it->second;
}

std::vector<std::string> known_types(const std::vector<std::string>& search_path) {
  std::vector<std::string> names;
  {
    std::lock_guard lock(types_mutex());
    for (const auto& [name, t] : types()) names.push_back(name);
  }
  const std::string prefix = "liboscar_applet_", suffix = ".so";
  for (const auto& dir : search_path) {
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
      const auto file = entry.path().filename().string();
      if (file.starts_with(prefix) && file.ends_with(suffix) && file.size() > prefix.size() + 3) {
        names.push_back(file.substr(prefix.size(), file.size() - prefix.size() - suffix.size()));
      }
    }
  }
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  return names;
}

}  // namespace

namespace internal {
bool register_applet_type(const char* type, AppletFactory factory, const char* source_file) {
  std::lock_guard lock(types_mutex());
  const auto [it, added] = types().emplace(type, AppletType{factory, source_file});
  if (!added && it->second.source_file != source_file) {
    // Two applets claiming one name is a build error of ours: say where both come from.
    std::fprintf(stderr, "applet type '%s' is registered twice: %s and %s\n", type,
                 it->second.source_file.c_str(), source_file);
    std::abort();
  }
  return true;
}
}  // namespace internal

std::unique_ptr<Applet> make_applet(const std::string& type, AppletSetup& setup,
                                    const std::vector<std::string>& search_path) {
  const auto* t = find_type(type);
  if (!t) {
    const std::string file = "liboscar_applet_" + type + ".so";
    for (const auto& dir : search_path) {
      const auto candidate = std::filesystem::path(dir) / file;
      if (!std::filesystem::exists(candidate)) continue;
      if (!dlopen(candidate.c_str(), RTLD_NOW | RTLD_GLOBAL)) {
        throw std::runtime_error(
            fmt::format("applet plugin '{}' failed to load: {}", candidate.string(), dlerror()));
      }
      t = find_type(type);
      if (!t) {
        throw std::runtime_error(
            fmt::format("applet plugin '{}' loaded but registers no applet "
                        "type '{}' (OSCAR_REGISTER_APPLET)",
                        candidate.string(), type));
      }
      break;
    }
  }
  if (!t) {
    throw std::runtime_error(fmt::format(
        "unknown applet type '{}': no plugin liboscar_applet_{}.so in [{}]; applet types that "
        "can be loaded: {}",
        type, type, fmt::join(search_path, ", "), fmt::join(known_types(search_path), ", ")));
  }
  return t->make(setup);
}

}  // namespace oscar::coordinator
