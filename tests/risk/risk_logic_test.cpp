// The risk classifier's logic: the frame rules (on summaries computed from
// synthetic images; the robot's tree is robot_model's, tested there),
// debouncing and deadlines on an explicit monotonic clock.
#include <gtest/gtest.h>

#include <functional>

#include <iomanip>
#include <limits>
#include <sstream>

#include "occupant_test_config.hpp"
#include "synthetic_frames.hpp"
#include "tofguard/deployment/config.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/discrepancy/discrepancy_image.hpp"
#include "tofguard/risk/arm_coverage.hpp"
#include "tofguard/risk/cameras_judgement.hpp"
#include "tofguard/risk/frame_classifier.hpp"
#include "tofguard/risk/protective_field.hpp"
#include "tofguard/risk/risk_monitor.hpp"
#include "tofguard/robot_model/kinematic_tree.hpp"
#include "tofguard/speed_limit_t.hpp"
#include "tool_support.hpp"

namespace tofguard::test {
namespace {

// risk::fixed, which writes every number of a verdict's detail, is what an
// ostream with std::fixed and std::setprecision writes (the detail's text
// did not change when it stopped using one): halfway cases, signs, zero,
// NaN, infinities, and a number too long for its buffer.
TEST(FixedText, IsWhatAStreamWithFixedPrecisionWrites) {
  const auto streamed = [](double value, int decimals) {
    std::ostringstream s;
    s << std::fixed << std::setprecision(decimals) << value;
    return s.str();
  };
  const double values[] = {0.0,
                           -0.0,
                           0.05,
                           0.15,
                           0.25,
                           2.5,
                           -2.5,
                           1.005,
                           -0.049,
                           123.45,
                           1e15,
                           -3.14159,
                           1e-300,
                           1e300,
                           1e308,
                           6.02e23,
                           std::numeric_limits<double>::quiet_NaN(),
                           -std::numeric_limits<double>::quiet_NaN(),
                           std::numeric_limits<double>::infinity(),
                           -std::numeric_limits<double>::infinity()};
  for (const double value : values) {
    for (int decimals = 0; decimals <= 6; ++decimals)
      EXPECT_EQ(risk::fixed(value, decimals), streamed(value, decimals)) << value << " " << decimals;
  }
  EXPECT_EQ(risk::fixed(2.25, 1), "2.2");  // round half to even, as printf
  EXPECT_EQ(risk::fixed(-0.04, 1), "-0.0");
}

using risk::ClassifierContext;
using risk::classify_frame;
using risk::FrameFinding;
using risk::RiskMonitor;

const deployment::Config& sim_config() {
  static const deployment::Config config = deployment::load_config(ideal_camera_config(), nullptr);
  return config;
}

// With several cameras the judgement weighs the links no camera sees by
// their surface, read from the arm's meshes as the renderer draws them:
// every link of the default arm with geometry has one, and without the
// arm's surface two cameras are refused rather than judged with no limit
// on the arm unseen.
TEST(CamerasJudgement, SeveralCamerasNeedTheArmsSurface) {
  const deployment::Config& config = sim_config();
  const std::vector<risk::LinkArea> areas = risk::read_robot_link_areas(
      config.robot.urdf_path, config.robot.package_paths, config.renderer.geometry);
  const robot_model::KinematicTree robot = robot_model::load_kinematic_tree(config.robot.urdf_path);
  ASSERT_EQ(areas.size(), static_cast<size_t>(robot.num_robot_links));
  for (int i = 0; i < robot.num_robot_links; ++i) {
    EXPECT_EQ(areas[i].name, robot.links[i].name);
    EXPECT_EQ(areas[i].area_m2 > 0, !robot.links[i].visuals.empty()) << areas[i].name;
  }
  std::vector<risk::RiskCamera> two = {{"tof-mast", 30, config.channels, {}},
                                       {"tof-side", 30, config.channels, {}}};
  two[1].channels.depth += "/tof-side";
  EXPECT_NO_THROW(risk::CamerasJudgement(config.risk, two, robot, areas, std::nullopt, 0));
  try {
    risk::CamerasJudgement judgement(config.risk, two, robot, {{"world", 0.0}}, std::nullopt, 0);
    ADD_FAILURE() << "judged two cameras without the arm's surface";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no robot link with a surface area"), std::string::npos) << e.what();
  }
}

// The deadline tests below count on one deadline for the camera and the
// joint states (sim.yaml's depth deadline is 150 ms).
const deployment::Config& config_depth_100ms() {
  static const deployment::Config config = [] {
    deployment::Config c = sim_config();
    c.risk.depth_deadline_us = 100000;
    return c;
  }();
  return config;
}

const robot_model::KinematicTree& friend_arm() {
  static const robot_model::KinematicTree tree =
      robot_model::load_kinematic_tree(sim_config().robot.urdf_path);
  return tree;
}

// Summary of a synthetic camera scene against the default model (links
// base_link, link1, link2 of the FRIEND arm, and a floor).
discrepancy_t summary_of(const std::vector<Box>& camera_scene, int64_t seq = 7, uint32_t noise_seed = 1) {
  const SyntheticImage model = draw(default_arm());
  const SyntheticImage seen = draw(camera_scene);
  link_labels_t labels = labels_frame(model.label, seq);
  add_pixel_cover(&labels, model.depth_mm);
  return discrepancy::compute_discrepancy(depth_frame(with_noise(seen.depth_mm, noise_seed), seq),
                                          depth_frame(model.depth_mm, seq), labels,
                                          discrepancy::discrepancy_options(sim_config().discrepancy))
      .summary;
}

// The synthetic scene is small (176 x 144 px at 2 m): the frame rules are
// tested with fields of 0.3 m (protective) and 0.5 m (warning); sim.yaml's
// own sizes are tested in ProtectiveField below.
risk::FieldSize test_field() {
  risk::FieldSize field;
  field.arm_speed_m_s = 0;
  field.protective_m = 0.3;
  field.warning_m = 0.5;
  return field;
}

FrameFinding classify(const discrepancy_t& d, bool arm_moving = false,
                      const risk::FieldSize& field = test_field()) {
  ClassifierContext context;
  context.arm_moving = arm_moving;
  context.field = field;
  return classify_frame(d, friend_arm(), sim_config().risk, context);
}

// The frame rules are one ordered table (docs/safety-chain.md, "Frame
// rules"): the first that applies is the finding.
// sim.yaml's fields (docs/safety-chain.md, "Protective fields"): T_r =
// (1 + 3) / 30 Hz + 60 ms, S at rest = 1.6 (T_r + 0.15) + 0.03 + 0.2.
TEST(ProtectiveField, SizedFromTheConfigAndTheArmsSpeed) {
  const risk::RiskSettings& settings = sim_config().risk;
  const double response_s = risk::chain_response_time_s(settings, 30.0);
  EXPECT_NEAR(response_s, 4.0 / 30 + 0.06, 1e-12);
  const risk::FieldSize at_rest = risk::field_size(settings, response_s, 0);
  EXPECT_NEAR(at_rest.protective_m, 1.6 * (response_s + 0.15) + 0.03 + 0.2, 1e-12);
  EXPECT_NEAR(at_rest.protective_m, 0.779, 1e-3);
  EXPECT_NEAR(at_rest.warning_m, at_rest.protective_m + 0.3, 1e-12);
  // Each m/s of arm speed adds T_r.
  EXPECT_NEAR(risk::field_size(settings, response_s, 1.0).protective_m - at_rest.protective_m, response_s,
              1e-12);
  // At 25 Hz the response is longer, and so is S.
  EXPECT_GT(risk::field_size(settings, risk::chain_response_time_s(settings, 25.0), 0).protective_m,
            at_rest.protective_m);
}

TEST(ProtectiveField, ArmSpeedBoundFromTheJointsReachAndTheirSpeeds) {
  discrepancy_t d{};
  d.field_available = true;
  d.num_joints = 2;
  d.joint_name = {"a1", "a2"};
  d.joint_reach_m = {0.8, 0.5};
  joint_state_t state{};
  state.name = {"a2", "a1"};
  state.position = {0, 0};
  state.velocity = {-0.4, 0.5};
  std::string why;
  EXPECT_NEAR(risk::arm_speed_bound_m_s(d, &state, &why), 0.5 * 0.8 + 0.4 * 0.5, 1e-12);
  // Anything that keeps the speed from being bounded: +infinity, and why.
  EXPECT_TRUE(std::isinf(risk::arm_speed_bound_m_s(d, nullptr, &why)));
  EXPECT_NE(why.find("no joint state"), std::string::npos) << why;
  joint_state_t without_speeds = state;
  without_speeds.velocity.clear();
  EXPECT_TRUE(std::isinf(risk::arm_speed_bound_m_s(d, &without_speeds, &why)));
  EXPECT_NE(why.find("joint 'a1' has no speed"), std::string::npos) << why;
  discrepancy_t no_cover = d;
  no_cover.field_available = false;
  EXPECT_TRUE(std::isinf(risk::arm_speed_bound_m_s(no_cover, &state, &why)));
  discrepancy_t no_kinematics = d;
  no_kinematics.num_joints = 0;
  no_kinematics.joint_name.clear();
  no_kinematics.joint_reach_m.clear();
  EXPECT_TRUE(std::isinf(risk::arm_speed_bound_m_s(no_kinematics, &state, &why)));
  // A field never sized protects everything.
  const risk::FieldSize unsized;
  EXPECT_TRUE(std::isinf(unsized.protective_m));
}

TEST(ProtectiveField, Iso13855IntrusionDistance) {
  EXPECT_DOUBLE_EQ(risk::iso13855_intrusion_distance_m(0.014), 0);
  EXPECT_NEAR(risk::iso13855_intrusion_distance_m(0.030), 0.128, 1e-12);
  EXPECT_NEAR(risk::iso13855_intrusion_distance_m(std::sqrt(0.0015)), 0.1978, 1e-4);  // sim.yaml's d
  EXPECT_DOUBLE_EQ(risk::iso13855_intrusion_distance_m(0.041), 0.85);
}

TEST(ProtectiveField, ObjectDistanceIsWhereTheAreaReachesTheMinimum) {
  discrepancy_t d = summary_of(default_arm());
  EXPECT_FALSE(risk::object_distance_m(d, 0.0015).has_value());
  place_unexplained_surface(&d, 0.30, 0.001);
  EXPECT_FALSE(risk::object_distance_m(d, 0.0015).has_value()) << "too small alone";
  place_unexplained_surface(&d, 0.42, 0.001);
  ASSERT_TRUE(risk::object_distance_m(d, 0.0015).has_value());
  EXPECT_NEAR(*risk::object_distance_m(d, 0.0015), 0.42, 1e-6);
  EXPECT_NEAR(risk::field_range_m(d), 2.0, 1e-6);
}

TEST(FrameClassifier, RulesAreEvaluatedInTheDocumentedOrder) {
  std::vector<std::string> names;
  for (const risk::FrameRule& rule : risk::frame_rules()) names.push_back(rule.name);
  EXPECT_EQ(names,
            (std::vector<std::string>{
                "unusable frame", "invalid pixels", "uncalibrated camera", "frozen image",
                "calibration error", "cameras disagree", "joint error: links missing",
                "joint error: links beside unexplained surfaces", "unknown object", "unexplained blob"}));
  // An object near the arm that also makes a large blob is an unknown
  // object, not unclassified: the earlier rule wins.
  discrepancy_t d = summary_of(default_arm());
  d.largest_blob_area_m2 = 0.5f;
  place_unexplained_surface(&d, 0.1, 0.002);
  EXPECT_EQ(classify(d).cause, risk_t::CAUSE_UNKNOWN_OBJECT);
  d = summary_of(default_arm());
  d.largest_blob_area_m2 = 0.5f;
  place_unexplained_surface(&d, 0.1, 0.001);  // below risk.unknown_object_min_area_m2 = 0.0015
  EXPECT_EQ(classify(d).cause, risk_t::CAUSE_UNCLASSIFIED);
}

// Several cameras: most of this frame's shared static points off the other
// camera's surfaces (discrepancy_t.registration_*) is a calibration error;
// too few points, or a minority off, says nothing.
TEST(FrameClassifier, CamerasThatDisagreeWhereTheirViewsOverlapAreACalibrationError) {
  discrepancy_t d = summary_of(default_arm());
  d.registration_points = 400;
  d.registration_median_mm = 3;
  d.registration_mismatch_fraction = 0.1f;
  EXPECT_EQ(classify(d).cause, risk_t::CAUSE_NONE);
  d.registration_median_mm = -52;
  d.registration_mismatch_fraction = 0.8f;
  const risk::FrameFinding f = classify(d);
  EXPECT_EQ(f.cause, risk_t::CAUSE_CALIBRATION_ERROR);
  EXPECT_EQ(f.suspect, "TOF_DEPTH");
  EXPECT_NE(f.detail.find("the cameras disagree where their views overlap"), std::string::npos) << f.detail;
  EXPECT_NE(f.detail.find("80 % of 400 points"), std::string::npos) << f.detail;
  d.registration_points = 99;
  EXPECT_EQ(classify(d).cause, risk_t::CAUSE_NONE) << "too few points to say";
}

TEST(FrameClassifier, NoiseOnlyFramesAreSafe) {
  for (uint32_t seed = 1; seed <= 10; ++seed) {
    const FrameFinding f = classify(summary_of(default_arm(), 7, seed), /*arm_moving=*/true);
    EXPECT_EQ(f.cause, risk_t::CAUSE_NONE) << f.detail;
  }
}

TEST(FrameClassifier, ShiftedLinkIsAJointErrorOfTheJointAboveIt) {
  // link2 (40 x 20 px) seen 16 px off. Its silhouette pixels do not count
  // (top and bottom rows and its right column border the floor; its left
  // column borders link1 at the same depth): missing on 16 x 18 of 39 x 18
  // counted pixels. a2 moves it.
  const FrameFinding f = classify(summary_of(default_arm(16)));
  EXPECT_EQ(f.cause, risk_t::CAUSE_JOINT_ERROR) << f.detail;
  EXPECT_EQ(f.suspect, "a2");
  EXPECT_NEAR(f.score, 16.0 / 39.0, 1e-9);
  EXPECT_DOUBLE_EQ(f.threshold, sim_config().risk.joint_link_missing_fraction);
  EXPECT_NE(f.detail.find("link2"), std::string::npos) << f.detail;
}

TEST(FrameClassifier, MismatchOnSeveralLinksBlamesTheJointAboveAllOfThem) {
  // link1 and link2 both displaced: their common ancestor link1 hangs on a1.
  std::vector<Box> scene = {
      {40, 100, 60, 140, kArmMm, 1}, {50, 60, 70, 100, kArmMm, 2}, {76, 60, 116, 80, kArmMm, 3}};
  const FrameFinding f = classify(summary_of(scene));
  EXPECT_EQ(f.cause, risk_t::CAUSE_JOINT_ERROR) << f.detail;
  EXPECT_EQ(f.suspect, "a1");
}

// Nothing in the joint rules is tuned to the default arm: the same
// summaries, their links renamed to three consecutive links of the iiwa14
// and the Kinova Gen3 (../shared/robots), blame those arms' own joints.
TEST(FrameClassifier, JointErrorsOnTheIiwa14AndTheKinovaGen3BlameTheirOwnJoints) {
  if (shared_dir().empty())
    GTEST_SKIP() << "../shared is absent: the iiwa14 and Kinova Gen3 models are not available";
  struct Arm {
    std::string urdf;
    std::vector<std::string> links;  // replaces base_link, link1, link2
    std::string joint_above_link2;   // the one-link shift's suspect
    std::string joint_above_both;    // the two-link shift's suspect
  };
  const std::string robots = shared_dir() + "/robots";
  const std::vector<Arm> arms = {
      {robots + "/iiwa14/urdf/iiwa14_no_collision.urdf",
       {"iiwa_link_0", "iiwa_link_1", "iiwa_link_2"},
       "iiwa_joint_2",
       "iiwa_joint_1"},
      {robots + "/iiwa14/urdf/iiwa14_no_collision.urdf",
       {"iiwa_link_4", "iiwa_link_5", "iiwa_link_6"},
       "iiwa_joint_6",
       "iiwa_joint_5"},
      {robots +
           "/kinova_gen3/kortex_description/arms/gen3/7dof/urdf/GEN3-7DOF-NOVISION_FOR_URDF_ARM_V12.urdf",
       {"base_link", "shoulder_link", "half_arm_1_link"},
       "joint_2",
       "joint_1"},
      {robots +
           "/kinova_gen3/kortex_description/arms/gen3/7dof/urdf/GEN3-7DOF-NOVISION_FOR_URDF_ARM_V12.urdf",
       {"forearm_link", "spherical_wrist_1_link", "spherical_wrist_2_link"},
       "joint_6",
       "joint_5"},
  };
  const std::vector<Box> both_shifted = {
      {40, 100, 60, 140, kArmMm, 1}, {50, 60, 70, 100, kArmMm, 2}, {76, 60, 116, 80, kArmMm, 3}};
  for (const Arm& arm : arms) {
    SCOPED_TRACE(arm.links[0]);
    const robot_model::KinematicTree tree = robot_model::load_kinematic_tree(arm.urdf);
    auto renamed = [&](discrepancy_t d) {
      for (size_t i = 0; i < arm.links.size(); ++i) d.link_name[i] = arm.links[i];
      return d;
    };
    const FrameFinding one =
        classify_frame(renamed(summary_of(default_arm(16))), tree, sim_config().risk, {});
    EXPECT_EQ(one.cause, risk_t::CAUSE_JOINT_ERROR) << one.detail;
    EXPECT_EQ(one.suspect, arm.joint_above_link2) << one.detail;
    const FrameFinding two = classify_frame(renamed(summary_of(both_shifted)), tree, sim_config().risk, {});
    EXPECT_EQ(two.cause, risk_t::CAUSE_JOINT_ERROR) << two.detail;
    EXPECT_EQ(two.suspect, arm.joint_above_both) << two.detail;
  }
}

TEST(FrameClassifier, WholeArmShiftedWithTheFixedBaseIsACalibrationError) {
  // The camera a few centimetres off: the near arm (base_link included,
  // which no joint can move) shifts 8 px, the distant floor stays within
  // tolerance.
  std::vector<Box> scene = default_arm();
  for (Box& b : scene) {
    b.u0 += 8;
    b.u1 += 8;
  }
  const FrameFinding f = classify(summary_of(scene));
  EXPECT_EQ(f.cause, risk_t::CAUSE_CALIBRATION_ERROR) << f.detail;
  EXPECT_NE(f.detail.find("the fixed base_link among them"), std::string::npos) << f.detail;
}

TEST(FrameClassifier, LinkSeenNearerWithSurfacesBesideItIsAJointErrorNotAnObject) {
  // link2 moved towards the camera (1.3 m instead of 1.5 m): it is seen
  // nearer, never missing, and its end shows up beside the model.
  std::vector<Box> scene = default_arm();
  scene[2].depth_mm = 1300;
  scene.push_back({100, 60, 110, 80, 1300, 0});
  const discrepancy_t d = summary_of(scene);
  ASSERT_GE(d.near_arm_area_m2, sim_config().risk.unknown_object_min_area_m2);
  const FrameFinding f = classify(d);
  EXPECT_EQ(f.cause, risk_t::CAUSE_JOINT_ERROR) << f.detail;
  EXPECT_EQ(f.suspect, "a2");
  EXPECT_NE(f.detail.find("link2 mismatch"), std::string::npos) << f.detail;
}

TEST(FrameClassifier, ObjectInFrontOfTheArmIsAnUnknownObject) {
  std::vector<Box> scene = default_arm();
  scene.push_back({30, 110, 50, 130, 1400, 0});  // 0.1 m in front of base_link
  const discrepancy_t d = summary_of(scene);
  // 20 x 20 px at 1.4 m, less the two columns beside base_link's modelled
  // outline (u = 39, 40: silhouette pixels).
  EXPECT_NEAR(d.near_arm_area_m2, (400 - 2 * 20) * (1.4 / 200) * (1.4 / 200), 1e-4);
  const FrameFinding f = classify(d);
  EXPECT_EQ(f.cause, risk_t::CAUSE_UNKNOWN_OBJECT) << f.detail;
  EXPECT_FALSE(f.warning_only);
  // The half in front of base_link hides it: at the arm (the first 1 cm
  // bin), inside S.
  EXPECT_NEAR(f.score, 0.01, 1e-6);
  EXPECT_DOUBLE_EQ(f.threshold, 0.3);
  EXPECT_NE(f.detail.find("unknown object 1 cm from the arm, inside the protective field"), std::string::npos)
      << f.detail;
}

TEST(FrameClassifier, SmallObjectFarFromTheArmIsSafe) {
  std::vector<Box> scene = default_arm();
  scene.push_back({140, 10, 150, 20, 1900, 0});  // 10x10 px, 0.65 m away
  EXPECT_EQ(classify(summary_of(scene)).cause, risk_t::CAUSE_NONE);
}

// Protective and warning fields: S 0.3 m, warning to 0.5 m (test_field).
TEST(FrameClassifier, ALargeSurfaceBeyondTheProtectiveFieldWarnsAndBeyondTheWarningFieldIsSafe) {
  std::vector<Box> scene = default_arm();
  scene.push_back({110, 0, 176, 50, 1900, 0});  // 66x50 px at 1.9 m: 0.30 m^2, 0.45 m from the arm
  const discrepancy_t d = summary_of(scene);
  const FrameFinding f = classify(d);
  EXPECT_EQ(f.cause, risk_t::CAUSE_UNKNOWN_OBJECT) << f.detail;
  EXPECT_TRUE(f.warning_only);
  EXPECT_NEAR(f.score, 0.45, 0.02);
  EXPECT_NE(f.detail.find("in the warning field"), std::string::npos) << f.detail;
  risk::FieldSize small = test_field();
  small.warning_m = 0.4;
  EXPECT_EQ(classify(d, false, small).cause, risk_t::CAUSE_NONE);
  // Whatever its size: the same surface within S stops.
  risk::FieldSize large = test_field();
  large.protective_m = 0.5;
  large.warning_m = 0.7;
  const FrameFinding stop = classify(d, false, large);
  EXPECT_EQ(stop.cause, risk_t::CAUSE_UNKNOWN_OBJECT);
  EXPECT_FALSE(stop.warning_only);
}

TEST(FrameClassifier, ArmSpeedThatCannotBeBoundedPutsEveryObjectInsideTheField) {
  std::vector<Box> scene = default_arm();
  scene.push_back({140, 10, 150, 20, 1900, 0});  // 10x10 px, 0.65 m away
  risk::FieldSize unbounded;                     // as a frame without a joint state or reach leaves it
  const FrameFinding f = classify(summary_of(scene), false, unbounded);
  EXPECT_EQ(f.cause, risk_t::CAUSE_UNKNOWN_OBJECT) << f.detail;
  EXPECT_FALSE(f.warning_only);
}

TEST(FrameClassifier, ProtectiveFieldBeyondTheMeasuredRangeStops) {
  risk::FieldSize beyond = test_field();
  beyond.protective_m = 2.5;  // sim.yaml's discrepancy.field.range_m: 2 m
  beyond.warning_m = 2.8;
  const FrameFinding f = classify(summary_of(default_arm()), false, beyond);
  EXPECT_EQ(f.cause, risk_t::CAUSE_UNCLASSIFIED) << f.detail;
  EXPECT_EQ(f.suspect, "discrepancy.field.range_m");
}

TEST(FrameClassifier, LargeFartherMismatchIsUnclassified) {
  // The model has a 66x50 px environment surface at 1.9 m that the camera
  // sees 0.1 m farther (the floor): a blob of farther mismatch, 0.30 m^2.
  std::vector<Box> modelled = default_arm();
  modelled.push_back({110, 0, 176, 50, 1900, link_labels_t::ENVIRONMENT_FIRST});
  const SyntheticImage model = draw(modelled);
  const SyntheticImage seen = draw(default_arm());
  link_labels_t labels = labels_frame(model.label, 7);
  add_pixel_cover(&labels, model.depth_mm);
  const discrepancy_t d = discrepancy::compute_discrepancy(
                              depth_frame(with_noise(seen.depth_mm, 1), 7), depth_frame(model.depth_mm, 7),
                              labels, discrepancy::discrepancy_options(sim_config().discrepancy))
                              .summary;
  const FrameFinding f = classify(d);
  EXPECT_EQ(f.cause, risk_t::CAUSE_UNCLASSIFIED) << f.detail;
  // Less its outline (silhouette pixels), at the camera's depth (2 m).
  EXPECT_NEAR(f.score, (66 - 1) * (50 - 1) * (2.0 / 200) * (2.0 / 200), 0.005);
}

TEST(FrameClassifier, ShiftOverArmAndEnvironmentIsACalibrationError) {
  // Everything seen 80 mm farther: the camera pose is off along its axis
  // (the tolerance at 2 m is 4 * 8.8 + 15 = 50 mm).
  std::vector<Box> scene = default_arm();
  for (Box& b : scene) b.depth_mm = static_cast<int16_t>(b.depth_mm + 80);
  const SyntheticImage model = draw(default_arm());
  SyntheticImage seen = draw(scene);
  for (int i = 0; i < kWidth * kHeight; ++i) {
    if (seen.label[i] == link_labels_t::ENVIRONMENT_FIRST) seen.depth_mm[i] = kFloorMm + 80;
  }
  const discrepancy_t d =
      discrepancy::compute_discrepancy(depth_frame(with_noise(seen.depth_mm, 2), 1),
                                       depth_frame(model.depth_mm, 1), labels_frame(model.label, 1),
                                       discrepancy::discrepancy_options(sim_config().discrepancy))
          .summary;
  const FrameFinding f = classify(d);
  EXPECT_EQ(f.cause, risk_t::CAUSE_CALIBRATION_ERROR) << f.detail;
  EXPECT_GT(f.score, 0.95);
  EXPECT_NEAR(d.environment_median_dis_mm, -80, 3);
  EXPECT_NEAR(d.robot_median_dis_mm, -80, 3);
}

TEST(FrameClassifier, SensorFaultsComeFirst) {
  discrepancy_t d = summary_of(default_arm());
  // Frozen: the same image again while the arm moves; not while it rests.
  d.repeat_count = 2;
  EXPECT_EQ(classify(d, /*arm_moving=*/true).cause, risk_t::CAUSE_SENSOR_FAULT);
  EXPECT_EQ(classify(d, true).suspect, "TOF_DEPTH");
  EXPECT_EQ(classify(d, false).cause, risk_t::CAUSE_NONE);
  d.repeat_count = 1;
  EXPECT_EQ(classify(d, true).cause, risk_t::CAUSE_NONE);

  d.calibrated = false;
  EXPECT_EQ(classify(d).cause, risk_t::CAUSE_SENSOR_FAULT);
  EXPECT_NE(classify(d).detail.find("calibrated"), std::string::npos);
  d.calibrated = true;

  d.invalid_fraction = 0.51f;
  FrameFinding f = classify(d);
  EXPECT_EQ(f.cause, risk_t::CAUSE_SENSOR_FAULT);
  EXPECT_FLOAT_EQ(static_cast<float>(f.score), 0.51f);
  EXPECT_DOUBLE_EQ(f.threshold, 0.5);
  d.invalid_fraction = 0;

  d.usable = false;
  d.unusable_kind = discrepancy_t::UNUSABLE_RENDERER;
  d.unusable_reason = "renderer: joint state too old";
  f = classify(d);
  EXPECT_EQ(f.cause, risk_t::CAUSE_SENSOR_FAULT);
  EXPECT_EQ(f.suspect, "TOF_LABELS");
  EXPECT_NE(f.detail.find("joint state too old"), std::string::npos);

  d.unusable_kind = discrepancy_t::UNUSABLE_NO_RENDERING;
  f = classify(d);
  EXPECT_EQ(f.cause, risk_t::CAUSE_COMPONENT_FAULT);
  EXPECT_EQ(f.suspect, "tofguard-renderer");

  // The arm where the camera's profile was not measured: the camera's.
  d.unusable_kind = discrepancy_t::UNUSABLE_OUTSIDE_PROFILE;
  d.unusable_reason = "camera needs recommissioning: the arm is 0.93-0.97 m from it";
  f = classify(d);
  EXPECT_EQ(f.cause, risk_t::CAUSE_SENSOR_FAULT);
  EXPECT_EQ(f.suspect, "TOF_DEPTH");
  EXPECT_EQ(f.detail, d.unusable_reason);
}

TEST(FrameClassifier, LinkUnknownToTheUrdfIsNeverJudgedSafe) {
  discrepancy_t d = summary_of(default_arm(16));
  d.link_name[2] = "elbow_of_another_robot";
  const FrameFinding f = classify(d);
  EXPECT_EQ(f.cause, risk_t::CAUSE_UNCLASSIFIED) << f.detail;
  EXPECT_EQ(f.suspect, "elbow_of_another_robot");
}

// ---- RiskMonitor: debouncing and deadlines on an explicit clock ----

constexpr int64_t kStart = 5'000'000'000;  // monotonic, unrelated to any utime
constexpr double kRateHz = 30;             // camera.rate_hz of config/sim.yaml
constexpr int64_t kMs = 1000;

heartbeat_t heartbeat(const std::string& process) {
  heartbeat_t hb{};
  hb.process = process;
  return hb;
}

joint_state_t joints(double velocity) {
  joint_state_t s{};
  s.num_joints = 1;
  s.name = {"a1"};
  s.position = {0};
  s.velocity = {velocity};
  return s;
}

// A joint state taken at `utime` (each new: a repeated one is refused).
joint_state_t joints_at_time(double velocity, int64_t utime) {
  joint_state_t s = joints(velocity);
  s.utime = utime;
  return s;
}

// Everything fresh at `now`.
void feed_all(RiskMonitor* m, int64_t now) {
  m->on_depth(now);
  // A new joint state each time (a repeated one is refused as a duplicate).
  joint_state_t state = joints(0.5);
  state.utime = now;
  m->on_joint_state(state, now);
  for (const char* p : {"tofguard-camera", "tofguard-renderer", "tofguard-discrepancy"}) {
    m->on_heartbeat(heartbeat(p), now);
  }
}

// The verdict on one frame through the production path (on_frame, which
// releases it at once: sim.yaml does not wait for estimates, and a frame
// without a model mismatch never waits).
// A frame offered again is renumbered as the camera's next frame (seq and
// utime one more than the last judged): the monitor refuses a repeated or
// older frame (RiskMonitor::on_frame).
risk_t judged_at_once(RiskMonitor* m, discrepancy_t frame, int64_t now) {
  static std::map<const RiskMonitor*, std::pair<int64_t, int64_t>> last;  // seq, utime
  if (last.count(m) && frame.seq <= last[m].first) {
    frame.seq = last[m].first + 1;
    frame.utime = std::max(frame.utime, last[m].second + 1);
  }
  last[m] = {frame.seq, frame.utime};
  const std::vector<risk_t> verdicts = m->on_frame(frame, now);
  EXPECT_EQ(verdicts.size(), 1u) << "frame " << frame.seq << " should be judged on arrival";
  return verdicts.empty() ? risk_t{} : verdicts.front();
}

// The verdicts on three frames 33 ms apart made from `d` (seq 40, 41, 42)
// by a monitor with the occupant of `with_user`, each judged at once;
// `before(frame, now)` runs before each is judged (e.g. a joint state).
std::vector<risk_t> three_frames_with_user(
    const deployment::Config& with_user, const discrepancy_t& d,
    const std::function<void(RiskMonitor*, const discrepancy_t&, int64_t)>& before = nullptr) {
  RiskMonitor m(with_user.risk, with_user.channels, friend_arm(), kRateHz, kStart);
  m.set_occupant(*with_user.occupant);
  std::vector<risk_t> verdicts;
  for (int i = 0; i < 3; ++i) {
    const int64_t now = kStart + i * 33 * kMs;
    feed_all(&m, now);
    discrepancy_t frame = d;
    frame.seq = 40 + i;
    frame.utime = d.utime + i * 33'000;
    if (before) before(&m, frame, now);
    verdicts.push_back(judged_at_once(&m, frame, now));
  }
  return verdicts;
}

// The user's body regions (docs/safety-chain.md, "The user"): a frame
// whose arm is faster than the face's limit is an unknown-object finding
// naming the face, stopped after the debounce; slower, the limit is the
// face's and the frame is safe.
TEST(RiskMonitor, TheArmFasterThanTheUsersFaceAllowsIsStoppedAfterTheDebounce) {
  const deployment::Config with_user =
      deployment::load_config(sim_config_variant("risk-logic-occupant", {}, occupant_section()), nullptr);
  ASSERT_TRUE(with_user.occupant.has_value());
  discrepancy_t d = summary_of(default_arm(), 40);
  ASSERT_TRUE(d.usable);
  ASSERT_TRUE(d.field_available);
  // One joint, a1, reaching 0.35 m (the synthetic frame carries no
  // kinematics of its own).
  ASSERT_EQ(d.num_joints, 0);
  d.num_joints = 1;
  d.joint_name = {"a1"};
  for (auto* per_joint :
       {&d.joint_score, &d.joint_information, &d.joint_naming_score, &d.joint_naming_information,
        &d.joint_static_bound, &d.joint_search_offset, &d.joint_search_gain}) {
    per_joint->assign(1, 0.0);
  }
  d.joint_fit_pixels.assign(1, 0);
  d.joint_reach_m.assign(1, 0.35);
  d.num_body_regions = kNumBodyRegions;
  d.body_region.clear();
  d.body_region_separation_m.clear();
  for (const BodyRegion region : all_body_regions()) {
    d.body_region.push_back(body_region_name(region));
    // The face 20 cm away (15 cm beyond its 5 cm envelope); the rest 1 m.
    d.body_region_separation_m.push_back(region == BodyRegion::kFace ? 0.20f : 1.0f);
  }
  // The user seen where modelled.
  d.body_region_modelled_pixels.assign(kNumBodyRegions, 100);
  d.body_region_missing_pixels.assign(kNumBodyRegions, 0);
  d.body_region_seen_pixels.assign(kNumBodyRegions, 100);
  d.body_region_seen_separation_m.assign(kNumBodyRegions, -1.0f);
  // a1 at `speed` rad/s: the arm's bound is 0.35 m * speed.
  auto state_at = [&](double speed, int64_t utime) {
    joint_state_t s{};
    s.utime = utime;
    s.num_joints = d.num_joints;
    s.name = d.joint_name;
    s.position.assign(d.num_joints, 0.0);
    s.velocity.assign(d.num_joints, speed);
    return s;
  };
  const double response_s = risk::chain_response_time_s(with_user.risk, kRateHz);
  // (0.20 - 0.05 envelope - 0.03 clearance - sin 3 deg * 0.35 m) / (T_r + 0.15 s) = 0.296 m/s.
  const double face_limit = (0.15 - 0.03 - std::sin(3 * M_PI / 180) * 0.35) / (response_s + 0.15);
  EXPECT_NEAR(face_limit, 0.296, 0.001);

  // Below the limit, above it, and of no known speed (a1's speed not a
  // number: the arm's speed cannot be bounded).
  for (const double speed : {0.9 * face_limit, 1.1 * face_limit, std::nan("")}) {
    const double per_joint = speed / 0.35;
    const std::vector<risk_t> verdicts =
        three_frames_with_user(with_user, d, [&](RiskMonitor* m, const discrepancy_t& frame, int64_t now) {
          m->on_joint_state(state_at(per_joint, frame.utime), now);
          const speed_limit_t limit = m->speed_limit(frame);
          EXPECT_EQ(limit.set_by, speed_limit_t::SET_BY_BODY_REGION) << limit.reason;
          EXPECT_EQ(limit.body_region, "face");
          EXPECT_NEAR(limit.max_arm_speed_m_s, face_limit, 1e-3) << limit.reason;
          EXPECT_NEAR(limit.separation_m, 0.15, 1e-6);
        });
    if (std::isnan(speed)) {
      EXPECT_EQ(verdicts[2].level, risk_t::DANGEROUS) << verdicts[2].detail;
      EXPECT_EQ(verdicts[2].cause, risk_t::CAUSE_UNKNOWN_OBJECT);
      EXPECT_NE(verdicts[2].detail.find("arm speed not bounded, 15 cm from the user's face, limit 0.30 m/s"),
                std::string::npos)
          << verdicts[2].detail;
    } else if (speed < face_limit) {
      for (const risk_t& r : verdicts) EXPECT_EQ(r.level, risk_t::SAFE) << r.detail;
    } else {
      EXPECT_EQ(verdicts[0].level, risk_t::WARNING) << verdicts[0].detail;
      EXPECT_EQ(verdicts[2].level, risk_t::DANGEROUS) << verdicts[2].detail;
      EXPECT_EQ(verdicts[2].cause, risk_t::CAUSE_UNKNOWN_OBJECT);
      EXPECT_NE(verdicts[2].detail.find("arm at 0.33 m/s, 15 cm from the user's face, limit 0.30 m/s"),
                std::string::npos)
          << verdicts[2].detail;
    }
  }
}

// The user not where the model seats them: with more than 200 of the
// user's pixels seen, more than half of them farther than their envelope
// is an unclassified finding after the debounce; half or less, or too few
// pixels to say, is none.
TEST(RiskMonitor, AnEmptyChairIsSaidAndStopsTheArm) {
  const deployment::Config with_user =
      deployment::load_config(sim_config_variant("risk-logic-presence", {}, occupant_section()), nullptr);
  discrepancy_t d = summary_of(default_arm(), 40);
  d.num_body_regions = kNumBodyRegions;
  d.body_region.clear();
  for (const BodyRegion region : all_body_regions()) d.body_region.push_back(body_region_name(region));
  d.body_region_separation_m.assign(kNumBodyRegions, 1.0f);
  d.body_region_seen_pixels.assign(kNumBodyRegions, 0);
  d.body_region_seen_separation_m.assign(kNumBodyRegions, -1.0f);
  struct Case {
    int modelled_per_region;
    int missing_per_region;
    bool stopped;
  };
  // 12 regions: 240 pixels of which 11/20 missing; 10/20 missing; 132
  // pixels, all missing (too few to say).
  for (const Case c : {Case{20, 11, true}, Case{20, 10, false}, Case{11, 11, false}}) {
    d.body_region_modelled_pixels.assign(kNumBodyRegions, c.modelled_per_region);
    d.body_region_missing_pixels.assign(kNumBodyRegions, c.missing_per_region);
    const std::vector<risk_t> verdicts = three_frames_with_user(with_user, d);
    const std::string what =
        std::to_string(c.missing_per_region) + " of " + std::to_string(c.modelled_per_region);
    if (!c.stopped) {
      for (const risk_t& r : verdicts)
        EXPECT_NE(r.cause, risk_t::CAUSE_UNCLASSIFIED) << what << ": " << r.detail;
      continue;
    }
    EXPECT_EQ(verdicts[0].level, risk_t::WARNING) << what;
    EXPECT_EQ(verdicts[2].level, risk_t::DANGEROUS) << what;
    EXPECT_EQ(verdicts[2].cause, risk_t::CAUSE_UNCLASSIFIED);
    EXPECT_NE(verdicts[2].detail.find(
                  "the user is not where the occupant model seats them (missing fraction): 55 % "
                  "of the 240 modelled user pixels"),
              std::string::npos)
        << verdicts[2].detail;
    EXPECT_NE(verdicts[2].detail.find("mostly missing: skull_and_forehead, face,"), std::string::npos)
        << verdicts[2].detail;
  }
}

// Rules for a region the frame does not carry (a renderer without the
// occupant): nothing to size the limit on, 0 m/s.
TEST(RiskMonitor, AFrameWithoutTheUsersRegionsLimitsTheArmToStand) {
  const deployment::Config with_user = deployment::load_config(
      sim_config_variant("risk-logic-occupant-missing", {}, occupant_section()), nullptr);
  RiskMonitor m(with_user.risk, with_user.channels, friend_arm(), kRateHz, kStart);
  m.set_occupant(*with_user.occupant);
  const speed_limit_t limit = m.speed_limit(summary_of(default_arm(), 40));
  EXPECT_EQ(limit.set_by, speed_limit_t::SET_BY_NO_JUDGEMENT);
  EXPECT_DOUBLE_EQ(limit.max_arm_speed_m_s, 0);
  EXPECT_NE(limit.reason.find("no separation from the user's"), std::string::npos) << limit.reason;
}

TEST(RiskMonitor, NothingArrivedIsStaleAfterTheFirstDeadline) {
  RiskMonitor m(config_depth_100ms().risk, config_depth_100ms().channels, friend_arm(), kRateHz, kStart);
  EXPECT_FALSE(m.check_deadlines(kStart + 100 * kMs).has_value());
  const auto r = m.check_deadlines(kStart + 101 * kMs);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->seq, -1);
  EXPECT_EQ(r->utime, 0);
  EXPECT_EQ(r->level, risk_t::DANGEROUS);
  EXPECT_EQ(r->cause, risk_t::CAUSE_SENSOR_FAULT);
  EXPECT_EQ(r->suspect, "TOF_DEPTH");
  EXPECT_DOUBLE_EQ(r->score, 101);
  EXPECT_DOUBLE_EQ(r->threshold, 100);
  EXPECT_NE(r->detail.find("nothing since start"), std::string::npos) << r->detail;
}

TEST(RiskMonitor, EachInputHasItsOwnDeadlineAndCause) {
  RiskMonitor m(config_depth_100ms().risk, config_depth_100ms().channels, friend_arm(), kRateHz, kStart);
  int64_t now = kStart;
  feed_all(&m, now);
  discrepancy_t d = summary_of(default_arm(), 40);
  EXPECT_EQ(judged_at_once(&m, d, now).level, risk_t::SAFE);
  EXPECT_FALSE(m.check_deadlines(now + 100 * kMs).has_value());

  // Camera stalls: TOF_DEPTH 100 ms.
  now += 90 * kMs;
  feed_all(&m, now);
  judged_at_once(&m, d, now);
  now += 101 * kMs;
  m.on_joint_state(joints_at_time(0.5, now), now);
  for (const char* p : {"tofguard-camera", "tofguard-renderer", "tofguard-discrepancy"})
    m.on_heartbeat(heartbeat(p), now);
  auto r = m.check_deadlines(now);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->suspect, "TOF_DEPTH");
  EXPECT_GE(r->utime, d.utime);  // the last frame's utime, however old (d renumbered)

  // Joint state stalls: 100 ms.
  feed_all(&m, now);
  judged_at_once(&m, d, now);
  now += 101 * kMs;
  m.on_depth(now);
  for (const char* p : {"tofguard-camera", "tofguard-renderer", "tofguard-discrepancy"})
    m.on_heartbeat(heartbeat(p), now);
  judged_at_once(&m, d, now);
  r = m.check_deadlines(now);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->cause, risk_t::CAUSE_SENSOR_FAULT);
  EXPECT_EQ(r->suspect, "JOINT_STATE");
  // A frame judged meanwhile is dangerous too, with its own seq.
  const risk_t frame = judged_at_once(&m, d, now);
  EXPECT_EQ(frame.level, risk_t::DANGEROUS);
  EXPECT_GE(frame.seq, 40);  // d, renumbered as a new frame
  EXPECT_EQ(frame.suspect, "JOINT_STATE");

  // A heartbeat stops: 250 ms -> component fault naming the process.
  feed_all(&m, now);
  for (int i = 0; i < 6; ++i) {
    now += 50 * kMs;
    m.on_depth(now);
    m.on_joint_state(joints_at_time(0.5, now), now);
    judged_at_once(&m, d, now);
    m.on_heartbeat(heartbeat("tofguard-camera"), now);
    m.on_heartbeat(heartbeat("tofguard-discrepancy"), now);
  }
  r = m.check_deadlines(now);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->cause, risk_t::CAUSE_COMPONENT_FAULT);
  EXPECT_EQ(r->suspect, "tofguard-renderer");
  EXPECT_DOUBLE_EQ(r->score, 300);

  // The discrepancy stream stops while the camera is fresh: 200 ms.
  feed_all(&m, now);
  judged_at_once(&m, d, now);
  for (int i = 0; i < 5; ++i) {
    now += 50 * kMs;
    feed_all(&m, now);
  }
  r = m.check_deadlines(now);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->cause, risk_t::CAUSE_COMPONENT_FAULT);
  EXPECT_EQ(r->suspect, "SAFETY_DISCREPANCY");
}

TEST(RiskMonitor, CameraPoseIsWatchedOnlyWhenRequired) {
  deployment::Config config = sim_config();
  RiskMonitor optional(config.risk, config.channels, friend_arm(), kRateHz, kStart);
  feed_all(&optional, kStart + 2000 * kMs);
  judged_at_once(&optional, summary_of(default_arm()), kStart + 2000 * kMs);
  EXPECT_FALSE(optional.check_deadlines(kStart + 2000 * kMs).has_value());

  config.risk.camera_pose_required = true;
  RiskMonitor required(config.risk, config.channels, friend_arm(), kRateHz, kStart);
  feed_all(&required, kStart + 2000 * kMs);
  judged_at_once(&required, summary_of(default_arm()), kStart + 2000 * kMs);
  const auto r = required.check_deadlines(kStart + 2000 * kMs);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->suspect, "CAMERA_POSE");
  required.on_camera_pose(kStart + 2000 * kMs);
  EXPECT_FALSE(required.check_deadlines(kStart + 2000 * kMs).has_value());
}

TEST(RiskMonitor, MismatchIsWarningUntilDebouncedThenDangerousAndClearsAfterClearFramesGoodFrames) {
  RiskMonitor m(sim_config().risk, sim_config().channels, friend_arm(), kRateHz, kStart);
  const discrepancy_t bad = summary_of(default_arm(16), 100);
  const discrepancy_t good = summary_of(default_arm(), 104);
  int64_t now = kStart;
  std::vector<int8_t> levels;
  for (int i = 0; i < 4; ++i) {
    now += 33 * kMs;
    feed_all(&m, now);
    const risk_t r = judged_at_once(&m, bad, now);
    EXPECT_EQ(r.cause, risk_t::CAUSE_JOINT_ERROR);
    EXPECT_EQ(r.suspect, "a2");
    EXPECT_EQ(r.seq, 100 + i);  // the same image as consecutive frames
    EXPECT_GE(r.utime, bad.utime);
    levels.push_back(r.level);
  }
  // debounce_frames = 3.
  EXPECT_EQ(levels,
            (std::vector<int8_t>{risk_t::WARNING, risk_t::WARNING, risk_t::DANGEROUS, risk_t::DANGEROUS}));
  // The diagnosis stays open, its cause and suspect latched, until
  // risk.evidence.clear_frames (10) good frames in a row.
  for (int i = 1; i < sim_config().risk.evidence_clear_frames; ++i) {
    now += 33 * kMs;
    feed_all(&m, now);
    const risk_t r = judged_at_once(&m, good, now);
    EXPECT_EQ(r.level, risk_t::DANGEROUS);
    EXPECT_EQ(r.cause, risk_t::CAUSE_JOINT_ERROR);
    EXPECT_EQ(r.suspect, "a2");
    EXPECT_EQ(r.detail.rfind("diagnosis open since seq 102: joint a2", 0), 0u) << r.detail;
    EXPECT_NE(r.detail.find("this frame: no finding"), std::string::npos) << r.detail;
  }
  now += 33 * kMs;
  feed_all(&m, now);
  const risk_t r = judged_at_once(&m, good, now);
  EXPECT_EQ(r.level, risk_t::SAFE);
  EXPECT_EQ(r.cause, risk_t::CAUSE_NONE);
  now += 33 * kMs;
  feed_all(&m, now);
  EXPECT_EQ(judged_at_once(&m, bad, now).level, risk_t::WARNING);
}

TEST(RiskMonitor, SensorFaultsUseTheirOwnDebounce) {
  RiskMonitor m(sim_config().risk, sim_config().channels, friend_arm(), kRateHz, kStart);
  discrepancy_t unusable = summary_of(default_arm());
  unusable.usable = false;
  unusable.unusable_kind = discrepancy_t::UNUSABLE_RENDERER;
  unusable.unusable_reason = "renderer: joint a3 missing";
  feed_all(&m, kStart);
  EXPECT_EQ(judged_at_once(&m, unusable, kStart).level, risk_t::WARNING);
  EXPECT_EQ(judged_at_once(&m, unusable, kStart).level, risk_t::DANGEROUS);  // sensor_debounce_frames = 2
}

TEST(RiskMonitor, FrozenImageNeedsAMovingArm) {
  RiskMonitor m(sim_config().risk, sim_config().channels, friend_arm(), kRateHz, kStart);
  discrepancy_t frozen = summary_of(default_arm());
  frozen.repeat_count = 3;
  m.on_depth(kStart);
  m.on_joint_state(joints_at_time(0.0, 1), kStart);
  EXPECT_EQ(judged_at_once(&m, frozen, kStart).level, risk_t::SAFE);
  m.on_joint_state(joints_at_time(-0.3, 2), kStart);
  const risk_t r = judged_at_once(&m, frozen, kStart);
  EXPECT_EQ(r.cause, risk_t::CAUSE_SENSOR_FAULT);
  EXPECT_NE(r.detail.find("frozen"), std::string::npos);
}

// The frozen rule asks whether the arm moved when the frame was captured,
// not what the latest joint state says: a replay judges a frame the same
// however late it is processed.
TEST(RiskMonitor, FrozenImageIsJudgedByTheJointStateAtTheFramesCaptureTime) {
  constexpr int64_t kCapture = 1'700'000'000'000'000;
  auto joints_at = [](double velocity, int64_t utime) {
    joint_state_t s = joints(velocity);
    s.utime = utime;
    return s;
  };
  discrepancy_t frozen = summary_of(default_arm());
  frozen.repeat_count = 3;
  frozen.utime = kCapture;
  {
    RiskMonitor m(sim_config().risk, sim_config().channels, friend_arm(), kRateHz, kStart);
    m.on_depth(kStart);
    m.on_joint_state(joints_at(0.3, kCapture - 10 * kMs), kStart);
    m.on_joint_state(joints_at(0.0, kCapture + 50 * kMs), kStart);  // the arm halted after the capture
    EXPECT_EQ(judged_at_once(&m, frozen, kStart).cause, risk_t::CAUSE_SENSOR_FAULT);
  }
  {
    RiskMonitor m(sim_config().risk, sim_config().channels, friend_arm(), kRateHz, kStart);
    m.on_depth(kStart);
    m.on_joint_state(joints_at(0.0, kCapture - 10 * kMs), kStart);
    m.on_joint_state(joints_at(0.3, kCapture + 50 * kMs), kStart);  // it started after the capture
    EXPECT_EQ(judged_at_once(&m, frozen, kStart).level, risk_t::SAFE);
  }
}

TEST(RiskMonitor, JointNamesMustBeTheRobotsMovingJoints) {
  RiskMonitor m(sim_config().risk, sim_config().channels, friend_arm(), kRateHz, kStart);
  joint_state_t s = joints(0);
  EXPECT_EQ(m.check_joint_names(s), "");
  s.name = {"mount"};
  EXPECT_EQ(m.check_joint_names(s), "name[0]: expected a moving joint of the robot's URDF, got 'mount'");
}

}  // namespace
}  // namespace tofguard::test
