#pragma once
// Shared by the applet tests: error messages, and the smallest dependency cycle (Abb. 4.9).

#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>

#include "oscar/applets/model.hpp"

namespace oscar::applets::testing {

/// The message of the std::invalid_argument `f` throws, or "no exception".
template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no exception";
}

/// Whether `pred` becomes true within `limit` (polled every 2 ms): threaded tests wait for an
/// outcome, never a fixed time.
template <typename P>
bool eventually(P pred, std::chrono::milliseconds limit = std::chrono::seconds{10}) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < end) {
    if (pred()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds{2});
  }
  return pred();
}

/// Service applets A (provides S1) and B (provides S2): a bundle of A using S2 and one of B
/// using S1 close a cycle (seed Abb. 4.9).
struct TwoServiceApplets {
  Model m;
  ServiceId s1 = m.add_service("S1");
  ServiceId s2 = m.add_service("S2");
  AppletId a = provider("A", s1);
  AppletId b = provider("B", s2);

 private:
  AppletId provider(const char* name, ServiceId service) {
    const AppletId id = m.add_applet(name);
    m.provide(id, service);
    return id;
  }
};

}  // namespace oscar::applets::testing
