#include "module_spec.hpp"

#include <fstream>
#include <regex>
#include <stdexcept>

#include <fmt/format.h>

namespace oscar::new_module {
namespace {

const std::set<std::string>& keywords() {
  static const std::set<std::string> k{"alignas",
                                       "alignof",
                                       "and",
                                       "asm",
                                       "auto",
                                       "bitand",
                                       "bitor",
                                       "bool",
                                       "break",
                                       "case",
                                       "catch",
                                       "char",
                                       "class",
                                       "compl",
                                       "concept",
                                       "const",
                                       "consteval",
                                       "constexpr",
                                       "constinit",
                                       "const_cast",
                                       "continue",
                                       "co_await",
                                       "co_return",
                                       "co_yield",
                                       "decltype",
                                       "default",
                                       "delete",
                                       "do",
                                       "double",
                                       "dynamic_cast",
                                       "else",
                                       "enum",
                                       "explicit",
                                       "export",
                                       "extern",
                                       "false",
                                       "float",
                                       "for",
                                       "friend",
                                       "goto",
                                       "if",
                                       "inline",
                                       "int",
                                       "long",
                                       "mutable",
                                       "namespace",
                                       "new",
                                       "noexcept",
                                       "not",
                                       "nullptr",
                                       "operator",
                                       "or",
                                       "private",
                                       "protected",
                                       "public",
                                       "register",
                                       "reinterpret_cast",
                                       "requires",
                                       "return",
                                       "short",
                                       "signed",
                                       "sizeof",
                                       "static",
                                       "static_assert",
                                       "static_cast",
                                       "struct",
                                       "switch",
                                       "template",
                                       "this",
                                       "thread_local",
                                       "throw",
                                       "true",
                                       "try",
                                       "typedef",
                                       "typeid",
                                       "typename",
                                       "union",
                                       "unsigned",
                                       "using",
                                       "virtual",
                                       "void",
                                       "volatile",
                                       "wchar_t",
                                       "while",
                                       "xor"};
  return k;
}

const std::vector<std::string> kCueTypes{"Bool", "LineSeg3DSeq", "GvImage"};

// The words OMG IDL 4 reserves (case-insensitively): a module with types of its own becomes an
// IDL module of its name, and its types IDL structs.
bool idl_keyword(std::string word) {
  static const std::set<std::string> k{
      "abstract",  "any",       "alias",      "attribute", "bitfield",    "bitmask",
      "bitset",    "boolean",   "case",       "char",      "component",   "connector",
      "const",     "consumes",  "context",    "custom",    "default",     "double",
      "exception", "emits",     "enum",       "eventtype", "factory",     "false",
      "finder",    "fixed",     "float",      "getraises", "getter",      "home",
      "import",    "in",        "inout",      "interface", "local",       "long",
      "manages",   "map",       "mirrorport", "module",    "multiple",    "native",
      "object",    "octet",     "oneway",     "out",       "primarykey",  "private",
      "port",      "porttype",  "provides",   "public",    "publishes",   "raises",
      "readonly",  "setraises", "setter",     "sequence",  "short",       "string",
      "struct",    "supports",  "switch",     "true",      "truncatable", "typedef",
      "typeid",    "typename",  "typeprefix", "unsigned",  "union",       "uses",
      "valuebase", "valuetype", "void",       "wchar",     "wstring",     "int8",
      "uint8",     "int16",     "int32",      "int64",     "uint16",      "uint32",
      "uint64"};
  for (auto& c : word) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return k.contains(word);
}
const std::vector<std::string> kParamTypes{"bool", "int", "int64", "double", "string", "duration"};

std::string join(const std::vector<std::string>& v) {
  std::string out;
  for (const auto& s : v) out += (out.empty() ? "" : ", ") + s;
  return out;
}

void check_identifier(const std::string& name, const std::string& what) {
  static const std::regex id("[A-Za-z_][A-Za-z0-9_]*");
  if (!std::regex_match(name, id)) {
    throw std::invalid_argument(fmt::format(
        "{} '{}' is not a C++ identifier (letters, digits and _, not starting with a digit)", what,
        name));
  }
  if (keywords().count(name)) {
    throw std::invalid_argument(fmt::format("{} '{}' is a C++ keyword", what, name));
  }
  if (name.find("__") != std::string::npos ||
      (name.size() > 1 && name[0] == '_' && std::isupper(static_cast<unsigned char>(name[1])))) {
    throw std::invalid_argument(
        fmt::format("{} '{}' is reserved in C++ (__ or _ and a capital)", what, name));
  }
}

}  // namespace

Port ModuleSpec::parse_port(const std::string& text, const char* option) {
  const auto colon = text.find(':');
  if (colon == std::string::npos) {
    throw std::invalid_argument(
        fmt::format("{} '{}': expected name:Type, e.g. image:GvImage", option, text));
  }
  auto type = text.substr(colon + 1);
  if (type.rfind("oscar::", 0) == 0) type = type.substr(7);
  return {text.substr(0, colon), type};
}

Param ModuleSpec::parse_param(const std::string& text) {
  static const std::regex form("([^:=]*):([^=]*)=(.*)");
  std::smatch m;
  if (!std::regex_match(text, m, form)) {
    throw std::invalid_argument(
        fmt::format("--param '{}': expected name:type=default, e.g. gain:double=1.5", text));
  }
  return {m[1], m[2], m[3]};
}

void ModuleSpec::validate(const std::set<std::string>& taken) const {
  check_identifier(name, "module name");
  if (std::regex_search(name, std::regex("[A-Z]"))) {
    throw std::invalid_argument(fmt::format(
        "module name '{}' must be snake_case (lower-case letters, digits and _)", name));
  }
  if (taken.count(name)) {
    throw std::invalid_argument(fmt::format(
        "module name '{}' is taken: a kernel type or module folder of that name exists", name));
  }
  if (outputs.empty()) {
    throw std::invalid_argument("a module needs at least one --output name:Type");
  }
  std::set<std::string> own;
  for (const auto& t : types) {
    check_identifier(t, "--type");
    if (!std::regex_match(t, std::regex("[A-Z][A-Za-z0-9]*"))) {
      throw std::invalid_argument(
          fmt::format("--type '{}' must be CamelCase (a capital, then letters and digits)", t));
    }
    if (std::find(kCueTypes.begin(), kCueTypes.end(), t) != kCueTypes.end()) {
      throw std::invalid_argument(
          fmt::format("--type '{}' is OSCAR's own cue type: use it without --type", t));
    }
    if (idl_keyword(t))
      throw std::invalid_argument(fmt::format("--type '{}' is an IDL keyword", t));
    if (!own.insert(t).second)
      throw std::invalid_argument(fmt::format("--type '{}' is given twice", t));
  }
  if (!types.empty() && (idl_keyword(name) || name == "oscar")) {
    throw std::invalid_argument(
        fmt::format("module name '{}' is {}: a module with --type is an IDL module of its name",
                    name, name == "oscar" ? "OSCAR's IDL module" : "an IDL keyword"));
  }
  std::set<std::string> names;
  const auto unique = [&](const std::string& n, const char* what) {
    check_identifier(n, what);
    if (!names.insert(n).second)
      throw std::invalid_argument(fmt::format("{} '{}': the name is used twice", what, n));
  };
  for (const auto* ports : {&inputs, &outputs}) {
    for (const auto& p : *ports) {
      const char* what = ports == &inputs ? "input" : "output";
      unique(p.name, what);
      if (ports == &inputs && own.contains(p.type)) {
        throw std::invalid_argument(fmt::format(
            "input '{}': a --type of the module's own is for its outputs (the generated system "
            "test feeds each input from a bench_source, which publishes OSCAR's types); read "
            "another module's type by hand (docs/kernels.md, \"Types of your own\")",
            p.name));
      }
      if (std::find(kCueTypes.begin(), kCueTypes.end(), p.type) == kCueTypes.end() &&
          !own.contains(p.type)) {
        throw std::invalid_argument(fmt::format(
            "{} '{}': unknown cue type '{}' (known: {}; a type of the module's own needs "
            "--type {})",
            what, p.name, p.type, join(kCueTypes) + (types.empty() ? "" : ", " + join(types)),
            p.type));
      }
    }
  }
  for (const auto& p : params) {
    unique(p.name, "param");
    if (std::find(kParamTypes.begin(), kParamTypes.end(), p.type) == kParamTypes.end()) {
      throw std::invalid_argument(fmt::format("param '{}': unknown type '{}' (known: {})", p.name,
                                              p.type, join(kParamTypes)));
    }
    static const std::map<std::string, std::regex> forms{
        {"bool", std::regex("true|false")},
        {"int", std::regex("-?[0-9]{1,9}")},
        {"int64", std::regex("-?[0-9]{1,18}")},
        {"double", std::regex("-?([0-9]+\\.?[0-9]*|\\.[0-9]+)([eE][-+]?[0-9]+)?")},
        {"string", std::regex("[^\"\\\\\n]*")},
        {"duration", std::regex("[0-9]+(\\.[0-9]+)?(ns|us|ms|s|min|h)")}};
    if (!std::regex_match(p.default_value, forms.at(p.type))) {
      throw std::invalid_argument(
          fmt::format("param '{}': default '{}' is no {} value{}", p.name, p.default_value, p.type,
                      p.type == "duration" ? " (e.g. 33ms, 1.5s)"
                      : p.type == "bool"   ? " (true or false)"
                      : p.type == "string" ? " (no quotes, backslashes or newlines)"
                                           : ""));
    }
  }
}

std::string ModuleSpec::class_name() const {
  std::string out;
  bool up = true;
  for (char c : name) {
    if (c == '_') {
      up = true;
      continue;
    }
    out += up ? static_cast<char>(std::toupper(static_cast<unsigned char>(c))) : c;
    up = false;
  }
  return out;
}

bool ModuleSpec::is_own_type(const std::string& type) const {
  return std::find(types.begin(), types.end(), type) != types.end();
}

std::string ModuleSpec::cpp_cue_type(const std::string& type) const {
  return (is_own_type(type) ? name : std::string("oscar")) + "::" + type;
}

std::filesystem::path write_module(const ModuleSpec& spec, const std::filesystem::path& dir) {
  const auto folder = dir / spec.name;
  if (std::filesystem::exists(folder)) {
    throw std::runtime_error(
        fmt::format("'{}' exists: choose another name or --dir", folder.string()));
  }
  for (const auto& [path, text] : generate(spec)) {
    const auto file = folder / path;
    std::filesystem::create_directories(file.parent_path());
    std::ofstream out(file);
    out << text;
    if (!out.flush()) throw std::runtime_error(fmt::format("cannot write '{}'", file.string()));
  }
  const auto list = dir / "CMakeLists.txt";
  if (!spec.out_of_tree && std::filesystem::exists(list)) {
    std::ifstream in(list);
    const std::string text((std::istreambuf_iterator<char>(in)), {});
    std::ofstream(list, std::ios::app) << (text.empty() || text.back() == '\n' ? "" : "\n")
                                       << "add_subdirectory(" << spec.name << ")\n";
  }
  return folder;
}

}  // namespace oscar::new_module
