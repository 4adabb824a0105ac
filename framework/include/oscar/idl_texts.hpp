#pragma once
// The self-contained IDL text of every OSCAR type, by fully qualified name ("oscar::GvImage"),
// embedded at configure time: the `omgidl` schemas of the MCAP files `oscar record` writes.

#include <map>
#include <string>

namespace oscar {

const std::map<std::string, std::string>& idl_texts();

}  // namespace oscar
