// An applet that submits jobs to the live swarm at a steady rate (docs/swarm.md, "The live
// swarm"): each a small square at one of the configured stations, in a window from now, as a
// warehouse's order stream would. It counts the coordinator's answers and logs them.
#include <oscar/swarm.h>
#include <oscar/swarmPubSubTypes.h>
#include <spdlog/spdlog.h>
#include <oscar/coordinator/applet.hpp>
#include <oscar/time.hpp>
#include <oscar/topic_io.hpp>
#include <oscar/topics.hpp>

#include <atomic>
#include <memory>
#include <random>
#include <sstream>
#include <stdexcept>

namespace {

// "a,b" as two numbers; `what` names the parameter in errors.
std::pair<double, double> pair_of(const std::string& text, const std::string& what) {
  std::istringstream in(text);
  double a = 0, b = 0;
  char comma = 0;
  if (!(in >> a >> comma >> b) || comma != ',' || !(in >> std::ws).eof()) {
    throw std::invalid_argument(what + ": expected two numbers 'a,b', got '" + text + "'");
  }
  return {a, b};
}

// A range "low,high".
std::pair<double, double> range_of(const std::string& text, const std::string& what) {
  const auto r = pair_of(text, what);
  if (r.first > r.second || r.first < 0) {
    throw std::invalid_argument(what + ": expected 'low,high' with 0 <= low <= high, got '" + text +
                                "'");
  }
  return r;
}

class JobGenerator final : public oscar::coordinator::Applet {
 public:
  explicit JobGenerator(oscar::coordinator::AppletSetup& setup)
      : Applet(setup),
        participant_(setup.participant()),
        every_(std::stoi(setup.param("every_ms", "1000"))),
        window_(range_of(setup.param("window_s", "5,60"), "applet '" + name() + "' window_s")),
        duration_(range_of(setup.param("duration_s", "2,5"), "applet '" + name() + "' duration_s")),
        half_size_(std::stod(setup.param("size_m", "0.5")) / 2),
        count_(std::stoi(setup.param("count", "0"))),
        rng_(static_cast<unsigned>(std::stoul(setup.param("seed", "1")))) {
    std::istringstream stations(setup.param("stations", ""));
    for (std::string s; std::getline(stations, s, ';');) {
      stations_.push_back(pair_of(s, "applet '" + name() + "' station"));
    }
    if (stations_.empty()) {
      throw std::invalid_argument("applet '" + name() +
                                  "': stations is empty (expected 'x,y;x,y;...')");
    }
    if (every_.count() <= 0) {
      throw std::invalid_argument("applet '" + name() + "': every_ms must be > 0");
    }
    if (window_.second - window_.first < duration_.second) {
      throw std::invalid_argument("applet '" + name() +
                                  "': window_s is shorter than the longest duration_s");
    }
  }

  void init(oscar::applets::AppletContext& /*ctx*/) override {
    if (!participant_) throw std::logic_error("applet '" + name() + "' runs without DDS");
    writer_ = std::make_unique<Writer>(*participant_, oscar::topics::swarm_request());
    replies_ = std::make_unique<Reader>(
        *participant_, oscar::topics::swarm_reply(), [this](const oscar::SwarmReply& r, auto&) {
          if (r.sender() != name()) return;
          if (r.outcome() == oscar::SWARM_COMMITTED) ++committed_;
          if (r.outcome() == oscar::SWARM_REFUSED || r.outcome() == oscar::SWARM_ABORTED) {
            ++refused_;
            spdlog::info("applet {}: request {} {}: {}", name(), r.request(),
                         r.outcome() == oscar::SWARM_REFUSED ? "refused" : "aborted", r.reason());
          }
        });
  }

  void step(oscar::applets::AppletContext& /*ctx*/) override {
    const auto now = std::chrono::steady_clock::now();
    if (count_ > 0 && sent_ >= static_cast<unsigned long long>(count_)) return;
    if (last_ && now - *last_ < every_) return;
    if (writer_->matched() == 0) return;  // no coordinator with a swarm yet
    last_ = now;
    submit();
    if (sent_ % 10 == 0) {
      spdlog::info("applet {}: {} jobs sent, {} committed, {} refused or aborted", name(), sent_,
                   committed_.load(), refused_.load());
    }
  }

  std::chrono::milliseconds period() const override { return std::chrono::milliseconds(20); }

 private:
  using Writer = oscar::TopicWriter<oscar::SwarmRequest, oscar::SwarmRequestPubSubType>;
  using Reader = oscar::TopicReader<oscar::SwarmReply, oscar::SwarmReplyPubSubType>;

  void submit() {
    const auto& [x, y] =
        stations_[std::uniform_int_distribution<std::size_t>(0, stations_.size() - 1)(rng_)];
    const double d =
        std::uniform_real_distribution<double>(duration_.first, duration_.second)(rng_);
    oscar::SwarmJobSpec job;
    job.id(name() + "-" + std::to_string(++sent_));
    job.area().x({x - half_size_, x + half_size_, x + half_size_, x - half_size_});
    job.area().y({y - half_size_, y - half_size_, y + half_size_, y + half_size_});
    const auto t = oscar::wall_now();
    job.earliest_start_ns(t + static_cast<oscar::Stamp>(window_.first * 1e9));
    job.latest_finish_ns(t + static_cast<oscar::Stamp>(window_.second * 1e9));
    job.duration_s(d);
    oscar::SwarmRequest r;
    r.sender(name());
    r.id(sent_);
    r.kind(oscar::SWARM_SCHEDULE);
    r.jobs().push_back(job);
    writer_->write(r);
  }

  oscar::DdsParticipant* participant_;
  std::chrono::milliseconds every_;
  std::pair<double, double> window_, duration_;
  double half_size_;
  int count_;
  std::mt19937 rng_;
  std::vector<std::pair<double, double>> stations_;
  unsigned long long sent_ = 0;
  std::atomic<unsigned long long> committed_{0}, refused_{0};
  std::optional<std::chrono::steady_clock::time_point> last_;
  std::unique_ptr<Writer> writer_;
  std::unique_ptr<Reader> replies_;  // last: its callback uses the members above
};

}  // namespace

OSCAR_REGISTER_APPLET(JobGenerator, "job_generator")
