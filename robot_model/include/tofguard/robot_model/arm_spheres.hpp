#pragma once
// The robot's geometry as a cover of spheres, for the 3-D distance from a
// seen surface to the arm (the protective and warning fields):
// cheap to query for every unexplained pixel of every frame, and
// conservative.
//
// Conservative: every triangle of every robot shape lies inside at least
// one sphere of its link (a sphere holding a triangle's three corners holds
// the whole triangle), so for any point p
//   distance_to_arm_m(p) <= the true distance from p to the arm's surface,
// and, since every sphere holds a point of the surface,
//   distance_to_arm_m(p) >= true distance - 2 * max_radius_m.
// The error is towards "near", towards a stop; its bound is stated by the
// cover itself (max_radius_m), not assumed. Only the surface is covered: a
// point deep inside a link is at most its distance to the link's surface
// (half the link's thickness), not 0; a camera sees surfaces, and one
// inside the modelled arm is nearer than the arm anyway.
//
// Frames and units as in kinematic_tree.hpp: centres in their link's frame,
// metres; distances in metres.
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "tofguard/robot_model/kinematics.hpp"
#include "tofguard/robot_model/occupant_model.hpp"
#include "tofguard/robot_model/scene_model.hpp"

namespace tofguard::robot_model {

struct LinkSphere {
  int link_index = -1;  // KinematicTree::links index (a robot link)
  Eigen::Vector3d center_link_m = Eigen::Vector3d::Zero();
  double radius_m = 0;
};

struct ArmSpheres {
  std::vector<LinkSphere> spheres;
  // The cell size the cover was made with, and its largest sphere: the
  // distances it gives are at most 2 * max_radius_m below the truth.
  double cell_m = 0;
  double max_radius_m = 0;
};

// Covers every shape of the robot's links (not the environment's) at
// `cell_m` resolution (> 0): triangles longer than cell_m are split until
// no edge is, each goes to the cubic cell (link frame, edge cell_m) of its
// centroid, and each occupied cell becomes the smallest sphere about its
// triangles' bounding-box centre that holds all their corners. A smaller
// cell gives a tighter cover and more spheres (about the arm's surface
// area / cell_m^2).
ArmSpheres cover_arm_with_spheres(const SceneModel& scene, double cell_m);

// The cover placed at one joint state: each sphere's centre in the world
// frame. Made once per frame; every distance query of that frame uses it.
struct PlacedSphere {
  Eigen::Vector3d center_world_m = Eigen::Vector3d::Zero();
  double radius_m = 0;
};
using PlacedArmSpheres = std::vector<PlacedSphere>;

// Places the cover at the link poses given (forward_kinematics of the
// frame's joint state; they must be usable and of the cover's model).
PlacedArmSpheres place_arm_spheres(const ArmSpheres& cover, const LinkPoses& poses);

// Distance (m) from `point_world` (world frame) to the placed cover, 0
// inside a sphere. +infinity when the cover is empty.
double distance_to_arm_m(const PlacedArmSpheres& placed, const Eigen::Vector3d& point_world);

// The separation (m) between the placed cover and a part of the occupant
// (occupant_model.hpp): the smallest over the spheres of the exact distance
// from the sphere's centre to the part's shapes less the sphere's radius, 0
// where they overlap. Like distance_to_arm_m it is never more than the true
// separation from the arm's surface. +infinity when the cover is empty.
double separation_from_arm_m(const PlacedArmSpheres& placed, const OccupantPart& part);

// The smallest separation_from_arm_m over each region's parts, for every
// region the occupant has (OccupantModel::regions order, head to feet).
std::vector<std::pair<BodyRegion, double>> body_region_separations_m(const PlacedArmSpheres& placed,
                                                                     const OccupantModel& occupant);

}  // namespace tofguard::robot_model
