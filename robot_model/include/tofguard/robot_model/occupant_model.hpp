#pragma once
// The wheelchair's occupant as body regions: the user the arm serves, who
// sits within its reach and cannot move out of its way. An occupant URDF
// (config/models/wheelchair_occupant.urdf) holds fixed links of boxes,
// spheres and cylinders, each named after the body region of ISO/TS 15066
// Annex A it is (common/body_region.hpp), optionally followed by "_left" or "_right".
// Everything the safety rules need from it is geometry: the exact distance
// from a point to a region's shapes (a seen surface inside the region's
// envelope is that region of the user), and the separation between a region
// and the arm's cover of spheres (the rules' input, docs/safety-chain.md,
// "The user").
//
// Frames and units: the URDF's root link is the frame of the environment
// link the config seats the occupant on (occupant.seated_on); shapes are
// kept in the world frame (the robot's root link, kinematic_tree.hpp),
// metres. Loading happens once, at start; anything wrong with the model is
// a ModelError then.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tofguard/common/body_region.hpp"
#include "tofguard/common/region_shape.hpp"
#include "tofguard/robot_model/kinematic_tree.hpp"

namespace tofguard::robot_model {

// One primitive of a region (common/region_shape.hpp); its
// frame_from_shape is in the world frame here.
using RegionShape = tofguard::RegionShape;

// One link of the occupant URDF.
struct OccupantPart {
  std::string link_name;  // e.g. "forearm_left"
  BodyRegion region = BodyRegion::kChest;
  std::vector<RegionShape> shapes;  // at least one
};

struct OccupantModel {
  std::string file;  // the URDF, as given
  std::vector<OccupantPart> parts;
  // The regions that have at least one part.
  std::vector<BodyRegion> regions() const;
};

// The pose of a link reached from its root through fixed joints only, in
// its root's frame (the world for an environment link). Throws ModelError
// when the link is unknown or a moving joint lies on its way.
Eigen::Isometry3d fixed_link_pose(const KinematicTree& tree, const std::string& link);

// Loads the occupant URDF: fixed joints only; every link with geometry is
// named after a body region and has boxes, spheres and cylinders only
// (their <visual> elements; <collision> is ignored). `world_from_root`:
// where the URDF's root link is in the world (fixed_link_pose of the
// environment link it is seated on). Throws ModelError naming the file, the
// link and what was expected.
OccupantModel load_occupant(const std::string& urdf, const Eigen::Isometry3d& world_from_root);

// The smallest distance (m) from `point_world` to the part's shapes'
// surfaces (tofguard::distance_to_shape_m), 0 inside.
double distance_to_part_m(const OccupantPart& part, const Eigen::Vector3d& point_world);

}  // namespace tofguard::robot_model
