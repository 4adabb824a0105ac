#pragma once
// The AppletContext of an applet running in the threaded Runtime (runtime.hpp): its calls go to
// the Runtime's scheduler under the Runtime's lock.

#include "oscar/applets/applet_context.hpp"

namespace oscar::applets {

class Runtime;

/// An applet's calls on the Runtime it runs in (seed 000 §4.4.1, §4.5.3, §4.6.2).
class RuntimeContext final : public AppletContext {
 public:
  RuntimeContext(Runtime& runtime, AppletId applet) : runtime_(runtime), applet_(applet) {}

  void request(const std::string& bundle) override;
  void release(const std::string& bundle) override;
  void yield(const std::string& bundle) override;
  void trigger(const std::string& bundle) override;
  void set_priority(const std::string& bundle, int priority) override;
  void set_deadline(const std::string& bundle, std::optional<Deadline> deadline) override;
  Notification negotiate(const std::string& bundle, const Negotiation& answer) override;
  std::optional<Notification> negotiate(const std::string& bundle,
                                        const NegotiationRound& round) override;
  bool negotiating(const std::string& bundle) const override;
  bool being_revoked(const std::string& bundle) const override;
  bool use(const std::string& bundle, const std::function<void()>& body) override;
  bool granted(const std::string& bundle) const override;
  AppletId id() const override { return applet_; }

 private:
  BundleId bundle_id(const std::string& bundle) const;
  // Throws while the applet reacts to a revocation (seed footnote 11).
  void refuse_reprioritising(const std::string& bundle, const char* what) const;
  Runtime& runtime_;
  AppletId applet_;
};

}  // namespace oscar::applets
