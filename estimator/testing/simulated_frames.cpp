#include "simulated_frames.hpp"

#include <stdexcept>

#include "estimator_process.hpp"
#include "kinematics.hpp"

namespace tofguard::estimator::testing {

SimulatedFrames::SimulatedFrames(const Config& config)
    : config_(config),
      scene_(load_estimator_scene(config)),
      renderer_(std::make_unique<renderer::DepthRenderer>(scene_, config.renderer.near_m, config.renderer.far_m)),
      calibration_(config.camera.depth_calibration.enabled ? config.camera.depth_calibration.coefficients_m
                                                           : std::vector<double>{}) {}

std::vector<float> SimulatedFrames::capture(const renderer::JointPositions& true_joints,
                                            const Eigen::Isometry3d& true_world_from_optical,
                                            const Intrinsics& intrinsics, uint64_t frame_index,
                                            const std::vector<renderer::ExtraObject>& objects) {
  const renderer::LinkPoses poses = renderer::forward_kinematics(scene_, true_joints);
  if (!poses.usable) throw std::runtime_error(poses.unusable_reason);
  const renderer::RenderResult rendered = renderer_->render_at(poses, true_world_from_optical, intrinsics, objects);
  if (!rendered.usable) throw std::runtime_error(rendered.unusable_reason);
  const camera::TofErrorModel model(config_.camera.sim, intrinsics);
  camera::TofImage image = model.apply(rendered.depth_m, frame_index);
  calibration_.apply_z(&image.depth_m, camera::RadialToZ(intrinsics));
  return image.depth_m;
}

}  // namespace tofguard::estimator::testing
