#include "oscar/applets/scenario.hpp"

#include <algorithm>
#include <map>
#include <set>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "yaml_helpers.hpp"

namespace oscar::applets {
namespace {

using internal::fail_at;
using internal::flag;
using internal::number;

BundleId bundle_at(const Model& model, const YAML::Node& node, const std::string& file) {
  const std::string ref = node.IsScalar() ? node.as<std::string>() : "";
  const auto slash = ref.find('/');
  if (slash == std::string::npos) {
    fail_at(node, file, "'" + ref + "' must name a bundle as applet/bundle");
  }
  try {
    return model.bundle_id(model.applet_id(ref.substr(0, slash)), ref.substr(slash + 1));
  } catch (const std::invalid_argument& e) {
    fail_at(node, file, e.what());
  }
}

// The keys of each event: its own and its fields (docs/applets.md, "Events").
const std::map<std::string, std::set<std::string>> kEvents = {
    {"request", {"trigger"}},
    {"release", {}},
    {"yield", {}},
    {"trigger", {}},
    {"set_priority", {"priority"}},
    {"set_deadline", {"t_early_ms", "t_duration_ms", "t_finish_ms", "clear"}},
    {"crash", {}},
    {"advance_ms", {}},
    {"negotiate", {"min_ms", "max_ms", "accept"}}};
const std::set<std::string> kStepKeys = {"label", "t_ms", "do", "expect", "expect_active"};

// Whether `key` names an event or one of an event's fields.
bool is_event_key(const std::string& key) {
  for (const auto& [event, fields] : kEvents) {
    if (key == event || fields.count(key)) return true;
  }
  return false;
}

std::string joined(const std::vector<std::string>& keys) {
  std::string out;
  for (const auto& k : keys) out += (out.empty() ? "" : ", ") + k;
  return out;
}

// One event: a mapping with exactly one event key and only that event's fields; an event written
// directly in a step may sit beside the step's own keys (`step_keys`).
Action parse_action(const Model& model, const YAML::Node& a, const std::string& file,
                    const std::set<std::string>& step_keys = {}) {
  if (!a.IsMap()) fail_at(a, file, "an event must be a mapping such as {request: Applet/bundle}");
  Action act;
  act.where = where(a, file);
  std::string kind;
  for (const auto& kv : a) {
    const auto key = kv.first.as<std::string>();
    if (kEvents.count(key) && !(key == "trigger" && a["request"])) {
      if (!kind.empty())
        fail_at(kv.first, file, "one event per mapping: '" + kind + "' and '" + key + "'");
      kind = key;
    }
  }
  if (kind.empty()) {
    std::vector<std::string> events;
    for (const auto& [event, fields] : kEvents) events.push_back(event);
    fail_at(a, file, "unknown event (allowed: " + joined(events) + ")");
  }
  const std::set<std::string>& fields = kEvents.at(kind);
  for (const auto& kv : a) {
    const auto key = kv.first.as<std::string>();
    if (key == kind || fields.count(key) || step_keys.count(key)) continue;
    std::vector<std::string> allowed{kind};
    allowed.insert(allowed.end(), fields.begin(), fields.end());
    fail_at(kv.first, file,
            "event '" + kind + "': unknown key '" + key + "' (allowed: " + joined(allowed) +
                (step_keys.empty() ? "" : "; and the step's label, t_ms, expect, expect_active") +
                ")");
  }
  const YAML::Node v = a[kind];
  auto ms_field = [&](const char* key) {
    if (!a[key]) fail_at(a, file, kind + " needs '" + key + "'");
    return milliseconds{number(a[key], file, key)};
  };
  if (kind == "request") {
    act.kind = Action::Kind::kRequest;
    act.bundle = bundle_at(model, v, file);
    act.trigger = flag(a["trigger"], file, "trigger");
  } else if (kind == "release") {
    act.kind = Action::Kind::kRelease;
    act.bundle = bundle_at(model, v, file);
  } else if (kind == "yield") {
    act.kind = Action::Kind::kYield;
    act.bundle = bundle_at(model, v, file);
  } else if (kind == "trigger") {
    act.kind = Action::Kind::kTrigger;
    act.bundle = bundle_at(model, v, file);
  } else if (kind == "set_priority") {
    act.kind = Action::Kind::kSetPriority;
    act.bundle = bundle_at(model, v, file);
    if (!a["priority"]) fail_at(a, file, "set_priority needs 'priority'");
    act.priority = parse_priority(a["priority"], file);
  } else if (kind == "set_deadline") {
    act.kind = Action::Kind::kSetDeadline;
    act.bundle = bundle_at(model, v, file);
    if (!flag(a["clear"], file, "clear")) {
      act.deadline =
          Deadline{ms_field("t_early_ms"), ms_field("t_duration_ms"), ms_field("t_finish_ms")};
    }
  } else if (kind == "crash") {
    act.kind = Action::Kind::kCrash;
    try {
      act.applet = model.applet_id(v.as<std::string>());
    } catch (const std::invalid_argument& e) {
      fail_at(v, file, e.what());
    }
  } else if (kind == "advance_ms") {
    act.kind = Action::Kind::kAdvance;
    act.advance = milliseconds{number(v, file, "advance_ms")};
    if (act.advance.count() < 0) fail_at(v, file, "advance_ms must not be negative");
  } else {
    act.kind = Action::Kind::kNegotiate;
    act.bundle = bundle_at(model, v, file);
    act.negotiation =
        Negotiation{ms_field("min_ms"), ms_field("max_ms"), flag(a["accept"], file, "accept")};
  }
  return act;
}

std::string note(const Model& m, const Notification& n) {
  // A reassigner speaks for one service (seed Abb. 4.13): name it.
  const std::string who = m.applet(n.applet).name + "/" + m.bundle(n.bundle).name +
                          (n.service ? "[" + m.service(*n.service).name + "]" : "");
  switch (n.kind) {
    case Notification::Kind::kGranted:
      return who + ": granted";
    case Notification::Kind::kRevokeRequested: {
      std::string to;
      for (AppletId a : n.new_holders) to += (to.empty() ? "" : ",") + m.applet(a).name;
      return who + ": revoke requested (to " + (to.empty() ? "nobody" : to) + ", until " +
             std::to_string(n.until.count()) + " ms)";
    }
    case Notification::Kind::kNegotiationAccepted:
      return who + ": negotiation accepted until " + std::to_string(n.until.count()) + " ms";
    case Notification::Kind::kNegotiationRejected:
      return who + ": negotiation rejected, yield by " + std::to_string(n.until.count()) + " ms";
    case Notification::Kind::kRevokedByForce:
      return who + ": revoked by force";
    case Notification::Kind::kDeadlineExpired:
      return who + ": deadline expired (t_finish " + std::to_string(n.until.count()) +
             " ms), request withdrawn";
    case Notification::Kind::kDeadlineOverlap:
      return who + ": deadline overlaps " + m.applet(m.bundle(*n.other).applet).name + "/" +
             m.bundle(*n.other).name;
  }
  return who;
}

}  // namespace

Scenario Scenario::load_file(const std::string& path) { return parse(read_text_file(path), path); }

Scenario Scenario::parse(const std::string& yaml_text, const std::string& file) {
  const YAML::Node root = parse_yaml(yaml_text, file);
  Scenario s;
  s.system_ = load_system(root, file);
  if (const auto r = root["runner"]) {
    if (!r.IsMap() || r.size() != 1 || !r["auto_yield"]) {
      fail_at(r, file, "runner: the only key is auto_yield (true or false)");
    }
    try {
      s.auto_yield_ = r["auto_yield"].as<bool>();
    } catch (const YAML::Exception&) {
      fail_at(r["auto_yield"], file, "runner.auto_yield must be true or false");
    }
  }
  const YAML::Node timeline = root["timeline"];
  if (!timeline || !timeline.IsSequence()) {
    fail_at(timeline ? timeline : root, file, "'timeline' must be a list of steps");
  }
  for (const auto& st : timeline) {
    if (!st.IsMap()) fail_at(st, file, "a step must be a mapping");
    Step step;
    step.where = where(st, file);
    bool has_event = false;
    for (const auto& kv : st) {
      const auto key = kv.first.as<std::string>();
      if (kStepKeys.count(key)) continue;
      if (!is_event_key(key)) {
        fail_at(kv.first, file,
                "step: unknown key '" + key +
                    "' (allowed: label, t_ms, do, expect, expect_active, or one event)");
      }
      if (st["do"]) {
        fail_at(kv.first, file,
                "step: '" + key + "' beside 'do' (write the event into the do list)");
      }
      has_event = true;
    }
    if (st["label"]) step.label = st["label"].as<std::string>();
    if (st["t_ms"]) step.t = milliseconds{number(st["t_ms"], file, "t_ms")};
    if (st["do"]) {
      if (!st["do"].IsSequence()) fail_at(st["do"], file, "'do' must be a list of events");
      for (const auto& a : st["do"]) step.actions.push_back(parse_action(s.system_.model, a, file));
    } else if (has_event) {
      step.actions.push_back(parse_action(s.system_.model, st, file, kStepKeys));
    }
    for (const char* key : {"expect", "expect_active"}) {
      const auto e = st[key];
      if (!e) continue;
      if (!e.IsMap()) fail_at(e, file, std::string("'") + key + "' must map services to holders");
      for (const auto& kv : e) {
        const auto svc = kv.first.as<std::string>();
        if (!s.system_.model.find_service(svc)) {
          fail_at(kv.first, file, std::string(key) + ": unknown service '" + svc + "'");
        }
        (std::string(key) == "expect" ? step.expect : step.expect_active)
            .emplace_back(svc, kv.second.as<std::string>());
      }
    }
    if (step.label.empty()) step.label = "step " + std::to_string(s.steps_.size() + 1);
    s.steps_.push_back(std::move(step));
  }
  return s;
}

std::vector<StepResult> Scenario::run(Scheduler* final_state) const {
  Scheduler sched(system_.model, system_.options);
  for (BundleId b : system_.requested_at_start) sched.request(b);
  std::vector<StepResult> out;
  const Model& m = sched.model();
  // Applets following the seed's conventions yield between two main-loop steps; on the logical
  // clock that is at once.
  auto yield_revoked = [&] {
    for (BundleId b = 0; auto_yield_ && b < m.bundles().size(); ++b) {
      if (sched.revoke_deadline(b)) sched.yield(b);
    }
  };
  // The clock moves from event to event (a t_early reached, a t_finish passed, a wait limit), so
  // that what they revoke is yielded at that time, as it is after an action.
  auto advance = [&](milliseconds t) {
    for (auto next = sched.next_event(); next && *next <= t; next = sched.next_event()) {
      sched.advance_to(std::max(sched.now(), *next));
      yield_revoked();
    }
    sched.advance_to(t);
  };
  for (const Step& step : steps_) {
    try {
      if (step.t) advance(*step.t);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(step.where + ": " + e.what());
    }
    for (const Action& a : step.actions) {
      try {
        switch (a.kind) {
          case Action::Kind::kRequest:
            sched.request(a.bundle);
            if (a.trigger) sched.trigger(a.bundle);
            break;
          case Action::Kind::kRelease:
            sched.release(a.bundle);
            break;
          case Action::Kind::kYield:
            sched.yield(a.bundle);
            break;
          case Action::Kind::kTrigger:
            sched.trigger(a.bundle);
            break;
          case Action::Kind::kSetPriority:
            sched.set_priority(a.bundle, a.priority);
            break;
          case Action::Kind::kSetDeadline:
            sched.set_deadline(a.bundle, a.deadline);
            break;
          case Action::Kind::kCrash:
            sched.crash(a.applet);
            break;
          case Action::Kind::kAdvance:
            advance(sched.now() + a.advance);
            break;
          case Action::Kind::kNegotiate:
            sched.negotiate(a.bundle, a.negotiation);
            break;
        }
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(a.where + ": " + e.what());
      }
      yield_revoked();
    }
    StepResult r;
    r.label = step.label;
    r.t = sched.now();
    for (ServiceId s = 0; s < m.services().size(); ++s) {
      r.holders.emplace_back(m.service(s).name, sched.holder(s));
      r.active.emplace_back(m.service(s).name, sched.active_holder(s));
    }
    for (const Notification& n : sched.take_notifications()) r.notes.push_back(note(m, n));
    for (const auto& [svc, want] : step.expect) {
      const std::string got = sched.holder(m.service_id(svc));
      if (got != want) {
        r.mismatches.push_back(step.where + ": '" + step.label + "': service " + svc +
                               ": expected " + want + ", got " + got);
      }
    }
    for (const auto& [svc, want] : step.expect_active) {
      const std::string got = sched.active_holder(m.service_id(svc));
      if (got != want) {
        r.mismatches.push_back(step.where + ": '" + step.label + "': service " + svc +
                               " in use by: expected " + want + ", got " + got);
      }
    }
    out.push_back(std::move(r));
  }
  if (final_state) *final_state = std::move(sched);
  return out;
}

std::string format_text(const std::vector<StepResult>& results) {
  if (results.empty()) return "(no steps)\n";
  std::vector<std::size_t> width{4, 6, 5};
  for (const auto& r : results) width[2] = std::max(width[2], r.label.size());
  for (std::size_t i = 0; i < results[0].holders.size(); ++i) {
    std::size_t w = results[0].holders[i].first.size();
    for (const auto& r : results) w = std::max(w, r.holders[i].second.size());
    width.push_back(w);
  }
  auto cell = [](const std::string& s, std::size_t w) {
    return s + std::string(w - s.size() + 2, ' ');
  };
  std::string out = cell("step", width[0]) + cell("t_ms", width[1]) + cell("event", width[2]);
  for (std::size_t i = 0; i < results[0].holders.size(); ++i) {
    out += cell(results[0].holders[i].first, width[3 + i]);
  }
  out.erase(out.find_last_not_of(' ') + 1);
  out += '\n';
  for (std::size_t k = 0; k < results.size(); ++k) {
    const auto& r = results[k];
    std::string line = cell(std::to_string(k + 1), width[0]) +
                       cell(std::to_string(r.t.count()), width[1]) + cell(r.label, width[2]);
    for (std::size_t i = 0; i < r.holders.size(); ++i)
      line += cell(r.holders[i].second, width[3 + i]);
    line.erase(line.find_last_not_of(' ') + 1);
    out += line + '\n';
    for (const auto& n : r.notes) out += "      " + n + '\n';
    for (const auto& mm : r.mismatches) out += "  MISMATCH " + mm + '\n';
  }
  return out;
}

std::string format_json(const std::vector<StepResult>& results) {
  nlohmann::ordered_json steps = nlohmann::ordered_json::array();
  for (const auto& r : results) {
    nlohmann::ordered_json holders = nlohmann::ordered_json::object();
    for (const auto& [svc, h] : r.holders) holders[svc] = h;
    nlohmann::ordered_json active = nlohmann::ordered_json::object();
    for (const auto& [svc, h] : r.active) active[svc] = h;
    steps.push_back({{"event", r.label},
                     {"t_ms", r.t.count()},
                     {"holders", holders},
                     {"active", active},
                     {"notes", r.notes},
                     {"mismatches", r.mismatches}});
  }
  return nlohmann::ordered_json{{"steps", steps}}.dump(2) + "\n";
}

}  // namespace oscar::applets
