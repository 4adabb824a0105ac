#pragma once
/// @file Resource wishes (seed 004 §2.4, docs/kernels.md "Resource wishes"): only the
/// coordinator configures modules, but a kernel may ask it for a service — e.g. a detector that
/// asks for the camera in half frames. The system file declares what each wish of a kernel asks
/// for (a bundle of services with a priority, under `coordinator: wishes:`); the kernel asks and
/// drops it while it runs, and the coordinator's plan grants it or not, as an applet's request.

#include <atomic>
#include <functional>
#include <mutex>
#include <string>

namespace oscar {

/// One wish of a kernel, declared in its constructor (KernelSetup::wish). ask() and drop() may be
/// called from process() and on_deactivate(); granted() from anywhere.
class Wish {
 public:
  Wish(std::string kernel, std::string name) : kernel_(std::move(kernel)), name_(std::move(name)) {}
  Wish(const Wish&) = delete;
  Wish& operator=(const Wish&) = delete;

  const std::string& kernel() const { return kernel_; }
  /// The bundle it names under the kernel's entry of `coordinator: wishes:`.
  const std::string& name() const { return name_; }

  /// Asks the coordinator for it (again); nothing happens if it is asked already.
  void ask() { set_asked(true); }
  /// Withdraws it (the coordinator releases it); nothing happens if it is not asked.
  void drop() { set_asked(false); }
  bool asked() const { return asked_; }
  /// Whether the coordinator's plan grants it now: what it asked for may be used. False until
  /// the coordinator's plan says so, and again once it is dropped or revoked.
  bool granted() const { return asked_ && granted_; }

  /// The frame's side: `on_change` is called after each change of asked() (on the caller's
  /// thread), to send the module's wishes to the coordinator; on_change({}) detaches it.
  void on_change(std::function<void()> f) {
    std::lock_guard lock(mutex_);
    on_change_ = std::move(f);
  }
  /// The frame's side: what the coordinator's plan says.
  void set_granted(bool granted) { granted_ = granted; }

 private:
  void set_asked(bool asked) {
    if (asked_.exchange(asked) == asked) return;
    // Called under the lock: once on_change({}) returns, the frame's side is never called again.
    std::lock_guard lock(mutex_);
    if (on_change_) on_change_();
  }

  std::string kernel_, name_;
  std::atomic<bool> asked_{false};
  std::atomic<bool> granted_{false};
  std::mutex mutex_;
  std::function<void()> on_change_;
};

}  // namespace oscar
