#pragma once
// The robot's URDF, parsed once (urdfdom), plus any number of
// static-environment URDFs: the kinematic tree (links and the joints between
// them, joint types, axes, limits, mimic joints), each link's geometry as the
// URDF states it (shapes and mesh URIs, not yet read: scene_model.hpp turns
// them into triangles), and the queries the safety rules ask of the tree
// (which links are distal to a joint, which movable joint is the nearest one
// above a set of links).
//
// Frames: every URDF link frame as the URDF defines it. "World" is the
// robot's root link; every environment URDF's root link is placed at that
// same frame (config: "placed in the same world frame as the robot's root
// link"). Units: metres and radians throughout (metres for prismatic joints).
//
// Loading happens once, at start; everything that can be wrong with the
// tree (malformed XML, a joint type tofguard does not model, a moving joint
// in an environment, a broken mimic) is a ModelError there.
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace tofguard::robot_model {

// A model that cannot be used. what() is one line naming the file and, where
// it applies, the link and the mesh, e.g.
//   "friend_arm.urdf: link 'link3': mesh 'package://arm/l3.stl' not found (searched: ...)".
class ModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class JointType { kFixed, kRevolute, kContinuous, kPrismatic };

// URDF <limit>, in the joint's units (radians or metres; per second for
// velocity). Continuous and fixed joints have no position limits.
struct JointLimits {
  bool has_position_limits = false;
  double lower = 0;
  double upper = 0;
  double velocity = 0;  // 0 when the URDF gives none
  double effort = 0;    // N*m or N; 0 when the URDF gives none
};

struct Joint {
  std::string name;
  JointType type = JointType::kFixed;
  int parent_link = -1;
  int child_link = -1;
  // Joint frame in the parent link's frame (URDF <origin>: xyz, then rpy as
  // fixed-axis roll about x, pitch about y, yaw about z: R = Rz*Ry*Rx).
  Eigen::Isometry3d parent_from_joint = Eigen::Isometry3d::Identity();
  // Unit axis in the joint frame: rotation axis (revolute, continuous, right
  // hand rule, radians) or translation direction (prismatic, metres).
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();
  JointLimits limits;
  // Mimic: value = multiplier * value(mimicked joint) + offset.
  int mimic_joint = -1;
  double mimic_multiplier = 1;
  double mimic_offset = 0;
};

// One <visual> or <collision> element as the URDF states it. Its checks
// (positive sizes, a mesh that can be found and read) are made when the
// geometry is built (scene_model.hpp), and only for the geometry source
// rendered.
struct GeometryElement {
  // kMissing: the element has no usable <geometry>; kUnknown: a geometry
  // type tofguard does not draw.
  enum class Kind { kMissing, kBox, kSphere, kCylinder, kMesh, kUnknown };
  Kind kind = Kind::kMissing;
  Eigen::Isometry3d link_from_geometry = Eigen::Isometry3d::Identity();
  Eigen::Vector3d box_size_m = Eigen::Vector3d::Zero();  // edge lengths along x, y, z
  double radius_m = 0;                                   // sphere, cylinder
  double length_m = 0;                                   // cylinder, along z
  std::string mesh_uri;                                  // as written in the URDF
  Eigen::Vector3d mesh_scale = Eigen::Vector3d::Ones();  // per axis of the mesh's frame
};

struct Link {
  std::string name;
  // The joint whose child this link is; -1 for a root (the robot's root and
  // every environment root, all at the world frame).
  int parent_joint = -1;
  bool is_environment = false;
  // The URDF file it came from, as given, for messages (and to resolve
  // relative mesh paths).
  std::string file;
  std::vector<GeometryElement> visuals;
  std::vector<GeometryElement> collisions;
  // <inertial><mass>, kg; nullopt when the link has no <inertial>.
  std::optional<double> mass_kg;
};

struct KinematicTree {
  // Robot links first (index 0 is the robot's root), then each
  // environment's links, each URDF depth-first from its root with siblings
  // in the order of their names; so every link comes after its parent.
  std::vector<Link> links;
  int num_robot_links = 0;
  // Ordered so that a joint's parent link's pose is known before it.
  std::vector<Joint> joints;
  // The robot joints a joint state must provide (revolute, continuous,
  // prismatic, not mimic), in link order.
  std::vector<std::string> actuated_joint_names;
  // The robot joints that move (every type but fixed, mimic joints
  // included), in link order.
  std::vector<std::string> movable_joint_names;
  // The prismatic joints (positions in metres; every other moving joint's
  // in radians).
  std::set<std::string> prismatic_joint_names;

  // Index of the link called `name` (robot links win over environment links
  // of the same name), -1 when there is none.
  int find_link(const std::string& name) const;
  std::vector<std::string> link_names() const;
  // True for a link of the robot (not of an environment).
  bool is_robot_link(const std::string& link) const;
  bool is_movable_joint(const std::string& joint) const;
  bool is_prismatic_joint(const std::string& joint) const { return prismatic_joint_names.count(joint) > 0; }

  // Tree queries by link name (an unknown link has no chain).
  // True when `link` is `ancestor` or lies below it in the tree.
  bool is_descendant_or_self(const std::string& link, const std::string& ancestor) const;
  // The deepest link that is an ancestor-or-self of every link in `links`
  // (all must be known); "" for an empty list or links of different trees.
  std::string lowest_common_ancestor(const std::vector<std::string>& links) const;
  // The movable joint nearest above `link`: its own parent joint when that
  // moves, else the first moving joint further up; "" when there is none
  // (the link is fixed to its root).
  std::string nearest_movable_joint_above(const std::string& link) const;
  // The links from the root down to `link` (root first, `link` last).
  std::vector<std::string> chain_from_root(const std::string& link) const;
  // The link a joint moves (its child link); "" for an unknown joint.
  std::string child_link(const std::string& joint) const;

 private:
  // Link indices from `link` up to its root, link first.
  std::vector<int> chain_to_root(const std::string& link) const;
};

// The mass of the robot's moving parts, kg: the sum of <inertial><mass>
// over the robot links that some movable joint moves (ISO/TS 15066 Annex A's
// M, from which the robot's effective mass in a contact is M/2 + payload).
// A moving link with neither geometry nor <inertial> is a frame (0 kg).
// Throws ModelError naming the first moving link with geometry but no
// <inertial>: a missing mass is not a light arm.
double moving_mass_kg(const KinematicTree& tree);

// Parses the robot's URDF and the environments' (fixed joints only).
// Throws ModelError.
KinematicTree load_kinematic_tree(const std::string& robot_urdf,
                                  const std::vector<std::string>& environment_urdfs = {});

}  // namespace tofguard::robot_model
