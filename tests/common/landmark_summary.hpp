#pragma once
// The once-a-second summary landmark_pose logs, read back from a module log (the landmark
// tests and `oscar bench landmarks` use it where they cannot subscribe, e.g. on test hosts).

#include <fstream>
#include <regex>
#include <string>
#include <vector>

namespace oscar::test {

struct LandmarkSummary {
  int poses = 0;
  double seconds = 0, rate_hz = 0;
  int both = 0;
  double p50_ms = 0, p99_ms = 0;
  bool truth = false;
  double worst_mm = 0, worst_deg = 0;
};

inline std::vector<LandmarkSummary> landmark_summaries(const std::string& log_file) {
  static const std::regex line(
      R"((\d+) poses in ([\d.]+) s \(([\d.]+)/s\), (\d+) from both cameras; acquisition->pose )"
      R"(p50 ([\d.]+) ms p99 ([\d.]+) ms; (no ground truth|vs ground truth worst ([\d.]+) mm )"
      R"(([\d.]+) deg))");
  std::vector<LandmarkSummary> out;
  std::ifstream in(log_file);
  for (std::string text; std::getline(in, text);) {
    std::smatch m;
    if (!std::regex_search(text, m, line)) continue;
    LandmarkSummary s;
    s.poses = std::stoi(m[1]);
    s.seconds = std::stod(m[2]);
    s.rate_hz = std::stod(m[3]);
    s.both = std::stoi(m[4]);
    s.p50_ms = std::stod(m[5]);
    s.p99_ms = std::stod(m[6]);
    s.truth = m[8].matched;
    if (s.truth) {
      s.worst_mm = std::stod(m[8]);
      s.worst_deg = std::stod(m[9]);
    }
    out.push_back(s);
  }
  return out;
}

}  // namespace oscar::test
