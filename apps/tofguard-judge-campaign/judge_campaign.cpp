#include "judge_campaign.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "joint_motion.hpp"
#include "plot_panel.hpp"
#include "report_format.hpp"
#include "simulated_frames.hpp"
#include "tofguard/common/camera_profile.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/common/risk_names.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/discrepancy/discrepancy_image.hpp"
#include "tofguard/discrepancy/discrepancy_process.hpp"
#include "tofguard/discrepancy/witness_frames.hpp"
#include "tofguard/renderer/rendered_kinematics.hpp"
#include "tofguard/renderer/renderer_service.hpp"
#include "tofguard/risk/cameras_judgement.hpp"
#include "tofguard/risk/protective_field.hpp"
#include "tofguard/risk/risk_monitor.hpp"
#include "tofguard/risk/sequential_evidence.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/robot_model/arm_spheres.hpp"
#include "tofguard/robot_model/kinematic_tree.hpp"
#include "tofguard/robot_model/kinematics.hpp"
#include "tool_support.hpp"

namespace tofguard::test {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.141592653589793;
constexpr double kDegToRad = kPi / 180;

// A floor (top at z = 0) and a wall 0.8 m behind the robot's root: static
// structure at several depths and slopes, as a room gives a real camera.
std::string write_generic_scene(const std::string& dir) {
  fs::create_directories(dir);
  const std::string path = dir + "/floor_and_wall.urdf";
  std::ofstream out(path);
  out << R"(<?xml version="1.0"?>
<robot name="floor_and_wall">
  <link name="room"/>
  <link name="floor"><visual><origin xyz="0 0 -0.01"/><geometry><box size="4 4 0.02"/></geometry></visual></link>
  <link name="wall"><visual><origin xyz="-0.8 0 1.0"/><geometry><box size="0.02 4 2"/></geometry></visual></link>
  <joint name="room_floor" type="fixed"><parent link="room"/><child link="floor"/></joint>
  <joint name="room_wall" type="fixed"><parent link="room"/><child link="wall"/></joint>
</robot>
)";
  if (!out) throw std::runtime_error(path + ": cannot write the campaign's scene");
  return path;
}

// Optical frame (x right, y down, z forward) at `eye` looking at `target`,
// world z up.
Eigen::Isometry3d look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear().col(0) = x;
  pose.linear().col(1) = y;
  pose.linear().col(2) = z;
  pose.translation() = eye;
  return pose;
}

deployment::Config embedded_config() {
  return deployment::load_config(ideal_camera_config("judge-campaign"), nullptr);
}

// The campaign judges frames only: no deadlines to feed, no estimate, no
// plan (each has its own tests).
void judge_frames_only(deployment::Config* config) {
  config->risk.required_heartbeats.clear();
  config->risk.estimate_enabled = false;
  config->risk.plan_enabled = false;
  config->risk.camera_pose_required = false;
}

// Pixels whose noise-free depth differs by more than 3 sigma(d) between the
// model at the true joints and pose and `reported_depth_m` (or that one
// has a surface and the other none).
int changed_pixels(renderer::DepthRenderer& model, const robot_model::SceneModel& scene,
                   const robot_model::JointPositions& true_joints, const Eigen::Isometry3d& true_pose,
                   const std::vector<float>& reported_depth_m, const Intrinsics& intrinsics,
                   const DepthNoise& noise) {
  const robot_model::LinkPoses poses = robot_model::forward_kinematics(scene, true_joints);
  const renderer::RenderResult truth = model.render_at(poses, true_pose, intrinsics);
  if (!truth.usable) throw std::runtime_error(truth.unusable_reason);
  int changed = 0;
  for (size_t i = 0; i < truth.depth_m.size(); ++i) {
    const double a = truth.depth_m[i];
    const double b = reported_depth_m[i];
    if ((a > 0) != (b > 0)) {
      ++changed;
      continue;
    }
    const double sigma_m = metres_from_mm(noise.sigma_mm(1000.0 * std::max(a, b)));
    if (std::abs(a - b) > 3 * sigma_m) ++changed;
  }
  return changed;
}

// The unit of a fault group's magnitude, "" for groups without one.
std::string magnitude_unit(const std::string& group) {
  if (group == "joint offset" || group == "camera rotation") return "deg";
  if (group == "camera translation" || group == "object held still") return "cm";
  return "";
}

// " 5 deg" for a group with a magnitude, "" otherwise.
std::string magnitude_text(const std::string& group, double magnitude) {
  const std::string unit = magnitude_unit(group);
  if (unit.empty()) return "";
  std::ostringstream s;
  s << " " << magnitude << " " << unit;
  return s.str();
}

// "median / p99 / max" of latencies in seconds, as ms; "-" when none.
std::string latency_text(std::vector<double> latency_s) {
  if (latency_s.empty()) return "-";
  std::sort(latency_s.begin(), latency_s.end());
  const auto ms = [](double s) { return std::to_string(std::lround(1000 * s)); };
  return ms(quantile(latency_s, 0.5)) + " / " + ms(quantile(latency_s, 0.99)) + " / " + ms(latency_s.back());
}

}  // namespace

CampaignArm default_campaign_arm() {
  CampaignArm arm{"default arm (config/sim.yaml)", embedded_config()};
  judge_frames_only(&arm.config);
  return arm;
}

CampaignArm two_camera_campaign_arm() {
  CampaignArm arm{
      "default arm, two cameras (config/sim-two-cameras.yaml)",
      deployment::load_config(config_variant(source_dir() + "/config/sim-two-cameras.yaml",
                                             "judge-campaign-two-cameras-" + std::to_string(::getpid())),
                              nullptr)};
  judge_frames_only(&arm.config);
  return arm;
}

CampaignArm camera_alone(const CampaignArm& arm, const std::string& camera_id) {
  CampaignArm alone{arm.name + ", " + camera_id + " alone", deployment::select_camera(arm.config, camera_id)};
  deployment::CameraSection lone = alone.config.camera;
  lone.name_suffix = "";
  alone.config.cameras = {lone};
  alone.config.camera = lone;
  alone.config.channels = arm.config.channels;  // the first camera's names
  return alone;
}

Eigen::Vector3d occluder_before(const CampaignArm& arm, const std::string& camera_id, double distance_m) {
  const deployment::Config camera =
      arm.config.cameras.size() > 1 ? deployment::select_camera(arm.config, camera_id) : arm.config;
  if (camera.camera.id != camera_id)
    throw std::invalid_argument(arm.name + ": no camera '" + camera_id + "' to put an occluder before");
  return camera.camera.pose.frame_from_optical() * Eigen::Vector3d(0, 0, distance_m);
}

CampaignArm with_second_camera(const CampaignArm& arm, double turn_deg) {
  if (arm.config.cameras.size() != 1)
    throw std::invalid_argument(arm.name + ": a second camera needs one first");
  CampaignArm two = arm;
  deployment::CameraSection second = with_camera_turned(arm, turn_deg).config.camera;
  second.id = arm.config.camera.id + "-2";
  second.name_suffix = "/" + second.id;
  second.profile = arm.config.camera.profile;
  // (A lone camera's settings are config.camera's; generic_campaign_arm
  // places that one.)
  two.config.cameras = {arm.config.camera, second};
  two.name = arm.name + ", a second camera turned " + fixed_text(turn_deg, 0) + " deg";
  return two;
}

CampaignArm generic_campaign_arm(const std::string& name, const std::string& urdf,
                                 const std::vector<std::string>& package_paths, const std::string& scene_dir,
                                 const Eigen::Vector3d& eye_m, const Eigen::Vector3d& target_m) {
  CampaignArm arm{name, embedded_config()};
  deployment::Config& c = arm.config;
  c.robot.urdf_path = urdf;
  c.robot.package_paths = package_paths;
  c.environment.urdf_paths = {write_generic_scene(scene_dir)};
  const Eigen::Isometry3d pose = look_at(eye_m, target_m);
  c.camera.pose = CameraPose("world", pose.translation(), UnitQuaternion(Eigen::Quaterniond(pose.linear())));
  // Every actuated joint about a bent pose (inside its limits), each with
  // its own period so that the poses do not repeat.
  const robot_model::KinematicTree tree = robot_model::load_kinematic_tree(urdf);
  c.joints_sim.motion.clear();
  for (size_t i = 0; i < tree.actuated_joint_names.size(); ++i) {
    const std::string& name_i = tree.actuated_joint_names[i];
    sim::JointMotion m;
    m.joint = name_i;
    const bool prismatic = tree.is_prismatic_joint(name_i);
    const double sign = (i / 2) % 2 == 0 ? 1.0 : -1.0;
    m.center = prismatic ? 0 : (i % 2 == 1 ? 0.7 * sign : 0.3 * sign);
    m.amplitude = prismatic ? 0.01 : 0.3;
    m.period_s = 5.0 + 1.3 * static_cast<double>(i);
    m.phase_rad = static_cast<double>(i);
    for (const robot_model::Joint& j : tree.joints) {
      if (j.name != name_i || !j.limits.has_position_limits) continue;
      const double margin = 0.1 * (j.limits.upper - j.limits.lower);
      m.center =
          std::clamp(m.center, j.limits.lower + margin + m.amplitude, j.limits.upper - margin - m.amplitude);
    }
    c.joints_sim.motion.push_back(m);
  }
  judge_frames_only(&c);
  return arm;
}

std::optional<CampaignArm> iiwa14_campaign_arm(const std::string& shared_dir, const std::string& scene_dir) {
  const std::string urdf = shared_dir + "/robots/iiwa14/urdf/iiwa14_no_collision_relative.urdf";
  if (shared_dir.empty() || !fs::exists(urdf)) return std::nullopt;
  return generic_campaign_arm("iiwa14", urdf, {}, scene_dir + "/iiwa14", {1.5, 0.5, 1.3}, {0, 0, 0.6});
}

std::optional<CampaignArm> kinova_gen3_campaign_arm(const std::string& shared_dir,
                                                    const std::string& scene_dir) {
  const std::string root = shared_dir + "/robots/kinova_gen3";
  const std::string urdf =
      root + "/kortex_description/arms/gen3/7dof/urdf/GEN3-7DOF-NOVISION_FOR_URDF_ARM_V12.urdf";
  if (shared_dir.empty() || !fs::exists(urdf)) return std::nullopt;
  return generic_campaign_arm("Kinova Gen3", urdf, {root}, scene_dir + "/kinova_gen3", {1.3, 0.45, 1.1},
                              {0, 0, 0.5});
}

CampaignArm with_camera_rate(const CampaignArm& arm, double rate_hz) {
  CampaignArm rated = arm;
  rated.config.camera.rate_hz = rate_hz;
  for (deployment::CameraSection& camera : rated.config.cameras) camera.rate_hz = rate_hz;
  rated.name = arm.name + ", " + fixed_text(rate_hz, 0) + " Hz";
  return rated;
}

CampaignArm with_camera_turned(const CampaignArm& arm, double turn_deg) {
  CampaignArm turned = arm;
  const Eigen::Isometry3d turn(Eigen::AngleAxisd(turn_deg * kDegToRad, Eigen::Vector3d::UnitZ()));
  auto turned_pose = [&turn](const CameraPose& given) {
    const Eigen::Isometry3d pose = turn * given.frame_from_optical();
    return CameraPose(given.frame_id, pose.translation(), UnitQuaternion(Eigen::Quaterniond(pose.linear())));
  };
  turned.config.camera.pose = turned_pose(arm.config.camera.pose);
  for (deployment::CameraSection& camera : turned.config.cameras) camera.pose = turned_pose(camera.pose);
  turned.name = arm.name + ", camera turned " + fixed_text(turn_deg, 0) + " deg";
  return turned;
}

std::vector<CampaignRun> fault_runs(const CampaignArm& arm, const FaultMagnitudes& magnitudes) {
  std::vector<CampaignRun> runs;
  uint64_t seed = 1000;
  auto add = [&](CampaignFault fault) {
    CampaignRun run;
    run.fault = std::move(fault);
    run.start_s = 0.77 * static_cast<double>(runs.size());
    run.noise_seed = seed++;
    runs.push_back(run);
  };
  int n = 0;
  for (const sim::JointMotion& m : arm.config.joints_sim.motion) {
    for (double deg : magnitudes.joint_offsets_deg) {
      CampaignFault f;
      f.kind = CampaignFault::Kind::kJointOffset;
      f.group = "joint offset";
      f.magnitude = deg;
      f.joint = m.joint;
      const double sign = (n++ % 2 == 0) ? 1.0 : -1.0;
      f.offset = sign * deg * kDegToRad;
      std::ostringstream label;
      label << m.joint << " " << (sign > 0 ? "+" : "-") << deg << " deg";
      f.label = label.str();
      add(f);
    }
  }
  // Along / about the reported optical frame's axes (x right, y down, z
  // the optical axis), the sign alternating with axis and magnitude.
  const char* const axis_names[] = {"x", "y", "z (optical axis)"};
  auto camera_fault = [&](const std::string& group, double magnitude, int axis, double sign) {
    CampaignFault f;
    f.kind = CampaignFault::Kind::kCameraPose;
    f.group = group;
    f.magnitude = magnitude;
    f.camera_error = Eigen::Isometry3d::Identity();
    std::ostringstream label;
    if (group == "camera translation") {
      f.camera_error.translation()[axis] = sign * magnitude / 100;
      label << "camera " << magnitude << " cm along " << axis_names[axis];
    } else {
      f.camera_error.linear() =
          Eigen::AngleAxisd(sign * magnitude * kDegToRad, Eigen::Vector3d::Unit(axis)).toRotationMatrix();
      label << "camera turned " << magnitude << " deg about " << std::string(axis_names[axis]).substr(0, 1);
    }
    f.label = label.str();
    add(f);
  };
  for (size_t i = 0; i < magnitudes.camera_translations_cm.size(); ++i)
    for (int axis = 0; axis < 3; ++axis)
      camera_fault("camera translation", magnitudes.camera_translations_cm[i], axis,
                   (i + static_cast<size_t>(axis)) % 2 == 0 ? 1.0 : -1.0);
  for (size_t i = 0; i < magnitudes.camera_rotations_deg.size(); ++i)
    for (int axis = 0; axis < 3; ++axis)
      camera_fault("camera rotation", magnitudes.camera_rotations_deg[i], axis,
                   (i + static_cast<size_t>(axis)) % 2 == 0 ? 1.0 : -1.0);
  return runs;
}

std::vector<CampaignRun> stream_fault_runs(int runs_each) {
  std::vector<CampaignRun> runs;
  uint64_t seed = 3000;
  const std::pair<CampaignFault::Kind, const char*> kinds[] = {
      {CampaignFault::Kind::kFrozenImage, "camera image frozen"},
      {CampaignFault::Kind::kCameraStall, "camera stream stalled"},
      {CampaignFault::Kind::kJointStall, "joint stream stalled"},
  };
  for (const auto& [kind, label] : kinds) {
    for (int i = 0; i < runs_each; ++i) {
      CampaignRun run;
      run.fault.kind = kind;
      run.fault.group = label;
      run.fault.label = label;
      run.frames_after_onset = 30;
      run.start_s = 1.3 * i;
      run.noise_seed = seed++;
      runs.push_back(run);
    }
  }
  return runs;
}

std::vector<CampaignRun> nominal_runs(double seconds, double run_s, double rate_hz, uint64_t seed) {
  std::vector<CampaignRun> runs;
  const int frames_per_run = static_cast<int>(std::lround(run_s * rate_hz));
  for (double t = 0; t < seconds; t += run_s) {
    CampaignRun run;
    run.fault.label = "nominal";
    run.onset_frame = frames_per_run;  // never reached: every frame is before the onset
    run.frames_after_onset = 0;
    run.start_s = t;
    run.noise_seed = seed++;
    runs.push_back(run);
  }
  return runs;
}

namespace {

// The protective and warning fields of `arm` at rest.
risk::FieldSize field_at_rest(const CampaignArm& arm) {
  const risk::RiskSettings& r = arm.config.risk;
  return risk::field_size(r, risk::chain_response_time_s(r, arm.config.camera.rate_hz), 0);
}

// A person (0.4 x 0.3 x 1.7 m) or a cart (0.6 x 0.4 x 0.8 m) walking past
// at 1 m/s, `beyond_m` beyond the warning field of the arm at rest.
CampaignFault passer(const risk::FieldSize& at_rest, double beyond_m, bool cart, int side) {
  CampaignFault f;
  f.kind = CampaignFault::Kind::kObject;
  f.object_size_m = cart ? Eigen::Vector3d(0.6, 0.4, 0.8) : Eigen::Vector3d(0.4, 0.3, 1.7);
  f.object_distance_m = at_rest.warning_m + beyond_m;
  f.object_side = side;
  f.object_speed_m_s = 1.0;
  f.object_in_field = false;
  f.label = cart ? "cart passing" : "person walking past";
  f.group = f.label;
  return f;
}

}  // namespace

std::vector<CampaignRun> object_runs(const CampaignArm& arm, const std::vector<double>& distances_m,
                                     double beyond_m) {
  const risk::RiskSettings& r = arm.config.risk;
  const risk::FieldSize at_rest = field_at_rest(arm);
  std::vector<CampaignRun> runs;
  uint64_t seed = 5000;
  int side = 1;
  auto add = [&](CampaignFault fault, double start_s) {
    CampaignRun run;
    fault.kind = CampaignFault::Kind::kObject;
    run.fault = std::move(fault);
    run.onset_frame = 15;
    run.frames_after_onset = 45;
    run.start_s = start_s;
    run.noise_seed = seed++;
    runs.push_back(run);
  };
  for (double d : distances_m) {
    for (double start_s : {0.0, 2.5}) {
      CampaignFault f;
      f.object_distance_m = d;
      f.object_side = side;
      side = -side;
      f.object_in_field = d < at_rest.protective_m;
      f.label = "object " + std::to_string(std::lround(d * 100)) + " cm";
      f.group = "object held still";
      f.magnitude = d * 100;
      add(f, start_s);
    }
  }
  for (double start_s : {0.0, 1.7, 3.4}) {
    CampaignFault hand;
    hand.object_size_m = Eigen::Vector3d(0.1, 0.1, 0.2);
    hand.object_distance_m = at_rest.warning_m + 0.2;
    hand.object_side = side;
    side = -side;
    hand.object_speed_m_s = r.field_approach_speed_m_s;
    hand.object_approaches = true;
    hand.label = "hand approaching";
    hand.group = hand.label;
    add(hand, start_s);
  }
  for (double start_s : {0.0, 2.0}) {
    add(passer(at_rest, beyond_m, /*cart=*/false, side), start_s);
    side = -side;
    add(passer(at_rest, beyond_m, /*cart=*/true, side), start_s + 1.0);
    side = -side;
  }
  return runs;
}

std::vector<CampaignRun> passer_runs(const CampaignArm& arm, double seconds, uint64_t seed) {
  // Each run: 1 s of the scene alone, then 4 s of a person or a cart
  // crossing (4 m at 1 m/s: in view and out again), 0.1 m beyond the
  // warning field where it comes nearest.
  const risk::FieldSize at_rest = field_at_rest(arm);
  const double rate_hz = arm.config.camera.rate_hz;
  std::vector<CampaignRun> runs;
  int side = 1;
  for (double t = 0; t < seconds; t += 5.0) {
    CampaignRun run;
    const bool cart = runs.size() % 2 == 1;
    run.fault = passer(at_rest, 0.1, cart, side);
    if (cart) side = -side;
    // It starts where its path comes nearest the arm and walks on across
    // the view, on alternating sides of the image.
    run.onset_frame = static_cast<int>(std::lround(rate_hz));
    run.frames_after_onset = static_cast<int>(std::lround(4 * rate_hz));
    run.start_s = t;
    run.noise_seed = seed++;
    runs.push_back(run);
  }
  return runs;
}

namespace {

// The distance from the axis-aligned box (centre, half edges; world) to
// the nearest sphere of `placed`, m (0 when they touch).
double box_to_arm_m(const Eigen::Vector3d& center, const Eigen::Vector3d& half,
                    const robot_model::PlacedArmSpheres& placed) {
  double best = std::numeric_limits<double>::infinity();
  for (const robot_model::PlacedSphere& s : placed) {
    const Eigen::Vector3d outside = ((s.center_world_m - center).cwiseAbs() - half).cwiseMax(0.0);
    best = std::min(best, outside.norm() - s.radius_m);
  }
  return std::max(0.0, best);
}

// An object counts as in view from this many pixels (15 cm^2, the
// smallest object counted, is about 18 px at 2 m with fx = 221 px).
constexpr int kObjectSeenPixels = 20;

// Where a kObject fault's box starts and how it moves (world, m and m/s).
struct ObjectPath {
  Eigen::Vector3d start = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
};

// The box placed `fault.object_distance_m` from the arm along `direction`
// from `anchor` (bisection on the cover's distance).
Eigen::Vector3d place_along(const CampaignFault& fault, const robot_model::PlacedArmSpheres& placed,
                            const Eigen::Vector3d& anchor, const Eigen::Vector3d& direction) {
  const Eigen::Vector3d half = fault.object_size_m / 2;
  double lo = 0;
  double hi = 5;
  for (int i = 0; i < 60; ++i) {
    const double mid = (lo + hi) / 2;
    (box_to_arm_m(anchor + mid * direction, half, placed) < fault.object_distance_m ? lo : hi) = mid;
  }
  return anchor + hi * direction;
}

// Where the box starts: at its distance from the arm's point farthest
// from its root (a hand reaches for the tool), in whichever of 16
// directions (8 about the optical axis, level with the point or 45 degrees
// away from the camera) the camera sees most of it, preferring
// fault.object_side's half of the image on a tie; and how it moves.
ObjectPath place_object(const CampaignFault& fault, const robot_model::PlacedArmSpheres& placed,
                        const Eigen::Isometry3d& world_from_optical, renderer::DepthRenderer* view,
                        const robot_model::LinkPoses& poses, const Intrinsics& intrinsics) {
  Eigen::Vector3d anchor = Eigen::Vector3d::Zero();
  for (const robot_model::PlacedSphere& s : placed) {
    if (s.center_world_m.norm() > anchor.norm()) anchor = s.center_world_m;
  }
  const Eigen::Matrix3d r = world_from_optical.linear();
  ObjectPath path;
  int best_pixels = -1;
  for (int away = 0; away < 2; ++away) {
    for (int k = 0; k < 8; ++k) {
      const double angle = fault.object_side * k * 3.141592653589793 / 4;
      const Eigen::Vector3d in_image(std::cos(angle), std::sin(angle), away);
      const Eigen::Vector3d direction = (r * in_image).normalized();
      const Eigen::Vector3d start = place_along(fault, placed, anchor, direction);
      renderer::ExtraObject box;
      box.size_m = fault.object_size_m;
      box.world_from_object.translation() = start;
      const renderer::RenderResult seen = view->render_at(poses, world_from_optical, intrinsics, {box});
      int pixels = 0;
      for (int16_t label : seen.labels) pixels += label == kLabelExtraObjectFirst ? 1 : 0;
      if (pixels > best_pixels) {
        best_pixels = pixels;
        path.start = start;
      }
    }
  }
  const Eigen::Vector3d to_arm = (anchor - path.start).normalized();
  if (fault.object_approaches) {
    path.velocity = fault.object_speed_m_s * to_arm;
  } else {
    // Horizontally across the line to the arm (world z up).
    Eigen::Vector3d across = Eigen::Vector3d::UnitZ().cross(to_arm);
    if (across.norm() < 1e-6) across = Eigen::Vector3d::UnitX();
    path.velocity = fault.object_speed_m_s * across.normalized();
  }
  return path;
}

// What every run of an arm's campaign shares: the true scene, the model as
// tofguard-renderer loads it (the config's geometry, padding and mesh
// simplification), and the tree tofguard-risk loads.
struct CampaignWorld {
  // `camera_config`: the deployment as one camera's processes see it
  // (deployment::select_camera with several cameras); must outlive this.
  explicit CampaignWorld(const deployment::Config& camera_config)
      : config(camera_config),
        truth(config),
        model_scene(robot_model::load_scene(config.robot.urdf_path, config.environment.urdf_paths,
                                            renderer::scene_options(config.renderer, config.robot))),
        model(model_scene, config.renderer.near_m, config.renderer.far_m),
        arm_cover(robot_model::cover_arm_with_spheres(model_scene, config.renderer.arm_cover_cell_m)),
        truth_cover(robot_model::cover_arm_with_spheres(model_scene, 0.01)),
        robot_tree(robot_model::load_kinematic_tree(config.robot.urdf_path)),
        discrepancy_process(deployment::discrepancy_process_settings(config)),
        options(discrepancy::process_discrepancy_options(discrepancy_process)),
        intrinsics(config.camera.intrinsics),
        period_s(1.0 / config.camera.rate_hz),
        period_us(static_cast<int64_t>(std::llround(period_s * 1e6))),
        reported_pose(config.camera.pose.frame_from_optical()),
        evidence(config.risk, robot_tree, config.camera.rate_hz) {}

  const deployment::Config& config;
  SimulatedFrames truth;
  const robot_model::SceneModel model_scene;
  renderer::DepthRenderer model;
  const robot_model::ArmSpheres arm_cover;
  // The objects' true distances: a finer cover (1 cm cells, within 3 cm
  // of the surface) than the renderer's.
  const robot_model::ArmSpheres truth_cover;
  const robot_model::KinematicTree robot_tree;
  // tofguard-discrepancy's settings (its witnesses: the other cameras) and
  // the options it derives from them (with several cameras it looks
  // through the others' frames).
  const settings::DiscrepancyProcessSettings discrepancy_process;
  const discrepancy::DiscrepancyOptions options;
  const Intrinsics intrinsics;
  const double period_s;
  const int64_t period_us;
  const Eigen::Isometry3d reported_pose;
  // The risk monitor's stop tests as configured: what a frame can show
  // (SequentialEvidence::smallest_offset).
  const risk::SequentialEvidence evidence;
};

// The cameras as tofguard-risk judges them (no heartbeats: the campaign
// judges frames only).
std::vector<risk::RiskCamera> risk_cameras(const std::vector<CampaignWorld*>& worlds) {
  std::vector<risk::RiskCamera> cameras;
  for (const CampaignWorld* w : worlds) {
    cameras.push_back({w->config.camera.id, w->config.camera.rate_hz, w->config.channels, {}});
  }
  return cameras;
}

// One run of the campaign: its frames through the discrepancy and the risk
// judgement (each camera's frame through its own discrepancy, the other
// cameras' frames its witnesses; one judgement of all), and what they
// decided.
class CampaignRunJudge {
 public:
  // `robot_link_areas`: as tofguard-risk reads them (with several cameras).
  CampaignRunJudge(const std::vector<CampaignWorld*>& worlds,
                   const std::vector<risk::LinkArea>& robot_link_areas, const CampaignRun& run)
      : worlds_(worlds),
        w_(*worlds.front()),
        config_(w_.config),
        run_(run),
        fault_camera_(run.fault.camera),
        judgement_(config_.risk, risk_cameras(worlds), w_.robot_tree, robot_link_areas, std::nullopt, 0),
        repeats_(worlds.size()),
        last_depth_m_(worlds.size()),
        kind_(run.fault.kind),
        stall_(kind_ == Kind::kCameraStall || kind_ == Kind::kJointStall),
        object_fault_(kind_ == Kind::kObject) {
    for (const CampaignWorld* w : worlds) witness_frames_.emplace_back(w->discrepancy_process.witnesses);
    if (fault_camera_ >= worlds.size()) {
      throw std::invalid_argument("campaign fault " + run.fault.label + ": no camera " +
                                  std::to_string(fault_camera_));
    }
    result_.label = run.fault.label;
    result_.group = run.fault.group;
    result_.magnitude = run.fault.magnitude;
  }

  CampaignResult judge() {
    const int num_frames = run_.onset_frame + run_.frames_after_onset;
    for (int k = 0; k < num_frames; ++k) judge_frame(k);
    grade();
    return result_;
  }

 private:
  using Kind = CampaignFault::Kind;

  void judge_frame(int k) {
    const double t_s = run_.start_s + k * w_.period_s;
    const int64_t now_us = (k + 1) * w_.period_us;
    const bool faulty = kind_ != Kind::kNone && k >= run_.onset_frame;
    robot_model::JointPositions true_joints;
    const joint_state_t state = reported_state(k, t_s, faulty, &true_joints);
    objects_.clear();
    if (faulty && object_fault_) move_object(k, true_joints, true_pose(0, faulty));
    if (run_.occluder_size_m > 0) objects_.push_back(occluder());
    if (stall_ && faulty && !result_.stopped) check_deadlines(k, now_us);
    // Each camera's frame k (none from a stalled camera's).
    std::vector<std::optional<depth_image_t>> frames(worlds_.size());
    for (size_t c = 0; c < worlds_.size(); ++c) {
      if (kind_ == Kind::kCameraStall && faulty && c == fault_camera_) continue;
      frames[c] = capture(c, k, faulty, state, true_joints, true_pose(c, faulty));
    }
    std::vector<Rendered> rendered(worlds_.size());
    for (size_t c = 0; c < worlds_.size(); ++c) {
      if (!frames[c]) continue;
      rendered[c] = render(c, k, *frames[c], state);
      show_to_witnesses(c, *frames[c], rendered[c].labels);
    }
    for (size_t c = 0; c < worlds_.size(); ++c) {
      if (frames[c]) judgement_.monitor(c).on_depth(now_us);
      if (!(kind_ == Kind::kJointStall && faulty)) judgement_.monitor(c).on_joint_state(state, now_us);
    }
    for (size_t c = 0; c < worlds_.size(); ++c) {
      if (!frames[c]) continue;
      discrepancy::DiscrepancyFrame frame =
          discrepancy_of(c, k, *frames[c], rendered[c], witness_frames_[c].views_at(frames[c]->utime),
                         true_joints, true_pose(c, faulty));
      if (c == 0 && (k < run_.onset_frame || kind_ == Kind::kNone)) add_nominal_scores(frame.summary);
      if (c == 0 && faulty && kind_ == Kind::kJointOffset) add_fault_search_gain(frame.summary);
      for (const risk_t& verdict : judgement_.on_frame(c, frame.summary, now_us)) judge_verdict(verdict, k);
    }
    every_camera_judged_ = true;
  }

  // CampaignRun's occluder, in the world.
  renderer::ExtraObject occluder() const {
    renderer::ExtraObject box;
    box.kind = renderer::ExtraObject::Kind::kBox;
    box.size_m = Eigen::Vector3d::Constant(run_.occluder_size_m);
    box.world_from_object.translation() = run_.occluder_centre_m;
    return box;
  }

  // Where camera `c` really is: the reported pose, or the camera fault's.
  Eigen::Isometry3d true_pose(size_t c, bool faulty) const {
    const Eigen::Isometry3d& reported = worlds_[c]->reported_pose;
    return faulty && kind_ == Kind::kCameraPose && c == fault_camera_ ? reported * run_.fault.camera_error
                                                                      : reported;
  }

  // The joint state frame k reports (a joint offset fault's joint off by
  // its offset), and the true joints into *true_joints.
  joint_state_t reported_state(int k, double t_s, bool faulty,
                               robot_model::JointPositions* true_joints) const {
    joint_state_t state{};
    state.utime = 1'700'000'000'000'000 + k * w_.period_us;
    state.robot_id = config_.robot.id;
    for (const sim::JointMotion& m : config_.joints_sim.motion) {
      const double q = joint_position(m, t_s);
      (*true_joints)[m.joint] = q;
      state.name.push_back(m.joint);
      state.position.push_back(q + (faulty && kind_ == Kind::kJointOffset && m.joint == run_.fault.joint
                                        ? run_.fault.offset
                                        : 0.0));
      state.velocity.push_back(joint_velocity(m, t_s));
    }
    state.num_joints = static_cast<int32_t>(state.name.size());
    return state;
  }

  // A kObject fault's box in frame k (placed at the onset): its distance
  // to the arm and how the camera sees it.
  void move_object(int k, const robot_model::JointPositions& true_joints,
                   const Eigen::Isometry3d& true_pose) {
    const robot_model::PlacedArmSpheres placed = robot_model::place_arm_spheres(
        w_.truth_cover, robot_model::forward_kinematics(w_.model_scene, true_joints));
    if (k == run_.onset_frame) {
      object_path_ =
          place_object(run_.fault, placed, true_pose, &w_.model,
                       robot_model::forward_kinematics(w_.model_scene, true_joints), w_.intrinsics);
    }
    renderer::ExtraObject box;
    box.kind = renderer::ExtraObject::Kind::kBox;
    box.size_m = run_.fault.object_size_m;
    box.world_from_object.translation() =
        object_path_.start + object_path_.velocity * ((k - run_.onset_frame) * w_.period_s);
    objects_.push_back(box);
    object_distance_m_ = box_to_arm_m(box.world_from_object.translation(), box.size_m / 2, placed);
    // The camera's view of it, without noise.
    const renderer::RenderResult seen = w_.model.render_at(
        robot_model::forward_kinematics(w_.model_scene, true_joints), true_pose, w_.intrinsics, objects_);
    int pixels = 0;
    for (int16_t label : seen.labels) pixels += label == kLabelExtraObjectFirst ? 1 : 0;
    if (k == run_.onset_frame) {
      result_.object_distance_at_onset_m = object_distance_m_;
      result_.object_min_distance_m = object_distance_m_;
      result_.object_pixels = pixels;
    }
    // First seen: as large as the smallest object counted, at 2 m.
    if (result_.object_first_seen_m < 0 && pixels >= kObjectSeenPixels) {
      result_.object_first_seen_m = object_distance_m_;
    }
    result_.object_min_distance_m = std::min(result_.object_min_distance_m, object_distance_m_);
  }

  // A stalled stream: its messages stop at the onset; the monitor's
  // deadlines, checked every millisecond, must stop the arm. The
  // latency runs from when the first missing message was due.
  void check_deadlines(int k, int64_t now_us) {
    const int64_t due_us = (run_.onset_frame + 1) * w_.period_us;
    for (int64_t t_us = now_us - w_.period_us + 1000; t_us <= now_us; t_us += 1000) {
      for (size_t c = 0; c < worlds_.size(); ++c) {
        const std::optional<risk_t> timeout = judgement_.monitor(c).check_deadlines(t_us);
        if (!timeout) continue;
        const std::optional<risk_t> published = judgement_.published(c, *timeout);
        if (!published || published->level != risk_t::DANGEROUS) continue;
        record_stop(*published, k - run_.onset_frame + 1, 1e-6 * static_cast<double>(t_us - due_us), 0);
        return;
      }
    }
  }

  // Camera `c`'s frame k (a frozen camera repeats its last image).
  depth_image_t capture(size_t c, int k, bool faulty, const joint_state_t& state,
                        const robot_model::JointPositions& true_joints, const Eigen::Isometry3d& true_pose) {
    CampaignWorld& w = *worlds_[c];
    const bool frozen = kind_ == Kind::kFrozenImage && c == fault_camera_;
    std::vector<float> depth_m =
        frozen && faulty && !last_depth_m_[c].empty()
            ? last_depth_m_[c]
            : w.truth.capture(true_joints, true_pose, w.intrinsics,
                              (run_.noise_seed + 7919 * c) * 100000 + static_cast<uint64_t>(k), objects_);
    if (frozen) last_depth_m_[c] = depth_m;
    return make_depth_image(w.config.camera.id, w.intrinsics, state.utime, k, /*calibrated=*/true, depth_m);
  }

  // The model rendered at the reported joints and camera `c`'s reported
  // pose, and its labels and kinematics as tofguard-renderer publishes
  // them (with several cameras, where the camera was).
  struct Rendered {
    renderer::RenderResult result;
    depth_image_t depth;
    link_labels_t labels;
  };
  Rendered render(size_t c, int k, const depth_image_t& camera, const joint_state_t& state) {
    CampaignWorld& w = *worlds_[c];
    robot_model::JointPositions reported_joints;
    for (int i = 0; i < state.num_joints; ++i) reported_joints[state.name[i]] = state.position[i];
    const robot_model::LinkPoses poses = robot_model::forward_kinematics(w.model_scene, reported_joints);
    if (!poses.usable) throw std::runtime_error(poses.unusable_reason);
    Rendered r;
    r.result = w.model.render_at(poses, w.reported_pose, w.intrinsics);
    if (!r.result.usable) throw std::runtime_error(r.result.unusable_reason);
    r.depth = make_depth_image(w.config.camera.id, w.intrinsics, state.utime, k, /*calibrated=*/true,
                               r.result.depth_m);
    r.labels = renderer::make_rendered_link_labels(camera, r.result, w.model_scene, w.arm_cover);
    if (worlds_.size() > 1) renderer::set_rendered_optical_pose(w.reported_pose, &r.labels);
    return r;
  }

  // Camera `c`'s frame and labels to every other camera's witnesses, as
  // its tofguard-discrepancy takes them in (paired by seq, corrected by
  // camera c's profile).
  void show_to_witnesses(size_t c, const depth_image_t& frame, const link_labels_t& labels) {
    const std::string& id = worlds_[c]->config.camera.id;
    for (discrepancy::WitnessFrames& witnesses : witness_frames_) {
      const size_t index = witnesses.index_of(id);
      if (index == witnesses.cameras()) continue;  // camera c's own
      witnesses.add_depth(index, frame);
      if (const std::string why = witnesses.add_labels(index, labels); !why.empty()) {
        throw std::runtime_error("campaign: " + id + "'s frame cannot be looked through: " + why);
      }
    }
  }

  // Camera `c`'s frame's discrepancy as tofguard-discrepancy computes it.
  discrepancy::DiscrepancyFrame discrepancy_of(size_t c, int k, const depth_image_t& camera,
                                               const Rendered& rendered,
                                               const std::vector<discrepancy::WitnessView>& witnesses,
                                               const robot_model::JointPositions& true_joints,
                                               const Eigen::Isometry3d& true_pose) {
    CampaignWorld& w = *worlds_[c];
    if (c == 0 && k == run_.onset_frame && kind_ != Kind::kNone) {
      result_.changed_pixels =
          changed_pixels(w.model, w.model_scene, true_joints, true_pose, rendered.result.depth_m,
                         w.intrinsics, w.options.tolerance.noise);
    }
    discrepancy::DiscrepancyFrame frame = discrepancy::compute_discrepancy(
        camera, rendered.depth, rendered.labels, w.options, nullptr, witnesses);
    // As tofguard-discrepancy counts a camera repeating its image.
    frame.summary.depth_hash = discrepancy::depth_hash(camera.depth_mm);
    frame.summary.repeat_count = repeats_[c].update(frame.summary.depth_hash);
    return frame;
  }

  void add_score(double score, double information) {
    if (!(information > 0)) return;
    const double t = score / std::sqrt(information);
    ++result_.nominal_scores;
    result_.nominal_score_sum_sq += t * t;
    result_.nominal_scores_beyond_4 += std::abs(t) > 4 ? 1 : 0;
    result_.nominal_score_max_abs = std::max(result_.nominal_score_max_abs, std::abs(t));
  }

  // A nominal frame's joint scores (and, on request, camera scores), and
  // their frame-to-frame differences.
  void add_nominal_scores(const discrepancy_t& d) {
    for (int j = 0; j < d.num_joints; ++j) {
      add_score(d.joint_score[j], d.joint_information[j]);
      if (!(d.joint_information[j] > 0)) continue;
      const double t = d.joint_score[j] / std::sqrt(d.joint_information[j]);
      const auto previous = previous_t_.find(d.joint_name[j]);
      if (previous != previous_t_.end()) {
        ++result_.nominal_differences;
        result_.nominal_difference_sum_sq += (t - previous->second) * (t - previous->second) / 2;
      }
      previous_t_[d.joint_name[j]] = t;
    }
    if (kind_ == Kind::kNone) {
      add_smallest_offsets(d);
      add_search_gains(d);
    }
    if (std::getenv("TOFGUARD_CAMPAIGN_CAMERA_SCORES") != nullptr)
      for (int a = 0; a < 6 && d.evidence_available; ++a)
        add_score(d.camera_score[a], d.camera_information[7 * a]);
  }

  // Per joint, the smallest offset this nominal frame can show, as the
  // risk monitor's stop tests take their evidence (degrees; mm when
  // prismatic).
  void add_smallest_offsets(const discrepancy_t& d) {
    for (int j = 0; j < d.num_joints; ++j) {
      const double offset = w_.evidence.smallest_offset(d, j);
      const bool prismatic = w_.model_scene.is_prismatic_joint(d.joint_name[j]);
      result_.nominal_smallest_offset[d.joint_name[j]].push_back(
          static_cast<float>(prismatic ? 1000 * offset : offset * 180 / M_PI));
    }
  }

  // Per joint, the naming search's gain on this nominal frame (none when
  // the frame carries no search).
  void add_search_gains(const discrepancy_t& d) {
    if (!risk::searched(d)) return;
    for (int j = 0; j < d.num_joints; ++j) {
      const double large = w_.evidence.joint_alternatives(d.joint_name[j]).large;
      const double gain = d.joint_search_gain[j];
      result_.nominal_search_gain[d.joint_name[j]].push_back(gain);
      if (std::abs(d.joint_search_offset[j]) >= large)
        result_.nominal_search_gain_large[d.joint_name[j]].push_back(gain);
    }
  }

  // The faulty joint's naming search gain on this frame of the fault.
  void add_fault_search_gain(const discrepancy_t& d) {
    if (!risk::searched(d)) return;
    const auto at = std::find(d.joint_name.begin(), d.joint_name.end(), run_.fault.joint);
    if (at != d.joint_name.end())
      result_.fault_search_gain.push_back(d.joint_search_gain[at - d.joint_name.begin()]);
  }

  // A verdict published at frame k (with several cameras it carries the
  // worst camera's latest seq, which may be its timeout's -1).
  void judge_verdict(const risk_t& verdict, int k) {
    // With several cameras the first frame's verdicts, before every camera
    // has had one judged, are DANGEROUS (VerdictFusion: no frame of that
    // camera judged yet); the chain allows motion only after a reset,
    // accepted only while the verdict is SAFE.
    if (!every_camera_judged_) return;
    ++result_.frames_judged;
    // An object outside the protective field must never stop the arm:
    // its stops count as false stops, unless the arm's speed had grown
    // the field over it then (an UNKNOWN_OBJECT stop whose S reaches the
    // object's true distance, within the 3 cm the true distance's cover
    // may err).
    const bool inside_s_then = object_fault_ && k >= run_.onset_frame && verdict.level == risk_t::DANGEROUS &&
                               verdict.cause == risk_t::CAUSE_UNKNOWN_OBJECT &&
                               object_distance_m_ <= verdict.threshold + 0.03;
    const bool after_onset =
        k >= run_.onset_frame && kind_ != Kind::kNone &&
        (!object_fault_ || run_.fault.object_in_field || inside_s_then || result_.stopped);
    if (k >= run_.onset_frame && verdict.level == risk_t::WARNING) ++result_.warnings_after_onset;
    if (verdict.level == risk_t::DANGEROUS && !after_onset && !result_.false_stop) {
      result_.false_stop = true;
      result_.false_stop_detail = "frame " + std::to_string(k) + ": " + verdict.detail;
    }
    if (!after_onset) return;
    if (!result_.stopped) {
      if (verdict.level != risk_t::DANGEROUS) return;
      const int frames = k - run_.onset_frame + 1;
      record_stop(verdict, frames, frames * w_.period_s, object_distance_m_);
      return;
    }
    if (verdict.level == risk_t::SAFE) ++result_.safe_after_stop;
    if (verdict.suspect != result_.suspect || verdict.cause != result_.cause) ++result_.suspect_changes;
  }

  // Records the first DANGEROUS verdict at or after the onset.
  void record_stop(const risk_t& verdict, int frames, double latency_s, double object_distance_m) {
    result_.stopped = true;
    result_.stop_frames = frames;
    result_.stop_latency_s = latency_s;
    result_.cause = verdict.cause;
    result_.suspect = verdict.suspect;
    result_.detail = verdict.detail;
    result_.stop_score = verdict.score;
    result_.stop_threshold = verdict.threshold;
    // Judged in the frame it belongs to: the object's distance then.
    result_.object_distance_at_stop_m = object_distance_m;
  }

  // Whether the stop was expected and named the right cause and suspect.
  void grade() {
    if (kind_ == Kind::kJointOffset) {
      result_.right_cause = result_.stopped && result_.cause == risk_t::CAUSE_JOINT_ERROR;
      result_.right_suspect = result_.right_cause && result_.suspect == run_.fault.joint;
    } else if (kind_ == Kind::kCameraPose) {
      result_.right_cause = result_.stopped && result_.cause == risk_t::CAUSE_CALIBRATION_ERROR;
      result_.right_suspect = result_.right_cause;
    } else if (object_fault_) {
      result_.right_cause = result_.stopped && result_.cause == risk_t::CAUSE_UNKNOWN_OBJECT;
      result_.right_suspect = result_.right_cause;
      result_.object = true;
      result_.approaching = run_.fault.object_approaches;
    } else if (kind_ == Kind::kFrozenImage || stall_) {
      // A sensor fault naming the stream that froze or stopped (a stalled
      // camera starves the discrepancy stream too: either is right).
      result_.right_cause = result_.stopped && result_.cause == risk_t::CAUSE_SENSOR_FAULT;
      const ChannelNames& faulty = worlds_[fault_camera_]->config.channels;
      const bool names_stream =
          kind_ == Kind::kJointStall
              ? result_.suspect == config_.channels.joint_state
              : result_.suspect == faulty.depth || (stall_ && result_.suspect == faulty.discrepancy);
      result_.right_suspect = result_.right_cause && names_stream;
    }
    result_.expected_stop = kind_ != Kind::kNone && !(object_fault_ && !run_.fault.object_in_field);
  }

  const std::vector<CampaignWorld*> worlds_;
  CampaignWorld& w_;                  // the first camera's
  const deployment::Config& config_;  // as the first camera's processes see it
  const CampaignRun& run_;
  const size_t fault_camera_;
  risk::CamerasJudgement judgement_;
  std::vector<discrepancy::RepeatCounter> repeats_;
  std::vector<std::vector<float>> last_depth_m_;  // the image a frozen camera repeats
  // Per camera, its tofguard-discrepancy's witnesses: the other cameras'
  // frames (witness_frames.hpp).
  std::vector<discrepancy::WitnessFrames> witness_frames_;
  CampaignResult result_;
  const Kind kind_;
  const bool stall_;
  const bool object_fault_;
  bool every_camera_judged_ = worlds_.size() == 1;
  std::map<std::string, double> previous_t_;
  ObjectPath object_path_;
  std::vector<renderer::ExtraObject> objects_;
  double object_distance_m_ = 0;
};

}  // namespace

std::vector<CampaignResult> run_campaign(const CampaignArm& arm, const std::vector<CampaignRun>& runs) {
  // Each camera's deployment as its processes see it.
  std::vector<deployment::Config> camera_configs;
  if (arm.config.cameras.size() < 2) {
    camera_configs.push_back(arm.config);
  } else {
    for (const deployment::CameraSection& camera : arm.config.cameras) {
      camera_configs.push_back(deployment::select_camera(arm.config, camera.id));
    }
  }
  std::vector<std::unique_ptr<CampaignWorld>> worlds;
  std::vector<CampaignWorld*> world_pointers;
  for (const deployment::Config& config : camera_configs) {
    worlds.push_back(std::make_unique<CampaignWorld>(config));
    world_pointers.push_back(worlds.back().get());
  }
  // Each robot link's surface area as tofguard-risk reads it, once, with
  // several cameras (the arm no camera sees); one camera needs none.
  const std::vector<risk::LinkArea> robot_link_areas =
      camera_configs.size() < 2
          ? std::vector<risk::LinkArea>{}
          : risk::read_robot_link_areas(arm.config.robot.urdf_path, arm.config.robot.package_paths,
                                        arm.config.renderer.geometry);
  std::vector<CampaignResult> results;
  for (const CampaignRun& run : runs)
    results.push_back(CampaignRunJudge(world_pointers, robot_link_areas, run).judge());
  return results;
}

namespace {

// A per-joint figure of every run (`member` of CampaignResult), all runs'
// values together.
template <typename T>
std::map<std::string, std::vector<T>> by_joint_over_runs(
    const std::vector<CampaignResult>& results,
    std::map<std::string, std::vector<T>> CampaignResult::*member) {
  std::map<std::string, std::vector<T>> by_joint;
  for (const CampaignResult& r : results) {
    for (const auto& [joint, values] : r.*member)
      by_joint[joint].insert(by_joint[joint].end(), values.begin(), values.end());
  }
  return by_joint;
}

// One line: per joint over the nominal runs' frames, the median of the
// smallest offset a frame can show, and the share of frames that can show
// none (docs/safety-chain.md, "The smallest fault a frame can show"); ""
// without nominal frames.
std::string smallest_offsets_text(const std::vector<CampaignResult>& results) {
  auto by_joint = by_joint_over_runs(results, &CampaignResult::nominal_smallest_offset);
  if (by_joint.empty()) return "";
  std::ostringstream out;
  out << "\nSmallest joint offset a nominal frame can show (B/I + d'/2 + decay/(d' I); deg, mm if "
         "prismatic), "
         "median over the frames (none: not seen, or the allowance covers the whole alternative):";
  const char* separator = " ";
  for (auto& [joint, offsets] : by_joint) {
    const auto none = std::count_if(offsets.begin(), offsets.end(), [](float v) { return std::isinf(v); });
    std::nth_element(offsets.begin(), offsets.begin() + offsets.size() / 2, offsets.end());
    const float median = offsets[offsets.size() / 2];
    out << separator << joint << " " << (std::isinf(median) ? std::string("none") : fixed_text(median, 1));
    if (none > 0) out << " (none on " << fixed_text(100.0 * none / offsets.size(), 0) << " %)";
    separator = ", ";
  }
  out << "\n";
  return out.str();
}

// One line: per joint over the nominal runs' frames, the naming search's
// gain (its 99th percentile and the largest, chi^2), and the largest where
// the searched offset is the large-offset test's alternative or more: what
// nominal frames give a test on the search's gain (docs/safety-chain.md,
// "A large offset"); "" without such frames.
std::string search_gains_text(const std::vector<CampaignResult>& results) {
  auto all = by_joint_over_runs(results, &CampaignResult::nominal_search_gain);
  auto large = by_joint_over_runs(results, &CampaignResult::nominal_search_gain_large);
  if (all.empty()) return "";
  std::ostringstream out;
  out << "\nThe naming search's gain on the nominal frames (chi^2), per joint: 99th percentile / largest; "
         "at a searched offset of the large-offset test's or more: the largest (frames):";
  const char* separator = " ";
  for (auto& [joint, gains] : all) {
    std::sort(gains.begin(), gains.end());
    out << separator << joint << " " << fixed_text(quantile(gains, 0.99), 0) << " / "
        << fixed_text(gains.back(), 0);
    const std::vector<double>& at_large = large[joint];
    const auto largest = std::max_element(at_large.begin(), at_large.end());
    out << " (" << (largest == at_large.end() ? std::string("-") : fixed_text(*largest, 0)) << ", "
        << at_large.size() << ")";
    separator = ", ";
  }
  out << "\n";
  return out.str();
}

// "; the naming search's gain of the joint ..." for a missed joint offset
// (its median and largest over the frames from the onset); "" without.
std::string fault_search_gain_text(std::vector<double> gains) {
  if (gains.empty()) return "";
  std::sort(gains.begin(), gains.end());
  return "; the naming search's gain of the joint from the onset: median " +
         fixed_text(quantile(gains, 0.5), 0) + ", largest " + fixed_text(gains.back(), 0) + " chi^2";
}

}  // namespace

std::string campaign_report(const std::string& arm, const std::vector<CampaignResult>& results,
                            double frame_period_s) {
  struct Tally {
    int runs = 0, detected = 0, right_cause = 0, right_suspect = 0, false_stops = 0, safe_after = 0,
        switches = 0, frames = 0;
    std::vector<double> latency_s;
    int64_t scores = 0, scores_beyond_4 = 0;
    double score_sum_sq = 0, score_max_abs = 0;
    int64_t differences = 0;
    double difference_sum_sq = 0;
  };
  // By group, then magnitude (numerically).
  std::map<std::pair<std::string, double>, Tally> by_kind;
  std::ostringstream misses;
  int64_t nominal_frames = 0;
  int nominal_false_stops = 0;
  for (const CampaignResult& r : results) {
    if (r.object) continue;  // object_report
    const std::string kind = r.group.empty() ? "nominal" : r.group;
    Tally& t = by_kind[{kind, r.magnitude}];
    t.scores += r.nominal_scores;
    t.score_sum_sq += r.nominal_score_sum_sq;
    t.scores_beyond_4 += r.nominal_scores_beyond_4;
    t.score_max_abs = std::max(t.score_max_abs, r.nominal_score_max_abs);
    t.differences += r.nominal_differences;
    t.difference_sum_sq += r.nominal_difference_sum_sq;
    ++t.runs;
    t.frames += r.frames_judged;
    t.false_stops += r.false_stop ? 1 : 0;
    if (r.false_stop)
      misses << "- " << arm << ", " << r.label << ": false stop, " << r.false_stop_detail << "\n";
    if (kind == "nominal") {
      nominal_frames += r.frames_judged;
      nominal_false_stops += r.false_stop ? 1 : 0;
      continue;
    }
    t.detected += r.stopped ? 1 : 0;
    t.right_cause += r.right_cause ? 1 : 0;
    t.right_suspect += r.right_suspect ? 1 : 0;
    t.safe_after += r.safe_after_stop;
    t.switches += r.suspect_changes;
    if (r.stopped) t.latency_s.push_back(r.stop_latency_s);
    if (std::getenv("TOFGUARD_CAMPAIGN_VERBOSE") != nullptr) {
      misses << "  " << r.label << " (" << r.changed_pixels
             << " px changed): " << (r.stopped ? std::to_string(r.stop_frames) + " frames, " : "no stop, ")
             << risk_cause_name(r.cause) << " " << r.suspect << ": " << r.detail << "\n";
    }
    if (!r.stopped) {
      misses << "- " << arm << ", " << r.label << ": not detected (the fault changes " << r.changed_pixels
             << " pixels by more than 3 sigma" << fault_search_gain_text(r.fault_search_gain) << ")\n";
    } else if (!r.right_suspect) {
      misses << "- " << arm << ", " << r.label << ": stopped as " << risk_cause_name(r.cause)
             << (r.suspect.empty() ? "" : " " + r.suspect) << " (" << r.detail << ")\n";
    }
    if (r.safe_after_stop > 0 || r.suspect_changes > 0) {
      misses << "- " << arm << ", " << r.label << ": after the stop " << r.safe_after_stop << " SAFE, "
             << r.suspect_changes << " other cause/suspect\n";
    }
  }
  if (by_kind.empty()) return "";
  std::ostringstream out;
  out << "| " << arm
      << " | runs | frames | detected | right cause | right suspect at stop | latency from onset, median / "
         "p99 / max (ms) | SAFE after stop | suspect changes | false stops |\n"
      << "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (auto& [key, t] : by_kind) {
    const auto& [group, magnitude] = key;
    out << "| " << group << magnitude_text(group, magnitude) << " | " << t.runs << " | " << t.frames << " | "
        << t.detected << " | " << t.right_cause << " | " << t.right_suspect << " | "
        << latency_text(t.latency_s) << " | " << t.safe_after << " | " << t.switches << " | " << t.false_stops
        << " |\n";
  }
  if (nominal_frames > 0) {
    const double hours = static_cast<double>(nominal_frames) * frame_period_s / 3600;
    out << "\nNominal: " << nominal_frames << " frames (" << fixed_text(hours * 60, 1) << " min at "
        << fixed_text(1 / frame_period_s, 0) << " Hz), " << nominal_false_stops << " false stops ("
        << fixed_text(nominal_false_stops / hours, 1) << " per hour)\n";
  }
  int64_t scores = 0, beyond = 0, differences = 0;
  double sum_sq = 0, max_abs = 0, difference_sum_sq = 0;
  for (const auto& [kind, t] : by_kind) {
    differences += t.differences;
    difference_sum_sq += t.difference_sum_sq;
    scores += t.scores;
    beyond += t.scores_beyond_4;
    sum_sq += t.score_sum_sq;
    max_abs = std::max(max_abs, t.score_max_abs);
  }
  if (scores > 0) {
    out << "\nFault-free frames: " << scores
        << " standardised scores s/sqrt(I) (joints, camera axes): variance "
        << fixed_text(sum_sq / static_cast<double>(scores), 2) << " (N(0,1): 1), beyond 4: " << beyond << " ("
        << fixed_text(1e6 * static_cast<double>(beyond) / static_cast<double>(scores), 0)
        << " per million; N(0,1): 63), largest |t| " << fixed_text(max_abs, 1)
        << "; from frame to frame (noise alone): variance "
        << fixed_text(differences > 0 ? difference_sum_sq / static_cast<double>(differences) : 0, 2) << "\n";
  }
  out << smallest_offsets_text(results);
  out << search_gains_text(results);
  const std::string m = misses.str();
  if (!m.empty()) out << "\n" << m;
  return out.str();
}

std::string object_report(const std::string& arm, const std::vector<CampaignResult>& results,
                          const deployment::Config& config) {
  struct Tally {
    int runs = 0, detected = 0, right_cause = 0, false_stops = 0, frames = 0, warnings = 0, pixels = 0;
    bool expected = true;
    std::vector<double> latency_s;
    std::vector<double> onset_m, min_m, at_stop_m, s_m, first_seen_m;
  };
  const risk::RiskSettings& r = config.risk;
  // What the person covers after the verdict while the chain and the robot
  // stop, at K: the stop must come at least this much farther than C.
  const double after_verdict_m =
      r.field_approach_speed_m_s * (r.field_chain_latency_us + r.field_stopping_time_us) * 1e-6 +
      r.field_stopping_distance_m;
  std::map<std::string, Tally> by_kind;
  std::vector<std::string> order;
  std::ostringstream misses;
  const auto cm = [](double m) { return fixed_text(100 * m, 0); };
  for (const CampaignResult& res : results) {
    if (!res.object) continue;
    if (by_kind.find(res.label) == by_kind.end()) order.push_back(res.label);
    Tally& t = by_kind[res.label];
    ++t.runs;
    t.expected = res.expected_stop;
    t.frames += res.frames_judged;
    t.warnings += res.warnings_after_onset;
    t.pixels += res.object_pixels;
    t.onset_m.push_back(res.object_distance_at_onset_m);
    if (res.object_first_seen_m >= 0) t.first_seen_m.push_back(res.object_first_seen_m);
    t.min_m.push_back(res.object_min_distance_m);
    t.false_stops += res.false_stop ? 1 : 0;
    if (res.false_stop)
      misses << "- " << arm << ", " << res.label << ": false stop, " << res.false_stop_detail << "\n";
    if (!res.expected_stop) {
      // Only a stop inside S at the time (the arm's speed grew the field).
      t.detected += res.stopped ? 1 : 0;
      t.right_cause += res.right_cause ? 1 : 0;
      if (res.stopped) t.s_m.push_back(res.stop_threshold);
      continue;
    }
    t.detected += res.stopped ? 1 : 0;
    t.right_cause += res.right_cause ? 1 : 0;
    if (res.stopped) {
      t.latency_s.push_back(res.stop_latency_s);
      t.at_stop_m.push_back(res.object_distance_at_stop_m);
      if (res.right_cause) t.s_m.push_back(res.stop_threshold);
    }
    if (!res.stopped) {
      misses << "- " << arm << ", " << res.label << ": not stopped (" << res.object_pixels << " px seen, "
             << cm(res.object_distance_at_onset_m) << " cm from the arm at the onset, "
             << cm(res.object_min_distance_m) << " cm at the nearest)\n";
    } else if (!res.right_cause) {
      misses << "- " << arm << ", " << res.label << ": stopped as " << risk_cause_name(res.cause) << " ("
             << res.detail << ")\n";
    }
    // An object that approaches into view from beyond S must be stopped
    // while it is farther than C plus what it covers until the arm has
    // halted (ISO 13855's promise); one first seen inside S cannot be
    // (the camera's view limits the field).
    if (res.approaching && res.object_first_seen_m >= 0 && res.stopped &&
        res.object_first_seen_m < res.stop_threshold) {
      misses << "- " << arm << ", " << res.label << ": first in view " << cm(res.object_first_seen_m)
             << " cm from the arm, inside S = " << cm(res.stop_threshold) << " cm\n";
    } else if (res.approaching && res.stopped &&
               res.object_distance_at_stop_m - after_verdict_m < r.field_intrusion_distance_m) {
      misses << "- " << arm << ", " << res.label << ": stopped at " << cm(res.object_distance_at_stop_m)
             << " cm: less than C + K (latency + T_s) + S_s = "
             << cm(r.field_intrusion_distance_m + after_verdict_m) << " cm\n";
    }
  }
  const auto median = [](std::vector<double> v) {
    if (v.empty()) return std::string("-");
    std::sort(v.begin(), v.end());
    return fixed_text(100 * v[v.size() / 2], 0);
  };
  const auto least = [](const std::vector<double>& v) {
    return v.empty() ? std::string("-") : fixed_text(100 * *std::min_element(v.begin(), v.end()), 0);
  };
  std::ostringstream out;
  out << "| " << arm
      << " | runs | in the field at rest | object px at onset (mean) | distance at onset, median (cm) | "
         "first in view, "
         "median (cm) | nearest (cm) | "
         "stopped | as unknown object | latency from onset, median / p99 / max (ms) | distance at the stop, "
         "least (cm) "
         "| "
         "S at the stop, median (cm) | WARNING frames | false stops |\n"
      << "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const std::string& kind : order) {
    Tally& t = by_kind[kind];
    out << "| " << kind << " | " << t.runs << " | " << (t.expected ? "yes" : "no") << " | "
        << t.pixels / t.runs << " | " << median(t.onset_m) << " | " << median(t.first_seen_m) << " | "
        << least(t.min_m) << " | " << t.detected << " | " << t.right_cause << " | "
        << latency_text(t.latency_s) << " | " << least(t.at_stop_m) << " | " << median(t.s_m) << " | "
        << t.warnings << " | " << t.false_stops << " |\n";
  }
  const std::string m = misses.str();
  if (!m.empty()) out << "\n" << m;
  return out.str();
}

std::string campaign_tsv(const std::string& arm, const std::vector<CampaignResult>& results, bool header) {
  std::ostringstream out;
  if (header) {
    out << "arm\tgroup\tmagnitude\tunit\tlabel\texpected_stop\tstopped\tright_cause\tright_suspect\t"
           "latency_ms\tfalse_stop\tframes\tchanged_pixels\n";
  }
  for (const CampaignResult& r : results) {
    out << arm << "\t" << (r.group.empty() ? "nominal" : r.group) << "\t" << r.magnitude << "\t"
        << magnitude_unit(r.group) << "\t" << r.label << "\t" << r.expected_stop << "\t" << r.stopped << "\t"
        << r.right_cause << "\t" << r.right_suspect << "\t"
        << (r.stopped ? fixed_text(1000 * r.stop_latency_s, 1) : std::string("")) << "\t" << r.false_stop
        << "\t" << r.frames_judged << "\t" << r.changed_pixels << "\n";
  }
  return out.str();
}

namespace {

struct PlotPoint {
  int runs = 0, detected = 0;
  std::vector<double> latency_ms;
};
// arm -> magnitude -> runs there.
using PlotSeries = std::map<std::string, std::map<double, PlotPoint>>;

// One panel: a curve per arm of `value(point, 0)` against the magnitude
// (and of `value(point, 1)`, thinner and open, when `with_second`), in the
// rectangle `area` of `image`; `value` returns NaN for no value.
template <typename Value>
void draw_panel(cv::Mat* image, const cv::Rect& area, const PlotSeries& series, const std::string& title,
                const std::string& x_label, double y_max, const std::string& y_label, Value value,
                bool with_second = false) {
  double x_max = 0;
  std::vector<double> ticks;
  for (const auto& [arm, points] : series)
    for (const auto& [m, p] : points) {
      x_max = std::max(x_max, m);
      if (std::find(ticks.begin(), ticks.end(), m) == ticks.end()) ticks.push_back(m);
    }
  x_max *= 1.08;
  if (!(y_max > 0)) y_max = 1;
  PanelStyle style;
  style.top = 70;
  style.title_scale = 0.6;
  style.tick_label_dx = -8;
  style.x_label_dx = -40;
  const PanelArea panel = draw_panel_frame(image, area, style, title, x_label, y_label, x_max, y_max, ticks);
  int i = 0;
  for (const auto& [arm, points] : series) {
    for (int curve = 0; curve < (with_second ? 2 : 1); ++curve) {
      std::vector<std::pair<double, double>> xy;
      for (const auto& [m, p] : points) xy.push_back({m, value(p, curve)});
      draw_curve(image, panel, xy, plot_colour(i), curve == 0);
    }
    ++i;
  }
}

}  // namespace

std::vector<std::string> plot_campaign(const std::string& tsv_text, const std::string& dir) {
  // (group, robot) -> (unit, series by the rest of the arm's name: its
  // rate and placement). The robot is the arm's name before ", ".
  std::map<std::pair<std::string, std::string>, std::pair<std::string, PlotSeries>> plots;
  std::istringstream in(tsv_text);
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream fields(line);
    for (std::string field; std::getline(fields, field, '\t');) f.push_back(field);
    if (f.size() < 13 || f[0] == "arm" || f[3].empty() || f[5] != "1") continue;  // sized faults
    const size_t comma = f[0].find(", ");
    const std::string robot = f[0].substr(0, comma);
    const std::string variant = comma == std::string::npos ? "as configured" : f[0].substr(comma + 2);
    auto& [unit, series] = plots[{f[1], robot}];
    unit = f[3];
    PlotPoint& p = series[variant][std::stod(f[2])];
    ++p.runs;
    if (f[6] == "1") {
      ++p.detected;
      p.latency_ms.push_back(std::stod(f[9]));
    }
  }
  // A file name of `text`: lower-case letters and digits, '-' between.
  const auto slug = [](const std::string& text) {
    std::string out;
    for (char c : text) {
      if (std::isalnum(static_cast<unsigned char>(c)) != 0) {
        out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      } else if (!out.empty() && out.back() != '-') {
        out += '-';
      }
    }
    while (!out.empty() && out.back() == '-') out.pop_back();
    return out;
  };
  fs::create_directories(dir);
  std::vector<std::string> written;
  for (auto& [key, unit_series] : plots) {
    const auto& [group, robot] = key;
    auto& [unit, series] = unit_series;
    double latency_max = 0;
    for (auto& [variant, points] : series)
      for (auto& [m, p] : points) {
        std::sort(p.latency_ms.begin(), p.latency_ms.end());
        if (!p.latency_ms.empty()) latency_max = std::max(latency_max, quantile(p.latency_ms, 0.99));
      }
    // The latency axis up to a round number: 1, 2 or 5 times a power of 10.
    const double latency_axis = round_axis(latency_max, 1);
    const int legend_h = 22 * static_cast<int>(series.size()) + 20;
    cv::Mat image(560 + legend_h, 900, CV_8UC3, cv::Scalar(255, 255, 255));
    const std::string x_label = group + " (" + unit + ")";
    draw_panel(&image, {0, 0, 450, 560}, series, robot + ": detection rate", x_label, 100,
               "% of runs stopped", [](const PlotPoint& p, int) { return 100.0 * p.detected / p.runs; });
    draw_panel(
        &image, {450, 0, 450, 560}, series, "latency from onset (median filled, p99 open)", x_label,
        latency_axis, "ms",
        [](const PlotPoint& p, int curve) {
          if (p.latency_ms.empty()) return std::nan("");
          return quantile(p.latency_ms, curve == 0 ? 0.5 : 0.99);
        },
        /*with_second=*/true);
    int i = 0;
    for (const auto& [variant, points] : series) {
      draw_legend_entry(&image, {30, 570 + 22 * i}, 40, 50, plot_colour(i), robot + ", " + variant);
      ++i;
    }
    const std::string path = dir + "/detection-" + slug(group) + "-" + slug(robot) + ".png";
    if (!cv::imwrite(path, image)) throw std::runtime_error(path + ": cannot write the plot");
    written.push_back(path);
  }
  return written;
}

}  // namespace tofguard::test
