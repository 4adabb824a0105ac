#pragma once
/// @file Command ports: the typed commands a kernel accepts through the configuration flow
/// (docs/kernels.md, "Command ports").

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "oscar/idl_type_info.hpp"

namespace oscar {

/// A kernel's answer to a command: accepted, or refused with the reason.
struct CommandAnswer {
  bool accepted = false;
  std::string text;  ///< accepted: what it did (may be empty); refused: why

  static CommandAnswer accept(std::string text = {}) { return {true, std::move(text)}; }
  static CommandAnswer refuse(std::string reason) { return {false, std::move(reason)}; }
};

/// The type-independent part of a declared command; the frame works with this.
class CommandPort {
 public:
  using Handler = std::function<CommandAnswer(const void* request)>;
  CommandPort(std::string kernel, std::string name, const IdlTypeInfo& type, Handler handler);
  CommandPort(const CommandPort&) = delete;
  CommandPort& operator=(const CommandPort&) = delete;

  const std::string& kernel() const { return kernel_; }
  const std::string& name() const { return name_; }
  /// The request type.
  const IdlTypeInfo& type() const { return type_; }

  /// The request decoded from the CDR bytes a sender says are a `type_name`.
  /// @throws std::invalid_argument if `type_name` is not the declared type or the bytes are no
  ///         CDR encoding of it.
  std::shared_ptr<const void> decode(const std::string& type_name,
                                     const std::vector<std::uint8_t>& cdr) const;
  /// Runs the kernel's handler with a request of type(); what it throws passes. A refusal
  /// without a reason gets one.
  CommandAnswer call(const void* request) const;

 private:
  std::string kernel_, name_;
  const IdlTypeInfo& type_;
  Handler handler_;
};

}  // namespace oscar
