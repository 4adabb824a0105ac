// MARVIN's coordination module (seed 004 §4.2, "Exploration eines Ganges"): a state machine that
// activates the modules each mission phase needs and reconfigures the framegrabber between
// phases. Phase `explore` (wall following with door search) holds one bundle; when the door
// search sees a door sign it gives that bundle back and asks for phase `identify` (door
// identification: localise the door sign in half frames, then read it), whose bundle the plan
// grants with other modules; after `read_ms` it counts the door and explores again, until
// `doors` doors are done. Which modules run, and in which frame mode, is the system file's
// `services:` (docs/coordinator.md, "A mission in phases").
#include <spdlog/spdlog.h>
#include <oscar/coordinator/applet.hpp>
#include <oscar/perception_types.hpp>

#include <chrono>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

namespace {

using Clock = std::chrono::steady_clock;

class MarvinMission final : public oscar::coordinator::Applet {
 public:
  explicit MarvinMission(oscar::coordinator::AppletSetup& setup)
      : Applet(setup),
        explore_(setup.param("explore", "explore")),
        identify_(setup.param("identify", "identify")),
        signs_address_(setup.param("door_signs", "door_search/tags")),
        located_address_(setup.param("door_located", "door_locate/tags")),
        explore_min_(whole_number(setup, "explore_min_ms", "1000")),
        read_(whole_number(setup, "read_ms", "1000")),
        doors_(whole_number(setup, "doors", "0")) {}

  void init(oscar::applets::AppletContext& ctx) override {
    signs_ = &cues<oscar::TagDetections>(signs_address_);
    located_ = &cues<oscar::TagDetections>(located_address_);
    enter(ctx, Phase::kExplore, "mission starts");
  }

  void step(oscar::applets::AppletContext& ctx) override {
    const auto now = Clock::now();
    switch (phase_) {
      case Phase::kExplore:
        // A sign counts once the wall following ran a while (the last door is behind us).
        if (ctx.granted(explore_) && now - entered_ >= explore_min_ && sees_tags(*signs_, seen_)) {
          enter(ctx, Phase::kIdentify, "door sign seen");
        }
        break;
      case Phase::kIdentify:
        if (!ctx.granted(identify_)) break;
        if (!located_at_) {
          if (sees_tags(*located_, seen_)) {
            located_at_ = now;
            spdlog::info("applet {}: door localised in half frames, reading its sign", name());
          }
        } else if (now - *located_at_ >= read_) {
          ++done_;
          spdlog::info("applet {}: door {} identified", name(), done_);
          if (doors_ > 0 && done_ >= doors_) {
            enter(ctx, Phase::kDone, "all doors identified");
          } else {
            enter(ctx, Phase::kExplore, "next door");
          }
        }
        break;
      case Phase::kDone:
        break;
    }
  }

  std::chrono::milliseconds period() const override { return std::chrono::milliseconds(20); }

 private:
  enum class Phase { kExplore, kIdentify, kDone };

  static long long whole_number(oscar::coordinator::AppletSetup& setup, const std::string& key,
                                const std::string& fallback) {
    const auto text = setup.param(key, fallback);
    std::size_t used = 0;
    long long value = -1;
    try {
      value = std::stoll(text, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != text.size() || value < 0) {
      throw std::invalid_argument("applet '" + setup.name() + "': " + key +
                                  " must be a whole number >= 0, not '" + text + "'");
    }
    return value;
  }

  // A cue newer than `seen` with at least one tag (the feed counts every cue).
  static bool sees_tags(const oscar::coordinator::CueFeed<oscar::TagDetections>& feed,
                        std::uint64_t& seen) {
    const auto count = feed.received();
    if (count == seen) return false;
    seen = count;
    const auto cue = feed.latest();
    return cue && !cue->detections().empty();
  }

  static const char* name_of(Phase p) {
    return p == Phase::kExplore ? "explore" : p == Phase::kIdentify ? "identify" : "done";
  }

  // Gives back the bundle of the phase it leaves and asks for the next one's: the plan then
  // activates and deactivates the modules in one reconciliation.
  void enter(oscar::applets::AppletContext& ctx, Phase next, const char* why) {
    if (phase_ == Phase::kExplore && next != Phase::kExplore) ctx.release(explore_);
    if (phase_ == Phase::kIdentify) ctx.release(identify_);
    if (next == Phase::kExplore) ctx.request(explore_);
    if (next == Phase::kIdentify) ctx.request(identify_);
    spdlog::info("applet {}: phase {} -> {} ({})", name(), started_ ? name_of(phase_) : "-",
                 name_of(next), why);
    started_ = true;
    phase_ = next;
    entered_ = Clock::now();
    located_at_.reset();
    seen_ = next == Phase::kExplore ? signs_->received() : located_->received();
  }

  std::string explore_, identify_, signs_address_, located_address_;
  std::chrono::milliseconds explore_min_, read_;
  long long doors_;  // 0: no end
  const oscar::coordinator::CueFeed<oscar::TagDetections>* signs_ = nullptr;
  const oscar::coordinator::CueFeed<oscar::TagDetections>* located_ = nullptr;
  Phase phase_ = Phase::kExplore;
  bool started_ = false;
  Clock::time_point entered_;
  std::optional<Clock::time_point> located_at_;
  std::uint64_t seen_ = 0;
  long long done_ = 0;
};

}  // namespace

OSCAR_REGISTER_APPLET(MarvinMission, "marvin_mission")
