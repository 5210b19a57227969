#include "commissioned_camera.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <vector>

#include "joint_motion.hpp"
#include "simulated_frames.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/renderer/depth_renderer.hpp"
#include "tofguard/renderer/rendered_kinematics.hpp"
#include "tofguard/renderer/renderer_service.hpp"
#include "tofguard/robot_model/arm_spheres.hpp"
#include "tofguard/robot_model/scene_model.hpp"
#include "tofguard/sim/tof_error_model.hpp"
#include "tofguard/tune/recording_tuner.hpp"

namespace tofguard::test {
namespace {

// `seconds` of the arm's nominal motion from motion time `start_s`, every
// frame captured by the (imperfect) simulated camera with noise stream
// `noise_seed` and rendered as tofguard-renderer renders it.
std::vector<tune::RenderedPair> nominal_frames(const deployment::Config& config, double seconds,
                                               double start_s, uint64_t noise_seed) {
  SimulatedFrames truth(config);
  const robot_model::SceneModel model_scene =
      robot_model::load_scene(config.robot.urdf_path, config.environment.urdf_paths,
                              renderer::scene_options(config.renderer, config.robot));
  renderer::DepthRenderer model(model_scene, config.renderer.near_m, config.renderer.far_m);
  const robot_model::ArmSpheres arm_cover =
      robot_model::cover_arm_with_spheres(model_scene, config.renderer.arm_cover_cell_m);
  const Eigen::Isometry3d pose = config.camera.pose.frame_from_optical();
  const Intrinsics& in = config.camera.intrinsics;
  const int frames = static_cast<int>(std::floor(seconds * config.camera.rate_hz));
  std::vector<tune::RenderedPair> pairs;
  for (int k = 0; k < frames; ++k) {
    const double t_s = start_s + k / config.camera.rate_hz;
    robot_model::JointPositions q;
    for (const sim::JointMotion& m : config.joints_sim.motion) q[m.joint] = joint_position(m, t_s);
    const int64_t utime = 1'700'000'000'000'000 + static_cast<int64_t>(std::llround(t_s * 1e6));
    const depth_image_t camera = make_depth_image(config.camera.id, in, utime, k, /*calibrated=*/true,
                                                  truth.capture(q, pose, in, noise_seed * 100000 + k));
    const robot_model::LinkPoses poses = robot_model::forward_kinematics(model_scene, q);
    const renderer::RenderResult rendered = model.render_at(poses, pose, in);
    if (!rendered.usable) throw std::runtime_error(rendered.unusable_reason);
    tune::RenderedPair pair;
    pair.camera = camera;
    pair.rendered = make_depth_image(config.camera.id, in, utime, k, /*calibrated=*/true, rendered.depth_m);
    pair.labels = renderer::make_rendered_link_labels(camera, rendered, model_scene, arm_cover);
    pairs.push_back(std::move(pair));
  }
  return pairs;
}

// The motion time in [from_s, to_s), on a grid of kApproachStepS, at which
// the arm comes nearest the camera: the least radial distance of a rendered
// pixel of a link a joint moves. A user commissions on recordings that take
// the arm through its whole workspace (docs/camera.md); the nominal
// motion's sinusoids reach their nearest combination only now and then, so
// the recordings are centred there (the scene behind the arm, the far end
// of the range, is in every frame).
constexpr double kApproachStepS = 0.2;

double nearest_approach_s(const deployment::Config& config, double from_s, double to_s) {
  const robot_model::SceneModel model_scene =
      robot_model::load_scene(config.robot.urdf_path, config.environment.urdf_paths,
                              renderer::scene_options(config.renderer, config.robot));
  renderer::DepthRenderer model(model_scene, config.renderer.near_m, config.renderer.far_m);
  const Eigen::Isometry3d pose = config.camera.pose.frame_from_optical();
  const Intrinsics& in = config.camera.intrinsics;
  double nearest_m = std::numeric_limits<double>::infinity(), nearest_at_s = from_s;
  for (double t_s = from_s; t_s < to_s; t_s += kApproachStepS) {
    robot_model::JointPositions q;
    for (const sim::JointMotion& m : config.joints_sim.motion) q[m.joint] = joint_position(m, t_s);
    const renderer::RenderResult rendered =
        model.render_at(robot_model::forward_kinematics(model_scene, q), pose, in);
    if (!rendered.usable) throw std::runtime_error(rendered.unusable_reason);
    for (int v = 0; v < in.height; ++v) {
      for (int u = 0; u < in.width; ++u) {
        const size_t i = static_cast<size_t>(v) * in.width + u;
        const int link =
            link_of_label(rendered.labels[i], rendered.num_robot_links, rendered.num_robot_links);
        if (link < 0 || rendered.depth_m[i] <= 0) continue;
        const double r_m = rendered.depth_m[i] / z_per_radial(in.fx, in.fy, in.cx, in.cy, u, v);
        if (r_m < nearest_m) {
          nearest_m = r_m;
          nearest_at_s = t_s;
        }
      }
    }
  }
  return nearest_at_s;
}

tune::TuneSettings tune_settings(const deployment::Config& config) {
  tune::TuneSettings settings;
  settings.renderer = deployment::renderer_process_settings(config);
  settings.discrepancy = config.discrepancy;
  settings.risk = config.risk;
  return settings;
}

std::string fixed(double value, int decimals) {
  std::ostringstream s;
  s.precision(decimals);
  s << std::fixed << value;
  return s.str();
}

}  // namespace

CommissionedCamera commission_imperfect_camera(const CampaignArm& arm, uint64_t seed, double seconds) {
  CommissionedCamera out;
  out.arm = arm;
  out.arm.name = arm.name + " camera " + std::to_string(seed);
  deployment::Config& config = out.arm.config;
  const sim::SimResidualSettings truth = sim::draw_imperfect_camera(seed, config.camera.sim.amplitude_at_1m);
  config.camera.sim.residual = truth;
  // Learn the profile on one recording and check it on a second three
  // times as long (docs/camera.md: 40 s and 120 s; the allowance beside a
  // link's steps is the worst its poses show), each centred where the arm
  // comes nearest the camera within its own stretch of the motion
  // (600-1800 s, 1800-3000 s: beyond the 0-600 s the nominal runs take).
  const double check_seconds = kCheckRecordingLengths * seconds;
  const double learn_from_s = std::max(0.0, nearest_approach_s(config, 600, 1800) - seconds / 2);
  const double check_from_s = std::max(0.0, nearest_approach_s(config, 1800, 3000) - check_seconds / 2);
  tune::TuneOptions learn;
  learn.learn_profile = true;
  const tune::TuneResult learned = tune::tune_rendered_frames(
      tune_settings(config), nominal_frames(config, seconds, learn_from_s, 1000 + seed),
      out.arm.name + " learning", learn);
  if (!learned.usable) {
    out.error = learned.error;
    return out;
  }
  config.discrepancy.camera_profile = std::make_shared<const CameraProfile>(learned.profile_fit.profile);
  // ...and measure what is left with it on the second.
  const tune::TuneResult checked = tune::tune_rendered_frames(
      tune_settings(config), nominal_frames(config, check_seconds, check_from_s, 2000 + seed),
      out.arm.name + " checking");
  if (!checked.usable) {
    out.error = checked.error;
    return out;
  }
  config.discrepancy.noise_sigma_at_0m_mm = checked.fit.sigma_at_0m_mm;
  config.discrepancy.noise_sigma_per_m2_mm = checked.fit.sigma_per_m2_mm;
  config.discrepancy.evidence_pixels_per_sample = checked.pixels_per_sample;
  config.discrepancy.evidence_static_bias_mm = checked.tuned.static_bias_mm;
  config.discrepancy.evidence_fixed_pattern_sigma_mm = checked.tuned.fixed_pattern_sigma_mm;
  config.discrepancy.evidence_silhouette_band_px = checked.tuned.silhouette_band_px;
  config.discrepancy.evidence_silhouette_bias_mm = checked.tuned.silhouette_bias_mm;
  config.discrepancy.evidence_silhouette_bias_by_link_mm = checked.tuned.silhouette_bias_by_link_mm;
  config.discrepancy.evidence_silhouette_band_step_mm = checked.tuned.silhouette_band_step_mm;
  std::ostringstream summary;
  summary << out.arm.name << ": wiggle " << fixed(truth.wiggle_amplitude_mm, 1) << " mm / "
          << fixed(truth.wiggle_period_m, 2) << " m, slope " << fixed(truth.slope_mm_per_m, 1)
          << " mm/m, fixed pattern " << fixed(truth.pixel_offset_sigma_mm, 1) << " mm, amplitude bias "
          << fixed(truth.reflectivity_bias_mm_per_decade, 1) << " mm/decade, multipath "
          << fixed(truth.multipath_max_mm, 1)
          << " mm; profile: " << fixed(learned.profile_fit.smallest_correction_mm, 1) << ".."
          << fixed(learned.profile_fit.largest_correction_mm, 1) << " mm over "
          << fixed(learned.profile_fit.first_m, 2) << "-" << fixed(learned.profile_fit.last_m, 2)
          << " m, pixel offsets sigma " << fixed(learned.profile_fit.pixel_sigma_mm, 1)
          << " mm; pose against depth: t (" << fixed(100 * learned.profile_fit.pose.correction[0], 2) << ", "
          << fixed(100 * learned.profile_fit.pose.correction[1], 2) << ", "
          << fixed(100 * learned.profile_fit.pose.correction[2], 2) << ") cm, r ("
          << fixed(learned.profile_fit.pose.correction[3] * 180 / M_PI, 2) << ", "
          << fixed(learned.profile_fit.pose.correction[4] * 180 / M_PI, 2) << ", "
          << fixed(learned.profile_fit.pose.correction[5] * 180 / M_PI, 2) << ") deg; deployed noise "
          << fixed(checked.fit.sigma_at_0m_mm, 2) << " + " << fixed(checked.fit.sigma_per_m2_mm, 3)
          << " d^2 mm, static_bias " << fixed(checked.tuned.static_bias_mm, 1) << " mm, fixed pattern "
          << fixed(checked.tuned.fixed_pattern_sigma_mm, 1) << " mm, near steps "
          << fixed(checked.tuned.silhouette_bias_mm, 1) << " mm within " << checked.tuned.silhouette_band_px
          << " px";
  if (!checked.static_error.near_steps.link.empty()) {
    double least_mm = checked.tuned.silhouette_bias_mm;
    for (const auto& link : checked.tuned.silhouette_bias_by_link_mm)
      least_mm = std::min(least_mm, link.second);
    summary << " (" << checked.static_error.near_steps.link << "; its links " << fixed(least_mm, 1) << ".."
            << fixed(checked.tuned.silhouette_bias_mm, 1) << " mm; concave corners "
            << checked.static_error.near_steps.corner_band_px << " px, up to "
            << fixed(checked.static_error.near_steps.corner_bias_mm, 1) << " mm)";
  }
  summary << ", arm pixels outside the profile's range "
          << fixed(100 * checked.profile_coverage.outside_share(), 2) << " %";
  if (!checked.allowance_raised.empty()) {
    summary << " (static_bias raised from " << fixed(checked.measured_static_bias_mm, 1)
            << " mm: " << checked.allowance_raised << ")";
  }
  out.summary = summary.str();
  out.ok = true;
  return out;
}

}  // namespace tofguard::test
