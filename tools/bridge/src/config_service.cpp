#include "config_service.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include <oscar/config_client.hpp>

#include "json_schemas.hpp"
#include "oscar/time.hpp"

namespace oscar::bridge {
using json = nlohmann::ordered_json;

namespace {
// The command kinds offered, in `oscar config`'s words. Not shutdown (stopping a module is the
// registry's: `oscar shutdown`/`restart`) and not kernel commands (each command port is a
// service of its own, with its request's JSON schema: command_services.hpp).
constexpr std::pair<const char*, CommandKind> kOffered[] = {
    {"activate", CMD_ACTIVATE},   {"deactivate", CMD_DEACTIVATE}, {"trigger", CMD_TRIGGER},
    {"set-cycle", CMD_SET_CYCLE}, {"set-param", CMD_SET_PARAM},   {"rewire", CMD_REWIRE},
    {"suspend", CMD_SUSPEND},     {"resume", CMD_RESUME},         {"stub", CMD_STUB}};

constexpr std::chrono::milliseconds kReplyWait{3000};
constexpr std::chrono::milliseconds kRewireWait{1000};  // the module's default (config.idl)
constexpr std::chrono::milliseconds kLongestRewireWait{30000};

std::string offered_list() {
  std::vector<std::string> names;
  for (const auto& [name, kind] : kOffered) names.emplace_back(name);
  return fmt::format("{}", fmt::join(names, ", "));
}
}  // namespace

std::string ConfigRequest::text() const {
  if (kind == CMD_COMMAND) {
    return fmt::format("{} command {} {}", command.module, command.kernel, command.name);
  }
  for (const auto& [name, k] : kOffered) {
    if (k == kind)
      return fmt::format("{} {}{}{}", module, name, args.empty() ? "" : " ", fmt::join(args, " "));
  }
  return module;
}

ServiceInfo config_service_info(std::uint32_t id) {
  return {.id = id,
          .name = "oscar/config",
          .type = "oscar.Config",
          .request_schema_name = "oscar.ConfigRequest",
          .request_schema = json_schema("oscar.ConfigRequest"),
          .response_schema_name = "oscar.ConfigResponse",
          .response_schema = json_schema("oscar.ConfigResponse")};
}

ConfigRequest parse_config_request(std::string_view payload) {
  const auto j = json::parse(payload, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) {
    throw std::invalid_argument(
        "oscar/config: the request must be a JSON object such as "
        R"({"module": "cams", "command": "set-cycle", "args": ["cam_a", "33ms"]})");
  }
  ConfigRequest r;
  const auto module = j.find("module");
  if (module == j.end() || !module->is_string() || module->get<std::string>().empty()) {
    throw std::invalid_argument("oscar/config: 'module' must name the target module");
  }
  r.module = module->get<std::string>();
  const auto command = j.find("command");
  if (command == j.end() || !command->is_string()) {
    throw std::invalid_argument("oscar/config: 'command' must be one of " + offered_list());
  }
  auto wanted = command->get<std::string>();
  std::replace(wanted.begin(), wanted.end(), '_', '-');  // set_cycle as well as set-cycle
  bool found = false;
  for (const auto& [name, kind] : kOffered) {
    if (wanted == name) {
      r.kind = kind;
      found = true;
    }
  }
  if (!found) {
    throw std::invalid_argument(
        fmt::format("oscar/config: command '{}' is not offered (offered: {})",
                    command->get<std::string>(), offered_list()));
  }
  if (const auto args = j.find("args"); args != j.end()) {
    if (!args->is_array()) throw std::invalid_argument("oscar/config: 'args' must be an array");
    for (const auto& a : *args) {
      if (!a.is_string()) {
        throw std::invalid_argument(fmt::format(
            "oscar/config: each of 'args' must be a string (as on oscar config's command line), "
            "got {}",
            a.dump()));
      }
      r.args.push_back(a.get<std::string>());
    }
  }
  return r;
}

std::string config_response_json(const ConfigReply& reply) {
  json kernels = json::array();
  for (const auto& k : reply.state().kernels()) {
    kernels.push_back({{"name", k.name()},
                       {"type", k.type()},
                       {"mode", k.mode()},
                       {"cycle_ms", static_cast<double>(k.cycle_ns()) / 1e6},
                       {"stub", k.stub()},
                       {"params", k.params()}});
  }
  return json{{"module", reply.module_name()},
              {"transition", reply.state().last_transition()},
              {"note", reply.note()},
              {"suspended", reply.state().suspended()},
              {"kernels", kernels}}
      .dump();
}

ConfigWorker::ConfigWorker(DdsParticipant& participant, std::string sender, std::size_t max_pending)
    : participant_(participant),
      sender_(std::move(sender)),
      max_pending_(max_pending),
      thread_([this] { run(); }) {}

ConfigWorker::~ConfigWorker() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
    pending_.clear();
  }
  wake_.notify_all();
  thread_.join();
}

bool ConfigWorker::submit(ConfigRequest request, Done done) {
  {
    std::lock_guard lock(mutex_);
    if (pending_.size() >= max_pending_) return false;
    pending_.emplace_back(std::move(request), std::move(done));
  }
  wake_.notify_one();
  return true;
}

void ConfigWorker::run() {
  ConfigClient client(participant_, sender_);
  for (;;) {
    std::pair<ConfigRequest, Done> next;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || !pending_.empty(); });
      if (stop_) return;
      next = std::move(pending_.front());
      pending_.pop_front();
    }
    auto& [request, done] = next;
    Outcome outcome;
    try {
      auto timeout = kReplyWait;
      if (request.kind == CMD_REWIRE) {  // the module replies after the new source's first cue
        timeout += request.args.size() == 4
                       ? std::min(kLongestRewireWait,
                                  std::chrono::duration_cast<std::chrono::milliseconds>(
                                      parse_duration(request.args[3])))
                       : kRewireWait;
      }
      if (request.kind == CMD_COMMAND) {
        const auto& c = request.command;
        const auto reply = client.send_command(c.module, c.kernel, c.name, c.request_type,
                                               std::move(request.request_cdr), timeout);
        outcome.ok = reply.ok();
        outcome.text = reply.ok() ? command_response_json(c, reply.answer()) : reply.error();
      } else {
        const auto reply = client.send(request.module, request.kind, request.args, timeout);
        outcome.ok = reply.ok();
        outcome.text = reply.ok() ? config_response_json(reply) : reply.error();
      }
    } catch (const std::exception& e) {
      outcome.text = e.what();
    }
    done(std::move(outcome));
  }
}

}  // namespace oscar::bridge
