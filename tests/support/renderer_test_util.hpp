#pragma once
// Helpers for the renderer tests: the model test helpers
// (model_test_util.hpp), camera poses and images by pixel.
#include <filesystem>
#include <string>

#include <Eigen/Geometry>

#include "model_test_util.hpp"
#include "tofguard/renderer/depth_renderer.hpp"

namespace tofguard::renderer::test {

using tofguard::test::pose;
using tofguard::test::rpy_rotation;
using tofguard::test::write_test_file;

inline CameraPose camera_pose_in(const std::string& frame, const Eigen::Isometry3d& frame_from_optical) {
  CameraPose pose;
  pose.frame_id = frame;
  pose.translation_m = frame_from_optical.translation();
  pose.rotation = Eigen::Quaterniond(frame_from_optical.rotation());
  return pose;
}

inline int count_label(const RenderResult& result, int label) {
  int n = 0;
  for (int16_t l : result.labels) n += l == label;
  return n;
}

}  // namespace tofguard::renderer::test
