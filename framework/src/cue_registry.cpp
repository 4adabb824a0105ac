#include <algorithm>
#include <map>
#include <mutex>

#include "oscar/cue_type_info.hpp"
#include "oscar/cue_types.hpp"
#include "oscar/perception_types.hpp"
#include "oscar/plain_cue_types.hpp"
#include "oscar/swarm_types.hpp"

namespace oscar {
namespace {
struct Registry {
  std::mutex mutex;
  std::map<std::string, std::unique_ptr<CueTypeInfo>> types;
};
Registry& registry() {
  static Registry r;
  return r;
}
}  // namespace

const CueTypeInfo& register_cue_type(CueTypeInfo info) {
  auto& r = registry();
  std::lock_guard lock(r.mutex);
  auto& slot = r.types[info.name];
  if (!slot) slot = std::make_unique<CueTypeInfo>(std::move(info));
  return *slot;
}

const CueTypeInfo* find_cue_type(const std::string& name) {
  auto& r = registry();
  std::lock_guard lock(r.mutex);
  const auto it = r.types.find(name);
  return it == r.types.end() ? nullptr : it->second.get();
}

std::vector<std::string> cue_type_names() {
  auto& r = registry();
  std::lock_guard lock(r.mutex);
  std::vector<std::string> names;
  for (const auto& [name, info] : r.types) names.push_back(name);
  return names;
}

CueHeaderLayout cue_header_layout(const std::string& type_name) {
  register_plain_cue_types();
  const auto* type = find_cue_type(type_name);
  return type ? type->header.layout : CueHeaderLayout::kSequences;
}

void register_plain_cue_types() {
  cue_type_info<PlainBool>();
  cue_type_info<PlainLineSeg3DSeq>();
  cue_type_info<PlainGvImage>();
}

void register_standard_cue_types() {
  cue_type_info<Bool>();
  cue_type_info<LineSeg3DSeq>();
  cue_type_info<GvImage>();
  cue_type_info<CameraImage>();
  cue_type_info<TagDetections>();
  cue_type_info<LandmarkPose>();
  cue_type_info<RobotState>();
  cue_type_info<SafetyViolation>();
  register_plain_cue_types();
}

}  // namespace oscar
