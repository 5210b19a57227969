// The embedded default's camera profile (config/sim.yaml's
// discrepancy.camera_profile) and each camera's of the two-camera scene
// (config/sim-two-cameras.yaml) cover the distances their arm reaches over
// the whole simulated motion, not only their recordings': compute_discrepancy
// refuses a frame whose arm lies beyond the profile's range
// (add_profile_coverage, kMaxShareOutsideProfile), so a gap would stop
// scripts/demo as "camera needs recommissioning" once the arm got there. The
// motion's joints have periods of 4-11 s; an hour of it at 0.5 s steps
// (7200 poses, each rendered as tofguard-renderer renders it from the
// configured camera pose) covers every joint's range many times; the
// assistive task (joints_sim.task) is covered the same way.
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <limits>

#include "joint_motion.hpp"
#include "simulated_frames.hpp"
#include "tofguard/common/camera_profile.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/deployment/config.hpp"
#include "tofguard/renderer/rendered_kinematics.hpp"
#include "tofguard/robot_model/kinematic_tree.hpp"
#include "tofguard/sim/simulated_arm.hpp"
#include "tool_support.hpp"

namespace tofguard {
namespace {

constexpr double kMotionS = 3600;
constexpr double kStepS = 0.5;

// Where the arm lies against the profile's range over the poses added.
class CoverageScan {
 public:
  explicit CoverageScan(const deployment::Config& config)
      : config_(config), profile_(*config.discrepancy.camera_profile), frames_(config) {}

  // The arm at `q` as tofguard-renderer renders it from the configured pose.
  void add(const robot_model::JointPositions& q, double t_s) {
    const Intrinsics& in = config_.camera.intrinsics;
    const renderer::RenderResult result = frames_.renderer().render_at(
        robot_model::forward_kinematics(frames_.scene(), q), config_.camera.pose.frame_from_optical(), in);
    ASSERT_TRUE(result.usable) << result.unusable_reason;
    const depth_image_t depth = make_depth_image(profile_.camera_id, in, 1, 1, true, result.depth_m);
    const link_labels_t labels =
        renderer::make_rendered_link_labels(depth, result, frames_.scene(), robot_model::ArmSpheres{});
    ProfileCoverage coverage;
    add_profile_coverage(profile_, depth, labels, {}, &coverage);
    ++poses;
    if (coverage.pixels == 0) return;
    ++poses_with_arm;
    if (coverage.outside_share() > worst_share) {
      worst_share = coverage.outside_share();
      worst_at_s = t_s;
    }
    // The arm's nearest and farthest radial distance (its moving links).
    for (int v = 0; v < in.height; ++v) {
      for (int u = 0; u < in.width; ++u) {
        const size_t i = static_cast<size_t>(v) * in.width + u;
        if (!on_moving_link(labels, labels.label[i]) || depth.depth_mm[i] <= 0) continue;
        const double r_m = depth.depth_mm[i] * 1e-3 / z_per_radial(in.fx, in.fy, in.cx, in.cy, u, v);
        nearest_m = std::min(nearest_m, r_m);
        farthest_m = std::max(farthest_m, r_m);
      }
    }
  }

  void expect_covered(const std::string& what) const {
    std::cout << "the arm over " << what << ": " << nearest_m << "-" << farthest_m
              << " m from the camera (radial); the profile " << profile_.distance_first_m << "-"
              << profile_.distance_first_m +
                     profile_.distance_bin_m * static_cast<double>(profile_.distance_correction_mm.size() - 1)
              << " m; the largest share outside it " << worst_share << " (at " << worst_at_s << " s)\n";
    EXPECT_EQ(poses_with_arm, poses) << "the camera sees the arm throughout";
    EXPECT_LE(worst_share, kMaxShareOutsideProfile) << "at " << worst_at_s << " s of " << what;
    EXPECT_GE(nearest_m, profile_.distance_first_m - profile_.distance_bin_m);
  }

  int64_t poses = 0, poses_with_arm = 0;
  double worst_share = 0, worst_at_s = 0;
  double nearest_m = std::numeric_limits<double>::infinity(), farthest_m = 0;

 private:
  const deployment::Config& config_;
  const CameraProfile& profile_;
  test::SimulatedFrames frames_;
};

// config/sim.yaml's camera, then each camera of config/sim-two-cameras.yaml
// as its own processes see the config (deployment::select_camera).
std::vector<deployment::Config> embedded_cameras() {
  std::vector<deployment::Config> configs = {
      deployment::load_config(test::source_dir() + "/config/sim.yaml", nullptr)};
  const deployment::Config two =
      deployment::load_config(test::source_dir() + "/config/sim-two-cameras.yaml", nullptr);
  for (const deployment::CameraSection& camera : two.cameras) {
    configs.push_back(deployment::select_camera(two, camera.id));
  }
  for (const deployment::Config& config : configs) {
    EXPECT_TRUE(config.discrepancy.camera_profile)
        << config.file << ": " << config.camera.id << " has no profile";
  }
  return configs;
}

TEST(EmbeddedProfile, CoversTheDistancesTheArmReachesOverItsWholeMotion) {
  for (const deployment::Config& config : embedded_cameras()) {
    SCOPED_TRACE(config.file + ", camera " + config.camera.id);
    ASSERT_TRUE(config.discrepancy.camera_profile);
    CoverageScan scan(config);
    for (double t_s = 0; t_s < kMotionS; t_s += kStepS) {
      robot_model::JointPositions q;
      for (const sim::JointMotion& m : config.joints_sim.motion) q[m.joint] = test::joint_position(m, t_s);
      scan.add(q, t_s);
      if (HasFatalFailure()) return;
    }
    scan.expect_covered(std::to_string(kMotionS) + " s of the periodic motion, camera " + config.camera.id);
  }
}

// The assistive task (tofguard-joints-sim --task, scripts/demo) too: two
// cycles at 0.1 s steps of motion time.
TEST(EmbeddedProfile, CoversTheDistancesTheArmReachesOverItsTask) {
  for (const deployment::Config& config : embedded_cameras()) {
    SCOPED_TRACE(config.file + ", camera " + config.camera.id);
    ASSERT_TRUE(config.discrepancy.camera_profile);
    const std::vector<std::string> joints =
        robot_model::load_kinematic_tree(config.robot.urdf_path).actuated_joint_names;
    sim::SimulatedArm arm(config.joints_sim, joints, config.file, /*task=*/true);
    CoverageScan scan(config);
    constexpr double kTaskStepS = 0.1;
    for (double t_s = 0; t_s < 2 * arm.task_cycle_s(); t_s += kTaskStepS) {
      robot_model::JointPositions q;
      const sim::ArmState& state = arm.true_state();
      for (size_t i = 0; i < state.name.size(); ++i) q[state.name[i]] = state.position[i];
      scan.add(q, t_s);
      if (HasFatalFailure()) return;
      arm.step(kTaskStepS, true);
    }
    scan.expect_covered("two cycles of the task, camera " + config.camera.id);
  }
}

}  // namespace
}  // namespace tofguard
