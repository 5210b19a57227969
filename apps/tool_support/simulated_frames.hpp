#pragma once
// Depth frames as the simulated ToF camera publishes them, made in-process
// for the estimator's tests and benchmark: the URDF scene rendered with the
// renderer library at the true joints and the true camera pose, the camera's
// ToF error model (noise, mixed and invalid pixels, systematic error) applied,
// then the config's distance calibration, like tofguard-camera does.
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Geometry>

#include "tofguard/camera/depth_calibration.hpp"
#include "tofguard/deployment/config.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/estimator/motion_estimator.hpp"
#include "tofguard/renderer/depth_renderer.hpp"
#include "tofguard/robot_model/scene_model.hpp"
#include "tofguard/sim/tof_error_model.hpp"

namespace tofguard::test {

class SimulatedFrames {
 public:
  // The config's robot and environment (visual geometry, no padding: what
  // the camera sees), its camera's error model and calibration.
  explicit SimulatedFrames(const deployment::Config& config);

  // Calibrated Z in metres (0 = no return), row-major, for `intrinsics`.
  // `frame_index` selects the noise, and the frame is taken frame_index /
  // camera.rate_hz seconds after the camera started (the error model's
  // warm-up drift). Throws std::runtime_error when the
  // scene cannot be rendered.
  std::vector<float> capture(const robot_model::JointPositions& true_joints,
                             const Eigen::Isometry3d& true_world_from_optical, const Intrinsics& intrinsics,
                             uint64_t frame_index, const std::vector<renderer::ExtraObject>& objects = {});

  // The frames an estimate is made of (estimator.frames_per_estimate):
  // the frame at `true_joints` (index `*frame_index + 1`) and the
  // num_frames - 1 frames before it at 30 Hz, the arm moving meanwhile
  // (every joint 0.5 degrees a frame), each reporting its joints with
  // `offset_rad` added to `joint` (an encoder offset; 0: none) and the
  // camera where it is. Advances *frame_index by num_frames.
  std::vector<estimator::EstimatorFrame> frames_with_offset(const robot_model::JointPositions& true_joints,
                                                            const Eigen::Isometry3d& world_from_optical,
                                                            const Intrinsics& intrinsics,
                                                            const std::string& joint, double offset_rad,
                                                            int num_frames, uint64_t* frame_index);

  const robot_model::SceneModel& scene() const { return scene_; }
  // The renderer, to share with an estimator on the same thread.
  renderer::DepthRenderer& renderer() { return *renderer_; }

 private:
  deployment::Config config_;
  robot_model::SceneModel scene_;
  std::unique_ptr<renderer::DepthRenderer> renderer_;
  camera::DepthCalibration calibration_;
};

}  // namespace tofguard::test
