#include "judge_campaign.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

#include "simulated_frames.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/common/risk_names.hpp"
#include "tofguard/discrepancy/discrepancy_image.hpp"
#include "tofguard/renderer/rendered_kinematics.hpp"
#include "tofguard/risk/protective_field.hpp"
#include "tofguard/risk/risk_monitor.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/robot_model/arm_spheres.hpp"
#include "tofguard/robot_model/kinematic_tree.hpp"
#include "tofguard/robot_model/kinematics.hpp"

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
  return deployment::load_config(std::string(TOFGUARD_SOURCE_DIR) + "/config/sim.yaml", nullptr);
}

// The campaign judges frames only: no deadlines to feed, no estimate, no
// plan (each has its own tests).
void judge_frames_only(deployment::Config* config) {
  config->risk.required_heartbeats.clear();
  config->risk.estimate_enabled = false;
  config->risk.plan_enabled = false;
  config->risk.camera_pose_required = false;
}

double joint_position(const sim::JointMotion& m, double t_s) {
  return m.center + m.amplitude * std::sin(2 * kPi * t_s / m.period_s + m.phase_rad);
}
double joint_velocity(const sim::JointMotion& m, double t_s) {
  return m.amplitude * 2 * kPi / m.period_s * std::cos(2 * kPi * t_s / m.period_s + m.phase_rad);
}

// Pixels whose noise-free depth differs by more than 3 sigma(d) between the
// model at the true joints and pose and `reported_depth_m` (or that one
// has a surface and the other none).
int changed_pixels(renderer::DepthRenderer& model, const robot_model::SceneModel& scene,
                   const robot_model::JointPositions& true_joints, const Eigen::Isometry3d& true_pose,
                   const std::vector<float>& reported_depth_m, const Intrinsics& intrinsics,
                   const discrepancy::DepthNoise& noise) {
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

std::string fixed_text(double value, int decimals) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(decimals);
  s << value;
  return s.str();
}

}  // namespace

CampaignArm default_campaign_arm() {
  CampaignArm arm{"default arm (config/sim.yaml)", embedded_config()};
  judge_frames_only(&arm.config);
  return arm;
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

std::vector<CampaignRun> standard_fault_runs(const CampaignArm& arm,
                                             const std::vector<double>& joint_offsets_deg) {
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
    for (double deg : joint_offsets_deg) {
      CampaignFault f;
      f.kind = CampaignFault::Kind::kJointOffset;
      f.joint = m.joint;
      const double sign = (n++ % 2 == 0) ? 1.0 : -1.0;
      f.offset = sign * deg * kDegToRad;
      std::ostringstream label;
      label << m.joint << " " << (sign > 0 ? "+" : "-") << deg << " deg";
      f.label = label.str();
      add(f);
    }
  }
  struct CameraCase {
    const char* label;
    Eigen::Vector3d translation_m;
    Eigen::Vector3d rotation_axis;
    double rotation_deg;
  };
  const CameraCase cases[] = {
      {"camera 2 cm along x", {0.02, 0, 0}, Eigen::Vector3d::UnitX(), 0},
      {"camera 2 cm along y", {0, -0.02, 0}, Eigen::Vector3d::UnitX(), 0},
      {"camera 2 cm along z (optical axis)", {0, 0, 0.02}, Eigen::Vector3d::UnitX(), 0},
      {"camera 3 cm along z (optical axis)", {0, 0, -0.03}, Eigen::Vector3d::UnitX(), 0},
      {"camera turned 1 deg about x", {0, 0, 0}, Eigen::Vector3d::UnitX(), 1},
      {"camera turned 1 deg about y", {0, 0, 0}, Eigen::Vector3d::UnitY(), -1},
      {"camera turned 1 deg about z", {0, 0, 0}, Eigen::Vector3d::UnitZ(), 1},
  };
  for (const CameraCase& c : cases) {
    CampaignFault f;
    f.kind = CampaignFault::Kind::kCameraPose;
    f.camera_error = Eigen::Isometry3d::Identity();
    f.camera_error.translation() = c.translation_m;
    f.camera_error.linear() =
        Eigen::AngleAxisd(c.rotation_deg * kDegToRad, c.rotation_axis).toRotationMatrix();
    f.label = c.label;
    add(f);
  }
  return runs;
}

std::vector<CampaignRun> nominal_runs(double seconds, double run_s, uint64_t seed) {
  std::vector<CampaignRun> runs;
  const int frames_per_run = static_cast<int>(std::lround(run_s * 30));
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

std::vector<CampaignRun> object_runs(const CampaignArm& arm, const std::vector<double>& distances_m,
                                     double beyond_m) {
  const risk::RiskSettings& r = arm.config.risk;
  const risk::FieldSize at_rest =
      risk::field_size(r, risk::chain_response_time_s(r, arm.config.camera.rate_hz), 0);
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
    add(hand, start_s);
  }
  for (double start_s : {0.0, 2.0}) {
    CampaignFault person;
    person.object_size_m = Eigen::Vector3d(0.4, 0.3, 1.7);
    person.object_distance_m = at_rest.warning_m + beyond_m;
    person.object_side = side;
    side = -side;
    person.object_speed_m_s = 1.0;
    person.object_in_field = false;
    person.label = "person walking past";
    add(person, start_s);
    CampaignFault cart = person;
    cart.object_size_m = Eigen::Vector3d(0.6, 0.4, 0.8);
    cart.object_side = side;
    side = -side;
    cart.label = "cart passing";
    add(cart, start_s + 1.0);
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

}  // namespace

std::vector<CampaignResult> run_campaign(const CampaignArm& arm, const std::vector<CampaignRun>& runs) {
  const deployment::Config& config = arm.config;
  SimulatedFrames truth(config);
  // The model as tofguard-renderer loads it (the config's geometry and
  // padding), and the tree tofguard-risk loads.
  robot_model::SceneOptions options;
  options.geometry = robot_model::parse_geometry_source(config.renderer.geometry);
  options.padding_m = config.renderer.padding_m;
  options.package_paths = config.robot.package_paths;
  const robot_model::SceneModel model_scene =
      robot_model::load_scene(config.robot.urdf_path, config.environment.urdf_paths, options);
  renderer::DepthRenderer model(model_scene, config.renderer.near_m, config.renderer.far_m);
  const robot_model::ArmSpheres arm_cover =
      robot_model::cover_arm_with_spheres(model_scene, config.renderer.arm_cover_cell_m);
  // The objects' true distances: a finer cover (1 cm cells, within 3 cm
  // of the surface) than the renderer's.
  const robot_model::ArmSpheres truth_cover = robot_model::cover_arm_with_spheres(model_scene, 0.01);
  const robot_model::KinematicTree robot_tree = robot_model::load_kinematic_tree(config.robot.urdf_path);
  const discrepancy::Parameters parameters = discrepancy::parameters_from(config.discrepancy);
  const Intrinsics intrinsics = config.camera.intrinsics;
  const double period_s = 1.0 / config.camera.rate_hz;
  const auto period_us = static_cast<int64_t>(std::llround(period_s * 1e6));
  const Eigen::Isometry3d reported_pose = config.camera.pose.frame_from_optical();

  std::vector<CampaignResult> results;
  for (const CampaignRun& run : runs) {
    risk::RiskMonitor monitor(config.risk, config.channels, robot_tree, config.camera.rate_hz, 0);
    CampaignResult result;
    result.label = run.fault.label;
    const int num_frames = run.onset_frame + run.frames_after_onset;
    std::map<std::string, double> previous_t;
    const bool object_fault = run.fault.kind == CampaignFault::Kind::kObject;
    ObjectPath object_path;
    std::vector<renderer::ExtraObject> objects;
    double object_distance_m = 0;
    for (int k = 0; k < num_frames; ++k) {
      const double t_s = run.start_s + k * period_s;
      const int64_t now_us = (k + 1) * period_us;
      const bool faulty = run.fault.kind != CampaignFault::Kind::kNone && k >= run.onset_frame;
      robot_model::JointPositions true_joints;
      joint_state_t state{};
      state.utime = 1'700'000'000'000'000 + k * period_us;
      state.robot_id = config.robot.id;
      for (const sim::JointMotion& m : config.joints_sim.motion) {
        const double q = joint_position(m, t_s);
        true_joints[m.joint] = q;
        state.name.push_back(m.joint);
        state.position.push_back(
            q + (faulty && run.fault.kind == CampaignFault::Kind::kJointOffset && m.joint == run.fault.joint
                     ? run.fault.offset
                     : 0.0));
        state.velocity.push_back(joint_velocity(m, t_s));
      }
      state.num_joints = static_cast<int32_t>(state.name.size());
      robot_model::JointPositions reported_joints;
      for (int i = 0; i < state.num_joints; ++i) reported_joints[state.name[i]] = state.position[i];
      const Eigen::Isometry3d true_pose = faulty && run.fault.kind == CampaignFault::Kind::kCameraPose
                                              ? reported_pose * run.fault.camera_error
                                              : reported_pose;

      objects.clear();
      if (faulty && object_fault) {
        const robot_model::PlacedArmSpheres placed = robot_model::place_arm_spheres(
            truth_cover, robot_model::forward_kinematics(model_scene, true_joints));
        if (k == run.onset_frame) {
          object_path = place_object(run.fault, placed, true_pose, &model,
                                     robot_model::forward_kinematics(model_scene, true_joints), intrinsics);
        }
        renderer::ExtraObject box;
        box.kind = renderer::ExtraObject::Kind::kBox;
        box.size_m = run.fault.object_size_m;
        box.world_from_object.translation() =
            object_path.start + object_path.velocity * ((k - run.onset_frame) * period_s);
        objects.push_back(box);
        object_distance_m = box_to_arm_m(box.world_from_object.translation(), box.size_m / 2, placed);
        // The camera's view of it, without noise.
        const renderer::RenderResult seen = model.render_at(
            robot_model::forward_kinematics(model_scene, true_joints), true_pose, intrinsics, objects);
        int pixels = 0;
        for (int16_t label : seen.labels) pixels += label == kLabelExtraObjectFirst ? 1 : 0;
        if (k == run.onset_frame) {
          result.object_distance_at_onset_m = object_distance_m;
          result.object_min_distance_m = object_distance_m;
          result.object_pixels = pixels;
        }
        // First seen: as large as the smallest object counted, at 2 m.
        if (result.object_first_seen_m < 0 && pixels >= kObjectSeenPixels) {
          result.object_first_seen_m = object_distance_m;
        }
        result.object_min_distance_m = std::min(result.object_min_distance_m, object_distance_m);
      }
      const std::vector<float> depth_m = truth.capture(
          true_joints, true_pose, intrinsics, run.noise_seed * 100000 + static_cast<uint64_t>(k), objects);
      const depth_image_t camera =
          make_depth_image(config.camera.id, intrinsics, state.utime, k, /*calibrated=*/true, depth_m);

      const robot_model::LinkPoses poses = robot_model::forward_kinematics(model_scene, reported_joints);
      if (!poses.usable) throw std::runtime_error(poses.unusable_reason);
      const renderer::RenderResult rendered_result = model.render_at(poses, reported_pose, intrinsics);
      if (!rendered_result.usable) throw std::runtime_error(rendered_result.unusable_reason);
      const depth_image_t rendered = make_depth_image(config.camera.id, intrinsics, state.utime, k,
                                                      /*calibrated=*/true, rendered_result.depth_m);
      // Labels and kinematics as tofguard-renderer publishes them.
      const link_labels_t labels =
          renderer::make_rendered_link_labels(camera, rendered_result, model_scene, arm_cover);

      if (k == run.onset_frame && run.fault.kind != CampaignFault::Kind::kNone) {
        result.changed_pixels =
            changed_pixels(model, model_scene, true_joints, true_pose, rendered_result.depth_m, intrinsics,
                           parameters.tolerance.noise);
      }
      const discrepancy::DiscrepancyFrame frame =
          discrepancy::compute_discrepancy(camera, rendered, labels, parameters);
      if (k < run.onset_frame || run.fault.kind == CampaignFault::Kind::kNone) {
        const discrepancy_t& d = frame.summary;
        auto add_score = [&](double score, double information) {
          if (!(information > 0)) return;
          const double t = score / std::sqrt(information);
          ++result.nominal_scores;
          result.nominal_score_sum_sq += t * t;
          result.nominal_scores_beyond_4 += std::abs(t) > 4 ? 1 : 0;
          result.nominal_score_max_abs = std::max(result.nominal_score_max_abs, std::abs(t));
        };
        for (int j = 0; j < d.num_joints; ++j) {
          add_score(d.joint_score[j], d.joint_information[j]);
          if (!(d.joint_information[j] > 0)) continue;
          const double t = d.joint_score[j] / std::sqrt(d.joint_information[j]);
          const auto previous = previous_t.find(d.joint_name[j]);
          if (previous != previous_t.end()) {
            ++result.nominal_differences;
            result.nominal_difference_sum_sq += (t - previous->second) * (t - previous->second) / 2;
          }
          previous_t[d.joint_name[j]] = t;
        }
        if (std::getenv("TOFGUARD_CAMPAIGN_CAMERA_SCORES") != nullptr)
          for (int a = 0; a < 6 && d.evidence_available; ++a)
            add_score(d.camera_score[a], d.camera_information[7 * a]);
      }
      monitor.on_depth(now_us);
      monitor.on_joint_state(state, now_us);
      for (const risk_t& verdict : monitor.on_frame(frame.summary, now_us)) {
        ++result.frames_judged;
        // An object outside the protective field must never stop the arm:
        // its stops count as false stops, unless the arm's speed had grown
        // the field over it then (an UNKNOWN_OBJECT stop whose S reaches the
        // object's true distance, within the 3 cm the true distance's cover
        // may err).
        const bool inside_s_then =
            object_fault && verdict.seq >= run.onset_frame && verdict.level == risk_t::DANGEROUS &&
            verdict.cause == risk_t::CAUSE_UNKNOWN_OBJECT && object_distance_m <= verdict.threshold + 0.03;
        const bool after_onset =
            verdict.seq >= run.onset_frame && run.fault.kind != CampaignFault::Kind::kNone &&
            (!object_fault || run.fault.object_in_field || inside_s_then || result.stopped);
        if (verdict.seq >= run.onset_frame && verdict.level == risk_t::WARNING) ++result.warnings_after_onset;
        if (verdict.level == risk_t::DANGEROUS && !after_onset && !result.false_stop) {
          result.false_stop = true;
          result.false_stop_detail = "seq " + std::to_string(verdict.seq) + ": " + verdict.detail;
        }
        if (!after_onset) continue;
        if (!result.stopped) {
          if (verdict.level != risk_t::DANGEROUS) continue;
          result.stopped = true;
          result.stop_frames = static_cast<int>(verdict.seq) - run.onset_frame + 1;
          result.cause = verdict.cause;
          result.suspect = verdict.suspect;
          result.detail = verdict.detail;
          result.stop_score = verdict.score;
          result.stop_threshold = verdict.threshold;
          // Judged in the frame it belongs to: the object's distance then.
          result.object_distance_at_stop_m = object_distance_m;
          continue;
        }
        if (verdict.level == risk_t::SAFE) ++result.safe_after_stop;
        if (verdict.suspect != result.suspect || verdict.cause != result.cause) ++result.suspect_changes;
      }
    }
    if (run.fault.kind == CampaignFault::Kind::kJointOffset) {
      result.right_cause = result.stopped && result.cause == risk_t::CAUSE_JOINT_ERROR;
      result.right_suspect = result.right_cause && result.suspect == run.fault.joint;
    } else if (run.fault.kind == CampaignFault::Kind::kCameraPose) {
      result.right_cause = result.stopped && result.cause == risk_t::CAUSE_CALIBRATION_ERROR;
      result.right_suspect = result.right_cause;
    } else if (object_fault) {
      result.right_cause = result.stopped && result.cause == risk_t::CAUSE_UNKNOWN_OBJECT;
      result.right_suspect = result.right_cause;
      result.object = true;
      result.approaching = run.fault.object_approaches;
    }
    result.expected_stop =
        run.fault.kind != CampaignFault::Kind::kNone && !(object_fault && !run.fault.object_in_field);
    results.push_back(result);
  }
  return results;
}

std::string campaign_report(const std::string& arm, const std::vector<CampaignResult>& results,
                            double frame_period_s) {
  struct Tally {
    int runs = 0, detected = 0, right_cause = 0, right_suspect = 0, false_stops = 0, safe_after = 0,
        switches = 0, frames = 0;
    std::vector<int> latency;
    int64_t scores = 0, scores_beyond_4 = 0;
    double score_sum_sq = 0, score_max_abs = 0;
    int64_t differences = 0;
    double difference_sum_sq = 0;
  };
  std::map<std::string, Tally> by_kind;
  std::ostringstream misses;
  for (const CampaignResult& r : results) {
    if (r.object) continue;  // object_report
    std::string kind = r.label;
    if (r.label.rfind("camera", 0) == 0) {
      kind = "camera pose";
    } else if (r.label.rfind("object", 0) == 0 || r.label.rfind("hand", 0) == 0 ||
               r.label.rfind("person", 0) == 0 || r.label.rfind("cart", 0) == 0) {
      kind = r.label;
    } else if (r.label != "nominal") {
      // "<joint> +<deg> deg"
      const size_t sign = r.label.find_last_of("+-");
      kind = "joint offset " + r.label.substr(sign + 1);
    }
    Tally& t = by_kind[kind];
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
    if (kind == "nominal") continue;
    t.detected += r.stopped ? 1 : 0;
    t.right_cause += r.right_cause ? 1 : 0;
    t.right_suspect += r.right_suspect ? 1 : 0;
    t.safe_after += r.safe_after_stop;
    t.switches += r.suspect_changes;
    if (r.stopped) t.latency.push_back(r.stop_frames);
    if (std::getenv("TOFGUARD_CAMPAIGN_VERBOSE") != nullptr) {
      misses << "  " << r.label << " (" << r.changed_pixels
             << " px changed): " << (r.stopped ? std::to_string(r.stop_frames) + " frames, " : "no stop, ")
             << risk_cause_name(r.cause) << " " << r.suspect << ": " << r.detail << "\n";
    }
    if (!r.stopped) {
      misses << "- " << arm << ", " << r.label << ": not detected (the fault changes " << r.changed_pixels
             << " pixels by more than 3 sigma)\n";
    } else if (!r.right_suspect) {
      misses << "- " << arm << ", " << r.label << ": stopped as " << risk_cause_name(r.cause)
             << (r.suspect.empty() ? "" : " " + r.suspect) << " (" << r.detail << ")\n";
    }
    if (r.safe_after_stop > 0 || r.suspect_changes > 0) {
      misses << "- " << arm << ", " << r.label << ": after the stop " << r.safe_after_stop << " SAFE, "
             << r.suspect_changes << " other cause/suspect\n";
    }
  }
  std::ostringstream out;
  out << "| " << arm
      << " | runs | frames | detected | right cause | right suspect at stop | median / max frames to stop "
         "(ms) | SAFE after stop | suspect changes | false stops |\n"
      << "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (auto& [kind, t] : by_kind) {
    std::string latency = "-";
    if (!t.latency.empty()) {
      std::sort(t.latency.begin(), t.latency.end());
      const int median = t.latency[t.latency.size() / 2];
      const int max = t.latency.back();
      std::ostringstream l;
      l << median << " / " << max << " (" << std::lround(median * frame_period_s * 1000) << " / "
        << std::lround(max * frame_period_s * 1000) << ")";
      latency = l.str();
    }
    out << "| " << kind << " | " << t.runs << " | " << t.frames << " | " << t.detected << " | "
        << t.right_cause << " | " << t.right_suspect << " | " << latency << " | " << t.safe_after << " | "
        << t.switches << " | " << t.false_stops << " |\n";
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
  const std::string m = misses.str();
  if (!m.empty()) out << "\n" << m;
  return out.str();
}

std::string object_report(const std::string& arm, const std::vector<CampaignResult>& results,
                          const deployment::Config& config) {
  struct Tally {
    int runs = 0, detected = 0, right_cause = 0, false_stops = 0, frames = 0, warnings = 0, pixels = 0;
    bool expected = true;
    std::vector<int> latency;
    std::vector<double> onset_m, min_m, at_stop_m, s_m, first_seen_m;
  };
  const risk::RiskSettings& r = config.risk;
  // What the person covers after the verdict while the chain and the robot
  // stop, at K: the stop must come at least this much farther than C.
  const double after_verdict_m =
      r.field_approach_speed_m_s * (r.field_chain_latency_us + r.field_stopping_time_us) * 1e-6 +
      r.field_stopping_distance_m;
  const double period_s = 1.0 / config.camera.rate_hz;
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
      t.latency.push_back(res.stop_frames);
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
         "stopped | as unknown object | median / max frames to stop (ms) | distance at the stop, least (cm) "
         "| "
         "S at the stop, median (cm) | WARNING frames | false stops |\n"
      << "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const std::string& kind : order) {
    Tally& t = by_kind[kind];
    std::string latency = "-";
    if (!t.latency.empty()) {
      std::sort(t.latency.begin(), t.latency.end());
      const int med = t.latency[t.latency.size() / 2];
      const int max = t.latency.back();
      latency = std::to_string(med) + " / " + std::to_string(max) + " (" +
                std::to_string(std::lround(med * period_s * 1000)) + " / " +
                std::to_string(std::lround(max * period_s * 1000)) + ")";
    }
    out << "| " << kind << " | " << t.runs << " | " << (t.expected ? "yes" : "no") << " | "
        << t.pixels / t.runs << " | " << median(t.onset_m) << " | " << median(t.first_seen_m) << " | "
        << least(t.min_m) << " | " << t.detected << " | " << t.right_cause << " | " << latency << " | "
        << least(t.at_stop_m) << " | " << median(t.s_m) << " | " << t.warnings << " | " << t.false_stops
        << " |\n";
  }
  const std::string m = misses.str();
  if (!m.empty()) out << "\n" << m;
  return out.str();
}

}  // namespace tofguard::test
