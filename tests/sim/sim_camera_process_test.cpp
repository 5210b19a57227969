// tofguard-camera with the simulated camera as a real process over real LCM
// (private network namespace) and real EGL rendering: frames at the
// embedded default's camera with seq counting frame slots (a missed slot
// leaves its gap, the capture times as many periods apart), calibrated,
// amplitude; a run-time stall fault stops the frames and is counted as
// dropped; an intruding box in front of the lens shows up at its distance.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <cmath>

#include "tofguard/common/camera_pose_message.hpp"
#include "tofguard/common/clock.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/deployment/config.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/heartbeat_t.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/renderer/depth_renderer.hpp"
#include "tofguard/renderer/renderer_service.hpp"
#include "tofguard/sim_camera_fault_t.hpp"
#include "tool_support.hpp"

namespace tofguard::test {
namespace {

const std::vector<double> kArm = {-0.3, 0.7, 0.0, 1.1, 0.0, 0.6, 0.0};

struct Rig {
  explicit Rig(const std::string& config_path = source_dir() + "/config/sim.yaml")
      : config(deployment::load_config(config_path, nullptr)) {
    images.subscribe("TOF_DEPTH", &Rig::on_depth, this);
    safety.subscribe("SAFETY_HEARTBEAT", &Rig::on_heartbeat, this);
    safety.subscribe("CAMERA_POSE", &Rig::on_pose, this);
  }
  deployment::Config config;
  lcm::LCM safety{config.lcm.url};
  lcm::LCM images{config.lcm.image_url};
  std::vector<depth_image_t> frames;
  std::map<int64_t, camera_pose_t> poses;  // by utime
  heartbeat_t heartbeat;
  int heartbeats = 0;
  int64_t last_truth_us = 0;

  void on_pose(const lcm::ReceiveBuffer*, const std::string&, const camera_pose_t* m) {
    poses[m->utime] = *m;
  }
  void on_depth(const lcm::ReceiveBuffer*, const std::string&, const depth_image_t* m) {
    frames.push_back(*m);
  }
  void on_heartbeat(const lcm::ReceiveBuffer*, const std::string&, const heartbeat_t* m) {
    if (m->process != "tofguard-camera") return;
    heartbeat = *m;
    ++heartbeats;
  }
  // The simulated arm's truth at 100 Hz (what tofguard-joints-sim sends).
  void pump() {
    if (monotonic_us() - last_truth_us >= 10000) {
      last_truth_us = monotonic_us();
      joint_state_t s;
      s.utime = wall_utime();
      s.robot_id = "friend-sim";
      s.num_joints = 7;
      s.name = {"a1", "a2", "a3", "a4", "a5", "a6", "a7"};
      s.position = kArm;
      s.velocity.assign(7, 0.0);
      safety.publish("SIM_TRUE_JOINT_STATE", &s);
    }
    safety.handleTimeout(1);
    images.handleTimeout(1);
  }
  void fault(int32_t kind, double duration_s, const Eigen::Vector3d& position = Eigen::Vector3d::Zero()) {
    sim_camera_fault_t f{};
    f.utime = wall_utime();
    f.camera_id = config.camera.id;
    f.kind = kind;
    f.duration_s = duration_s;
    for (int i = 0; i < 3; ++i) {
      f.drift_translation_m_per_s[i] = f.drift_rotation_rad_per_s[i] = 0;
      f.object_size_m[i] = 0.3;
      f.object_position_m[i] = position[i];
      f.object_velocity_m_per_s[i] = 0;
    }
    safety.publish("SIM_CAMERA_FAULT", &f);
  }
};

// Median valid depth of the 9x9 pixels around the principal point, mm.
int centre_depth_mm(const depth_image_t& f) {
  std::vector<int16_t> d;
  for (int v = static_cast<int>(f.cy) - 4; v <= static_cast<int>(f.cy) + 4; ++v)
    for (int u = static_cast<int>(f.cx) - 4; u <= static_cast<int>(f.cx) + 4; ++u)
      if (f.depth_mm[v * f.width + u] > 0) d.push_back(f.depth_mm[v * f.width + u]);
  if (d.size() < 20) return 0;
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

TEST(SimCameraProcess, PublishesFaultsAndRendersIntruders) {
  Rig rig;
  Subprocess camera("sim-camera",
                    {bin_dir() + "/tofguard-camera", "--config", source_dir() + "/config/sim.yaml"});
  ASSERT_TRUE(
      wait_until([&] { return rig.frames.size() >= 10; }, std::chrono::seconds(30), [&] { rig.pump(); }))
      << camera.stderr_text();
  // seq counts frame slots: the next frame is one slot on, or more when the
  // camera missed slots (late on a loaded machine, or no true joint state
  // yet at start), and its capture time is as many periods on (to within
  // half a period: the timer's jitter). At most 2 of the 10 steps may skip.
  const int64_t period_us = std::llround(1e6 / rig.config.camera.rate_hz);
  int skips = 0;
  for (size_t i = 1; i < rig.frames.size(); ++i) {
    const int64_t slots = rig.frames[i].seq - rig.frames[i - 1].seq;
    ASSERT_GE(slots, 1) << "seq " << rig.frames[i].seq << " after " << rig.frames[i - 1].seq;
    skips += slots > 1;
    EXPECT_NEAR(static_cast<double>(rig.frames[i].utime - rig.frames[i - 1].utime),
                static_cast<double>(slots * period_us), period_us / 2.0)
        << "seq " << rig.frames[i - 1].seq << " -> " << rig.frames[i].seq;
  }
  EXPECT_LE(skips, 2) << "missed slots in the first frames\n" << camera.stderr_text();
  const depth_image_t& f = rig.frames.back();
  EXPECT_EQ(f.camera_id, "tof-mast");
  EXPECT_EQ(f.width, 176);
  EXPECT_EQ(f.height, 144);
  EXPECT_TRUE(f.calibrated);
  EXPECT_EQ(f.num_pixels, 176 * 144);
  EXPECT_EQ(f.num_amplitude, 176 * 144);
  const auto valid = std::count_if(f.depth_mm.begin(), f.depth_mm.end(), [](int16_t d) { return d > 0; });
  EXPECT_GT(valid, 176 * 144 / 20) << "the arm and the environment are in view";
  EXPECT_LT(std::abs(wall_utime() - f.utime), 500000);

  // A 0.3 m box 0.6 m in front of the lens (its centre 0.75 m away).
  const Eigen::Vector3d optical_axis = rig.config.camera.pose.rotation * Eigen::Vector3d::UnitZ();
  rig.fault(sim_camera_fault_t::INTRUDING_OBJECT, 30.0,
            rig.config.camera.pose.translation_m + 0.75 * optical_axis);
  ASSERT_TRUE(wait_until(
      [&] {
        const int d = centre_depth_mm(rig.frames.back());
        return d > 450 && d < 750;
      },
      std::chrono::seconds(10), [&] { rig.pump(); }))
      << "centre depth " << centre_depth_mm(rig.frames.back()) << " mm\n"
      << camera.stderr_text();

  // Stall: no frames for 1 s, each lost slot counted as dropped.
  ASSERT_TRUE(wait_until([&] { return rig.heartbeats > 0; }, std::chrono::seconds(5), [&] { rig.pump(); }));
  const int64_t dropped_before = rig.heartbeat.frames_dropped;
  rig.fault(sim_camera_fault_t::STALL, 1.0);
  ASSERT_TRUE(wait_until([&] { return rig.heartbeat.frames_dropped >= dropped_before + 10; },
                         std::chrono::seconds(5), [&] { rig.pump(); }))
      << camera.stderr_text();
  const size_t frames_in_stall = rig.frames.size();
  const int64_t seq_before = rig.frames.back().seq;
  ASSERT_TRUE(wait_until([&] { return rig.frames.size() >= frames_in_stall + 3; }, std::chrono::seconds(5),
                         [&] { rig.pump(); }));
  EXPECT_GE(rig.frames.back().seq - seq_before, 10) << "lost slots leave a gap in seq";

  camera.signal(SIGTERM);
  EXPECT_EQ(camera.wait(std::chrono::seconds(5)), 0) << camera.stderr_text();
}

// Fraction of the robot's modelled pixels (rendered from `pose`) whose
// camera depth is within 30 mm of the model: about 1 when the camera was
// where `pose` says.
double robot_match_fraction(renderer::DepthRenderer* renderer, const depth_image_t& frame,
                            const CameraPose& pose) {
  robot_model::JointPositions joints;
  for (int i = 0; i < 7; ++i) joints["a" + std::to_string(i + 1)] = kArm[i];
  const Intrinsics k = intrinsics_of(frame);
  const renderer::RenderResult model = renderer->render(joints, pose, k);
  if (!model.usable) return -1;
  int robot = 0, match = 0;
  for (size_t i = 0; i < model.labels.size(); ++i) {
    if (!is_robot_label(model.labels[i]) || frame.depth_mm[i] <= 0) continue;
    ++robot;
    match += std::abs(frame.depth_mm[i] - model.depth_m[i] * 1000.0) < 30.0;
  }
  return robot > 200 ? static_cast<double>(match) / robot : -1;
}

TEST(SimCameraProcess, PanTiltHeadPublishesThePoseOfEachFrameAndAnOffsetReadingDisagrees) {
  // Pan +-10 deg (3 s), tilt +-3 deg (5 s); from 3 s on the head reads 8 deg
  // more pan than it has.
  const std::string config_path = sim_config_variant(
      "pan-tilt-camera",
      {{"    faults: []\n",
        "    faults: [{kind: pan_tilt_offset, start_s: 3.0, duration_s: 100, pan_offset_deg: 8, "
        "tilt_offset_deg: 0}]\n"
        "    pan_tilt: {pan_amplitude_deg: 10, pan_period_s: 3, tilt_amplitude_deg: 3, "
        "tilt_period_s: 5}\n"}});
  Rig rig(config_path);
  Subprocess camera("sim-camera-pan-tilt", {bin_dir() + "/tofguard-camera", "--config", config_path});
  ASSERT_TRUE(wait_until([&] { return !rig.frames.empty(); }, std::chrono::seconds(30), [&] { rig.pump(); }))
      << camera.stderr_text();
  // The camera started before its first frame's capture time.
  const int64_t first_utime = rig.frames.front().utime;
  ASSERT_TRUE(wait_until([&] { return rig.frames.back().utime > first_utime + 4'000'000; },
                         std::chrono::seconds(20), [&] { rig.pump(); }))
      << camera.stderr_text();
  // Whatever is still in flight.
  const int64_t until = monotonic_us() + 100'000;
  while (monotonic_us() < until) rig.pump();
  camera.signal(SIGTERM);
  EXPECT_EQ(camera.wait(std::chrono::seconds(5)), 0) << camera.stderr_text();

  const deployment::Config& config = rig.config;
  robot_model::SceneOptions options = renderer::scene_options(config.renderer, config.robot);
  options.padding_m = 0;
  const robot_model::SceneModel scene =
      robot_model::load_scene(config.robot.urdf_path, config.environment.urdf_paths, options);
  renderer::DepthRenderer renderer(scene, config.renderer.near_m, config.renderer.far_m);
  int consistent = 0, disagreeing = 0;
  double smallest_pan_deg = 1e9, largest_pan_deg = -1e9;
  for (const depth_image_t& frame : rig.frames) {
    // A pose for every frame, with its utime, about the configured pose.
    ASSERT_EQ(rig.poses.count(frame.utime), 1u) << "no CAMERA_POSE for the frame of seq " << frame.seq;
    const camera_pose_t& m = rig.poses.at(frame.utime);
    EXPECT_EQ(m.camera_id, "tof-mast");
    EXPECT_EQ(m.frame_id, config.camera.pose.frame_id);
    const CameraPose pose = from_camera_pose_message(m);
    EXPECT_LT((pose.translation_m - config.camera.pose.translation_m).norm(), 1e-9);
    const Eigen::Vector3d forward = pose.rotation * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d configured = config.camera.pose.rotation * Eigen::Vector3d::UnitZ();
    const double pan_deg =
        (std::atan2(forward.y(), forward.x()) - std::atan2(configured.y(), configured.x())) * 180 / M_PI;
    smallest_pan_deg = std::min(smallest_pan_deg, pan_deg);
    largest_pan_deg = std::max(largest_pan_deg, pan_deg);
    // The image was taken from the reported pose until the offset starts.
    const double fraction = robot_match_fraction(&renderer, frame, pose);
    if (frame.utime < first_utime + 2'500'000) {
      EXPECT_GT(fraction, 0.85) << "seq " << frame.seq;
      consistent += fraction > 0.85;
    } else if (frame.utime > first_utime + 3'500'000) {
      EXPECT_LT(fraction, 0.5) << "seq " << frame.seq;
      disagreeing += fraction < 0.5;
    }
  }
  EXPECT_GT(consistent, 20);
  EXPECT_GT(disagreeing, 5);
  // The head swept (almost) its whole range; with the offset up to 18 deg.
  EXPECT_LT(smallest_pan_deg, -8.0);
  EXPECT_GT(largest_pan_deg, 14.0);  // more than the head can turn: the offset
  EXPECT_LT(largest_pan_deg, 18.01);
}

}  // namespace
}  // namespace tofguard::test
