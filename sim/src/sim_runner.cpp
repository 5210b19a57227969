#include <cmath>
#include <iostream>
#include <memory>
#include <optional>
#include <utility>

#include "tofguard/camera/depth_calibration.hpp"
#include "tofguard/common/camera_pose_message.hpp"
#include "tofguard/common/clock.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/common/lcm_node.hpp"
#include "tofguard/common/wire_checks.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/renderer/depth_renderer.hpp"
#include "tofguard/renderer/rendered_occupant.hpp"
#include "tofguard/robot_model/scene_model.hpp"
#include "tofguard/sim/sim_camera.hpp"
#include "tofguard/sim/sim_camera_runner.hpp"
#include "tofguard/sim_camera_fault_t.hpp"

namespace tofguard::sim {
namespace {

// The real scene: the URDF robot and environment through the renderer
// library. Boxes become the renderer's extra objects.
class UrdfSceneRenderer : public SceneRenderer {
 public:
  explicit UrdfSceneRenderer(const SimCameraProcessSettings& settings) {
    robot_model::SceneOptions options;
    // The camera sees the real surfaces: visual geometry, no safety padding.
    options.geometry = robot_model::GeometrySource::kVisual;
    options.padding_m = 0;
    options.package_paths = settings.robot.package_paths;
    scene_ = robot_model::load_scene(settings.robot.urdf_path, settings.environment.urdf_paths, options);
    renderer_ = std::make_unique<renderer::DepthRenderer>(scene_, settings.near_m, settings.far_m);
  }

  RenderedDepth render(const std::map<std::string, double>& joints, const CameraPose& pose,
                       const Intrinsics& intrinsics, const std::vector<SimBox>& boxes,
                       const std::vector<RegionShape>& user) override {
    std::vector<renderer::ExtraObject> extra;
    for (const SimBox& box : boxes) {
      extra.push_back(
          renderer::ExtraObject::box(box.size_m, Eigen::Isometry3d(Eigen::Translation3d(box.center_m))));
    }
    for (const RegionShape& shape : user) extra.push_back(renderer::extra_object_of(shape));
    renderer::RenderResult result = renderer_->render(joints, pose, intrinsics, extra);
    RenderedDepth out;
    out.usable = result.usable;
    out.unusable_reason = result.unusable_reason;
    out.depth_m = std::move(result.depth_m);
    return out;
  }

  const std::string& description() const { return renderer_->description(); }

  // The simulated user of `sim` seated in this scene; none without one.
  // Throws robot_model::ModelError for a bad model or seat.
  std::optional<SimulatedUser> simulated_user(const SimCameraSettings& sim) const {
    if (!sim.user) return std::nullopt;
    Eigen::Isometry3d world_from_seat;
    try {
      world_from_seat = robot_model::fixed_link_pose(scene_, sim.user->seated_on);
    } catch (const robot_model::ModelError& e) {
      throw robot_model::ModelError("camera.sim.user.seated_on '" + sim.user->seated_on + "': " + e.what());
    }
    return SimulatedUser(robot_model::load_occupant(sim.user->urdf_path, world_from_seat), world_from_seat,
                         *sim.user);
  }

 private:
  robot_model::SceneModel scene_;
  std::unique_ptr<renderer::DepthRenderer> renderer_;
};

ActiveSimFault to_fault(const sim_camera_fault_t& m, int64_t now_utime) {
  static const char* kinds[] = {"", "frozen_image", "stall", "pose_drift", "intruding_object"};
  ActiveSimFault f;
  f.fault.kind = kinds[m.kind];
  f.fault.drift_translation_m_per_s = Eigen::Vector3d(m.drift_translation_m_per_s);
  f.fault.drift_rotation_rad_per_s = Eigen::Vector3d(m.drift_rotation_rad_per_s);
  f.fault.object_size_m = Eigen::Vector3d(m.object_size_m);
  f.fault.object_position_m = Eigen::Vector3d(m.object_position_m);
  f.fault.object_velocity_m_per_s = Eigen::Vector3d(m.object_velocity_m_per_s);
  f.start_utime = now_utime;
  f.end_utime = now_utime + static_cast<int64_t>(m.duration_s * 1e6);
  f.fault.duration_us = f.end_utime - f.start_utime;
  return f;
}

}  // namespace

int run_sim_camera(const SimCameraProcessSettings& settings) {
  const CameraSettings& camera_config = settings.camera;
  std::unique_ptr<UrdfSceneRenderer> scene;
  std::optional<SimulatedUser> user;
  try {
    scene = std::make_unique<UrdfSceneRenderer>(settings);
    user = scene->simulated_user(settings.sim);
  } catch (const std::exception& e) {
    std::cerr << "tofguard-camera: cannot set up the simulated camera's renderer: " << e.what() << std::endl;
    return 1;
  }
  std::cerr << "tofguard-camera: simulated ToF camera " << camera_config.id << " rendering with "
            << scene->description() << std::endl;

  LcmNode node(settings.lcm, settings.channels, "tofguard-camera");
  SimulatedCamera sim(camera_config, settings.sim, scene.get(), wall_utime(), std::move(user));
  const camera::DepthCalibration calibration(settings.depth_calibration.coefficients_m);
  const camera::RadialToZ rays(camera_config.intrinsics);
  const bool calibrated = settings.depth_calibration.enabled;

  node.subscribe<joint_state_t>(
      node.safety(), settings.channels.sim_true_joint_state,
      [&](const joint_state_t& s) {
        if (!sim.add_true_joint_state(s.utime, s.name, s.position)) {
          node.errors().report("truth", settings.channels.sim_true_joint_state +
                                            ": utime not newer than the last state; ignored");
        }
      },
      check_joint_state);
  node.subscribe<sim_camera_fault_t>(
      node.safety(), settings.channels.sim_camera_fault,
      [&](const sim_camera_fault_t& m) {
        if (m.camera_id != camera_config.id) return;  // for another camera
        const int64_t now = wall_utime();
        if (m.kind == sim_camera_fault_t::CLEAR) {
          sim.clear_faults(now);
          std::cerr << "tofguard-camera: faults cleared" << std::endl;
          return;
        }
        const ActiveSimFault fault = to_fault(m, now);
        sim.inject(fault);
        std::cerr << "tofguard-camera: fault " << fault.fault.kind << " for " << m.duration_s << " s"
                  << std::endl;
      },
      check_sim_camera_fault);

  // Frame slots on the monotonic clock, camera.sim.exposure_offset_ms after
  // each whole period of it (cameras on one computer expose in turn); the
  // capture time is one period before publication (exposure and read-out
  // of a real camera), so that the true joint states around it have
  // arrived.
  const int64_t period_us = static_cast<int64_t>(std::llround(1e6 / camera_config.rate_hz));
  const int64_t offset_us = std::llround(settings.sim.exposure_offset_ms * 1000);
  const int64_t first_slot_us = (monotonic_us() / period_us + 1) * period_us + offset_us;
  const int64_t start_us = first_slot_us - period_us;
  int64_t last_slot = 0;
  node.heartbeat().set_status("starting: waiting for true joint states");
  node.add_timer(period_us, first_slot_us, [&] {
    const int64_t slot = (monotonic_us() - start_us + period_us / 2) / period_us;
    if (slot <= last_slot) return;
    if (slot > last_slot + 1) {
      node.counters().frames_dropped += slot - last_slot - 1;
      node.errors().report("late", "late: " + std::to_string(slot - last_slot - 1) + " frame slot(s) missed");
    }
    last_slot = slot;
    const int64_t capture_utime = wall_utime() - period_us;
    // The pan-tilt head's reading for this frame, before the frame, so that
    // the renderer has it when the frame comes (it follows the head).
    if (const std::optional<CameraPose> reported = sim.reported_pose(capture_utime)) {
      const camera_pose_t pose = to_camera_pose_message(camera_config.id, capture_utime, *reported);
      node.safety().publish(settings.channels.camera_pose, &pose);
    }
    const SimulatedCamera::Frame frame = sim.capture(capture_utime, static_cast<uint64_t>(slot));
    if (frame.outcome != SimulatedCamera::Frame::Outcome::kImage) {
      node.counters().frames_dropped++;
      node.errors().report("frame", "frame " + std::to_string(slot) + " not published: " + frame.why);
      node.heartbeat().set_status("no frame: " + frame.why);
      return;
    }
    std::vector<float> depth_m = frame.image.depth_m;
    if (calibrated) calibration.apply_z(&depth_m, rays);
    const depth_image_t image = make_depth_image(camera_config.id, camera_config.intrinsics, capture_utime,
                                                 slot, calibrated, depth_m, frame.image.amplitude);
    node.images().publish(settings.channels.depth, &image);
    node.counters().frames_out++;
    node.heartbeat().set_last_frame_utime(capture_utime);
    node.heartbeat().set_status(frame.frozen ? "publishing (frozen-image fault)" : "publishing");
  });
  node.run();
  return 0;
}

}  // namespace tofguard::sim
