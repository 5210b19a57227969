#include "tofguard/common/camera_settings.hpp"

#include <cstdint>
#include <limits>

namespace tofguard {

// The rule is Intrinsics::check (camera_geometry.hpp); the YAML keys are its
// field names, so a violation names the key.
Intrinsics read_intrinsics(YamlMap& map) {
  constexpr double kAny = std::numeric_limits<double>::max();
  constexpr int64_t kAnyInt = std::numeric_limits<int>::max();
  const int width = static_cast<int>(map.integer("width", -kAnyInt, kAnyInt));
  const int height = static_cast<int>(map.integer("height", -kAnyInt, kAnyInt));
  const double fx = map.number("fx", -kAny, kAny);
  const double fy = map.number("fy", -kAny, kAny);
  const double cx = map.number("cx", -kAny, kAny);
  const double cy = map.number("cy", -kAny, kAny);
  if (auto v = Intrinsics::check(width, height, fx, fy, cx, cy)) map.fail(v->field, v->expected, v->got);
  return Intrinsics(width, height, fx, fy, cx, cy);
}

// The rule is CameraPose::check; `frame` is a non-empty string and the
// numbers are finite by YamlMap's reading, so only the quaternion's norm is
// left to refuse here, under its own key.
CameraPose read_camera_pose(YamlMap map) {
  const std::string frame = map.string("frame");
  const auto t = map.numbers("translation_m", 3);
  const auto q = map.numbers("rotation_wxyz", 4);
  const Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);
  if (auto v = UnitQuaternion::check(rotation, kConfigQuaternionTolerance, "rotation_wxyz")) {
    map.fail(v->field, v->expected, v->got);
  }
  map.finish();
  return CameraPose(frame, Eigen::Vector3d(t[0], t[1], t[2]),
                    UnitQuaternion(rotation, kConfigQuaternionTolerance));
}

}  // namespace tofguard
