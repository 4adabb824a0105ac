#pragma once
/// @file Kernel types by name: those linked in, and plugins loaded on demand.

#include <string>
#include <vector>

#include "oscar/kernel.hpp"

namespace oscar {

struct KernelTypeInfo {
  std::string type;
  internal::KernelFactory make;
  std::string source_file;  ///< where it was registered (for messages)
};

/// The registered kernel type, or nullptr.
const KernelTypeInfo* find_kernel_type(std::string_view type);
/// All registered kernel types, sorted.
std::vector<std::string> kernel_type_names();

/// The plugin search path: $OSCAR_PLUGIN_PATH (colon-separated) first, then the folders
/// `<dir of this program>/../lib/oscar/plugins` and `<dir of this program>/../lib`.
std::vector<std::string> plugin_search_path();

/// The search path of a module whose file names `plugins` (files and folders, ModuleSpec::plugins):
/// its folders before `search_path`; the plugin files it names are loaded at once.
/// @throws std::runtime_error as load_plugin() does.
std::vector<std::string> with_plugins(const std::vector<std::string>& plugins,
                                      std::vector<std::string> search_path);

/// The kernel type, loading its plugin (`liboscar_kernel_<type>.so`) from the search path if it
/// is not registered yet.
/// @throws std::runtime_error naming the type, the folders searched and every type that can be
///         loaded (with the closest to a misspelt name) if no plugin is found, with the loader's
///         message if the plugin fails to load, and if the plugin loads but does not register
///         the type.
const KernelTypeInfo& load_kernel_type(const std::string& type,
                                       const std::vector<std::string>& search_path);

/// Every kernel type that can be had: those registered, and those whose plugin
/// (`liboscar_kernel_<type>.so`) lies on the search path. Sorted, without duplicates.
std::vector<std::string> available_kernel_types(const std::vector<std::string>& search_path);

/// Loads one plugin file and returns the kernel types it registered.
/// @throws std::runtime_error with the loader's message if it cannot be loaded.
std::vector<std::string> load_plugin(const std::string& path);

}  // namespace oscar
