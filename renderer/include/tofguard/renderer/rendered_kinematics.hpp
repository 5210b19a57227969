#pragma once
// The arm's kinematics as rendered (link_labels_t's num_joints .. link_axis,
// docs/safety-chain.md "Evidence"): where every moving robot joint's axis
// was in the camera's optical frame at a frame's joints and camera pose, so
// that tofguard-discrepancy can say how an offset of each joint would
// change each pixel's depth. Pure functions: no GL, no LCM.
//
// Frames: world = the robot's root link; optical = the camera's optical
// frame (x right, y down, z forward). Metres and radians (metres for
// prismatic joints).
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tofguard/common/camera_geometry.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/link_labels_t.hpp"
#include "tofguard/renderer/depth_renderer.hpp"
#include "tofguard/robot_model/arm_spheres.hpp"
#include "tofguard/robot_model/kinematic_tree.hpp"
#include "tofguard/robot_model/kinematics.hpp"

namespace tofguard::renderer {

// One moving URDF joint of the robot (mimic joints included).
struct RenderedAxis {
  // The URDF joint's name (for messages and tests; not on the wire).
  std::string urdf_joint;
  // Index in RenderedKinematics::joint_names of the joint that drives it
  // (a mimic joint's leader), and how much it moves per unit of that joint
  // (1, or the mimic multiplier).
  int joint = -1;
  double multiplier = 1;
  bool prismatic = false;
  // A point on the axis (the joint frame's origin) and the axis' unit
  // direction, optical frame.
  Eigen::Vector3d origin_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
  // The next moving axis above towards the root (index in axes), -1: none.
  int parent = -1;
};

struct RenderedKinematics {
  // The actuated joints (KinematicTree::actuated_joint_names order).
  std::vector<std::string> joint_names;
  // KinematicTree::movable_joint_names order: a parent before its children.
  std::vector<RenderedAxis> axes;
  // Per robot link (KinematicTree::links order, robot links only): the
  // nearest moving axis above it, -1 when fixed to the root.
  std::vector<int> link_axis;
};

// The optical frame's pose in the world for `camera_pose` (given in link
// camera_pose.frame_id, so a camera on the arm moves with it) at the
// links' poses: what DepthRenderer::render renders from. nullopt (and
// `why` set when given) for unusable poses, an unknown frame or a
// non-unit rotation.
std::optional<Eigen::Isometry3d> world_from_optical(const robot_model::KinematicTree& tree,
                                                    const robot_model::LinkPoses& link_poses,
                                                    const CameraPose& camera_pose,
                                                    std::string* why = nullptr);

// The kinematics at `link_poses` (forward_kinematics of the tree, usable)
// seen from `world_from_optical`. TOFGUARD_DEMANDs poses that match the tree.
RenderedKinematics rendered_kinematics(const robot_model::KinematicTree& tree,
                                       const robot_model::LinkPoses& link_poses,
                                       const Eigen::Isometry3d& world_from_optical);
// The same at `joints` and `camera_pose`; nullopt (and `why`) when the
// joints or the pose cannot be used.
std::optional<RenderedKinematics> rendered_kinematics(const robot_model::KinematicTree& tree,
                                                      const robot_model::JointPositions& joints,
                                                      const CameraPose& camera_pose,
                                                      std::string* why = nullptr);
// The same for what a render produced (RenderResult::world_from_link and
// world_from_optical); nullopt for an unusable result.
std::optional<RenderedKinematics> rendered_kinematics(const robot_model::KinematicTree& tree,
                                                      const RenderResult& result);

// Writes the kinematics into link_labels_t's num_joints .. link_axis
// (replacing what was there). TOFGUARD_DEMANDs link_axis to hold
// labels->num_robot_links entries.
void set_rendered_kinematics(const RenderedKinematics& kinematics, link_labels_t* labels);

// The camera's pose into link_labels_t.world_from_optical (row-major 3x4,
// the optical frame in the model's root frame) and optical_pose_given.
void set_rendered_optical_pose(const Eigen::Isometry3d& world_from_optical, link_labels_t* labels);

// The arm's cover of spheres (robot_model/arm_spheres.hpp) as rendered:
// placed at `link_poses` (usable, of the cover's model) and seen from
// `world_from_optical`, for link_labels_t's arm_* fields (the protective
// fields, docs/safety-chain.md). Centres in the optical frame, metres.
struct RenderedArmCover {
  struct Sphere {
    int link = -1;  // robot link index (link_labels_t.link_name order)
    Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
    double radius_m = 0;
  };
  std::vector<Sphere> spheres;
  double max_radius_m = 0;
  // The occupant's body regions and their separations from the cover
  // (robot_model::body_region_separations_m, metres); empty without an
  // occupant.
  std::vector<std::pair<BodyRegion, double>> body_region_separations_m;
};
// With `occupant`, also each of its body regions' separation from the
// placed cover (body_region_separations_m), from the same placement.
RenderedArmCover rendered_arm_cover(const robot_model::ArmSpheres& cover,
                                    const robot_model::LinkPoses& link_poses,
                                    const Eigen::Isometry3d& world_from_optical,
                                    const robot_model::OccupantModel* occupant = nullptr);

// Writes the cover into link_labels_t's arm_cover_max_radius_m ..
// arm_sphere_radius_m and the body regions' separations into
// num_body_regions .. body_region_separation_m (replacing what was there).
void set_rendered_arm_cover(const RenderedArmCover& cover, link_labels_t* labels);

// The complete TOF_LABELS message of `frame` for a render (labels,
// kinematics and the arm's cover placed as rendered; an empty `cover`
// gives none); unusable (no kinematics, no cover) when the result is. For
// in-process chains (simulator + renderer + discrepancy without LCM).
link_labels_t make_rendered_link_labels(const depth_image_t& frame, const RenderResult& result,
                                        const robot_model::KinematicTree& tree,
                                        const robot_model::ArmSpheres& cover);

}  // namespace tofguard::renderer
