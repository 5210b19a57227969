#include "tofguard/discrepancy/occupant_shapes.hpp"

#include <cmath>
#include <limits>

namespace tofguard::discrepancy {
namespace {

RegionShape shape_from_wire(const link_labels_t& labels, int k) {
  RegionShape shape;
  const std::vector<float>& size = labels.occupant_shape_size_m[k];
  switch (labels.occupant_shape_kind[k]) {
    case link_labels_t::SHAPE_SPHERE:
      shape.kind = RegionShape::Kind::kSphere;
      shape.radius_m = size[0];
      break;
    case link_labels_t::SHAPE_CYLINDER:
      shape.kind = RegionShape::Kind::kCylinder;
      shape.radius_m = size[0];
      shape.half_length_m = size[1];
      break;
    default:
      shape.kind = RegionShape::Kind::kBox;
      shape.box_half_size_m = Eigen::Vector3d(size[0], size[1], size[2]);
      break;
  }
  Eigen::Matrix3d rotation;
  for (int i = 0; i < 9; ++i) rotation(i / 3, i % 3) = labels.occupant_shape_rotation[k][i];
  const std::vector<float>& c = labels.occupant_shape_center_m[k];
  shape.frame_from_shape.linear() = rotation;
  shape.frame_from_shape.translation() = Eigen::Vector3d(c[0], c[1], c[2]);
  return shape;
}

// The farthest a point of the shape lies from its centre, metres.
double extent_m(const RegionShape& shape) {
  switch (shape.kind) {
    case RegionShape::Kind::kSphere:
      return shape.radius_m;
    case RegionShape::Kind::kCylinder:
      return std::hypot(shape.radius_m, shape.half_length_m);
    case RegionShape::Kind::kBox:
      return shape.box_half_size_m.norm();
  }
  return 0;
}

}  // namespace

OccupantShapes::OccupantShapes(const link_labels_t& labels) {
  envelope_m_.assign(labels.body_region_envelope_m.begin(), labels.body_region_envelope_m.end());
  shapes_.reserve(labels.num_occupant_shapes);
  for (int k = 0; k < labels.num_occupant_shapes; ++k) {
    Shape s;
    s.shape = shape_from_wire(labels, k);
    s.region = labels.occupant_shape_region[k];
    s.reach_m = extent_m(s.shape) + envelope_m_[s.region];
    shapes_.push_back(s);
  }
}

int OccupantShapes::region_holding(const Eigen::Vector3d& point) const {
  int region = -1;
  double nearest = std::numeric_limits<double>::infinity();
  for (const Shape& s : shapes_) {
    if ((point - s.shape.frame_from_shape.translation()).squaredNorm() > s.reach_m * s.reach_m) continue;
    const double d = distance_to_shape_m(s.shape, point);
    if (d <= envelope_m_[s.region] && d < nearest) {
      nearest = d;
      region = s.region;
    }
  }
  return region;
}

}  // namespace tofguard::discrepancy
