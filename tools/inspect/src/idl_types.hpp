#pragma once
// A small reader of OMG IDL (the self-contained `omgidl` texts OSCAR embeds and writes to MCAP),
// a decoder that prints a serialized CDR sample of such a type as YAML-like text (how
// `oscar echo` shows any OSCAR type without compiled code for it) and an encoder from YAML to
// CDR (how `oscar config ... command` sends a kernel any request type).

#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace oscar::inspect {

/// A type as the IDL declares it.
struct IdlType {
  enum class Kind { kPrimitive, kString, kSequence, kArray, kStruct, kEnum };
  Kind kind = Kind::kPrimitive;
  std::string name;                  ///< primitive keyword, or the scoped name of a struct/enum
  std::shared_ptr<IdlType> element;  ///< of a sequence or array
  std::size_t array_size = 0;
};

struct IdlMember {
  std::string name;
  IdlType type;
};

/// Every struct and enum of one or more IDL texts, by scoped name ("oscar::GvImage").
class IdlTypes {
 public:
  /// Reads one IDL text (comments and preprocessor lines are skipped).
  /// @throws std::invalid_argument naming the token it did not understand.
  void add(const std::string& idl_text);
  bool has(const std::string& scoped_name) const;
  /// The members of the struct `scoped_name` in declaration order; nullptr if it is no struct
  /// known here.
  const std::vector<IdlMember>* members(const std::string& scoped_name) const;
  /// The enumerators of the enum `scoped_name` in declaration order; nullptr if it is no enum
  /// known here.
  const std::vector<std::string>* enumerators(const std::string& scoped_name) const;

  struct Options {
    std::size_t max_items = 16;  ///< longer sequences and arrays show their first items and size
  };
  /// The sample (with its 4-byte encapsulation header) as YAML-like text, one field a line.
  /// @throws std::invalid_argument for an unknown type; std::runtime_error if the bytes end early
  ///         or have an encapsulation it does not know.
  std::string to_text(const std::string& type, std::span<const std::uint8_t> payload,
                      const Options& options) const;

  /// The CDR encoding of `type` (XCDR1, little endian, with the 4-byte encapsulation header, as
  /// Fast DDS 2.9 writes samples) from YAML: a struct is a map of its members by name, and a
  /// member the map leaves out takes its IDL default (0, false, "", empty, the first
  /// enumerator); a sequence or array is a list, an enum its enumerator's name.
  /// @throws std::invalid_argument for an unknown type, or naming the member (e.g.
  ///         "frame.width") and the rule: an unknown member, a value that is no number of the
  ///         member's type or out of its range, an array of the wrong length, an unknown
  ///         enumerator.
  std::vector<std::uint8_t> from_yaml(const std::string& type, const YAML::Node& value) const;

 private:
  friend class Decoder;
  friend class Encoder;
  std::map<std::string, std::vector<IdlMember>> structs_;
  std::map<std::string, std::vector<std::string>> enums_;
};

/// A time in ns since the epoch as UTC text, e.g. "2026-11-22T09:43:47.838715176Z".
std::string utc_text(std::uint64_t ns);

}  // namespace oscar::inspect
