// tofguard-calibrate-extrinsics on a log made from the simulated camera
// (noise, mixed pixels, calibration) with a known pose while the arm moves
// through known poses: from a config pose 5 cm and 5 degrees wrong, the
// estimate comes back to the true pose. And its one-line errors.
#include "tofguard/estimator/extrinsics_calibration.hpp"

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "estimator_test_support.hpp"
#include "log_events.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/joint_state_t.hpp"

namespace tofguard::estimator {
namespace {

using test::deg;
using test::to_deg;

// A log of `poses` (one camera frame each, joint states 5 ms before and
// after it), frames from the simulated camera at the config's true pose.
std::string write_log(const std::string& name, const deployment::Config& config,
                      const std::vector<robot_model::JointPositions>& poses, bool with_depth) {
  const std::string dir = tofguard::test::output_dir() + "/estimator";
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/" + name;
  std::filesystem::remove(path);
  lcm::LogFile log(path, "w");
  tofguard::test::SimulatedFrames frames(config);
  const Eigen::Isometry3d camera = test::pose_of(config.camera.pose);
  const Intrinsics& in = config.camera.intrinsics;
  int64_t utime = 1700000000000000;
  for (size_t k = 0; k < poses.size(); ++k) {
    joint_state_t state;
    state.robot_id = config.robot.id;
    for (const auto& [joint, value] : poses[k]) {
      state.name.push_back(joint);
      state.position.push_back(value);
      state.velocity.push_back(0.0);
    }
    state.num_joints = static_cast<int32_t>(state.name.size());
    state.utime = utime - 5000;
    tofguard::test::write_log_event(&log, state.utime, config.channels.joint_state, state);
    if (with_depth) {
      const std::vector<float> depth_m = frames.capture(poses[k], camera, in, k + 1);
      const depth_image_t frame = make_depth_image(config.camera.id, config.camera.intrinsics, utime,
                                                   static_cast<int64_t>(k), true, depth_m);
      tofguard::test::write_log_event(&log, utime, config.channels.depth, frame);
    }
    state.utime = utime + 5000;
    tofguard::test::write_log_event(&log, state.utime, config.channels.joint_state, state);
    utime += 200000;
  }
  return path;
}

std::vector<robot_model::JointPositions> arm_poses() {
  std::vector<robot_model::JointPositions> poses;
  const robot_model::JointPositions a = test::reach_pose();
  const robot_model::JointPositions b = test::side_reach_pose();
  for (int k = 0; k < 8; ++k) {
    robot_model::JointPositions p;
    const double t = k / 7.0;
    for (const auto& [name, value] : a) p[name] = (1 - t) * value + t * b.at(name);
    p["a7"] += 0.3 * std::sin(k);
    poses.push_back(p);
  }
  return poses;
}

std::string yaml_list(const std::vector<double>& v) {
  std::ostringstream out;
  out << std::setprecision(10) << "[";
  for (size_t i = 0; i < v.size(); ++i) out << (i ? ", " : "") << v[i];
  out << "]";
  return out.str();
}

// Target (docs/estimator.md): within 5 mm and 0.3 degrees. Measured (2026-11-22, distance
// calibration along the rays): 3.4 mm and 0.07 degrees.
TEST(CalibrateExtrinsics, ConvergesFromFiveCentimetresAndFiveDegrees) {
  const deployment::Config truth_config = test::sim_config();
  const std::string log = write_log("calibration.lcm", truth_config, arm_poses(), true);

  // The config's pose 5 cm and 5 degrees off the truth.
  const Eigen::Isometry3d truth = test::pose_of(truth_config.camera.pose);
  Eigen::Isometry3d wrong = truth;
  wrong.translation() += Eigen::Vector3d(0.03, -0.03, 0.0283);  // 5.0 cm
  wrong.linear() =
      wrong.linear() * Eigen::AngleAxisd(deg(5), Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  const Eigen::Quaterniond q(wrong.linear());
  const std::string config_path = tofguard::test::sim_config_variant(
      "calibrate-extrinsics",
      {{"translation_m: [-0.90, -0.20, 1.80]",
        "translation_m: " +
            yaml_list({wrong.translation().x(), wrong.translation().y(), wrong.translation().z()})},
       {"rotation_wxyz: [0.302934347, -0.581931466, 0.669435574, -0.348486102]",
        "rotation_wxyz: " + yaml_list({q.w(), q.x(), q.y(), q.z()})}});
  const deployment::Config config = deployment::load_config(config_path, nullptr);

  const CalibrationResult result =
      calibrate_extrinsics(deployment::estimator_process_settings(config), log, CalibrationOptions());
  ASSERT_EQ(result.error, "");
  const Eigen::Isometry3d estimated = result.pose.frame_from_optical();
  const Eigen::Isometry3d error = truth.inverse() * estimated;
  const double error_mm = error.translation().norm() * 1000;
  const double error_deg = to_deg(Eigen::AngleAxisd(error.linear()).angle());
  std::cout << result.frames_used << " frames, " << result.iterations << " iterations, residual "
            << result.residual_before_mm << " -> " << result.residual_after_mm << " mm; error " << error_mm
            << " mm, " << error_deg << " deg\n";
  EXPECT_EQ(result.frames_used, 6);
  EXPECT_LT(error_mm, 5.0);
  EXPECT_LT(error_deg, 0.3);

  // The command line: the YAML block on stdout and in --out.
  const std::string out = tofguard::test::output_dir() + "/estimator/pose.yaml";
  std::string stdout_text, stderr_text;
  ASSERT_EQ(tofguard::test::run_command("calibrate-extrinsics",
                                        {tofguard::test::bin_dir() + "/tofguard-calibrate-extrinsics",
                                         "--config", config_path, log, "--out", out},
                                        &stdout_text, &stderr_text),
            0)
      << stderr_text;
  EXPECT_EQ(stdout_text, pose_yaml(result.pose));
  EXPECT_EQ(tofguard::test::read_file(out), stdout_text);
  EXPECT_NE(stdout_text.find("frame: world"), std::string::npos);
}

TEST(CalibrateExtrinsics, OneLineErrors) {
  const deployment::Config config = test::sim_config();
  const std::string config_path = tofguard::test::source_dir() + "/config/sim.yaml";
  const std::string bin = tofguard::test::bin_dir() + "/tofguard-calibrate-extrinsics";
  std::string err;
  // No depth frames in the log.
  const std::string joints_only = write_log("joints-only.lcm", config, arm_poses(), false);
  EXPECT_EQ(tofguard::test::run_command("calibrate-no-depth", {bin, "--config", config_path, joints_only},
                                        nullptr, &err),
            1);
  EXPECT_NE(err.find("no TOF_DEPTH frames of camera 'tof-mast'"), std::string::npos) << err;
  // All frames at one pose.
  const std::vector<robot_model::JointPositions> still(4, test::side_reach_pose());
  const std::string one_pose = write_log("one-pose.lcm", config, still, true);
  EXPECT_EQ(tofguard::test::run_command("calibrate-one-pose", {bin, "--config", config_path, one_pose},
                                        nullptr, &err),
            1);
  EXPECT_NE(err.find("too few frames with distinct arm poses (1"), std::string::npos) << err;
  // Not a log.
  EXPECT_EQ(tofguard::test::run_command("calibrate-missing",
                                        {bin, "--config", config_path, "/nonexistent.lcm"}, nullptr, &err),
            1);
  EXPECT_NE(err.find("/nonexistent.lcm: cannot open as an LCM log"), std::string::npos) << err;
}

}  // namespace
}  // namespace tofguard::estimator
