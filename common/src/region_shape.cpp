#include "tofguard/common/region_shape.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tofguard {

double distance_to_shape_m(const RegionShape& shape, const Eigen::Vector3d& point) {
  // A rigid transform's inverse: the rotation's transpose.
  const Eigen::Vector3d p =
      shape.frame_from_shape.linear().transpose() * (point - shape.frame_from_shape.translation());
  switch (shape.kind) {
    case RegionShape::Kind::kSphere:
      return std::max(0.0, p.norm() - shape.radius_m);
    case RegionShape::Kind::kBox:
      return (p.cwiseAbs() - shape.box_half_size_m).cwiseMax(0.0).norm();
    case RegionShape::Kind::kCylinder: {
      const double radial = std::max(0.0, std::hypot(p.x(), p.y()) - shape.radius_m);
      const double axial = std::max(0.0, std::abs(p.z()) - shape.half_length_m);
      return std::hypot(radial, axial);
    }
  }
  return std::numeric_limits<double>::infinity();
}

}  // namespace tofguard
