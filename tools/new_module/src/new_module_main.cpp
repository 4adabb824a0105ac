// oscar new-module NAME: generates a module folder (kernel, CMake, README, unit test).
#include <cstdio>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <oscar/command_line.hpp>

#include "module_spec.hpp"
#include "oscar/kernel_registry.hpp"

int main(int argc, char** argv) {
  CLI::App app{"oscar new-module: generate a module (kernel, CMake, README, unit test)"};
  oscar::new_module::ModuleSpec spec;
  std::vector<std::string> inputs, outputs, params;
  std::string dir;
  app.add_option("NAME", spec.name, "the kernel type and folder name (snake_case)")->required();
  app.add_option("--input", inputs, "an input, name:Type (Bool, LineSeg3DSeq, GvImage)");
  app.add_option("--output", outputs, "an output, name:Type (OSCAR's or one of --type)");
  app.add_option("--type", spec.types,
                 "a cue type of the module's own (CamelCase), declared in NAME_types.idl");
  app.add_option("--param", params,
                 "a parameter, name:type=default "
                 "(bool, int, int64, double, string, duration)");
  app.add_option("--dir", dir,
                 "where to create the folder (default: modules/ in-tree, . out-of-tree)");
  app.add_flag("--out-of-tree", spec.out_of_tree,
               "a stand-alone project built against the installed package (find_package(oscar))");
  OSCAR_PARSE_COMMAND_LINE(app, argc, argv);
  try {
    for (const auto& i : inputs) spec.inputs.push_back(spec.parse_port(i, "--input"));
    for (const auto& o : outputs) spec.outputs.push_back(spec.parse_port(o, "--output"));
    for (const auto& p : params) spec.params.push_back(spec.parse_param(p));
    if (dir.empty()) dir = spec.out_of_tree ? "." : "modules";
    if (!spec.out_of_tree &&
        !std::filesystem::exists(std::filesystem::path(dir) / "CMakeLists.txt")) {
      throw std::invalid_argument(fmt::format(
          "in-tree modules go into the repository's modules/ folder, which has a CMakeLists.txt; "
          "'{}' has none (run this in the repository, give --dir, or use --out-of-tree)",
          dir));
    }
    // Taken: every kernel type that can be loaded, and every folder in dir.
    const auto types = oscar::available_kernel_types(oscar::plugin_search_path());
    std::set<std::string> taken(types.begin(), types.end());
    if (std::filesystem::exists(std::filesystem::path(dir) / spec.name)) taken.insert(spec.name);
    spec.validate(taken);
    const auto folder = oscar::new_module::write_module(spec, dir);
    fmt::print("oscar new-module: wrote {}/ (kernel type '{}', class {})\n", folder.string(),
               spec.name, spec.class_name());
    if (!spec.out_of_tree)
      fmt::print("added add_subdirectory({}) to {}/CMakeLists.txt\n", spec.name, dir);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oscar new-module: %s\n", e.what());
    return 2;
  }
}
