#pragma once
// The robot's kinematic tree (links and the joints between them), read from
// its URDF with urdfdom: which links are distal to a joint, and which
// movable joint is the nearest one above a set of links. The risk
// classifier blames the joint above the links whose mismatch it sees.
#include <map>
#include <set>
#include <string>
#include <vector>

namespace tofguard::risk {

class RobotTree {
 public:
  // Throws std::runtime_error naming the file when it cannot be parsed.
  static RobotTree from_urdf_file(const std::string& path);
  static RobotTree from_urdf_string(const std::string& xml);

  bool has_link(const std::string& link) const { return parent_link_.count(link) > 0; }
  // Names of the joints that move (every type but fixed).
  const std::vector<std::string>& movable_joints() const { return movable_joints_; }
  bool is_movable_joint(const std::string& joint) const;
  // Names of the prismatic joints (positions in metres; every other moving
  // joint's in radians).
  const std::set<std::string>& prismatic_joints() const { return prismatic_joints_; }

  // True when `link` is `ancestor` or lies below it in the tree.
  bool is_descendant_or_self(const std::string& link, const std::string& ancestor) const;
  // The deepest link that is an ancestor-or-self of every link in `links`
  // (all must be known); "" for an empty list.
  std::string lowest_common_ancestor(const std::vector<std::string>& links) const;
  // The movable joint nearest above `link`: its own parent joint when that
  // moves, else the first moving joint further up; "" when there is none
  // (the link is fixed to the root).
  std::string nearest_movable_joint_above(const std::string& link) const;
  // The links from the root down to `link` (root first, `link` last).
  std::vector<std::string> chain_from_root(const std::string& link) const;
  // The link a joint moves (its child link); "" for an unknown joint.
  std::string child_link(const std::string& joint) const;

 private:
  struct Builder;  // fills a tree from a parsed urdf model (robot_tree.cpp)
  struct ParentJoint {
    std::string joint;  // "" for the root link
    bool movable = false;
  };
  // Chain from `link` up to the root, link first.
  std::vector<std::string> chain_to_root(const std::string& link) const;

  std::map<std::string, std::string> parent_link_;  // "" for the root
  std::map<std::string, ParentJoint> parent_joint_;
  std::map<std::string, std::string> child_of_joint_;
  std::vector<std::string> movable_joints_;
  std::set<std::string> prismatic_joints_;
};

}  // namespace tofguard::risk
