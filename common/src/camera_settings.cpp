#include "tofguard/common/camera_settings.hpp"

#include <cmath>

namespace tofguard {
namespace {

constexpr double kBig = 1e9;

}  // namespace

Intrinsics read_intrinsics(YamlMap& map) {
  Intrinsics in;
  in.width = static_cast<int>(map.integer("width", 1, 8192));
  in.height = static_cast<int>(map.integer("height", 1, 8192));
  in.fx = map.number("fx", 1e-6, kBig);
  in.fy = map.number("fy", 1e-6, kBig);
  in.cx = map.number("cx", -kBig, kBig);
  in.cy = map.number("cy", -kBig, kBig);
  return in;
}

CameraPose read_camera_pose(YamlMap map) {
  CameraPose pose;
  pose.frame_id = map.string("frame");
  const auto t = map.numbers("translation_m", 3);
  pose.translation_m = Eigen::Vector3d(t[0], t[1], t[2]);
  const auto q = map.numbers("rotation_wxyz", 4);
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (std::abs(norm - 1.0) > 1e-6) {
    map.fail("rotation_wxyz", "a unit quaternion w, x, y, z (norm 1 within 1e-6)",
             "norm " + std::to_string(norm));
  }
  pose.rotation = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
  map.finish();
  return pose;
}

}  // namespace tofguard
