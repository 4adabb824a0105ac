#include "oscar/module.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <future>
#include <map>
#include <set>
#include <stdexcept>

#include <fmt/format.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "dds/log_sink.hpp"
#include "dds/module_dds.hpp"
#include "module_slot.hpp"
#include "oscar/dds_participant.hpp"
#include "repeat_filter_sink.hpp"
#include "ring_pull_source.hpp"
#include "sequence_store.hpp"

namespace oscar {

namespace {
using Clock = std::chrono::steady_clock;

std::string source_kernel(const std::string& source) { return source.substr(0, source.find('/')); }
std::string source_channel(const std::string& source) {
  return source.substr(source.find('/') + 1);
}
}  // namespace

Module::Module(ModuleSpec spec, const std::vector<std::string>& plugin_path)
    : spec_(std::move(spec)) {
  // Before any kernel exists: a participant a kernel makes says whose process it is in.
  if (!spec_.system_modules.empty()) internal::note_hosted_module(spec_.name);
  // Every line goes to stdout and, once the module is on DDS, to oscar/log; a line repeated
  // within a second is held back and counted.
  log_sink_ = std::make_shared<internal::DdsLogSink>(spec_.name);
  auto repeats = std::make_shared<internal::RepeatFilterSink>(std::chrono::seconds(1));
  repeats->add_sink(std::make_shared<spdlog::sinks::stdout_color_sink_st>());
  repeats->add_sink(log_sink_);
  const auto make_logger = [&](const std::string& name) {
    auto logger = std::make_shared<spdlog::logger>(name, repeats);
    logger->set_pattern("%H:%M:%S.%e %^%-5l%$ [%n] %v");
    return logger;
  };
  log_ = make_logger(spec_.name);
  const auto search_path = [&] {
    try {
      return with_plugins(spec_.plugins, plugin_path);
    } catch (const std::exception& e) {
      throw std::runtime_error(fmt::format("{}: plugins: {}", spec_.where, e.what()));
    }
  }();
  for (const auto& k : spec_.kernels) {
    const auto& type = [&]() -> const KernelTypeInfo& {
      try {
        return load_kernel_type(k.type, search_path);
      } catch (const std::exception& e) {
        throw std::runtime_error(fmt::format("{}: kernel '{}': {}", k.where, k.name, e.what()));
      }
    }();
    std::map<std::string, InputOverrides> options;
    for (const auto& [input, wiring] : k.inputs) options[input] = {wiring.depth, wiring.transfer};
    auto slot = std::make_unique<Slot>();
    slot->spec = &k;
    try {
      slot->instance = std::make_unique<KernelInstance>(type, k.name, k.params, options,
                                                        make_logger(spec_.name + "/" + k.name));
    } catch (const std::exception& e) {
      throw std::invalid_argument(
          fmt::format("{}: kernel '{}' ({}): {}", k.where, k.name, k.type, e.what()));
    }
    slot->mode = spec_.effective_mode(k);
    slot->stub = k.stub.value_or(spec_.stub);
    for (const auto& [input, wiring] : k.inputs) {
      if (!wiring.source.empty()) slot->sources[input] = wiring.source;
    }
    slots_.push_back(std::move(slot));
  }
  check_multicore_rules();
  wire_in_process();
}

Module::~Module() {
  stop();
  // A pull source in this process watches its producer's output: it goes before any output.
  for (auto& s : slots_) {
    for (auto& input : s->instance->ports().inputs) input->set_pull_source(nullptr);
  }
}

KernelInstance& Module::kernel(const std::string& name) {
  for (auto& s : slots_) {
    if (s->instance->name() == name) return *s->instance;
  }
  throw std::invalid_argument(fmt::format("module '{}' has no kernel '{}'", spec_.name, name));
}

// Seed 004 §2.2: the conditions under which several kernels may share one frame and thread.
void Module::check_multicore_rules() const {
  const auto rule = [&](const std::string& name, const std::string& detail) {
    return std::invalid_argument(fmt::format("{}: module '{}' breaks the multi-core rule '{}': {}",
                                             spec_.where, spec_.name, name, detail));
  };
  std::vector<std::string> continuous;
  for (const auto& s : slots_) {
    if (s->continuous()) continuous.push_back(s->instance->name());
  }
  if (continuous.size() > 1) {
    throw rule("at most one kernel in continuous mode (it triggers the others)",
               fmt::format("kernels {} are all continuous", fmt::join(continuous, ", ")));
  }
  // The internal cue flow: wires whose source is a kernel of this module.
  std::map<std::string, int> fan_out;  // source address -> internal consumers
  std::map<std::string, int> fan_in;   // kernel -> internal inputs
  std::set<std::string> kinds;
  for (const auto& s : slots_) {
    for (const auto& [input, source] : s->sources) {  // as wired now (after rewires)
      if (!spec_.find_kernel(source_kernel(source))) continue;
      ++fan_out[source];
      ++fan_in[s->instance->name()];
      const auto transfer = s->instance->ports().find_input(input)->transfer();
      kinds.insert(transfer == Transfer::kPush ? "push" : "pull");
    }
  }
  if (kinds.size() > 1) {
    throw rule("inside a multi-core module only pull or only push",
               "its internal inputs mix push with pull/prefetch");
  }
  const auto branch =
      std::find_if(fan_out.begin(), fan_out.end(), [](const auto& kv) { return kv.second > 1; });
  const auto merge =
      std::find_if(fan_in.begin(), fan_in.end(), [](const auto& kv) { return kv.second > 1; });
  if (branch != fan_out.end() && merge != fan_in.end()) {
    throw rule("no branching together with merging of cue flow",
               fmt::format("{} branches to {} kernels and {} merges {} inputs", branch->first,
                           branch->second, merge->first, merge->second));
  }
}

void Module::wire_in_process() {
  for (auto& s : slots_) {
    for (const auto& [input_name, source] : s->sources) {
      if (!spec_.find_kernel(source_kernel(source))) continue;  // remote: wired when DDS starts
      try {
        connect(*s->instance->ports().find_input(input_name), source, std::nullopt);
      } catch (const std::exception& e) {
        throw std::invalid_argument(fmt::format("{}: kernel '{}' input '{}': {}", s->spec->where,
                                                s->instance->name(), input_name, e.what()));
      }
    }
  }
  // Triggers: a single-step kernel triggered by data runs when its trigger input gets a cue.
  // The processing thread is woken after the lock is released: woken under it, it would only
  // wait for the lock again (a second wake-up on the way of every cue).
  for (auto& s : slots_) {
    Slot* slot = s.get();
    for (auto& input : slot->instance->ports().inputs) {
      InputPort* port = input.get();
      const bool first_input = slot->instance->ports().inputs.front().get() == port;
      port->set_arrival_hook([this, slot, first_input, trigger = "input:" + port->name()] {
        {
          std::lock_guard lock(mutex_);
          const auto& t = slot->mode.trigger;
          if (!slot->single_step() || !(t == trigger || (t.empty() && first_input))) return;
          slot->pending = true;
        }
        wake_.notify_all();
      });
    }
  }
}

// Wiring in one place: at construction (producers in this module), when DDS starts (the others)
// and on a rewire (`switch_wait` set). The new connection is made before the old one is broken:
// a push input is handed the producer's cues (in process) or subscribes to its topic, a pull or
// prefetch input reads the producer's ring (in process) or asks it over DDS. Returns what a
// rewire's reply should note (a new source that did not show up in time), or "".
std::string Module::connect(InputPort& input, const std::string& source,
                            std::optional<std::chrono::milliseconds> switch_wait) {
  const auto producer = source_kernel(source);
  if (spec_.find_kernel(producer)) {
    auto* output = kernel(producer).ports().find_output(source_channel(source));
    if (!output) {
      throw std::invalid_argument(
          fmt::format("kernel '{}' has no output '{}'", producer, source_channel(source)));
    }
    check_types(input, output->address(), output->type());
    if (input.transfer() == Transfer::kPush) {
      output->connect(&input);  // also checks the reliability the input declares
    } else {
      input.set_pull_source(
          std::make_shared<internal::RingPullSource>(output->buffer(), input, output));
    }
    for (auto& s : slots_) {
      for (auto& out : s->instance->ports().outputs) {
        if (out.get() != output) out->disconnect(&input);
      }
    }
    if (dds_) dds_->disconnect_input(input);
    return "";
  }
  if (!dds_) {
    throw std::invalid_argument(fmt::format(
        "source '{}' is not in module '{}' and the module runs without DDS", source, spec_.name));
  }
  auto note = dds_->connect_input(input, source, switch_wait);
  for (auto& s : slots_) {
    for (auto& out : s->instance->ports().outputs) out->disconnect(&input);
  }
  return note;
}

void Module::mark_pending(Slot& slot) {
  slot.pending = true;
  wake_.notify_all();
}

void Module::start(int domain) {
  // Under a monitor, outputs continue the numbering of the module's earlier incarnations.
  if (const char* run_dir = std::getenv("OSCAR_RUN_DIR"); run_dir && *run_dir) {
    sequences_ = std::make_unique<internal::SequenceStore>(run_dir, spec_.name);
    for (auto& s : slots_) {
      for (auto& out : s->instance->ports().outputs) {
        out->persist_sequence(sequences_->counter(out->address()));
      }
    }
  }
  if (domain >= 0) {
    dds_ = std::make_unique<Dds>(*this, domain);
    dds_->wire_outputs(slots_);
    dds_->wire_wishes(slots_);
    for (auto& s : slots_) {
      for (const auto& [input, source] : s->sources) {
        if (spec_.find_kernel(source_kernel(source))) continue;  // wired at construction
        connect(*s->instance->ports().find_input(input), source, std::nullopt);
      }
    }
  }
  {
    std::lock_guard lock(mutex_);
    const auto now = Clock::now();
    for (auto& s : slots_) s->next_due = now;
    suspended_ = spec_.start_suspended;
  }
  // The modes as started, read before the processing thread runs: it may change one at once (a
  // kernel failing in on_activate() is deactivated), and that transition must stay the last.
  std::vector<std::string> modes;
  for (auto& s : slots_) modes.push_back(s->instance->name() + ": " + s->mode.describe());
  const auto started = fmt::format("started ({})", fmt::join(modes, ", "));
  {
    std::lock_guard lock(mutex_);
    last_transition_ = started;
  }
  processing_ = std::thread([this] { processing_loop(); });
  if (dds_) dds_->start_config();  // from here the log goes out over DDS too
  log_->info("{}", started);
  if (dds_) {
    dds_->publish_state(state());
    dds_->publish_wishes();
  }
}

void Module::wait() {
  std::unique_lock lock(mutex_);
  stopped_.wait(lock, [&] { return stop_requested_; });
}

void Module::request_stop() {
  std::lock_guard lock(mutex_);
  stop_requested_ = true;
  stopped_.notify_all();
}

void Module::stop() {
  if (dds_) dds_->stop_config();
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    stop_requested_ = true;
    stopped_.notify_all();
    wake_.notify_all();
  }
  if (processing_.joinable()) processing_.join();
  dds_.reset();
}

// Runs on the processing thread without the lock; `stub` was read under it.
void Module::run_slot(Slot& slot, Trigger trigger, bool stub) {
  const char* call = "on_activate()";
  try {
    if (!slot.active) {
      slot.instance->kernel().on_activate();
      slot.active = true;
      if (dds_) dds_->publish_wishes();  // what it still asks for counts again
    }
    call = stub ? "stub()" : "process()";
    busy_since_ns_.store(Clock::now().time_since_epoch().count(), std::memory_order_relaxed);
    slot.instance->run(wall_now(), trigger, stub);
    busy_since_ns_.store(0, std::memory_order_relaxed);
    slot.failures_in_a_row = 0;
  } catch (const std::exception& e) {
    busy_since_ns_.store(0, std::memory_order_relaxed);
    kernel_failed(slot, fmt::format("{}: {}", call, e.what()));
  }
}

// Counts the failure (oscar ps shows it) and acts once when the policy's count in a row is
// reached: a failure is reported and acted on, not logged and forgotten.
void Module::kernel_failed(Slot& slot, std::string failure) {
  const auto& policy = spec_.on_kernel_error;
  const auto& name = slot.instance->name();
  {
    std::lock_guard lock(mutex_);
    ++slot.failures;
    ++slot.failures_in_a_row;
    slot.failure = std::move(failure);
  }
  log_->error("kernel '{}' failed in {}", name, slot.failure);
  if (slot.failures_in_a_row != policy.after) return;
  switch (policy.action) {
    case KernelErrorPolicy::Action::kContinue:
      return;
    case KernelErrorPolicy::Action::kDeactivate: {
      std::string transition;
      {
        std::lock_guard lock(mutex_);
        transition = fmt::format(
            "{}: {} -> deactivated (failed {} times in a row; "
            "on_kernel_error: deactivate)",
            name, slot.mode.describe(), slot.failures_in_a_row);
        slot.mode.kind = ModeSpec::Kind::kDeactivated;
        slot.pending = false;
      }
      if (slot.active) {
        slot.active = false;
        try {
          slot.instance->kernel().on_deactivate();
        } catch (const std::exception& e) {
          log_->error("kernel '{}' failed in on_deactivate(): {}", name, e.what());
        }
      }
      report(transition);
      return;
    }
    case KernelErrorPolicy::Action::kRestart: {
      end_for_restart(
          fmt::format("kernel '{}' failed {} times in a row (on_kernel_error: restart); "
                      "last: {}",
                      name, slot.failures_in_a_row, slot.failure));
      return;
    }
  }
}

void Module::end_for_restart(std::string reason) {
  {
    std::lock_guard lock(mutex_);
    if (!exit_reason_.empty()) return;  // the first reason is the one to tell
    exit_reason_ = reason;
  }
  log_->error("stopping the module: {}", reason);  // not under mutex_: it writes to DDS
  std::lock_guard lock(mutex_);
  stop_requested_ = true;
  stopped_.notify_all();
}

// One thread runs every kernel of the module (seed 004 §2.2): the continuous kernel on its
// cycle, followed by the kernels it triggers; single-step kernels when their trigger holds.
void Module::processing_loop() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    while (!tasks_.empty()) {
      auto task = std::move(tasks_.front());
      tasks_.pop_front();
      lock.unlock();
      task();
      lock.lock();
    }
    if (stopping_) break;
    Slot* due = nullptr;
    for (auto& s : slots_) {
      if (s->continuous()) due = s.get();
    }
    const bool pending = std::any_of(slots_.begin(), slots_.end(),
                                     [](const auto& s) { return s->pending && s->single_step(); });
    const auto now = Clock::now();
    if (suspended_ || (!pending && (!due || due->next_due > now))) {
      if (!suspended_ && due) {
        wake_.wait_until(lock, due->next_due);
      } else {
        wake_.wait(lock);
      }
      continue;
    }
    std::vector<std::tuple<Slot*, Trigger, bool>> run;
    const bool activating = due && !due->active;  // on_activate() runs first: not cycle work
    if (due && due->next_due <= now) {
      run.emplace_back(due, Trigger::kCycle, due->stub);
      for (auto& s : slots_) {
        if (s.get() != due && s->single_step() && s->mode.trigger == "module") {
          run.emplace_back(s.get(), Trigger::kModule, s->stub);
        }
      }
      due->next_due += due->mode.cycle;
    }
    lock.unlock();
    for (auto [slot, trigger, stub] : run) run_slot(*slot, trigger, stub);
    lock.lock();
    if (due && !run.empty()) {
      const auto after = Clock::now();
      if (after > due->next_due && activating) {
        due->next_due = after;             // the cycles are counted from the end of the activation
      } else if (after > due->next_due) {  // the cycle took longer than the cycle time
        ++due->overruns;
        if (due->overruns == 1 || due->overruns % 100 == 0) {
          log_->warn("kernel '{}' overran its {} cycle ({} overruns so far)", due->instance->name(),
                     format_duration(due->mode.cycle), due->overruns);
        }
        due->next_due = after;
      }
    }
    // Kernels whose trigger fired, in declaration order (upstream first in a chain).
    for (bool again = true; again && !stopping_ && !suspended_;) {
      again = false;
      for (auto& s : slots_) {
        if (!s->pending || !s->single_step()) continue;
        s->pending = false;
        again = true;
        const auto trigger = s->mode.trigger == "command" ? Trigger::kCommand : Trigger::kInput;
        const bool stub = s->stub;
        lock.unlock();
        run_slot(*s, trigger, stub);
        lock.lock();
      }
    }
  }
  lock.unlock();
  for (auto& s : slots_) {
    if (s->active) {
      s->instance->kernel().on_deactivate();
      s->active = false;
    }
  }
}

void Module::post_and_wait(const std::function<void()>& task) {
  if (std::this_thread::get_id() == processing_.get_id() || !processing_.joinable()) {
    task();
    return;
  }
  std::packaged_task<void()> packaged(task);
  auto done = packaged.get_future();
  {
    std::lock_guard lock(mutex_);
    tasks_.emplace_back([&packaged] { packaged(); });
    wake_.notify_all();
  }
  done.get();  // rethrows what the task threw
}

void Module::report(const std::string& transition) {
  {
    std::lock_guard lock(mutex_);
    last_transition_ = transition;
  }
  log_->info("{}", transition);
  if (dds_) {
    dds_->publish_state(state());
    dds_->publish_wishes();  // a kernel activated or deactivated asks or withdraws its wishes
  }
}

std::string Module::exit_reason() const {
  std::lock_guard lock(mutex_);
  return exit_reason_;
}

bool Module::hung() const {
  const auto since = busy_since_ns_.load(std::memory_order_relaxed);
  return since != 0 && Clock::now().time_since_epoch().count() - since >
                           std::chrono::nanoseconds(spec_.watchdog).count();
}

ModuleState Module::state() const {
  std::lock_guard lock(mutex_);
  return state_locked();
}

ModuleState Module::state_locked() const {
  ModuleState st;
  st.module_name(spec_.name);
  st.host(spec_.host);
  st.pid(static_cast<std::int32_t>(getpid()));
  st.incarnation(spec_.incarnation);
  st.suspended(suspended_);
  st.last_transition(last_transition_);
  for (const auto& s : slots_) {
    KernelState k;
    k.name(s->instance->name());
    k.type(s->instance->type());
    k.mode(to_string(s->mode.kind));
    k.cycle_ns(s->continuous() ? s->mode.cycle.count() : 0);
    k.trigger(s->single_step() ? (s->mode.trigger.empty() ? "default" : s->mode.trigger) : "");
    k.stub(s->stub);
    k.cycles(s->instance->cycles());
    k.overruns(s->overruns);
    k.failures(s->failures);
    k.last_failure(s->failure);
    std::uint64_t published = 0;
    for (const auto& out : s->instance->ports().outputs) published += out->published();
    k.published(published);
    k.params(s->instance->ports().params.to_yaml());
    for (const auto& [input, source] : s->sources) k.inputs().push_back(input + "=" + source);
    for (const auto& c : s->instance->ports().commands) {
      DeclaredCommand d;
      d.name(c->name());
      d.type(c->type().name);
      k.commands().push_back(std::move(d));
    }
    st.kernels().push_back(std::move(k));
  }
  return st;
}

}  // namespace oscar
