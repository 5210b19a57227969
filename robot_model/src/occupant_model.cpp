#include "tofguard/robot_model/occupant_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tofguard::robot_model {
namespace {

RegionShape shape_of(const GeometryElement& g, const Eigen::Isometry3d& world_from_link,
                     const std::string& file, const std::string& link) {
  RegionShape shape;
  shape.frame_from_shape = world_from_link * g.link_from_geometry;
  switch (g.kind) {
    case GeometryElement::Kind::kBox:
      shape.kind = RegionShape::Kind::kBox;
      shape.box_half_size_m = g.box_size_m / 2;
      return shape;
    case GeometryElement::Kind::kSphere:
      shape.kind = RegionShape::Kind::kSphere;
      shape.radius_m = g.radius_m;
      return shape;
    case GeometryElement::Kind::kCylinder:
      shape.kind = RegionShape::Kind::kCylinder;
      shape.radius_m = g.radius_m;
      shape.half_length_m = g.length_m / 2;
      return shape;
    default:
      throw ModelError(file + ": occupant link '" + link +
                       "': a geometry other than box, sphere or cylinder (the occupant's regions are "
                       "primitives, so that the distance to them is exact)");
  }
}

void check_fixed_joints_only(const KinematicTree& tree, const std::string& file) {
  for (const Joint& joint : tree.joints) {
    if (joint.type != JointType::kFixed) {
      throw ModelError(file + ": occupant joint '" + joint.name +
                       "' moves (expected fixed joints only: where the real body may be beyond the "
                       "model is each region's envelope in the config)");
    }
  }
}

}  // namespace

std::vector<BodyRegion> OccupantModel::regions() const {
  std::vector<BodyRegion> out;
  for (const OccupantPart& part : parts) {
    if (std::find(out.begin(), out.end(), part.region) == out.end()) out.push_back(part.region);
  }
  std::sort(out.begin(), out.end());
  return out;
}

Eigen::Isometry3d fixed_link_pose(const KinematicTree& tree, const std::string& link) {
  if (tree.find_link(link) < 0) throw ModelError("no link '" + link + "' in the model");
  Eigen::Isometry3d root_from_link = Eigen::Isometry3d::Identity();
  for (const std::string& name : tree.chain_from_root(link)) {
    const int joint_index = tree.links[tree.find_link(name)].parent_joint;
    if (joint_index < 0) continue;
    const Joint& joint = tree.joints[joint_index];
    if (joint.type != JointType::kFixed) {
      throw ModelError("link '" + link + "' hangs on the moving joint '" + joint.name +
                       "' (expected a link fixed to its root)");
    }
    root_from_link = root_from_link * joint.parent_from_joint;
  }
  return root_from_link;
}

OccupantModel load_occupant(const std::string& urdf, const Eigen::Isometry3d& world_from_root) {
  const KinematicTree tree = load_kinematic_tree(urdf);
  check_fixed_joints_only(tree, urdf);
  OccupantModel model;
  model.file = urdf;
  for (const Link& link : tree.links) {
    if (link.visuals.empty()) continue;  // a frame, not a body part
    const std::optional<BodyRegion> region = body_region_of_link(link.name);
    if (!region) {
      throw ModelError(urdf + ": occupant link '" + link.name +
                       "' has geometry but no body region's name (expected one of " + body_region_names() +
                       ", optionally followed by _left or _right)");
    }
    OccupantPart part;
    part.link_name = link.name;
    part.region = *region;
    const Eigen::Isometry3d world_from_link = world_from_root * fixed_link_pose(tree, link.name);
    for (const GeometryElement& g : link.visuals)
      part.shapes.push_back(shape_of(g, world_from_link, urdf, link.name));
    model.parts.push_back(std::move(part));
  }
  if (model.parts.empty()) {
    throw ModelError(urdf +
                     ": the occupant has no body part (expected links with geometry named after "
                     "body regions)");
  }
  return model;
}

double distance_to_part_m(const OccupantPart& part, const Eigen::Vector3d& point_world) {
  double best = std::numeric_limits<double>::infinity();
  for (const RegionShape& shape : part.shapes) best = std::min(best, distance_to_shape_m(shape, point_world));
  return best;
}

}  // namespace tofguard::robot_model
