#pragma once
// The body regions of ISO/TS 15066 Annex A (its Table A.2), head to feet:
// what the occupant model's links are named after (robot_model/
// occupant_model.hpp), what the config's occupant.regions are keyed by, and
// what a speed limit names as the region that set it.
#include <optional>
#include <string>
#include <vector>

namespace tofguard {

enum class BodyRegion {
  kSkullAndForehead,
  kFace,
  kNeck,
  kBackAndShoulders,
  kChest,
  kAbdomen,
  kPelvis,
  kUpperArm,
  kForearm,
  kHand,
  kThigh,
  kLowerLeg,
};
constexpr int kNumBodyRegions = 12;

// The region's name as links and the config write it ("skull_and_forehead",
// "face", "neck", "back_and_shoulders", "chest", "abdomen", "pelvis",
// "upper_arm", "forearm", "hand", "thigh", "lower_leg").
const char* body_region_name(BodyRegion region);
// Every region, head to feet.
std::vector<BodyRegion> all_body_regions();
// The names, comma-separated, for messages.
std::string body_region_names();
// The region called exactly `name`; nullopt when none.
std::optional<BodyRegion> body_region_named(const std::string& name);
// The region a link name starts with: the region's name alone, or followed
// by '_' and anything ("forearm_left" -> kForearm); nullopt when none.
std::optional<BodyRegion> body_region_of_link(const std::string& link_name);
// The regions the arm must never touch, which get a clearance instead of a
// contact speed: the head (skull and forehead, face) and the neck
// (docs/safety-chain.md, "The user").
bool body_region_is_no_contact(BodyRegion region);

}  // namespace tofguard
