// The state at a frame's utime: the histories' limits from the renderer's
// settings (renderer::state_history_settings), the
// joints and camera pose looked up together, messages of other robots
// ignored, and which of the two makes a frame unusable.
#include <gtest/gtest.h>

#include "tofguard/common/camera_pose_message.hpp"
#include "tofguard/deployment/config.hpp"
#include "tofguard/renderer/state_history_settings.hpp"
#include "tofguard/robot_state/state_history.hpp"
#include "tofguard/settings/renderer_settings.hpp"
#include "tool_support.hpp"

namespace tofguard::robot_state {
namespace {

constexpr int64_t kT0 = 1'700'000'000'000'000;

const deployment::Config& sim_config() {
  static const deployment::Config config =
      deployment::load_config(test::source_dir() + "/config/sim.yaml", nullptr);
  return config;
}

StateHistorySettings settings_of(const deployment::Config& config) {
  return renderer::state_history_settings(config.renderer, config.robot.id, config.camera);
}

joint_state_t joint_state(const std::string& robot_id, int64_t utime, double a1) {
  joint_state_t m;
  m.utime = utime;
  m.robot_id = robot_id;
  m.num_joints = 1;
  m.name = {"a1"};
  m.position = {a1};
  m.velocity = {0.0};
  return m;
}

// The durations were converted to microseconds once, when the file was read
// (YamlMap::milliseconds_as_us, tests/deployment); they are taken as they are.
TEST(StateHistorySettings, LimitsComeFromTheRendererSettingsInMicroseconds) {
  deployment::Config config = sim_config();
  config.renderer.max_extrapolation_us = 12'346;
  config.renderer.camera_pose_history_us = 2'000'000;
  config.renderer.camera_pose_max_extrapolation_us = 40'000;
  config.renderer.camera_pose_max_gap_us = 80'000;
  const StateHistorySettings s = settings_of(config);
  EXPECT_EQ(s.robot_id, config.robot.id);
  EXPECT_EQ(s.joint_max_extrapolation_us, 12'346);
  EXPECT_EQ(s.camera_pose_history_us, 2'000'000);
  EXPECT_EQ(s.camera_pose_max_extrapolation_us, 40'000);
  EXPECT_EQ(s.camera_pose_max_gap_us, 80'000);
  EXPECT_EQ(s.static_camera_id, config.camera.id);
  EXPECT_EQ(s.static_camera_pose.frame_id, config.camera.pose.frame_id);
}

TEST(StateHistory, JointsAndCameraPoseAtAFramesUtime) {
  const deployment::Config& config = sim_config();
  StateHistory history(settings_of(config));
  const std::string camera = config.camera.id;

  StateAtFrame state = history.at(camera, kT0);
  EXPECT_FALSE(state.usable());
  EXPECT_EQ(state.unusable_reason(), "no joint state received yet");
  EXPECT_TRUE(state.camera_pose.usable);  // the config's static pose

  EXPECT_FALSE(history.add_joint_state(joint_state("another_robot", kT0, 1.0)));
  ASSERT_TRUE(history.add_joint_state(joint_state(config.robot.id, kT0, 0.0)));
  ASSERT_TRUE(history.add_joint_state(joint_state(config.robot.id, kT0 + 20'000, 0.2)));
  EXPECT_FALSE(history.add_joint_state(joint_state(config.robot.id, kT0 + 20'000, 0.3)));  // not newer

  state = history.at(camera, kT0 + 10'000);
  ASSERT_TRUE(state.usable()) << state.unusable_reason();
  EXPECT_NEAR(state.joints.joints.at("a1"), 0.1, 1e-12);
  EXPECT_EQ(state.camera_pose.pose.frame_id, config.camera.pose.frame_id);

  // A CAMERA_POSE replaces the static pose.
  CameraPose moved = config.camera.pose;
  moved.translation_m.x() += 0.5;
  ASSERT_TRUE(history.add_camera_pose(to_camera_pose_message(camera, kT0, moved)));
  state = history.at(camera, kT0 + 10'000);
  ASSERT_TRUE(state.usable());
  EXPECT_DOUBLE_EQ(state.camera_pose.pose.translation_m.x(), moved.translation_m.x());

  // An unknown camera: the joints are usable, the pose is not, and the
  // reason is the pose's.
  state = history.at("other_camera", kT0 + 10'000);
  EXPECT_TRUE(state.joints.usable);
  EXPECT_FALSE(state.usable());
  EXPECT_EQ(state.unusable_reason(), state.camera_pose.unusable_reason);
  EXPECT_FALSE(state.unusable_reason().empty());
}

}  // namespace
}  // namespace tofguard::robot_state
