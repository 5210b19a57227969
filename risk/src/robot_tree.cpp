#include "tofguard/risk/robot_tree.hpp"

#include <algorithm>
#include <stdexcept>

#include <urdf_parser/urdf_parser.h>

namespace tofguard::risk {

struct RobotTree::Builder {
  static RobotTree build(const urdf::ModelInterface& model) {
    RobotTree tree;
    for (const auto& [name, link] : model.links_) {
      const urdf::LinkConstSharedPtr parent = link->getParent();
      tree.parent_link_[name] = parent ? parent->name : "";
      ParentJoint pj;
      if (link->parent_joint) {
        pj.joint = link->parent_joint->name;
        pj.movable = link->parent_joint->type != urdf::Joint::FIXED;
      }
      tree.parent_joint_[name] = pj;
    }
    for (const auto& [name, joint] : model.joints_) {
      tree.child_of_joint_[name] = joint->child_link_name;
      if (joint->type != urdf::Joint::FIXED) tree.movable_joints_.push_back(name);
      if (joint->type == urdf::Joint::PRISMATIC) tree.prismatic_joints_.insert(name);
    }
    std::sort(tree.movable_joints_.begin(), tree.movable_joints_.end());
    return tree;
  }
};

RobotTree RobotTree::from_urdf_file(const std::string& path) {
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDFFile(path);
  if (!model) throw std::runtime_error(path + ": cannot parse the URDF (urdfdom)");
  return Builder::build(*model);
}

RobotTree RobotTree::from_urdf_string(const std::string& xml) {
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(xml);
  if (!model) throw std::runtime_error("cannot parse the URDF text (urdfdom)");
  return Builder::build(*model);
}

bool RobotTree::is_movable_joint(const std::string& joint) const {
  return std::binary_search(movable_joints_.begin(), movable_joints_.end(), joint);
}

std::vector<std::string> RobotTree::chain_to_root(const std::string& link) const {
  std::vector<std::string> chain;
  for (std::string at = link; !at.empty();) {
    const auto it = parent_link_.find(at);
    if (it == parent_link_.end()) break;
    chain.push_back(at);
    at = it->second;
  }
  return chain;
}

bool RobotTree::is_descendant_or_self(const std::string& link, const std::string& ancestor) const {
  const auto chain = chain_to_root(link);
  return std::find(chain.begin(), chain.end(), ancestor) != chain.end();
}

std::string RobotTree::lowest_common_ancestor(const std::vector<std::string>& links) const {
  if (links.empty()) return "";
  // Walk the first link's chain from the link up; the first entry that is an
  // ancestor-or-self of every link is the deepest common one.
  for (const std::string& candidate : chain_to_root(links.front())) {
    const bool common = std::all_of(links.begin(), links.end(), [&](const std::string& l) {
      return is_descendant_or_self(l, candidate);
    });
    if (common) return candidate;
  }
  return "";
}

std::string RobotTree::nearest_movable_joint_above(const std::string& link) const {
  for (const std::string& at : chain_to_root(link)) {
    const auto it = parent_joint_.find(at);
    if (it != parent_joint_.end() && it->second.movable) return it->second.joint;
  }
  return "";
}

std::string RobotTree::child_link(const std::string& joint) const {
  const auto it = child_of_joint_.find(joint);
  return it == child_of_joint_.end() ? "" : it->second;
}

}  // namespace tofguard::risk

namespace tofguard::risk {

std::vector<std::string> RobotTree::chain_from_root(const std::string& link) const {
  std::vector<std::string> chain = chain_to_root(link);
  std::reverse(chain.begin(), chain.end());
  return chain;
}

}  // namespace tofguard::risk
