#include "tofguard/renderer/rendered_occupant.hpp"

#include <algorithm>
#include <string>

#include "tofguard/common/demand.hpp"

namespace tofguard::renderer {

ExtraObject extra_object_of(const RegionShape& shape) {
  switch (shape.kind) {
    case RegionShape::Kind::kSphere:
      return ExtraObject::sphere(shape.radius_m, shape.frame_from_shape);
    case RegionShape::Kind::kCylinder:
      return ExtraObject::cylinder(shape.radius_m, 2 * shape.half_length_m, shape.frame_from_shape);
    case RegionShape::Kind::kBox:
      break;
  }
  return ExtraObject::box(2 * shape.box_half_size_m, shape.frame_from_shape);
}

std::vector<ExtraObject> occupant_render_objects(const robot_model::OccupantModel& occupant) {
  std::vector<ExtraObject> objects;
  for (const robot_model::OccupantPart& part : occupant.parts) {
    for (const RegionShape& shape : part.shapes) objects.push_back(extra_object_of(shape));
  }
  return objects;
}

namespace {

int8_t wire_kind(RegionShape::Kind kind) {
  switch (kind) {
    case RegionShape::Kind::kBox:
      return link_labels_t::SHAPE_BOX;
    case RegionShape::Kind::kSphere:
      return link_labels_t::SHAPE_SPHERE;
    case RegionShape::Kind::kCylinder:
      return link_labels_t::SHAPE_CYLINDER;
  }
  return link_labels_t::SHAPE_BOX;
}

std::vector<float> wire_size_m(const RegionShape& shape) {
  switch (shape.kind) {
    case RegionShape::Kind::kBox:
      return {static_cast<float>(shape.box_half_size_m.x()), static_cast<float>(shape.box_half_size_m.y()),
              static_cast<float>(shape.box_half_size_m.z())};
    case RegionShape::Kind::kSphere:
      return {static_cast<float>(shape.radius_m), 0.0f, 0.0f};
    case RegionShape::Kind::kCylinder:
      return {static_cast<float>(shape.radius_m), static_cast<float>(shape.half_length_m), 0.0f};
  }
  return {0.0f, 0.0f, 0.0f};
}

}  // namespace

void set_rendered_occupant(const robot_model::OccupantModel& occupant, const OccupantSettings& settings,
                           const Eigen::Isometry3d& world_from_optical, link_labels_t* labels) {
  const auto region_index = [&](BodyRegion region) {
    const auto at =
        std::find(labels->body_region.begin(), labels->body_region.end(), body_region_name(region));
    TOFGUARD_DEMAND(at != labels->body_region.end(),
                    "an occupant region missing from the labels' body_region");
    return static_cast<int16_t>(at - labels->body_region.begin());
  };
  labels->body_region_envelope_m.clear();
  for (const std::string& name : labels->body_region) {
    const auto region = body_region_named(name);
    TOFGUARD_DEMAND(region && settings.regions.count(*region) == 1,
                    "a body region without its occupant settings");
    labels->body_region_envelope_m.push_back(static_cast<float>(settings.regions.at(*region).envelope_m));
  }
  const Eigen::Isometry3d optical_from_world = world_from_optical.inverse();
  labels->num_occupant_shapes = 0;
  labels->occupant_shape_kind.clear();
  labels->occupant_shape_region.clear();
  labels->occupant_shape_center_m.clear();
  labels->occupant_shape_rotation.clear();
  labels->occupant_shape_size_m.clear();
  for (const robot_model::OccupantPart& part : occupant.parts) {
    for (const RegionShape& shape : part.shapes) {
      const Eigen::Isometry3d optical_from_shape = optical_from_world * shape.frame_from_shape;
      const Eigen::Vector3d center = optical_from_shape.translation();
      const Eigen::Matrix3d rotation = optical_from_shape.linear();
      labels->occupant_shape_kind.push_back(wire_kind(shape.kind));
      labels->occupant_shape_region.push_back(region_index(part.region));
      labels->occupant_shape_center_m.push_back(
          {static_cast<float>(center.x()), static_cast<float>(center.y()), static_cast<float>(center.z())});
      std::vector<float> row_major(9);
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) row_major[3 * r + c] = static_cast<float>(rotation(r, c));
      labels->occupant_shape_rotation.push_back(std::move(row_major));
      labels->occupant_shape_size_m.push_back(wire_size_m(shape));
      labels->num_occupant_shapes++;
    }
  }
}

}  // namespace tofguard::renderer
