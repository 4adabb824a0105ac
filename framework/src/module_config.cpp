// Configuration flow (docs/architecture.md, "Configuration"): commands, the authority rule, and
// replies.
#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "command_bounds.hpp"
#include "dds/module_dds.hpp"
#include "module_slot.hpp"
#include "oscar/security_files.hpp"
#include "oscar/time.hpp"

namespace oscar {
namespace {

// How long a rewire waits for the new source's first cue unless the command says (a source
// slower than 1 Hz needs its sender to say).
constexpr std::chrono::milliseconds kRewireWait{1000};

// The module the `coordinator:` section's process announces itself as (SystemSpec).
constexpr const char* kCoordinatorModule = "coordinator";

// Seed 004 §2.4: only the coordinator configures modules; the registry suspends, resumes and
// re-applies a restarted module's configuration; boot applies the initial configuration.
// Kernels' command ports are the coordinator's (and boot's) too: the registry restores
// configuration, it does not command actuators. The sender's name counts only from a process
// that hosts no module of the system (boot, the registry, an operator's tool): a kernel cannot
// borrow the coordinator's name, because the command comes from its module's process. In a
// secured system the name counts for nothing: the identity the writer authenticated as decides
// (DDS Security's permissions say who may write the topic at all, see docs/security.md).
constexpr const char* kRule =
    "only the coordinator configures modules (the registry may suspend, resume and re-apply; "
    "boot applies the initial configuration)";

std::optional<std::string> refusal_by_identity(const ConfigCommand& c, const std::string& identity,
                                               const std::string& kind, const std::string& module) {
  if (identity == security_files::module_identity(kCoordinatorModule) ||
      identity == security_files::kBoot || identity == security_files::kOperatorBoot) {
    return std::nullopt;
  }
  if (identity == security_files::kRegistry && c.kind() != CMD_TRIGGER && c.kind() != CMD_COMMAND) {
    return std::nullopt;
  }
  return fmt::format(
      "refused: the writer authenticated as {} may not {} module '{}' (whatever "
      "sender it names, here '{}'): {}",
      identity.empty() ? "an identity with no such right" : "'" + identity + "'", kind, module,
      c.sender(), kRule);
}

std::optional<std::string> refusal(const ConfigCommand& c, const CommandOrigin& origin,
                                   const std::string& kind, const std::string& module) {
  const bool from_coordinator =
      origin.modules.size() == 1 && origin.modules.front() == kCoordinatorModule;
  if (!origin.modules.empty() && !from_coordinator) {
    return fmt::format(
        "refused: '{}' may not {} module '{}': the command comes from the process of module "
        "'{}', and {}",
        c.sender(), kind, module, fmt::join(origin.modules, "', '"), kRule);
  }
  if (origin.identity) return refusal_by_identity(c, *origin.identity, kind, module);
  const std::string& sender = from_coordinator ? kCoordinatorModule : c.sender();
  if (sender == kCoordinatorModule || sender == "boot") return std::nullopt;
  if (sender == "registry" && c.kind() != CMD_TRIGGER && c.kind() != CMD_COMMAND) {
    return std::nullopt;
  }
  return fmt::format("refused: '{}' may not {} module '{}': {}", c.sender(), kind, module, kRule);
}

void need_args(const ConfigCommand& c, std::size_t n, const char* form) {
  if (c.args().size() != n) {
    throw std::invalid_argument(fmt::format("{} takes {} argument(s) ({}), got {}",
                                            internal::command_kind_name(c.kind()), n, form,
                                            c.args().size()));
  }
}

}  // namespace

Module::Slot& Module::slot_for(const std::string& kernel, const std::string& command) {
  for (auto& s : slots_) {
    if (s->instance->name() == kernel) return *s;
  }
  std::vector<std::string> names;
  for (auto& s : slots_) names.push_back(s->instance->name());
  throw std::invalid_argument(fmt::format("{}: module '{}' has no kernel '{}' (kernels: {})",
                                          command, spec_.name, kernel, fmt::join(names, ", ")));
}

std::vector<Module::Slot*> Module::slots_for(const std::string& kernel_or_all,
                                             const std::string& command) {
  std::vector<Slot*> out;
  if (kernel_or_all == "*") {
    for (auto& s : slots_) out.push_back(s.get());
  } else {
    out.push_back(&slot_for(kernel_or_all, command));
  }
  return out;
}

ConfigReply Module::apply(const ConfigCommand& c, const CommandOrigin& origin) {
  ConfigReply reply;
  reply.id(c.id());
  reply.module_name(spec_.name);
  // Checked before anything quotes the command: its fields are the writer's to choose.
  auto why = internal::malformed(c);
  const std::string kind = why ? "" : internal::command_kind_name(c.kind());
  if (!why) why = refusal(c, origin, kind, spec_.name);
  if (why) {
    reply.ok(false);
    reply.error(std::move(*why));
    log_->warn("{}", reply.error());
    reply.state(state());
    return reply;
  }
  try {
    if (c.kind() != CMD_COMMAND && (!c.payload_type().empty() || !c.payload().empty())) {
      throw std::invalid_argument(fmt::format(
          "only a command (CMD_COMMAND) carries a payload; this one has {} bytes of '{}'",
          c.payload().size(), c.payload_type()));
    }
    std::string transition;
    switch (c.kind()) {
      case CMD_ACTIVATE: {
        if (c.args().empty() || c.args().size() > 2) {
          throw std::invalid_argument(
              "activate takes [kernel|*] or [kernel|*, mode], e.g. ['cam', 'continuous:33ms']");
        }
        const auto targets = slots_for(c.args()[0], kind);
        post_and_wait([&] {
          for (auto* s : targets) {
            auto mode = c.args().size() == 2 ? ModeSpec::parse_text(c.args()[1])
                                             : spec_.effective_mode(*s->spec);
            if (mode.kind == ModeSpec::Kind::kDeactivated) mode = ModeSpec{};
            std::lock_guard lock(mutex_);
            if (mode.kind == ModeSpec::Kind::kContinuous) {
              for (auto& other : slots_) {
                if (other.get() != s && other->continuous()) {
                  throw std::invalid_argument(fmt::format(
                      "cannot make '{}' continuous: '{}' already is (multi-core rule: at most "
                      "one kernel in continuous mode)",
                      s->instance->name(), other->instance->name()));
                }
              }
            }
            transition += fmt::format("{}{}: {} -> {}", transition.empty() ? "" : "; ",
                                      s->instance->name(), s->mode.describe(), mode.describe());
            s->mode = mode;
            s->next_due = std::chrono::steady_clock::now();
          }
          wake_.notify_all();
        });
        break;
      }
      case CMD_DEACTIVATE: {
        need_args(c, 1, "kernel|*");
        const auto targets = slots_for(c.args()[0], kind);
        post_and_wait([&] {
          for (auto* s : targets) {
            {
              std::lock_guard lock(mutex_);
              transition += fmt::format("{}{}: {} -> deactivated", transition.empty() ? "" : "; ",
                                        s->instance->name(), s->mode.describe());
              s->mode.kind = ModeSpec::Kind::kDeactivated;
              s->pending = false;
            }
            if (s->active) {
              s->instance->kernel().on_deactivate();
              s->active = false;
            }
          }
        });
        break;
      }
      case CMD_TRIGGER: {
        need_args(c, 1, "kernel|*");
        std::lock_guard lock(mutex_);
        for (auto* s : slots_for(c.args()[0], kind)) {
          if (!s->single_step()) {
            throw std::invalid_argument(
                fmt::format("cannot trigger '{}': it is {}, not single_step", s->instance->name(),
                            s->mode.describe()));
          }
          mark_pending(*s);
        }
        break;  // not a transition: no report
      }
      case CMD_SET_CYCLE: {
        need_args(c, 2, "kernel, cycle");
        auto& s = slot_for(c.args()[0], kind);
        const auto cycle = parse_duration(c.args()[1]);
        std::lock_guard lock(mutex_);
        if (!s.continuous() || cycle.count() <= 0) {
          throw std::invalid_argument(
              fmt::format("set_cycle: '{}' is {}; only a continuous kernel has a (positive) cycle",
                          s.instance->name(), s.mode.describe()));
        }
        transition = fmt::format("{}: cycle {} -> {}", s.instance->name(),
                                 format_duration(s.mode.cycle), format_duration(cycle));
        s.mode.cycle = cycle;
        break;
      }
      case CMD_SET_PARAM: {
        need_args(c, 3, "kernel, name, value");
        auto& s = slot_for(c.args()[0], kind);
        const auto* field = s.instance->ports().params.find(c.args()[1]);
        if (field && !field->runtime && s.active) {
          throw std::invalid_argument(
              fmt::format("parameter '{}' of '{}' cannot change while it runs; deactivate it first",
                          c.args()[1], s.instance->name()));
        }
        post_and_wait([&] {
          {
            std::lock_guard lock(mutex_);  // state() reads the values from another thread
            s.instance->ports().params.set_text(c.args()[1], c.args()[2]);
          }
          s.instance->kernel().on_params_changed();
        });
        transition = fmt::format("{}: {} = {}", s.instance->name(), internal::excerpt(c.args()[1]),
                                 internal::excerpt(c.args()[2]));
        break;
      }
      case CMD_REWIRE: {
        if (c.args().size() != 3 && c.args().size() != 4) {
          throw std::invalid_argument(fmt::format(
              "rewire takes 3 or 4 arguments (kernel, input, source, longest wait for the new "
              "source's first cue, e.g. 2s), got {}",
              c.args().size()));
        }
        const auto wait =
            c.args().size() == 4
                ? std::chrono::duration_cast<std::chrono::milliseconds>(parse_duration(c.args()[3]))
                : kRewireWait;
        reply.note(
            internal::excerpt(rewire(slot_for(c.args()[0], kind), c.args()[1], c.args()[2], wait),
                              internal::kMaxReplyTextChars));
        transition = fmt::format("{}.{} <- {}", internal::excerpt(c.args()[0]),
                                 internal::excerpt(c.args()[1]), internal::excerpt(c.args()[2]));
        break;
      }
      case CMD_SUSPEND:
      case CMD_RESUME: {
        need_args(c, 0, "none");
        std::lock_guard lock(mutex_);
        suspended_ = c.kind() == CMD_SUSPEND;
        wake_.notify_all();
        transition = suspended_ ? "suspended (buffers kept)" : "resumed";
        break;
      }
      case CMD_STUB: {
        need_args(c, 2, "kernel|*, on|off");
        if (c.args()[1] != "on" && c.args()[1] != "off") {
          throw std::invalid_argument("stub: the second argument is 'on' or 'off'");
        }
        std::lock_guard lock(mutex_);
        for (auto* s : slots_for(c.args()[0], kind)) {
          s->stub = c.args()[1] == "on";
          transition += fmt::format("{}{}: stub {}", transition.empty() ? "" : "; ",
                                    s->instance->name(), c.args()[1]);
        }
        break;
      }
      case CMD_SHUTDOWN:
        transition = "shutdown requested";
        request_stop();
        break;
      case CMD_COMMAND: {
        need_args(c, 2, "kernel, command name");
        auto& s = slot_for(c.args()[0], kind);
        const auto& port = s.instance->command(c.args()[1]);
        const auto request = port.decode(c.payload_type(), c.payload());
        const auto answer = deliver_command(s, port, request.get());
        reply.answered(true);
        // A kernel's answer is its own text: the reply and the log get at most a page of it.
        const auto text = internal::excerpt(answer.text, internal::kMaxReplyTextChars);
        reply.answer(text);
        reply.ok(answer.accepted);
        if (!answer.accepted) {
          reply.error(fmt::format("command '{}' refused by kernel '{}': {}", port.name(),
                                  port.kernel(), text));
          log_->warn("{}", reply.error());
        }
        reply.state(state());
        return reply;  // not a transition: no report
      }
    }
    if (!transition.empty()) report(transition);
    reply.ok(true);
  } catch (const std::exception& e) {
    reply.ok(false);
    // An exception's text may quote an argument (up to kMaxArgChars) or a kernel's words.
    reply.error(internal::excerpt(fmt::format("{} failed: {}", kind, e.what()),
                                  internal::kMaxReplyTextChars));
    log_->warn("{}", reply.error());
  }
  reply.state(state());
  return reply;
}

// Runs the kernel's handler on the processing thread, between its cycles (docs/kernels.md,
// "Command ports"). A deactivated kernel and a suspended module refuse commands; a kernel that
// is activated but has not run yet gets its on_activate() first, as before its first cycle.
CommandAnswer Module::deliver_command(Slot& slot, const CommandPort& port, const void* request) {
  CommandAnswer answer;
  post_and_wait([&] {
    {
      std::lock_guard lock(mutex_);
      if (suspended_) {
        throw std::invalid_argument(
            fmt::format("module '{}' is suspended; its kernels take commands again once it resumes",
                        spec_.name));
      }
      if (slot.mode.kind == ModeSpec::Kind::kDeactivated) {
        throw std::invalid_argument(fmt::format(
            "kernel '{}' is deactivated; a kernel takes commands only while it is activated",
            slot.instance->name()));
      }
    }
    const auto call = fmt::format("command {}", port.name());
    try {
      if (!slot.active) {
        slot.instance->kernel().on_activate();
        slot.active = true;
        if (dds_) dds_->publish_wishes();
      }
      busy_since_ns_.store(std::chrono::steady_clock::now().time_since_epoch().count(),
                           std::memory_order_relaxed);
      answer = port.call(request);
      busy_since_ns_.store(0, std::memory_order_relaxed);
    } catch (const std::exception& e) {
      busy_since_ns_.store(0, std::memory_order_relaxed);
      const auto failure =
          fmt::format("{}: {}", slot.active ? call : std::string("on_activate()"), e.what());
      kernel_failed(slot, failure);
      throw std::runtime_error(
          fmt::format("kernel '{}' failed in {}", slot.instance->name(), failure));
    }
  });
  return answer;
}

std::string Module::rewire(Slot& slot, const std::string& input_name, const std::string& source,
                           std::chrono::milliseconds switch_wait) {
  auto* input = slot.instance->ports().find_input(input_name);
  if (!input) {
    throw std::invalid_argument(
        fmt::format("kernel '{}' has no input '{}'", slot.instance->name(), input_name));
  }
  const auto slash = source.find('/');
  if (slash == std::string::npos || slash == 0 || slash + 1 == source.size()) {
    throw std::invalid_argument(fmt::format("source '{}' must be '<kernel>/<channel>'", source));
  }
  std::map<std::string, std::string> before;
  {
    // The multi-core rules must hold for the wiring as it will be after the rewire.
    std::lock_guard lock(mutex_);
    before = slot.sources;
    slot.sources[input_name] = source;
    try {
      check_multicore_rules();
    } catch (...) {
      slot.sources = before;
      throw;
    }
  }
  try {
    return connect(*input, source, switch_wait);
  } catch (...) {
    std::lock_guard lock(mutex_);
    slot.sources = before;  // nothing was broken: the input keeps its old source
    throw;
  }
}

}  // namespace oscar
