#include "tofguard/common/body_region.hpp"

#include <array>

namespace tofguard {
namespace {

constexpr std::array<const char*, kNumBodyRegions> kRegionNames = {"skull_and_forehead",
                                                                   "face",
                                                                   "neck",
                                                                   "back_and_shoulders",
                                                                   "chest",
                                                                   "abdomen",
                                                                   "pelvis",
                                                                   "upper_arm",
                                                                   "forearm",
                                                                   "hand",
                                                                   "thigh",
                                                                   "lower_leg"};

}  // namespace

const char* body_region_name(BodyRegion region) { return kRegionNames.at(static_cast<size_t>(region)); }

std::vector<BodyRegion> all_body_regions() {
  std::vector<BodyRegion> regions;
  for (int i = 0; i < kNumBodyRegions; ++i) regions.push_back(static_cast<BodyRegion>(i));
  return regions;
}

std::string body_region_names() {
  std::string list;
  for (const char* name : kRegionNames) list += (list.empty() ? "" : ", ") + std::string(name);
  return list;
}

std::optional<BodyRegion> body_region_named(const std::string& name) {
  for (int i = 0; i < kNumBodyRegions; ++i) {
    if (name == kRegionNames[i]) return static_cast<BodyRegion>(i);
  }
  return std::nullopt;
}

std::optional<BodyRegion> body_region_of_link(const std::string& link_name) {
  // No region's name is another's followed by '_' ("upper_arm_left" can
  // only be an upper arm), so the first match is the only one.
  for (int i = 0; i < kNumBodyRegions; ++i) {
    const std::string region = kRegionNames[i];
    if (link_name == region || link_name.rfind(region + "_", 0) == 0) return static_cast<BodyRegion>(i);
  }
  return std::nullopt;
}

bool body_region_is_no_contact(BodyRegion region) {
  return region == BodyRegion::kSkullAndForehead || region == BodyRegion::kFace ||
         region == BodyRegion::kNeck;
}

}  // namespace tofguard
