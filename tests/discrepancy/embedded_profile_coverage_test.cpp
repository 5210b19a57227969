// The embedded default's camera profile (config/sim.yaml's
// discrepancy.camera_profile, learned on a 12 s recording) covers the
// distances its arm reaches over the whole simulated motion, not only the
// recording's: compute_discrepancy refuses a frame whose arm lies beyond the
// profile's range (add_profile_coverage, kMaxShareOutsideProfile), so a gap
// would stop scripts/demo as "camera needs recommissioning" once the arm
// got there. The motion's joints have periods of 4-11 s; an hour of it at
// 0.5 s steps (7200 poses, each rendered as tofguard-renderer renders it
// from the configured camera pose) covers every joint's range many times.
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
#include "tool_support.hpp"

namespace tofguard {
namespace {

constexpr double kMotionS = 3600;
constexpr double kStepS = 0.5;

TEST(EmbeddedProfile, CoversTheDistancesTheArmReachesOverItsWholeMotion) {
  const deployment::Config config = deployment::load_config(test::source_dir() + "/config/sim.yaml", nullptr);
  ASSERT_TRUE(config.discrepancy.camera_profile) << "config/sim.yaml names no camera profile";
  const CameraProfile& profile = *config.discrepancy.camera_profile;
  test::SimulatedFrames frames(config);
  const Intrinsics& in = config.camera.intrinsics;
  const Eigen::Isometry3d world_from_optical = config.camera.pose.frame_from_optical();
  double worst_share = 0, worst_at_s = 0;
  double nearest_m = std::numeric_limits<double>::infinity(), farthest_m = 0;
  int64_t frames_with_arm = 0;
  for (double t_s = 0; t_s < kMotionS; t_s += kStepS) {
    robot_model::JointPositions q;
    for (const sim::JointMotion& m : config.joints_sim.motion) q[m.joint] = test::joint_position(m, t_s);
    const renderer::RenderResult result = frames.renderer().render_at(
        robot_model::forward_kinematics(frames.scene(), q), world_from_optical, in);
    ASSERT_TRUE(result.usable) << result.unusable_reason;
    const depth_image_t depth = make_depth_image(profile.camera_id, in, 1, 1, true, result.depth_m);
    const link_labels_t labels =
        renderer::make_rendered_link_labels(depth, result, frames.scene(), robot_model::ArmSpheres{});
    ProfileCoverage coverage;
    add_profile_coverage(profile, depth, labels, {}, &coverage);
    if (coverage.pixels == 0) continue;
    ++frames_with_arm;
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
  std::cout << "the arm over " << kMotionS << " s of motion: " << nearest_m << "-" << farthest_m
            << " m from the camera (radial); the profile " << profile.distance_first_m << "-"
            << profile.distance_first_m +
                   profile.distance_bin_m * static_cast<double>(profile.distance_correction_mm.size() - 1)
            << " m; the largest share outside it " << worst_share << " (at " << worst_at_s << " s)\n";
  EXPECT_EQ(frames_with_arm, static_cast<int64_t>(kMotionS / kStepS)) << "the camera sees the arm throughout";
  EXPECT_LE(worst_share, kMaxShareOutsideProfile) << "at " << worst_at_s << " s of the motion";
  EXPECT_GE(nearest_m, profile.distance_first_m - profile.distance_bin_m);
}

}  // namespace
}  // namespace tofguard
