#pragma once
// A primitive of the occupant model's body regions (robot_model/
// occupant_model.hpp) and the exact distance from a point to its surface:
// the one geometry the renderer (separations from the arm) and
// tofguard-discrepancy (is a seen surface within a region's envelope?)
// share. Frame-agnostic: the shape's pose and the point are in the same
// frame (the world in robot_model, the camera's optical frame on the wire);
// metres.
#include <Eigen/Geometry>

namespace tofguard {

struct RegionShape {
  enum class Kind { kBox, kSphere, kCylinder };
  Kind kind = Kind::kBox;
  // The shape's own frame in the holder's frame: a box centred on it, a
  // cylinder centred on it along its z axis. A rigid transform.
  Eigen::Isometry3d frame_from_shape = Eigen::Isometry3d::Identity();
  Eigen::Vector3d box_half_size_m = Eigen::Vector3d::Zero();
  double radius_m = 0;       // sphere, cylinder
  double half_length_m = 0;  // cylinder
};

// Exact distance (m) from `point` (the shape's holder's frame) to the
// shape's surface, 0 inside.
double distance_to_shape_m(const RegionShape& shape, const Eigen::Vector3d& point);

}  // namespace tofguard
