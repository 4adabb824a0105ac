#include "oscar/command.hpp"

#include <stdexcept>

#include <fmt/format.h>

namespace oscar {

CommandPort::CommandPort(std::string kernel, std::string name, const IdlTypeInfo& type,
                         Handler handler)
    : kernel_(std::move(kernel)),
      name_(std::move(name)),
      type_(type),
      handler_(std::move(handler)) {}

std::shared_ptr<const void> CommandPort::decode(const std::string& type_name,
                                                const std::vector<std::uint8_t>& cdr) const {
  if (type_name != type_.name) {
    throw std::invalid_argument(fmt::format(
        "command '{}' of kernel '{}' takes {}, not {}", name_, kernel_, type_.name,
        type_name.empty() ? std::string("a command without a payload type") : type_name));
  }
  try {
    return type_.deserialize(cdr);
  } catch (const std::exception& e) {
    throw std::invalid_argument(
        fmt::format("command '{}' of kernel '{}': the payload is no {} ({})", name_, kernel_,
                    type_.name, e.what()));
  }
}

CommandAnswer CommandPort::call(const void* request) const {
  auto answer = handler_(request);
  if (!answer.accepted && answer.text.empty()) answer.text = "no reason given";
  return answer;
}

}  // namespace oscar
