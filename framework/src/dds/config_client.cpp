#include "oscar/config_client.hpp"

#include <algorithm>

#include <unistd.h>

#include <optional>
#include <thread>

#include <fmt/format.h>
#include <oscar/configPubSubTypes.h>

#include "oscar/malformed_samples.hpp"
#include "oscar/topics.hpp"

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include "oscar/time.hpp"

namespace oscar {
namespace dds = eprosima::fastdds::dds;

struct ConfigClient::Channel {
  dds::DataWriter* writer = nullptr;
  dds::DataReader* reader = nullptr;
  std::mutex mutex;  // one command at a time to this module
};

ConfigClient::ConfigClient(DdsParticipant& participant, std::string sender)
    : participant_(participant),
      sender_(std::move(sender)),
      // Ids unique across clients: replies of other clients' commands are read and skipped.
      next_id_((static_cast<unsigned long long>(getpid()) << 32) |
               (static_cast<unsigned long long>(wall_now()) & 0xffff0000ull)) {}

ConfigClient::~ConfigClient() {
  for (auto& [module, c] : channels_) {
    participant_.publisher().delete_datawriter(c->writer);
    participant_.subscriber().delete_datareader(c->reader);
  }
}

ConfigClient::Channel& ConfigClient::channel(const std::string& module) {
  if (const auto it = channels_.find(module); it != channels_.end()) return *it->second;
  // The replies are polled (send() waits for its own), so the reader has no listener and is
  // made here rather than as a TopicReader.
  const auto commands = topics::config(module);
  const auto replies = topics::config_reply(module);
  auto c = std::make_unique<Channel>();
  c->writer = participant_.publisher().create_datawriter(
      &participant_.topic(commands.name, new ConfigCommandPubSubType()), commands.writer_qos);
  c->reader = participant_.subscriber().create_datareader(
      &participant_.topic(replies.name, new ConfigReplyPubSubType()), replies.reader_qos);
  if (!c->writer || !c->reader) {
    if (c->writer) participant_.publisher().delete_datawriter(c->writer);
    if (c->reader) participant_.subscriber().delete_datareader(c->reader);
    throw std::runtime_error("cannot create the configuration endpoints for module " + module +
                             participant_.permission_hint(commands.name));
  }
  return *(channels_[module] = std::move(c));
}

void ConfigClient::connect(const std::string& module) {
  std::lock_guard lock(mutex_);
  channel(module);
}

ConfigReply ConfigClient::send(const std::string& module, CommandKind kind,
                               std::vector<std::string> args, std::chrono::milliseconds timeout) {
  ConfigCommand cmd;
  cmd.target(module);
  cmd.kind(kind);
  cmd.args(std::move(args));
  return send(std::move(cmd), timeout);
}

ConfigReply ConfigClient::send_command(const std::string& module, const std::string& kernel,
                                       const std::string& command, const std::string& type,
                                       std::vector<std::uint8_t> cdr,
                                       std::chrono::milliseconds timeout) {
  ConfigCommand cmd;
  cmd.target(module);
  cmd.kind(CMD_COMMAND);
  cmd.args({kernel, command});
  cmd.payload_type(type);
  cmd.payload(std::move(cdr));
  return send(std::move(cmd), timeout);
}

ModuleState ConfigClient::module_state(const std::string& module,
                                       std::chrono::milliseconds timeout) {
  const auto states = topics::module_state();
  auto* reader = participant_.subscriber().create_datareader(
      &participant_.topic(states.name, new ModuleStatePubSubType()), states.reader_qos);
  if (!reader) throw std::runtime_error("cannot read " + states.name);
  const auto until = std::chrono::steady_clock::now() + timeout;
  std::optional<ModuleState> found;
  while (!found && std::chrono::steady_clock::now() < until) {
    ModuleState s;
    dds::SampleInfo info;
    while (take_next(*reader, &s, info) == ReturnCode_t::RETCODE_OK) {
      if (info.valid_data && s.module_name() == module) found = s;
    }
    if (!found) reader->wait_for_unread_message(eprosima::fastrtps::Duration_t(0, 50'000'000));
  }
  participant_.subscriber().delete_datareader(reader);
  if (!found) {
    throw std::runtime_error(
        fmt::format("no module named '{}' is running (it published no state "
                    "on oscar/registry/module_state within {} ms)",
                    module, timeout.count()));
  }
  return *found;
}

ConfigReply ConfigClient::send(ConfigCommand cmd, std::chrono::milliseconds timeout) {
  const auto module = cmd.target();
  Channel* channel_ptr = nullptr;
  unsigned long long id = 0;
  {
    std::lock_guard lock(mutex_);
    channel_ptr = &channel(module);
    id = next_id_++;
  }
  // One command at a time per module (its replies share one reader); modules in parallel.
  auto& c = *channel_ptr;
  std::lock_guard channel_lock(c.mutex);
  const auto until = std::chrono::steady_clock::now() + timeout;
  // Wait until the module reads our commands and we read its replies.
  for (;;) {
    dds::PublicationMatchedStatus pub;
    dds::SubscriptionMatchedStatus sub;
    c.writer->get_publication_matched_status(pub);
    c.reader->get_subscription_matched_status(sub);
    if (pub.current_count > 0 && sub.current_count > 0) break;
    if (std::chrono::steady_clock::now() > until) {
      throw std::runtime_error(
          fmt::format("no module named '{}' is running (nobody reads {} after {} ms)", module,
                      topics::config(module).name, timeout.count()));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  cmd.id(id);
  cmd.sender(sender_);
  // At least once: a module that was just restarted may not read this writer yet while its dead
  // predecessor still counts as matched, so the command is repeated (same id; the module
  // answers a repeat from its memory) until the reply comes.
  auto resend = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() < until) {
    if (std::chrono::steady_clock::now() >= resend) {
      c.writer->write(&cmd);
      resend += std::chrono::milliseconds(100);
    }
    ConfigReply reply;
    dds::SampleInfo info;
    while (take_next(*c.reader, &reply, info) == ReturnCode_t::RETCODE_OK) {
      if (info.valid_data && reply.id() == cmd.id()) return reply;
    }
    c.reader->wait_for_unread_message(eprosima::fastrtps::Duration_t(0, 20'000'000));
  }
  throw std::runtime_error(fmt::format("module '{}' did not answer command {} within {} ms", module,
                                       cmd.id(), timeout.count()));
}

CommandKind parse_command_kind(const std::string& text) {
  static const std::pair<const char*, CommandKind> kinds[] = {
      {"activate", CMD_ACTIVATE},   {"deactivate", CMD_DEACTIVATE}, {"trigger", CMD_TRIGGER},
      {"set_cycle", CMD_SET_CYCLE}, {"set_param", CMD_SET_PARAM},   {"rewire", CMD_REWIRE},
      {"suspend", CMD_SUSPEND},     {"resume", CMD_RESUME},         {"stub", CMD_STUB},
      {"shutdown", CMD_SHUTDOWN},   {"command", CMD_COMMAND}};
  std::string known, wanted = text;
  std::replace(wanted.begin(), wanted.end(), '-', '_');  // `set-cycle` as well as `set_cycle`
  for (const auto& [name, kind] : kinds) {
    if (wanted == name) return kind;
    known += (known.empty() ? "" : ", ") + std::string(name);
  }
  throw std::invalid_argument(fmt::format("unknown command '{}' (commands: {})", text, known));
}

}  // namespace oscar
