#pragma once
// The static structure of an applet system (seed 000 §4.1–4.2): services, applets, resource
// bundles and hierarchical service dependencies. Dynamic state (requests, priorities, deadlines)
// lives in the Scheduler.

#include <chrono>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace oscar::applets {

using ServiceId = std::uint32_t;
using AppletId = std::uint32_t;
using ResourceId = std::uint32_t;
using BundleId = std::uint32_t;

/// How a resource wants to use its service (seed §4.2.2).
enum class Access : std::uint8_t { kShared, kExclusive };

/// Predefined priority levels; any int in between is allowed (seed §4.5.2).
inline constexpr int kPriorityLow = 100;
inline constexpr int kPriorityNormal = 200;
inline constexpr int kPriorityHigh = 300;
inline constexpr int kPrioritySystem = 400;

/// A deadline (seed §4.5.1, eq. 4.8–4.10): earliest start, duration and latest end of an access,
/// in the scheduler's clock.
struct Deadline {
  std::chrono::milliseconds t_early{0};
  std::chrono::milliseconds t_duration{0};
  std::chrono::milliseconds t_finish{0};
  /// The relative deadline t_finish - t_duration (eq. 4.8): the latest start.
  std::chrono::milliseconds relative() const { return t_finish - t_duration; }
};

/// A service a service depends on, declared in configuration (seed §4.2.3, Abb. 4.10).
struct Dependency {
  ServiceId service = 0;
  Access access = Access::kExclusive;
};

/// A functional unit (pilot, docking controller, display, ...).
struct Service {
  std::string name;
  bool exclusive_only = false;
  std::optional<AppletId> provider;  ///< The service applet that provides it, if any.
  std::vector<Dependency> dependencies;
  bool removed = false;  ///< Removed at run time: its id stays taken, its name is free again.
};

/// An applet's proxy to one service (seed §4.2.2).
struct Resource {
  AppletId applet = 0;
  ServiceId service = 0;
  Access access = Access::kShared;
  BundleId bundle = 0;
};

/// Resources granted all together or not at all (seed §4.2.2, Abb. 4.6). A single resource is a
/// bundle of one: the plan works on bundles only (Abb. 4.19 step 1 removes bundle children).
struct Bundle {
  AppletId applet = 0;
  std::string name;
  std::vector<ResourceId> resources;
  int priority = kPriorityNormal;  ///< Initial priority; the Scheduler may change it.
  /// Configured (`deadline:`): the deadline every request of the bundle gets, with its times
  /// counted from the request (t_early 5 s: not granted before 5 s after the request).
  std::optional<Deadline> request_deadline;
  bool removed = false;  ///< Its applet was removed.
};

/// An applet or service applet (seed §4.1).
struct Applet {
  std::string name;
  std::vector<ServiceId> provides;
  std::vector<BundleId> bundles;
  std::vector<ResourceId> resources;
  bool fail_stop = false;  ///< Using a non-granted resource throws instead of blocking (§4.6.2).
  bool removed = false;    ///< Removed at run time: its id stays taken, its name is free again.
};

/// A service to add, by names (Model::add): what the configuration says of it.
struct NewService {
  std::string name;
  bool exclusive_only = false;
  std::vector<std::pair<std::string, Access>> needs;  ///< Services it depends on (§4.2.3).
};

/// A bundle of an applet to add, by names.
struct NewBundle {
  std::string name;
  int priority = kPriorityNormal;
  std::vector<std::pair<std::string, Access>> resources;
  std::optional<Deadline> request_deadline;  ///< Bundle::request_deadline
};

/// An applet to add, by names (Model::add).
struct NewApplet {
  std::string name;
  bool fail_stop = false;
  std::vector<std::string> provides;  ///< Services it provides (a service applet, §4.2.3).
  std::vector<NewBundle> bundles;
};

/// Services and applets added to a model together: all of them or none (seed 000 §4.1.1: the
/// scheduler is told of services and applets as they come and go).
struct ModelAddition {
  std::vector<NewService> services;  ///< Added first; their needs may name each other.
  std::vector<NewApplet> applets;    ///< May use and provide the services added with them.
};

/// The ids an addition got, in the order of its lists.
struct AddedIds {
  std::vector<ServiceId> services;
  std::vector<AppletId> applets;
};

/// One use of a service while a bundle is granted: by a resource or by a service (a dependency
/// declared in configuration).
struct Use {
  enum class By : std::uint8_t { kResource, kService };
  ServiceId service = 0;
  Access access = Access::kShared;
  By by = By::kResource;
  std::uint32_t holder = 0;  ///< ResourceId or ServiceId, per `by`.
};

/// The static structure of an applet system. Every call validates its input and throws
/// std::invalid_argument naming the thing and the rule.
class Model {
 public:
  /// Adds a service. @throws std::invalid_argument on an empty or duplicate name.
  ServiceId add_service(std::string name, bool exclusive_only = false);
  /// Declares that `service` needs `dependency` (seed §4.2.3, declared only in configuration).
  /// @throws std::invalid_argument on a self-dependency or a duplicate.
  void add_dependency(ServiceId service, ServiceId dependency, Access access = Access::kExclusive);
  /// Adds an applet. @throws std::invalid_argument on an empty or duplicate name.
  AppletId add_applet(std::string name, bool fail_stop = false);
  /// Makes `applet` the service applet providing `service`; the service needs all of the
  /// applet's resources. @throws std::invalid_argument if another applet provides it.
  void provide(AppletId applet, ServiceId service);
  /// Adds a bundle of resources to an applet.
  /// @throws std::invalid_argument on an empty bundle, a service twice in one bundle, a shared
  /// resource on an exclusive-only service, or a duplicate bundle name.
  BundleId add_bundle(AppletId applet, std::string name,
                      const std::vector<std::pair<ServiceId, Access>>& resources,
                      int priority = kPriorityNormal);

  /// Gives every request of `bundle` a deadline counted from the request (seed §4.5.1: a
  /// reservation for later, a window that expires). @throws std::invalid_argument if t_duration
  /// is negative or t_early + t_duration > t_finish (eq. 4.9).
  void set_request_deadline(BundleId bundle, Deadline deadline);
  /// Adds services and applets by name, all or nothing: on any error the model is unchanged.
  /// New ids follow the ones given so far (a removed thing's id is never given again).
  /// @throws std::invalid_argument as the single calls do, and naming a removed or unknown
  ///         service.
  AddedIds add(const ModelAddition& addition);
  /// Removes an applet (its bundles with it) and frees its name; the services it provided have
  /// no provider any more. Its id and its bundles' ids stay taken.
  /// @throws std::invalid_argument if it was removed already.
  void remove_applet(AppletId applet);
  /// Removes a service and frees its name; its id stays taken.
  /// @throws std::invalid_argument naming the applets whose bundles use it, the services that
  ///         need it and the applet that provides it, while any does (remove those first).
  void remove_service(ServiceId service);

  /// @throws std::invalid_argument "unknown service 'X'".
  ServiceId service_id(std::string_view name) const;
  /// @throws std::invalid_argument "unknown applet 'X'".
  AppletId applet_id(std::string_view name) const;
  /// @throws std::invalid_argument "applet 'A' has no bundle 'B'".
  BundleId bundle_id(AppletId applet, std::string_view name) const;
  std::optional<ServiceId> find_service(std::string_view name) const;

  const std::vector<Service>& services() const { return services_; }
  const std::vector<Applet>& applets() const { return applets_; }
  const std::vector<Resource>& resources() const { return resources_; }
  const std::vector<Bundle>& bundles() const { return bundles_; }
  const Service& service(ServiceId id) const { return services_.at(id); }
  const Applet& applet(AppletId id) const { return applets_.at(id); }
  const Bundle& bundle(BundleId id) const { return bundles_.at(id); }
  const Resource& resource(ResourceId id) const { return resources_.at(id); }

  /// What granting `service` needs directly: its configured dependencies (used by the service)
  /// and all resources of its providing service applet (neededServices(s), seed Abb. 4.21).
  /// Valid after the last change to the model.
  std::span<const Use> needs(ServiceId service) const {
    ensure_analysed();
    const std::uint32_t begin = needs_begin_.at(service);
    return {needs_.data() + begin, needs_begin_[service + 1] - begin};
  }
  /// The bundle's resources as uses of their services, in bundle order. Valid after the last
  /// change to the model.
  std::span<const Use> bundle_uses(BundleId bundle) const {
    ensure_analysed();
    const std::uint32_t begin = bundle_uses_begin_.at(bundle);
    return {bundle_uses_.data() + begin, bundle_uses_begin_[bundle + 1] - begin};
  }

  /// Bundles that lie on a dependency cycle together with `bundle` (including itself), or empty
  /// if it lies on none (seed §4.2.3, Abb. 4.9). Valid after the last change to the model.
  const std::vector<BundleId>& cycle_of(BundleId bundle) const;
  /// The number of such cycles, and which one a bundle lies on (none: not on a cycle).
  std::size_t cycle_count() const {
    ensure_analysed();
    return cycles_.size();
  }
  /// The bundles on cycle `index` (< cycle_count()), in bundle order.
  const std::vector<BundleId>& cycle_members(std::size_t index) const {
    ensure_analysed();
    return cycles_.at(index);
  }
  std::optional<std::uint32_t> cycle_index(BundleId bundle) const {
    ensure_analysed();
    const std::uint32_t index = cycle_index_.at(bundle);
    if (index == kNoCycle) return std::nullopt;
    return index;
  }

 private:
  void invalidate() { analysed_ = false; }
  // The accessors above are inline: the plan calls them for every bundle.
  void ensure_analysed() const {
    if (!analysed_) analyse();
  }
  void analyse() const;

  std::vector<Service> services_;
  std::vector<Applet> applets_;
  std::vector<Resource> resources_;
  std::vector<Bundle> bundles_;
  std::unordered_map<std::string, ServiceId> service_ids_;
  std::unordered_map<std::string, AppletId> applet_ids_;

  mutable bool analysed_ = false;
  // Flat tables (offsets per service / per bundle, then the uses one after the other): the plan
  // walks them at random places, so each lookup is two loads, not a chain of pointers.
  mutable std::vector<std::uint32_t> needs_begin_;
  mutable std::vector<Use> needs_;
  mutable std::vector<std::uint32_t> bundle_uses_begin_;
  mutable std::vector<Use> bundle_uses_;
  mutable std::vector<std::vector<BundleId>> cycles_;  // members per cycle
  mutable std::vector<std::uint32_t> cycle_index_;     // per bundle; kNoCycle if none
  static constexpr std::uint32_t kNoCycle = ~std::uint32_t{0};
};

/// "shared" or "exclusive".
std::string_view to_string(Access access);

}  // namespace oscar::applets
