// The simulated wheelchair user's motions, measured on the default
// occupant model: each moves the parts it names by what the settings say,
// and nothing else.
#include <gtest/gtest.h>

#include <cmath>

#include "tofguard/robot_model/occupant_model.hpp"
#include "tofguard/sim/simulated_user.hpp"
#include "tool_support.hpp"

namespace tofguard::sim {
namespace {

robot_model::OccupantModel occupant() {
  return robot_model::load_occupant(test::source_dir() + "/config/models/wheelchair_occupant.urdf",
                                    Eigen::Isometry3d::Identity());
}

// The centre of the first shape of `link`, in the order shapes_at gives.
Eigen::Vector3d centre_of(const robot_model::OccupantModel& model, const std::vector<RegionShape>& shapes,
                          const std::string& link) {
  size_t k = 0;
  for (const robot_model::OccupantPart& part : model.parts) {
    if (part.link_name == link) return shapes[k].frame_from_shape.translation();
    k += part.shapes.size();
  }
  ADD_FAILURE() << "no link " << link;
  return Eigen::Vector3d::Zero();
}

TEST(SimulatedUser, BreathesTurnsTheHeadAndMovesTheRightHand) {
  const robot_model::OccupantModel model = occupant();
  SimUserSettings s;
  s.breathing_mm = 8;
  s.breathing_period_s = 4;
  s.head_turn_rad = 20 * M_PI / 180;
  s.head_period_s = 16;
  s.hand_motion_m = 0.04;
  s.hand_period_s = 8;
  const SimulatedUser user(model, Eigen::Isometry3d::Identity(), s);
  const std::vector<RegionShape> rest = user.shapes_at(0);
  // t = 2 s: the breath at its deepest (8 mm forward), the hand at +4 cm
  // (a quarter of 8 s), the head at 20 sin(45 deg) = 14.1 deg.
  const std::vector<RegionShape> moved = user.shapes_at(2);
  ASSERT_EQ(moved.size(), rest.size());
  EXPECT_NEAR((centre_of(model, moved, "chest") - centre_of(model, rest, "chest")).x(), 0.008, 1e-9);
  EXPECT_NEAR((centre_of(model, moved, "abdomen") - centre_of(model, rest, "abdomen")).x(), 0.008, 1e-9);
  EXPECT_NEAR((centre_of(model, moved, "hand_right") - centre_of(model, rest, "hand_right")).x(), 0.04, 1e-9);
  EXPECT_NEAR((centre_of(model, moved, "hand_left") - centre_of(model, rest, "hand_left")).norm(), 0, 1e-12);
  // The face's centre, 6.5 cm before the neck's axis, turns about it.
  const Eigen::Vector3d face = centre_of(model, moved, "face") - centre_of(model, rest, "neck");
  const double turned = std::atan2(face.y(), face.x());
  EXPECT_NEAR(turned, 20 * M_PI / 180 * std::sin(M_PI / 4), 1e-9);
  EXPECT_NEAR(std::hypot(face.x(), face.y()), 0.065, 1e-9);
  EXPECT_NEAR((centre_of(model, moved, "pelvis") - centre_of(model, rest, "pelvis")).norm(), 0, 1e-12);
}

}  // namespace
}  // namespace tofguard::sim
