// Making the applets an AppletHost runs: the system file's (by name) and applets joining the
// running system (docs/coordinator.md, "Adding and removing at run time").
#include "applet_host_impl.hpp"

namespace oscar::coordinator {

AppletHost::Impl::Impl(const SystemSpec& system, DdsParticipant& participant,
                       const std::vector<std::string>& names, std::string process,
                       const std::vector<std::string>& plugin_path, const YAML::Node& joining,
                       const std::string& joining_file)
    : system_(system),
      participant_(participant),
      config_(applet_system(system)),
      process_(std::move(process)),
      beat_every_(std::max(
          milliseconds(10),
          (system.coordinator ? system.coordinator->applet_lease : milliseconds(1500)) / 6)),
      hello_writer_(participant, topics::sched_hello()),
      beat_writer_(participant, topics::sched_beat()),
      call_writer_(participant, topics::sched_call()),
      command_writer_(participant, topics::sched_command()) {
  for (const auto& name : names) {
    const AppletSpec* spec = nullptr;
    if (system.coordinator) {
      for (const auto& a : system.coordinator->applets) {
        if (a.name == name) spec = &a;
      }
    }
    if (!spec) {
      throw std::invalid_argument(
          fmt::format("{}: no applet '{}' in the coordinator: section", system.file, name));
    }
    host(name, spec->type, spec->where, plugin_path, "");
  }
  if (joining && !joining.IsNull()) read_joining(joining, joining_file, plugin_path);
  notice_reader_ = std::make_unique<TopicReader<SchedNotice, SchedNoticePubSubType>>(
      participant, topics::sched_notice(),
      [this](const SchedNotice& n, const auto&) { on_notice(n); });
  reply_reader_ = std::make_unique<TopicReader<SchedReply, SchedReplyPubSubType>>(
      participant, topics::sched_reply(),
      [this](const SchedReply& r, const auto&) { on_reply(r); });
  command_reply_reader_ =
      std::make_unique<TopicReader<SchedCommandReply, SchedCommandReplyPubSubType>>(
          participant, topics::sched_command_reply(),
          [this](const SchedCommandReply& r, const auto&) { on_command_reply(r); });
}

void AppletHost::Impl::host(const std::string& name, const std::string& type,
                            const std::string& where, const std::vector<std::string>& plugin_path,
                            std::string spec) {
  auto h = std::make_unique<Hosted>();
  h->name = name;
  h->spec = std::move(spec);
  h->id = config_.model.applet_id(name);
  h->fail_stop = config_.model.applet(h->id).fail_stop;
  h->session = internal::fresh_id();
  AppletSetup setup(name, config_.applet_params[name], *this, &participant_);
  try {
    h->applet = make_applet(type, setup, plugin_path);
  } catch (const std::exception& e) {
    throw std::invalid_argument(fmt::format("{}: applet '{}': {}", where, name, e.what()));
  }
  for (const BundleId b : config_.requested_at_start) {
    if (config_.model.bundle(b).applet == h->id) {
      h->requested[config_.model.bundle(b).name] = true;
    }
  }
  hosted_.emplace(name, std::move(h));
}

void AppletHost::Impl::read_joining(const YAML::Node& joining, const std::string& file,
                                    const std::vector<std::string>& plugin_path) {
  const auto addition = system_.parse_addition(joining, file, system_.services);
  if (!addition.services.empty() || addition.applets.empty()) {
    throw std::invalid_argument(fmt::format(
        "{}: joining applets are listed under applets: only (services are added with `oscar "
        "applets add`)",
        file));
  }
  for (const auto& a : addition.applets) {
    if (a.remote()) {
      throw std::invalid_argument(
          fmt::format("{}: applet '{}': a joining applet runs in this process; leave process: "
                      "and host: out",
                      a.where, a.name));
    }
    // Its bundles may use services added at run time: the coordinator checks them when it
    // adds the applet; here only the names count.
    for (const auto& b : a.node["bundles"]) {
      for (const auto& r : b["resources"]) {
        if (!r.IsMap() || !r["service"] || !r["service"].IsScalar()) continue;
        const auto service = r["service"].as<std::string>();
        if (!config_.model.find_service(service)) config_.model.add_service(service);
      }
    }
    for (const auto& p : a.node["provides"]) {
      if (p.IsScalar() && !config_.model.find_service(p.as<std::string>())) {
        config_.model.add_service(p.as<std::string>());
      }
    }
  }
  auto loaded = applets::load_addition(config_.model, scheduler_doc(addition), file);
  config_.model.add(loaded.addition);
  for (auto& [name, params] : loaded.applet_params) config_.applet_params[name] = params;
  for (const auto& [applet, bundle] : loaded.requested_at_start) {
    config_.requested_at_start.push_back(
        config_.model.bundle_id(config_.model.applet_id(applet), bundle));
  }
  for (const auto& a : addition.applets) {
    YAML::Node entry;
    entry["applets"].push_back(a.node);
    host(a.name, a.type, a.where, plugin_path, YAML::Dump(entry));
  }
}

AppletHost::Impl::~Impl() {
  stop();
  notice_reader_.reset();
  reply_reader_.reset();
  command_reply_reader_.reset();
}

void AppletHost::Impl::start() {
  std::lock_guard lock(mutex_);
  if (started_) return;
  started_ = true;
  for (auto& [name, h] : hosted_) {
    Hosted* p = h.get();
    p->thread = std::thread([this, p] { applet_main(*p); });
  }
}

void AppletHost::Impl::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    for (auto& [name, h] : hosted_) h->cv.notify_all();
  }
  for (auto& [name, h] : hosted_) {
    if (h->thread.joinable()) h->thread.join();
  }
}

AppletHost::Impl::Hosted& AppletHost::Impl::hosted(const std::string& applet) {
  const auto it = hosted_.find(applet);
  if (it == hosted_.end()) {
    throw std::invalid_argument(fmt::format("applet '{}' is not hosted here", applet));
  }
  return *it->second;
}

AppletHost::AppletHost(const SystemSpec& system, DdsParticipant& participant,
                       const std::vector<std::string>& applets, std::string process,
                       const std::vector<std::string>& plugin_path)
    : impl_(std::make_unique<Impl>(system, participant, applets, std::move(process), plugin_path)) {
}

AppletHost::AppletHost(const SystemSpec& system, DdsParticipant& participant,
                       const std::vector<std::string>& applets, const YAML::Node& joining,
                       const std::string& joining_file, std::string process,
                       const std::vector<std::string>& plugin_path)
    : impl_(std::make_unique<Impl>(system, participant, applets, std::move(process), plugin_path,
                                   joining, joining_file)) {}

AppletHost::~AppletHost() = default;

void AppletHost::start() { impl_->start(); }
void AppletHost::stop() { impl_->stop(); }

std::vector<std::string> AppletHost::applets_of(const SystemSpec& system,
                                                const std::string& process) {
  std::vector<std::string> names;
  if (!system.coordinator) return names;
  for (const auto& a : system.coordinator->applets) {
    if (a.process == process) names.push_back(a.name);
  }
  return names;
}

}  // namespace oscar::coordinator
