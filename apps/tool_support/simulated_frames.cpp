#include "simulated_frames.hpp"

#include <stdexcept>

#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/estimator/estimator_process.hpp"
#include "tofguard/robot_model/kinematics.hpp"

namespace tofguard::test {

SimulatedFrames::SimulatedFrames(const deployment::Config& config)
    : config_(config),
      scene_(estimator::load_estimator_scene(deployment::estimator_process_settings(config))),
      renderer_(
          std::make_unique<renderer::DepthRenderer>(scene_, config.renderer.near_m, config.renderer.far_m)),
      calibration_(config.camera.depth_calibration.enabled ? config.camera.depth_calibration.coefficients_m
                                                           : std::vector<double>{}) {}

std::vector<float> SimulatedFrames::capture(const robot_model::JointPositions& true_joints,
                                            const Eigen::Isometry3d& true_world_from_optical,
                                            const Intrinsics& intrinsics, uint64_t frame_index,
                                            const std::vector<renderer::ExtraObject>& objects) {
  const robot_model::LinkPoses poses = robot_model::forward_kinematics(scene_, true_joints);
  if (!poses.usable) throw std::runtime_error(poses.unusable_reason);
  const renderer::RenderResult rendered =
      renderer_->render_at(poses, true_world_from_optical, intrinsics, objects);
  if (!rendered.usable) throw std::runtime_error(rendered.unusable_reason);
  const sim::TofErrorModel model(config_.camera.sim, intrinsics);
  sim::TofImage image = model.apply(rendered.depth_m, frame_index, frame_index / config_.camera.rate_hz);
  calibration_.apply_z(&image.depth_m, camera::RadialToZ(intrinsics));
  return image.depth_m;
}

std::vector<estimator::EstimatorFrame> SimulatedFrames::frames_with_offset(
    const robot_model::JointPositions& true_joints, const Eigen::Isometry3d& world_from_optical,
    const Intrinsics& intrinsics, const std::string& joint, double offset_rad, int num_frames,
    uint64_t* frame_index) {
  constexpr double kJointStepRad = 0.5 * 3.141592653589793 / 180;  // per frame
  std::vector<estimator::EstimatorFrame> frames;
  for (int k = 0; k < num_frames; ++k) {
    robot_model::JointPositions at = true_joints;
    for (auto& [name, position] : at) position -= k * kJointStepRad;
    estimator::EstimatorFrame frame;
    frame.intrinsics = intrinsics;
    frame.depth_m = capture(at, world_from_optical, intrinsics, ++*frame_index);
    frame.reported_joints = at;
    frame.reported_joints[joint] += offset_rad;
    frame.world_from_optical = world_from_optical;
    frames.push_back(std::move(frame));
  }
  return frames;
}

}  // namespace tofguard::test
