#include "idl_types.hpp"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <ctime>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace oscar::inspect {
namespace {

std::vector<std::string> tokenize(const std::string& text) {
  std::vector<std::string> out;
  std::size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (std::isspace(static_cast<unsigned char>(c))) {
      ++i;
    } else if (c == '#') {  // a preprocessor line
      while (i < text.size() && text[i] != '\n') ++i;
    } else if (text.compare(i, 2, "//") == 0) {
      while (i < text.size() && text[i] != '\n') ++i;
    } else if (text.compare(i, 2, "/*") == 0) {
      const auto end = text.find("*/", i + 2);
      i = end == std::string::npos ? text.size() : end + 2;
    } else if (text.compare(i, 2, "::") == 0) {
      out.emplace_back("::");
      i += 2;
    } else if (std::isalnum(static_cast<unsigned char>(c)) || c == '_') {
      std::size_t j = i;
      while (j < text.size() &&
             (std::isalnum(static_cast<unsigned char>(text[j])) || text[j] == '_'))
        ++j;
      out.push_back(text.substr(i, j - i));
      i = j;
    } else {
      out.emplace_back(1, c);
      ++i;
    }
  }
  return out;
}

const std::map<std::string, std::size_t>& primitive_sizes() {
  static const std::map<std::string, std::size_t> sizes{
      {"boolean", 1},       {"octet", 1}, {"char", 1},           {"int8", 1},
      {"uint8", 1},         {"short", 2}, {"unsigned short", 2}, {"long", 4},
      {"unsigned long", 4}, {"float", 4}, {"long long", 8},      {"unsigned long long", 8},
      {"double", 8}};
  return sizes;
}

// How deep modules, sequences and structs may nest: a text that comes over the network (a
// module's announced types) must not make the parser, the decoder or the encoder recurse without
// bound.
constexpr std::size_t kMaxNesting = 32;

class Parser {
 public:
  Parser(std::vector<std::string> tokens, std::map<std::string, std::vector<IdlMember>>& structs,
         std::map<std::string, std::vector<std::string>>& enums)
      : t_(std::move(tokens)), structs_(structs), enums_(enums) {}

  void definitions(const std::string& scope) {
    while (at_ < t_.size() && peek() != "}") {
      const auto word = next();
      if (word == "module") {
        const auto name = next();
        expect("{");
        const Nested nested(*this);
        definitions(scope + name + "::");
        expect("}");
        expect(";");
      } else if (word == "struct") {
        const auto name = next();
        auto& members = structs_[scope + name];
        members.clear();
        expect("{");
        while (peek() != "}") {
          auto type = type_spec(scope);
          auto member = next();
          if (peek() == "[") {
            next();
            IdlType array{IdlType::Kind::kArray, "", std::make_shared<IdlType>(type),
                          std::stoul(next())};
            expect("]");
            type = array;
          }
          expect(";");
          members.push_back({member, type});
        }
        expect("}");
        expect(";");
      } else if (word == "enum") {
        const auto name = next();
        auto& values = enums_[scope + name];
        values.clear();
        expect("{");
        while (peek() != "}") {
          values.push_back(next());
          if (peek() == ",") next();
        }
        expect("}");
        expect(";");
      } else {
        throw std::invalid_argument("IDL: unexpected '" + word +
                                    "' (expected module, struct or enum)");
      }
    }
  }

 private:
  IdlType type_spec(const std::string& scope) {
    auto word = next();
    if (word == "unsigned") {
      word.append(" ").append(next());
      if (word == "unsigned long" && peek() == "long") word.append(" ").append(next());
    } else if (word == "long" && peek() == "long") {
      word.append(" ").append(next());
    }
    if (primitive_sizes().count(word)) return {IdlType::Kind::kPrimitive, word, nullptr, 0};
    if (word == "string") {
      if (peek() == "<") skip_bound();
      return {IdlType::Kind::kString, word, nullptr, 0};
    }
    if (word == "sequence") {
      expect("<");
      const Nested nested(*this);
      auto element = std::make_shared<IdlType>(type_spec(scope));
      if (peek() == ",") {
        next();
        next();
      }
      expect(">");
      return {IdlType::Kind::kSequence, "", element, 0};
    }
    std::string name = word == "::" ? next() : word;  // a leading :: names the global scope
    while (peek() == "::") {
      next();
      name.append("::").append(next());
    }
    return {IdlType::Kind::kStruct, resolve(scope, name), nullptr, 0};
  }
  // A name as written inside `scope` ("oscar::"): the innermost declared match.
  std::string resolve(std::string scope, const std::string& name) const {
    while (true) {
      const auto full = scope + name;
      if (structs_.count(full) || enums_.count(full)) return full;
      if (scope.empty()) return name;
      scope.erase(scope.size() - 2);
      const auto colon = scope.rfind("::");
      scope = colon == std::string::npos ? "" : scope.substr(0, colon + 2);
    }
  }
  // One level deeper while it lives; more than kMaxNesting levels are refused.
  struct Nested {
    explicit Nested(Parser& p) : parser(p) {
      if (++parser.depth_ > kMaxNesting) {
        throw std::invalid_argument(
            fmt::format("IDL: modules or sequences nest deeper than {} levels", kMaxNesting));
      }
    }
    ~Nested() { --parser.depth_; }
    Nested(const Nested&) = delete;
    Nested& operator=(const Nested&) = delete;
    Parser& parser;
  };

  void skip_bound() {
    while (next() != ">") {
    }
  }
  const std::string& peek() const {
    static const std::string end;
    return at_ < t_.size() ? t_[at_] : end;
  }
  std::string next() {
    if (at_ >= t_.size()) throw std::invalid_argument("IDL: the text ends early");
    return t_[at_++];
  }
  void expect(const std::string& token) {
    const auto got = next();
    if (got != token)
      throw std::invalid_argument("IDL: expected '" + token + "', got '" + got + "'");
  }

  std::vector<std::string> t_;
  std::size_t at_ = 0;
  std::size_t depth_ = 0;
  std::map<std::string, std::vector<IdlMember>>& structs_;
  std::map<std::string, std::vector<std::string>>& enums_;
};

}  // namespace

std::string utc_text(std::uint64_t ns) {
  const std::time_t s = static_cast<std::time_t>(ns / 1'000'000'000);
  std::tm tm{};
  gmtime_r(&s, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
  return fmt::format("{}.{:09}Z", buf, ns % 1'000'000'000);
}

namespace {}  // namespace

namespace {

bool same(const IdlType& a, const IdlType& b) {
  if (a.kind != b.kind || a.name != b.name || a.array_size != b.array_size) return false;
  if (!a.element || !b.element) return !a.element && !b.element;
  return same(*a.element, *b.element);
}

bool same(const std::vector<IdlMember>& a, const std::vector<IdlMember>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const auto& x, const auto& y) {
    return x.name == y.name && same(x.type, y.type);
  });
}

// How deep the struct `name` nests structs (1: none), through members, sequences and arrays.
// @throws std::invalid_argument for a struct that contains itself or nests deeper than
//         kMaxNesting.
std::size_t nesting(const std::map<std::string, std::vector<IdlMember>>& structs,
                    const std::string& name, std::vector<std::string>& chain,
                    std::map<std::string, std::size_t>& known) {
  if (const auto k = known.find(name); k != known.end()) return k->second;
  chain.push_back(name);
  if (std::find(chain.begin(), chain.end() - 1, name) != chain.end() - 1) {
    throw std::invalid_argument(
        fmt::format("IDL: struct '{}' contains itself ({}): recursive types are not supported",
                    name, fmt::join(chain, " > ")));
  }
  const auto too_deep = [&] {
    return std::invalid_argument(fmt::format("IDL: structs nest deeper than {} levels ({} > ...)",
                                             kMaxNesting, chain.front()));
  };
  if (chain.size() > kMaxNesting) throw too_deep();
  std::size_t depth = 1;
  for (const auto& m : structs.at(name)) {
    const IdlType* t = &m.type;
    while (t->element) t = t->element.get();
    if (t->kind == IdlType::Kind::kStruct && structs.count(t->name)) {
      depth = std::max(depth, 1 + nesting(structs, t->name, chain, known));
    }
  }
  if (chain.size() - 1 + depth > kMaxNesting) throw too_deep();
  chain.pop_back();
  return known[name] = depth;
}

}  // namespace

void IdlTypes::add(const std::string& idl_text) {
  // Parsed into copies and taken only whole: a text that fails changes nothing here.
  auto structs = structs_;
  auto enums = enums_;
  Parser(tokenize(idl_text), structs, enums).definitions("");
  for (const auto& [name, members] : structs_) {
    if (!same(members, structs.at(name))) {
      throw std::invalid_argument(
          fmt::format("IDL: struct '{}' is declared here already, with other members", name));
    }
  }
  for (const auto& [name, values] : enums_) {
    if (values != enums.at(name)) {
      throw std::invalid_argument(
          fmt::format("IDL: enum '{}' is declared here already, with other enumerators", name));
    }
  }
  std::map<std::string, std::size_t> known;
  for (const auto& [name, members] : structs) {
    std::vector<std::string> chain;
    nesting(structs, name, chain, known);
  }
  structs_ = std::move(structs);
  enums_ = std::move(enums);
}

bool IdlTypes::has(const std::string& name) const { return structs_.count(name) > 0; }

const std::vector<IdlMember>* IdlTypes::members(const std::string& name) const {
  const auto it = structs_.find(name);
  return it == structs_.end() ? nullptr : &it->second;
}

const std::vector<std::string>* IdlTypes::enumerators(const std::string& name) const {
  const auto it = enums_.find(name);
  return it == enums_.end() ? nullptr : &it->second;
}

// Reads XCDR1/XCDR2 plain (final) data as Fast DDS 2.9 writes it.
class Decoder {
 public:
  Decoder(const IdlTypes& types, std::span<const std::uint8_t> payload, const IdlTypes::Options& o)
      : types_(types), o_(o) {
    if (payload.size() < 4 || payload[0] != 0 ||
        (payload[1] > 1 && (payload[1] < 6 || payload[1] > 11)))
      throw std::runtime_error("not a CDR encapsulation (first bytes are no CDR/XCDR2 header)");
    little_ = payload[1] & 1;
    align8_ = payload[1] <= 1 ? 8 : 4;
    body_ = payload.subspan(4);
  }

  void value(const IdlType& t, const std::string& indent, std::string& out, bool in_line) {
    switch (t.kind) {
      case IdlType::Kind::kPrimitive:
        out += primitive(t.name);
        break;
      case IdlType::Kind::kString: {
        const auto n = uint(4, 4);
        need(n);
        std::string s(reinterpret_cast<const char*>(body_.data() + at_), n ? n - 1 : 0);
        at_ += n;
        out += fmt::format("\"{}\"", s);
        break;
      }
      case IdlType::Kind::kEnum:
        break;
      case IdlType::Kind::kSequence:
      case IdlType::Kind::kArray: {
        const auto n = t.kind == IdlType::Kind::kSequence ? uint(4, 4) : t.array_size;
        const auto& e = *t.element;
        // A char array (a plain cue's source): its text up to the first NUL.
        if (t.kind == IdlType::Kind::kArray && e.kind == IdlType::Kind::kPrimitive &&
            e.name == "char") {
          need(n);
          const auto* chars = reinterpret_cast<const char*>(body_.data() + at_);
          out += fmt::format("\"{}\"", std::string(chars, std::find(chars, chars + n, '\0')));
          at_ += n;
          break;
        }
        const bool scalar = e.kind != IdlType::Kind::kStruct || is_enum(e);
        if (scalar) {
          out += "[";
          for (std::uint64_t i = 0; i < n; ++i) {
            if (i >= o_.max_items && e.kind == IdlType::Kind::kPrimitive) {
              skip(primitive_sizes().at(e.name), n - i);  // not shown: only stepped over
              break;
            }
            std::string item;
            value(e, indent, item, true);
            if (i < o_.max_items) out += (i ? ", " : "") + item;
          }
          out += n > o_.max_items ? fmt::format(", ...]  # {} items", n) : "]";
        } else if (n == 0) {
          out += " []";
        } else {
          for (std::uint64_t i = 0; i < n; ++i) {
            std::string item;
            structure(e.name, indent + "    ", item);
            if (i < o_.max_items) {
              out.append("\n").append(indent).append("  - ").append(item, indent.size() + 5);
            }
          }
          if (n > o_.max_items) out += fmt::format("\n{}  # ... {} items", indent, n);
        }
        break;
      }
      case IdlType::Kind::kStruct:
        if (is_enum(t)) {
          const auto v = uint(4, 4);
          const auto& names = types_.enums_.at(t.name);
          out += v < names.size() ? names[v] : std::to_string(v);
        } else if (in_line) {
          std::string inner;
          structure(t.name, indent + "  ", inner);
          out += "{" + inner + "}";
        } else {
          structure(t.name, indent + "  ", out);
        }
        break;
    }
  }

  // Members one a line, each "\n<indent>name: value".
  void structure(const std::string& name, const std::string& indent, std::string& out) {
    const auto it = types_.structs_.find(name);
    if (it == types_.structs_.end()) throw std::invalid_argument("unknown IDL type '" + name + "'");
    for (const auto& m : it->second) {
      out.append("\n").append(indent).append(m.name).append(":");
      const bool listed =
          (m.type.kind == IdlType::Kind::kSequence || m.type.kind == IdlType::Kind::kArray) &&
          m.type.element->kind == IdlType::Kind::kStruct && !is_enum(*m.type.element);
      const bool nested = listed || (m.type.kind == IdlType::Kind::kStruct && !is_enum(m.type));
      if (!nested) out += " ";
      const auto start = out.size();
      value(m.type, indent, out, false);
      // A cue header's stamps: the generation time in UTC, readably.
      if ((name == "oscar::CueHeader" || name == "oscar::PlainCueHeader") && m.name == "stamps" &&
          out.size() > start + 2) {
        const auto first = out.substr(start + 1, out.find_first_of(",]", start) - start - 1);
        if (!first.empty() && first != "0" && std::isdigit(static_cast<unsigned char>(first[0])))
          out += "  # generated " + utc_text(std::stoull(first));
      }
    }
  }

 private:
  bool is_enum(const IdlType& t) const {
    return t.kind == IdlType::Kind::kStruct && types_.enums_.count(t.name);
  }
  void need(std::uint64_t n) const {
    if (at_ + n > body_.size())
      throw std::runtime_error(fmt::format("the sample ends early: {} bytes, reading byte {}",
                                           body_.size() + 4, at_ + n + 4));
  }
  void skip(std::size_t size, std::uint64_t count) {
    const auto align = size == 8 ? align8_ : size;
    at_ = (at_ + align - 1) / align * align;
    need(size * count);
    at_ += size * count;
  }
  std::uint64_t uint(std::size_t size, std::size_t align) {
    at_ = (at_ + align - 1) / align * align;
    need(size);
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < size; ++i) {
      const std::uint64_t b = body_[at_ + i];
      v |= little_ ? b << (8 * i) : b << (8 * (size - 1 - i));
    }
    at_ += size;
    return v;
  }
  std::string primitive(const std::string& name) {
    const auto size = primitive_sizes().at(name);
    const auto v = uint(size, size == 8 ? align8_ : size);
    if (name == "boolean") return v ? "true" : "false";
    if (name == "double") {
      double d;
      std::memcpy(&d, &v, 8);
      return fmt::format("{}", d);
    }
    if (name == "float") {
      const auto u = static_cast<std::uint32_t>(v);
      float f;
      std::memcpy(&f, &u, 4);
      return fmt::format("{}", f);
    }
    const bool is_signed = name.find("unsigned") == std::string::npos && name != "octet" &&
                           name != "uint8" && name != "char";
    if (is_signed) {
      const auto shift = 64 - 8 * size;
      return std::to_string(static_cast<std::int64_t>(v << shift) >> shift);
    }
    return std::to_string(v);
  }

  const IdlTypes& types_;
  const IdlTypes::Options& o_;
  std::span<const std::uint8_t> body_;
  std::size_t at_ = 0;
  bool little_ = true;
  std::size_t align8_ = 8;
};

std::string IdlTypes::to_text(const std::string& type, std::span<const std::uint8_t> payload,
                              const Options& options) const {
  if (!has(type)) throw std::invalid_argument("unknown IDL type '" + type + "'");
  Decoder d(*this, payload, options);
  std::string out;
  d.structure(type, "", out);
  return out.empty() ? out : out.substr(1);
}

}  // namespace oscar::inspect

namespace oscar::inspect {

// Writes XCDR1 little-endian plain data, as Fast DDS 2.9 does (alignment counted from the end
// of the encapsulation header, 8 bytes for 8-byte primitives).
class Encoder {
 public:
  explicit Encoder(const IdlTypes& types) : types_(types) {}

  std::vector<std::uint8_t> encode(const std::string& type, const YAML::Node& node) {
    out_ = {0x00, 0x01, 0x00, 0x00};  // CDR, little endian
    structure(type, node, "");
    return std::move(out_);
  }

 private:
  static bool absent(const YAML::Node& n) { return !n.IsDefined() || n.IsNull(); }
  static std::string member_path(const std::string& path, const std::string& member) {
    return path.empty() ? member : path + "." + member;
  }
  [[noreturn]] static void fail(const std::string& path, const std::string& rule) {
    throw std::invalid_argument(path.empty() ? rule : fmt::format("{}: {}", path, rule));
  }
  bool is_enum(const IdlType& t) const {
    return t.kind == IdlType::Kind::kStruct && types_.enums_.count(t.name);
  }

  void structure(const std::string& name, const YAML::Node& node, const std::string& path) {
    const auto it = types_.structs_.find(name);
    if (it == types_.structs_.end()) fail(path, "unknown IDL type '" + name + "'");
    const auto& members = it->second;
    if (!absent(node)) {
      if (!node.IsMap()) fail(path, fmt::format("{} is a struct: give a map of its members", name));
      for (const auto& kv : node) {
        const auto key = kv.first.as<std::string>();
        if (std::none_of(members.begin(), members.end(),
                         [&](const IdlMember& m) { return m.name == key; })) {
          std::string known;
          for (const auto& m : members) known += (known.empty() ? "" : ", ") + m.name;
          fail(path, fmt::format("{} has no member '{}' (members: {})", name, key, known));
        }
      }
    }
    for (const auto& m : members) {
      value(m.type, absent(node) ? YAML::Node() : node[m.name], member_path(path, m.name));
    }
  }

  void value(const IdlType& t, const YAML::Node& node, const std::string& path) {
    switch (t.kind) {
      case IdlType::Kind::kPrimitive:
        primitive(t.name, node, path);
        return;
      case IdlType::Kind::kString: {
        const auto text = absent(node) ? std::string() : scalar(node, path, "a string");
        put(text.size() + 1, 4);
        out_.insert(out_.end(), text.begin(), text.end());
        out_.push_back(0);
        return;
      }
      case IdlType::Kind::kEnum:
        return;
      case IdlType::Kind::kSequence:
      case IdlType::Kind::kArray: {
        const bool array = t.kind == IdlType::Kind::kArray;
        if (!absent(node) && !node.IsSequence()) fail(path, "expected a list");
        const std::size_t n = absent(node) ? 0 : node.size();
        if (array && !absent(node) && n != t.array_size) {
          fail(path, fmt::format("expected a list of {} items, got {}", t.array_size, n));
        }
        if (!array) put(n, 4);
        const auto count = array ? t.array_size : n;
        for (std::size_t i = 0; i < count; ++i) {
          value(*t.element, i < n ? node[i] : YAML::Node(), fmt::format("{}[{}]", path, i));
        }
        return;
      }
      case IdlType::Kind::kStruct:
        if (is_enum(t)) {
          const auto& names = types_.enums_.at(t.name);
          if (absent(node)) {
            put(0, 4);
            return;
          }
          const auto text = scalar(node, path, "an enumerator");
          const auto at = std::find(names.begin(), names.end(), text);
          if (at == names.end()) {
            fail(path, fmt::format("'{}' is no enumerator of {} ({})", text, t.name,
                                   fmt::join(names, ", ")));
          }
          put(static_cast<std::uint64_t>(at - names.begin()), 4);
        } else {
          structure(t.name, node, path);
        }
        return;
    }
  }

  std::string scalar(const YAML::Node& node, const std::string& path, const char* what) {
    if (!node.IsScalar()) fail(path, fmt::format("expected {}", what));
    return node.Scalar();
  }

  void primitive(const std::string& name, const YAML::Node& node, const std::string& path) {
    const auto size = primitive_sizes().at(name);
    if (absent(node)) {
      put(0, size);
      return;
    }
    const auto text = scalar(node, path, ("a " + name).c_str());
    const auto wrong = [&] { fail(path, fmt::format("'{}' is no {}", text, name)); };
    if (name == "boolean") {
      bool b = false;
      if (!YAML::convert<bool>::decode(node, b)) wrong();
      put(b ? 1 : 0, 1);
    } else if (name == "double" || name == "float") {
      double d = 0;
      if (!YAML::convert<double>::decode(node, d)) wrong();
      if (name == "double") {
        std::uint64_t bits;
        std::memcpy(&bits, &d, 8);
        put(bits, 8);
      } else {
        const auto f = static_cast<float>(d);
        std::uint32_t bits;
        std::memcpy(&bits, &f, 4);
        put(bits, 4);
      }
    } else {
      const bool is_signed = name.find("unsigned") == std::string::npos && name != "octet" &&
                             name != "uint8" && name != "char";
      const auto bits = 8 * size;
      if (is_signed) {
        long long v = 0;
        if (!YAML::convert<long long>::decode(node, v)) wrong();
        const long long high =
            bits == 64 ? std::numeric_limits<long long>::max() : (1LL << (bits - 1)) - 1;
        if (v > high || v < -high - 1) {
          fail(path,
               fmt::format("{} is out of the range of {} ({}..{})", v, name, -high - 1, high));
        }
        put(static_cast<std::uint64_t>(v), size);
      } else {
        unsigned long long v = 0;
        if (text.starts_with("-") || !YAML::convert<unsigned long long>::decode(node, v)) wrong();
        const unsigned long long high =
            bits == 64 ? std::numeric_limits<unsigned long long>::max() : (1ULL << bits) - 1;
        if (v > high)
          fail(path, fmt::format("{} is out of the range of {} (0..{})", v, name, high));
        put(v, size);
      }
    }
  }

  void put(std::uint64_t v, std::size_t size) {
    while ((out_.size() - 4) % size) out_.push_back(0);
    for (std::size_t i = 0; i < size; ++i) out_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }

  const IdlTypes& types_;
  std::vector<std::uint8_t> out_;
};

std::vector<std::uint8_t> IdlTypes::from_yaml(const std::string& type,
                                              const YAML::Node& value) const {
  if (!has(type)) throw std::invalid_argument("unknown IDL type '" + type + "'");
  return Encoder(*this).encode(type, value);
}

}  // namespace oscar::inspect
