// The occupant model: the default occupant's body regions where the
// wheelchair is, exact distances to its shapes, one-line load errors; the
// body regions' names; and the arms' moving masses that size the contact
// speeds (the default arm, the iiwa14 and the Kinova Gen3).
#include <gtest/gtest.h>

#include <filesystem>
#include <limits>

#include "model_test_util.hpp"
#include "tofguard/robot_model/kinematic_tree.hpp"
#include "tofguard/robot_model/occupant_model.hpp"

namespace tofguard::robot_model::test {
namespace {

namespace fs = std::filesystem;
using tofguard::test::shared_dir;
using tofguard::test::source_dir;
using tofguard::test::write_test_file;

std::string models() { return source_dir() + "/config/models/"; }

OccupantModel default_occupant() {
  const KinematicTree environment =
      load_kinematic_tree(models() + "friend_arm.urdf", {models() + "wheelchair_environment.urdf"});
  return load_occupant(models() + "wheelchair_occupant.urdf", fixed_link_pose(environment, "wheelchair"));
}

const OccupantPart& part(const OccupantModel& model, const std::string& link) {
  for (const OccupantPart& p : model.parts) {
    if (p.link_name == link) return p;
  }
  throw std::runtime_error("no occupant part " + link);
}

TEST(BodyRegions, NamesAndLinks) {
  ASSERT_EQ(all_body_regions().size(), static_cast<size_t>(kNumBodyRegions));
  for (const BodyRegion region : all_body_regions()) {
    EXPECT_EQ(body_region_named(body_region_name(region)), region);
    EXPECT_EQ(body_region_of_link(std::string(body_region_name(region)) + "_left"), region);
  }
  EXPECT_EQ(body_region_of_link("upper_arm_right"), BodyRegion::kUpperArm);
  EXPECT_EQ(body_region_of_link("forearm"), BodyRegion::kForearm);
  EXPECT_FALSE(body_region_of_link("forearmrest").has_value());
  EXPECT_FALSE(body_region_of_link("seat").has_value());
  EXPECT_FALSE(body_region_named("hands").has_value());
  EXPECT_TRUE(body_region_is_no_contact(BodyRegion::kFace));
  EXPECT_TRUE(body_region_is_no_contact(BodyRegion::kSkullAndForehead));
  EXPECT_TRUE(body_region_is_no_contact(BodyRegion::kNeck));
  EXPECT_FALSE(body_region_is_no_contact(BodyRegion::kHand));
  EXPECT_FALSE(body_region_is_no_contact(BodyRegion::kChest));
}

TEST(OccupantModel, TheDefaultOccupantSitsInTheWheelchair) {
  const OccupantModel model = default_occupant();
  EXPECT_EQ(model.regions(), all_body_regions());
  EXPECT_EQ(model.parts.size(), 17u);  // 7 single regions, 5 left and right
  // The wheelchair's frame is 0.25 m behind the world's origin: the face's
  // box (centre x -0.045 in it, 6 cm deep) has its front at world x -0.265.
  const OccupantPart& face = part(model, "face");
  EXPECT_NEAR(distance_to_part_m(face, {-0.215, 0, 1.34}), 0.05, 1e-9);
  EXPECT_DOUBLE_EQ(distance_to_part_m(face, {-0.295, 0, 1.34}), 0.0);  // inside
  // The skull's sphere (radius 0.095 at x -0.37, z 1.39): 0.105 above its top.
  EXPECT_NEAR(distance_to_part_m(part(model, "skull_and_forehead"), {-0.37, 0, 1.59}), 0.105, 1e-9);
  // The right forearm: a cylinder along x (radius 0.04, 0.26 long) at
  // world (-0.22, -0.20, 0.84): 0.06 below it, and 0.03 beyond its end on
  // its axis.
  const OccupantPart& forearm = part(model, "forearm_right");
  EXPECT_EQ(forearm.region, BodyRegion::kForearm);
  EXPECT_NEAR(distance_to_part_m(forearm, {-0.22, -0.20, 0.74}), 0.06, 1e-9);
  EXPECT_NEAR(distance_to_part_m(forearm, {-0.22 + 0.13 + 0.03, -0.20, 0.84}), 0.03, 1e-9);
  // A corner: 3 cm beyond the end and 4 cm beyond the radius: 5 cm.
  EXPECT_NEAR(distance_to_part_m(forearm, {-0.22 + 0.16, -0.20, 0.84 + 0.08}), 0.05, 1e-9);
}

TEST(OccupantModel, LoadErrorsAreOneLineNamingFileLinkAndExpectation) {
  struct Bad {
    std::string name, urdf;
    std::vector<std::string> expected;
  };
  const std::string head = "<?xml version=\"1.0\"?><robot name=\"o\"><link name=\"seat\"/>";
  const std::vector<Bad> bad = {
      {"unnamed",
       head +
           "<joint name=\"j\" type=\"fixed\"><parent link=\"seat\"/><child link=\"elbow_pad\"/></joint>"
           "<link name=\"elbow_pad\"><visual><geometry><box size=\"0.1 0.1 0.1\"/></geometry></visual></link>"
           "</robot>",
       {"elbow_pad", "no body region's name", "forearm"}},
      {"mesh",
       head + "<joint name=\"j\" type=\"fixed\"><parent link=\"seat\"/><child link=\"hand\"/></joint>"
              "<link name=\"hand\"><visual><geometry><mesh filename=\"hand.stl\"/></geometry></visual></link>"
              "</robot>",
       {"hand", "other than box, sphere or cylinder"}},
      {"moving",
       head + "<joint name=\"turn\" type=\"revolute\"><parent link=\"seat\"/><child link=\"face\"/>"
              "<axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint>"
              "<link name=\"face\"><visual><geometry><sphere "
              "radius=\"0.1\"/></geometry></visual></link></robot>",
       {"turn", "moves", "fixed joints only"}},
      {"empty", head + "</robot>", {"no body part"}},
  };
  for (const Bad& b : bad) {
    const std::string path = write_test_file("occupant-" + b.name + ".urdf", b.urdf);
    std::string message = "(no error)";
    try {
      load_occupant(path, Eigen::Isometry3d::Identity());
    } catch (const ModelError& e) {
      message = e.what();
    }
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_NE(message.find(path), std::string::npos) << message;
    for (const std::string& part : b.expected) {
      EXPECT_NE(message.find(part), std::string::npos) << b.name << ": '" << part << "' missing: " << message;
    }
  }
}

TEST(OccupantModel, FixedLinkPoseRefusesALinkOnAMovingJoint) {
  const KinematicTree tree = load_kinematic_tree(models() + "friend_arm.urdf");
  EXPECT_TRUE(fixed_link_pose(tree, "base_link").translation().isApprox(Eigen::Vector3d(0, -0.35, 0.80)));
  EXPECT_THROW(fixed_link_pose(tree, "link3"), ModelError);
  EXPECT_THROW(fixed_link_pose(tree, "no_such_link"), ModelError);
}

// M of ISO/TS 15066 A.3.4: the sum of the masses the joints move.
TEST(MovingMass, TheDefaultArmTheIiwa14AndTheKinovaGen3) {
  EXPECT_NEAR(moving_mass_kg(load_kinematic_tree(models() + "friend_arm.urdf")), 10.0, 1e-9);
  const std::string no_mass = write_test_file(
      "arm-without-mass.urdf",
      "<?xml version=\"1.0\"?><robot name=\"a\"><link name=\"base\"/>"
      "<joint name=\"j1\" type=\"revolute\"><parent link=\"base\"/><child link=\"l1\"/><axis xyz=\"0 0 1\"/>"
      "<limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint><link name=\"l1\">"
      "<visual><geometry><sphere radius=\"0.1\"/></geometry></visual></link></robot>");
  try {
    moving_mass_kg(load_kinematic_tree(no_mass));
    ADD_FAILURE() << "an arm without masses has a moving mass";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("'l1' moves and has no <inertial><mass>"), std::string::npos)
        << e.what();
  }
  if (shared_dir().empty())
    GTEST_SKIP() << "../shared is absent: the iiwa14 and Kinova Gen3 models are not available";
  const fs::path robots = fs::path(shared_dir()) / "robots";
  const fs::path iiwa = robots / "iiwa14" / "urdf" / "iiwa14_no_collision_relative.urdf";
  const fs::path kinova = robots / "kinova_gen3" / "kortex_description" / "arms" / "gen3" / "7dof" / "urdf" /
                          "GEN3-7DOF-NOVISION_FOR_URDF_ARM_V12.urdf";
  if (!fs::exists(iiwa) || !fs::exists(kinova)) GTEST_SKIP() << iiwa << " or " << kinova << " is absent";
  // iiwa14: links 1-7 (the base, 5 kg, stays); Kinova Gen3: shoulder to
  // bracelet (its base, 1.697 kg, stays).
  EXPECT_NEAR(moving_mass_kg(load_kinematic_tree(iiwa.string())), 25.61, 1e-9);
  EXPECT_NEAR(moving_mass_kg(load_kinematic_tree(kinova.string())), 6.353, 1e-9);
}

}  // namespace
}  // namespace tofguard::robot_model::test
