// CobraControl, the coordination of seed 004 §4.2's landmark application: while it holds its
// cameras it triggers them every cycle (each module's in order, the modules side by side), and it
// sets their frame mode (MARVIN's coordinator switches the framegrabber between quarter and half
// frames), see docs/landmarks.md.
#include <spdlog/spdlog.h>
#include <oscar/command_types.hpp>
#include <oscar/coordinator/applet.hpp>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <future>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace {

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    const auto first = item.find_first_not_of(' ');
    if (first == std::string::npos) continue;
    out.push_back(item.substr(first, item.find_last_not_of(' ') - first + 1));
  }
  return out;
}

class CobraControl final : public oscar::coordinator::Applet {
 public:
  explicit CobraControl(oscar::coordinator::AppletSetup& setup)
      : Applet(setup), bundle_(setup.param("bundle", "cameras")) {
    const auto bad = [&](const std::string& what) {
      return std::invalid_argument("applet '" + name() + "': " + what);
    };
    for (const auto& item : split(setup.param("cameras", ""))) {
      // <service>:<module>/<kernel>
      const auto colon = item.find(':');
      const auto slash = item.find('/', colon == std::string::npos ? 0 : colon);
      if (colon == std::string::npos || colon == 0 || slash == std::string::npos ||
          slash == colon + 1 || slash + 1 == item.size()) {
        throw bad("cameras: '" + item + "' is not '<service>:<module>/<kernel>'");
      }
      cameras_.push_back({item.substr(0, colon), item.substr(colon + 1, slash - colon - 1),
                          item.substr(slash + 1)});
    }
    if (cameras_.empty()) {
      throw bad("cameras is empty (give '<service>:<module>/<kernel>,...', in trigger order)");
    }
    for (const auto& c : cameras_) {
      auto lane = std::find_if(lanes_.begin(), lanes_.end(),
                               [&](const auto& l) { return l.front().module == c.module; });
      if (lane == lanes_.end()) {
        lanes_.push_back({c});
      } else {
        lane->push_back(c);
      }
    }
    const auto cycle_text = setup.param("cycle_ms", "100");
    try {
      cycle_ = std::chrono::milliseconds(std::stoi(cycle_text));
    } catch (const std::exception&) {
      throw bad("cycle_ms: '" + cycle_text + "' is not a number of milliseconds");
    }
    if (cycle_.count() <= 0) throw bad("cycle_ms must be > 0");
    const auto modes = split(setup.param("frame_modes", ""));
    for (const auto& item : modes) {
      const auto colon = item.find(':');
      const auto mode = item.substr(0, colon);
      long cycles = 0;
      if (colon != std::string::npos) {
        try {
          cycles = std::stol(item.substr(colon + 1));
        } catch (const std::exception&) {
          cycles = 0;
        }
      }
      const bool known = mode == "full" || mode == "half" || mode == "quarter";
      // One mode holds for good; several take turns, each for its number of cycles.
      if (!known || (modes.size() > 1 && cycles <= 0) ||
          (modes.size() == 1 && colon != std::string::npos && cycles <= 0)) {
        throw bad(
            "frame_modes: '" + item + "' is not 'full|half|quarter[:<cycles>]' (" +
            (modes.size() > 1 ? "several modes take turns: each needs its cycles" : "cycles > 0") +
            ")");
      }
      schedule_.push_back({mode, static_cast<std::uint64_t>(cycles)});
      period_cycles_ += static_cast<std::uint64_t>(cycles);
    }
  }

  void step(oscar::applets::AppletContext& ctx) override {
    if (!ctx.granted(bundle_)) {
      if (holding_) spdlog::info("applet {}: lost its cameras: sequencing stops", name());
      holding_ = false;
      applied_mode_.reset();  // the next holding sets the mode afresh
      cycles_ = 0;
      return;
    }
    if (!holding_) {
      spdlog::info("applet {}: holds its cameras: triggering {} every {} ms", name(),
                   cameras_text(), cycle_.count());
      holding_ = true;
    }
    // The applet runs every cycle at a fixed rate. After a cycle that overran (the first one
    // waits until the modules are found), the steps that are due come at once: those are
    // skipped until half a cycle after the overrun one ended. A camera triggered again before
    // its last image went through its chain would take the two triggers as one and fall a
    // frame behind the other camera.
    if (last_end_ && std::chrono::steady_clock::now() - *last_end_ < cycle_ / 2) {
      if (++skipped_ == 1 || skipped_ % 100 == 0) {
        spdlog::warn("applet {}: cycle skipped after one that overran ({} so far)", name(),
                     skipped_);
      }
      return;
    }
    const auto mode = mode_for(cycles_++);
    if (mode && mode != applied_mode_) set_frame_mode(*mode);
    // Each module's cameras in order; the modules side by side (seed 004 §4.2: on two PCs both
    // images are grabbed and evaluated in parallel), the first module's from this thread.
    const auto started = std::chrono::steady_clock::now();
    std::vector<std::future<void>> others;
    for (std::size_t i = 1; i < lanes_.size(); ++i) {
      others.push_back(std::async(std::launch::async, [this, i] { run_lane(lanes_[i]); }));
    }
    run_lane(lanes_.front());
    for (auto& f : others) f.get();
    last_end_ = std::chrono::steady_clock::now();
    report(*last_end_ - started);
  }

  std::chrono::milliseconds period() const override { return cycle_; }

 private:
  struct Camera {
    std::string service, module, kernel;
  };

  // Triggers one module's cameras in order; a refused trigger ends the lane for this cycle (the
  // rest would run out of order).
  void run_lane(const std::vector<Camera>& lane) {
    for (const auto& c : lane) {
      const auto reply = trigger(c.service, c.module, c.kernel);
      if (!reply.ok()) {
        const auto n = ++refused_;
        if (n == 1 || n % 100 == 0) {
          spdlog::warn("applet {}: trigger {}/{} refused ({} so far): {}", name(), c.module,
                       c.kernel, n, reply.error());
        }
        return;
      }
    }
  }

  // Every kReportEvery cycles: how long the triggers took, from the first sent to the last
  // answered (commands from the coordinator's process to the cameras' modules over DDS).
  void report(std::chrono::steady_clock::duration sequence) {
    constexpr std::size_t kReportEvery = 100;
    sequence_ms_.push_back(std::chrono::duration<double, std::milli>(sequence).count());
    if (sequence_ms_.size() < kReportEvery) return;
    std::sort(sequence_ms_.begin(), sequence_ms_.end());
    spdlog::info("applet {}: {} cycles; triggers sent -> answered p50 {:.2f} ms, max {:.2f} ms",
                 name(), sequence_ms_.size(), sequence_ms_[sequence_ms_.size() / 2],
                 sequence_ms_.back());
    sequence_ms_.clear();
  }

  std::optional<std::string> mode_for(std::uint64_t cycle) const {
    if (schedule_.empty()) return std::nullopt;
    if (period_cycles_ == 0) return schedule_.front().first;
    auto at = cycle % period_cycles_;
    for (const auto& [mode, cycles] : schedule_) {
      if (at < cycles) return mode;
      at -= cycles;
    }
    return std::nullopt;  // not reached
  }

  void set_frame_mode(const std::string& mode) {
    oscar::SetFrameMode request;
    request.mode(mode);
    for (const auto& c : cameras_) {
      const auto reply = command(c.service, c.module, c.kernel, "frame_mode", request);
      if (!reply.ok()) {  // tried again next cycle
        spdlog::warn("applet {}: frame mode {} of {}/{} refused: {}", name(), mode, c.module,
                     c.kernel, reply.error());
        return;
      }
    }
    applied_mode_ = mode;
    spdlog::info("applet {}: frame mode -> {}", name(), mode);
  }

  std::string cameras_text() const {
    std::string text;
    for (const auto& c : cameras_) text += (text.empty() ? "" : ", ") + c.module + "/" + c.kernel;
    return text;
  }

  std::string bundle_;
  std::vector<Camera> cameras_;             // in trigger order
  std::vector<std::vector<Camera>> lanes_;  // by module, in the order of cameras_
  std::chrono::milliseconds cycle_{100};
  std::vector<std::pair<std::string, std::uint64_t>> schedule_;  // frame mode, cycles
  std::uint64_t period_cycles_ = 0;                              // 0: one mode for good
  bool holding_ = false;
  std::uint64_t cycles_ = 0;  // since it holds the cameras
  std::uint64_t skipped_ = 0;
  std::atomic<std::uint64_t> refused_ = 0;  // counted by the lanes
  std::optional<std::string> applied_mode_;
  std::optional<std::chrono::steady_clock::time_point> last_end_;  // of the last sequence
  std::vector<double> sequence_ms_;                                // since the last report
};

}  // namespace

OSCAR_REGISTER_APPLET(CobraControl, "cobra_control")
