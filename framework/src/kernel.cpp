#include <dlfcn.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <mutex>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "oscar/kernel_registry.hpp"
#include "oscar/process_util.hpp"

namespace oscar {
namespace {
struct TypeRegistry {
  std::mutex mutex;
  std::map<std::string, KernelTypeInfo, std::less<>> types;
};
TypeRegistry& type_registry() {
  static TypeRegistry r;
  return r;
}

bool is_identifier(std::string_view s) {
  if (s.empty() || std::isdigit(static_cast<unsigned char>(s[0]))) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  });
}
}  // namespace

InputPort* KernelPorts::find_input(std::string_view name) const {
  for (const auto& p : inputs) {
    if (p->name() == name) return p.get();
  }
  return nullptr;
}

OutputPort* KernelPorts::find_output(std::string_view name) const {
  for (const auto& p : outputs) {
    if (p->name() == name) return p.get();
  }
  return nullptr;
}

CommandPort* KernelPorts::find_command(std::string_view name) const {
  for (const auto& c : commands) {
    if (c->name() == name) return c.get();
  }
  return nullptr;
}

KernelSetup::KernelSetup(std::string kernel_name, std::string kernel_type, KernelPorts& ports,
                         YAML::Node params, std::map<std::string, InputOverrides> input_options)
    : name_(std::move(kernel_name)),
      type_(std::move(kernel_type)),
      ports_(ports),
      params_(std::move(params)),
      input_options_(std::move(input_options)) {}

void KernelSetup::check_port_name(const std::string& name) const {
  if (!is_identifier(name)) {
    throw std::invalid_argument(
        fmt::format("kernel '{}' ({}): port name '{}' must be an identifier (letters, digits, _)",
                    name_, type_, name));
  }
  if (ports_.find_input(name) || ports_.find_output(name)) {
    throw std::invalid_argument(fmt::format(
        "kernel '{}' ({}): port '{}' is declared twice; port names are unique per kernel", name_,
        type_, name));
  }
}

Wish& KernelSetup::wish(const std::string& name) {
  if (!is_identifier(name)) {
    throw std::invalid_argument(
        fmt::format("kernel '{}' ({}): wish name '{}' must be an identifier (letters, digits, _)",
                    name_, type_, name));
  }
  for (const auto& w : ports_.wishes) {
    if (w->name() == name) {
      throw std::invalid_argument(
          fmt::format("kernel '{}' ({}): wish '{}' is declared twice; wish names are unique per "
                      "kernel",
                      name_, type_, name));
    }
  }
  ports_.wishes.push_back(std::make_unique<Wish>(name_, name));
  return *ports_.wishes.back();
}

void KernelSetup::check_command_name(const std::string& name) const {
  if (!is_identifier(name)) {
    throw std::invalid_argument(fmt::format(
        "kernel '{}' ({}): command name '{}' must be an identifier (letters, digits, _)", name_,
        type_, name));
  }
  if (ports_.find_command(name)) {
    throw std::invalid_argument(fmt::format(
        "kernel '{}' ({}): command '{}' is declared twice; command names are unique per kernel",
        name_, type_, name));
  }
}

Input<RawCue>& KernelSetup::raw_input(const std::string& name, InputOptions defaults) {
  check_port_name(name);
  auto options = defaults;
  if (auto it = input_options_.find(name); it != input_options_.end()) {
    options = it->second.applied_to(defaults);
  }
  if (options.transfer != Transfer::kPush) {
    throw std::invalid_argument(fmt::format(
        "kernel '{}' ({}): input '{}' takes cues of any type, which arrive by push only, not {}",
        name_, type_, name, to_string(options.transfer)));
  }
  auto port = std::make_unique<Input<RawCue>>(name_, name, raw_cue_type(), options);
  auto& ref = *port;
  ports_.inputs.push_back(std::move(port));
  return ref;
}

std::vector<std::string> KernelSetup::configured_inputs() const {
  std::vector<std::string> names;
  for (const auto& [name, options] : input_options_) names.push_back(name);
  return names;
}

bool KernelSetup::unbound_params() const {
  return !params_bound_ && params_ && params_.IsMap() && params_.size() > 0;
}

namespace internal {
bool register_kernel_type(const char* type, KernelFactory factory, const char* source_file) {
  auto& r = type_registry();
  std::lock_guard lock(r.mutex);
  r.types.try_emplace(type, KernelTypeInfo{type, factory, source_file});
  return true;
}
}  // namespace internal

const KernelTypeInfo* find_kernel_type(std::string_view type) {
  auto& r = type_registry();
  std::lock_guard lock(r.mutex);
  const auto it = r.types.find(type);
  return it == r.types.end() ? nullptr : &it->second;
}

std::vector<std::string> kernel_type_names() {
  auto& r = type_registry();
  std::lock_guard lock(r.mutex);
  std::vector<std::string> names;
  for (const auto& [name, info] : r.types) names.push_back(name);
  return names;
}

std::vector<std::string> plugin_search_path() {
  std::vector<std::string> path;
  if (const char* env = std::getenv("OSCAR_PLUGIN_PATH")) {
    std::string_view rest(env);
    while (!rest.empty()) {
      const auto colon = rest.find(':');
      if (auto part = rest.substr(0, colon); !part.empty()) path.emplace_back(part);
      if (colon == std::string_view::npos) break;
      rest.remove_prefix(colon + 1);
    }
  }
  if (const auto dir = program_dir(); !dir.empty()) {
    path.push_back((dir / ".." / "lib" / "oscar" / "plugins").lexically_normal().string());
    path.push_back((dir / ".." / "lib").lexically_normal().string());
  }
  return path;
}

std::vector<std::string> available_kernel_types(const std::vector<std::string>& search_path) {
  auto types = kernel_type_names();
  const std::string prefix = "liboscar_kernel_", suffix = ".so";
  for (const auto& dir : search_path) {
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
      const auto name = e.path().filename().string();
      if (name.size() > prefix.size() + suffix.size() && name.starts_with(prefix) &&
          name.ends_with(suffix)) {
        types.push_back(name.substr(prefix.size(), name.size() - prefix.size() - suffix.size()));
      }
    }
  }
  std::sort(types.begin(), types.end());
  types.erase(std::unique(types.begin(), types.end()), types.end());
  return types;
}

std::vector<std::string> with_plugins(const std::vector<std::string>& plugins,
                                      std::vector<std::string> search_path) {
  std::vector<std::string> folders;
  for (const auto& p : plugins) {
    if (std::filesystem::is_directory(p)) {
      folders.push_back(p);
    } else {
      load_plugin(p);
    }
  }
  search_path.insert(search_path.begin(), folders.begin(), folders.end());
  return search_path;
}

namespace {
// Edits (insert, delete, replace) that turn `a` into `b`.
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const auto above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// " (did you mean 'x'?)" for the known type nearest to `type`, if one is near enough to be a typo.
std::string did_you_mean(const std::string& type, const std::vector<std::string>& known) {
  std::string best;
  std::size_t best_distance = std::max<std::size_t>(2, type.size() / 3) + 1;
  for (const auto& k : known) {
    if (const auto d = edit_distance(type, k); d < best_distance) {
      best = k;
      best_distance = d;
    }
  }
  return best.empty() ? "" : fmt::format(" (did you mean '{}'?)", best);
}
}  // namespace

std::vector<std::string> load_plugin(const std::string& path) {
  const auto before = kernel_type_names();
  // RTLD_GLOBAL: kernels of one module may share cue types defined in another plugin.
  void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_GLOBAL);
  if (!handle) {
    throw std::runtime_error(fmt::format("plugin '{}' failed to load: {}", path, dlerror()));
  }
  std::vector<std::string> added;
  for (const auto& name : kernel_type_names()) {
    if (std::find(before.begin(), before.end(), name) == before.end()) added.push_back(name);
  }
  return added;
}

const KernelTypeInfo& load_kernel_type(const std::string& type,
                                       const std::vector<std::string>& search_path) {
  if (const auto* info = find_kernel_type(type)) return *info;
  if (!is_identifier(type)) {
    throw std::runtime_error(fmt::format(
        "unknown kernel type '{}': type names are identifiers (letters, digits, _)", type));
  }
  const std::string file = "liboscar_kernel_" + type + ".so";
  for (const auto& dir : search_path) {
    const auto candidate = std::filesystem::path(dir) / file;
    if (!std::filesystem::exists(candidate)) continue;
    const auto added = load_plugin(candidate.string());
    if (const auto* info = find_kernel_type(type)) return *info;
    throw std::runtime_error(
        fmt::format("plugin '{}' loaded but registers no kernel type '{}' (it registers: {})",
                    candidate.string(), type,
                    added.empty() ? "nothing" : fmt::format("{}", fmt::join(added, ", "))));
  }
  const auto known = available_kernel_types(search_path);
  throw std::runtime_error(fmt::format(
      "unknown kernel type '{}'{}: no plugin {} in [{}]; types that can be loaded: {} (a plugin "
      "elsewhere: name it or its folder under the system file's plugins:, or in "
      "OSCAR_PLUGIN_PATH)",
      type, did_you_mean(type, known), file, fmt::join(search_path, ", "), fmt::join(known, ", ")));
}

}  // namespace oscar
