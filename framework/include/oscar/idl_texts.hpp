#pragma once
// The self-contained IDL text of every OSCAR type, by fully qualified name ("oscar::GvImage"),
// embedded at configure time: the `omgidl` schemas of the MCAP files `oscar record` writes.
// A module's own types (oscar_add_module(... IDL ...)) bring theirs along: its plugin registers
// them when it is loaded, and the module announces them to the tools (oscar/type_texts.hpp).

#include <map>
#include <optional>
#include <string>

namespace oscar {

/// OSCAR's own types (idl/oscar/*.idl).
const std::map<std::string, std::string>& idl_texts();

/// Registers the IDL texts of types OSCAR does not define, by fully qualified name; a plugin
/// built with oscar_add_module(... IDL ...) does so when it is loaded. A later text for a name
/// replaces the earlier one; OSCAR's own types cannot be replaced (they are looked up first).
void register_idl_texts(const std::map<std::string, std::string>& texts);

/// The IDL text of `type`: OSCAR's own, else a registered one; nullopt if there is none.
std::optional<std::string> find_idl_text(const std::string& type);

}  // namespace oscar
