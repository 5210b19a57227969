#include "tofguard/robot_model/kinematic_tree.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include "tofguard/common/error_log.hpp"

namespace tofguard::robot_model {
namespace {

// urdfdom reports problems only through console_bridge, and for some (an
// unknown geometry type) it logs an error, drops the element and returns a
// model anyway: a link silently without its geometry. This handler collects
// the errors so that any of them stops the load, said in one line.
class CapturingOutputHandler : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) errors += (errors.empty() ? "" : "; ") + text;
  }
  std::string errors;
};

urdf::ModelInterfaceSharedPtr parse_urdf_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ModelError(path + ": cannot read the URDF file");
  std::stringstream text;
  text << in.rdbuf();
  // console_bridge's handler is process-global.
  static std::mutex mutex;
  std::lock_guard<std::mutex> lock(mutex);
  CapturingOutputHandler handler;
  console_bridge::useOutputHandler(&handler);
  urdf::ModelInterfaceSharedPtr model;
  try {
    model = urdf::parseURDF(text.str());
  } catch (const std::exception& e) {
    handler.errors += (handler.errors.empty() ? "" : "; ") + std::string(e.what());
  }
  console_bridge::restorePreviousOutputHandler();
  if (!model || !handler.errors.empty()) {
    throw ModelError(
        path + ": malformed URDF: " +
        (handler.errors.empty() ? std::string("urdfdom could not parse it") : one_line(handler.errors)));
  }
  return model;
}

Eigen::Isometry3d to_isometry(const urdf::Pose& pose) {
  Eigen::Isometry3d result = Eigen::Isometry3d::Identity();
  result.translation() = Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z);
  // urdfdom turns rpy into this quaternion (R = Rz(yaw) * Ry(pitch) * Rx(roll)).
  result.linear() = Eigen::Quaterniond(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z)
                        .normalized()
                        .toRotationMatrix();
  return result;
}

GeometryElement to_geometry(const urdf::GeometrySharedPtr& geometry, const urdf::Pose& origin) {
  GeometryElement element;
  element.link_from_geometry = to_isometry(origin);
  if (!geometry) return element;  // kMissing
  switch (geometry->type) {
    case urdf::Geometry::BOX: {
      const auto& box = static_cast<const urdf::Box&>(*geometry);
      element.kind = GeometryElement::Kind::kBox;
      element.box_size_m = Eigen::Vector3d(box.dim.x, box.dim.y, box.dim.z);
      break;
    }
    case urdf::Geometry::SPHERE:
      element.kind = GeometryElement::Kind::kSphere;
      element.radius_m = static_cast<const urdf::Sphere&>(*geometry).radius;
      break;
    case urdf::Geometry::CYLINDER: {
      const auto& cylinder = static_cast<const urdf::Cylinder&>(*geometry);
      element.kind = GeometryElement::Kind::kCylinder;
      element.radius_m = cylinder.radius;
      element.length_m = cylinder.length;
      break;
    }
    case urdf::Geometry::MESH: {
      const auto& mesh = static_cast<const urdf::Mesh&>(*geometry);
      element.kind = GeometryElement::Kind::kMesh;
      element.mesh_uri = mesh.filename;
      element.mesh_scale = Eigen::Vector3d(mesh.scale.x, mesh.scale.y, mesh.scale.z);
      break;
    }
    default:
      element.kind = GeometryElement::Kind::kUnknown;
  }
  return element;
}

class TreeBuilder {
 public:
  void add_urdf(const std::string& path, bool is_environment) {
    const urdf::ModelInterfaceSharedPtr model = parse_urdf_file(path);
    const urdf::LinkConstSharedPtr root = model->getRoot();
    if (!root) throw ModelError(path + ": malformed URDF: no root link");
    std::map<std::string, int> joint_index;  // this file's joints, for mimic
    // Depth first from the root: every link after its parent, every joint
    // after the joint that moves its parent link.
    std::vector<std::pair<urdf::LinkConstSharedPtr, int>> stack{{root, -1}};
    while (!stack.empty()) {
      const auto [link, parent_link] = stack.back();
      stack.pop_back();
      const int link_index = static_cast<int>(tree_.links.size());
      Link entry;
      entry.name = link->name;
      entry.is_environment = is_environment;
      entry.file = path;
      if (parent_link >= 0) {
        entry.parent_joint = add_joint(*link->parent_joint, parent_link, link_index, path, is_environment);
        joint_index[link->parent_joint->name] = entry.parent_joint;
      }
      for (const auto& visual : link->visual_array)
        entry.visuals.push_back(to_geometry(visual->geometry, visual->origin));
      if (link->visual_array.empty() && link->visual) {
        entry.visuals.push_back(to_geometry(link->visual->geometry, link->visual->origin));
      }
      for (const auto& collision : link->collision_array) {
        entry.collisions.push_back(to_geometry(collision->geometry, collision->origin));
      }
      if (link->collision_array.empty() && link->collision) {
        entry.collisions.push_back(to_geometry(link->collision->geometry, link->collision->origin));
      }
      if (link->inertial) entry.mass_kg = link->inertial->mass;
      tree_.links.push_back(std::move(entry));
      // Siblings in the order of their names (urdfdom keeps no document
      // order), pushed in reverse so that the first is visited first.
      std::vector<urdf::LinkConstSharedPtr> children(link->child_links.begin(), link->child_links.end());
      std::sort(children.begin(), children.end(),
                [](const auto& a, const auto& b) { return a->name > b->name; });
      for (const auto& child : children) stack.emplace_back(child, link_index);
    }
    resolve_mimics(joint_index, path);
    if (!is_environment) tree_.num_robot_links = static_cast<int>(tree_.links.size());
  }

  KinematicTree take() { return std::move(tree_); }

 private:
  int add_joint(const urdf::Joint& source, int parent_link, int child_link, const std::string& path,
                bool is_environment) {
    Joint joint;
    joint.name = source.name;
    joint.parent_link = parent_link;
    joint.child_link = child_link;
    joint.parent_from_joint = to_isometry(source.parent_to_joint_origin_transform);
    switch (source.type) {
      case urdf::Joint::FIXED:
        joint.type = JointType::kFixed;
        break;
      case urdf::Joint::REVOLUTE:
        joint.type = JointType::kRevolute;
        break;
      case urdf::Joint::CONTINUOUS:
        joint.type = JointType::kContinuous;
        break;
      case urdf::Joint::PRISMATIC:
        joint.type = JointType::kPrismatic;
        break;
      default:
        throw ModelError(path + ": joint '" + source.name +
                         "': type not supported (fixed, revolute, continuous and prismatic are)");
    }
    if (is_environment && joint.type != JointType::kFixed) {
      throw ModelError(path + ": joint '" + source.name +
                       "': an environment URDF may only have fixed joints (it is static)");
    }
    if (joint.type != JointType::kFixed) {
      const Eigen::Vector3d axis(source.axis.x, source.axis.y, source.axis.z);
      if (!std::isfinite(axis.norm()) || axis.norm() < 1e-9) {
        throw ModelError(path + ": joint '" + source.name + "': axis must be a non-zero vector");
      }
      joint.axis = axis.normalized();
    }
    if (source.limits) {
      // urdfdom requires <limit> for revolute and prismatic joints; a
      // continuous joint's lower/upper mean nothing.
      joint.limits.has_position_limits =
          joint.type == JointType::kRevolute || joint.type == JointType::kPrismatic;
      if (joint.limits.has_position_limits) {
        joint.limits.lower = source.limits->lower;
        joint.limits.upper = source.limits->upper;
      }
      joint.limits.velocity = source.limits->velocity;
      joint.limits.effort = source.limits->effort;
    }
    if (source.mimic && joint.type != JointType::kFixed) {
      pending_mimics_.push_back({static_cast<int>(tree_.joints.size()), source.mimic->joint_name});
      joint.mimic_multiplier = source.mimic->multiplier;
      joint.mimic_offset = source.mimic->offset;
    }
    tree_.joints.push_back(joint);
    return static_cast<int>(tree_.joints.size() - 1);
  }

  void resolve_mimics(const std::map<std::string, int>& joint_index, const std::string& path) {
    for (const auto& [joint, leader_name] : pending_mimics_) {
      const auto leader = joint_index.find(leader_name);
      if (leader == joint_index.end() || tree_.joints[leader->second].type == JointType::kFixed) {
        throw ModelError(path + ": joint '" + tree_.joints[joint].name + "': mimics '" + leader_name +
                         "', which is not a moving joint of this URDF");
      }
      tree_.joints[joint].mimic_joint = leader->second;
    }
    for (const auto& [joint, leader_name] : pending_mimics_) {
      // A chain of mimics must end at an actuated joint.
      int at = joint;
      for (size_t steps = 0; tree_.joints[at].mimic_joint >= 0; ++steps) {
        if (steps > tree_.joints.size()) {
          throw ModelError(path + ": joint '" + tree_.joints[joint].name + "': mimic joints form a cycle");
        }
        at = tree_.joints[at].mimic_joint;
      }
    }
    // The joint sets, in link order (environment joints are all fixed).
    for (const Joint& joint : tree_.joints) {
      if (joint.type == JointType::kFixed || tree_.links[joint.parent_link].is_environment) continue;
      const auto add = [&](std::vector<std::string>& names) {
        if (std::find(names.begin(), names.end(), joint.name) == names.end()) names.push_back(joint.name);
      };
      add(tree_.movable_joint_names);
      if (joint.mimic_joint < 0) add(tree_.actuated_joint_names);
      if (joint.type == JointType::kPrismatic) tree_.prismatic_joint_names.insert(joint.name);
    }
    pending_mimics_.clear();
  }

  KinematicTree tree_;
  std::vector<std::pair<int, std::string>> pending_mimics_;
};

}  // namespace

KinematicTree load_kinematic_tree(const std::string& robot_urdf,
                                  const std::vector<std::string>& environment_urdfs) {
  TreeBuilder builder;
  builder.add_urdf(robot_urdf, false);
  for (const std::string& path : environment_urdfs) builder.add_urdf(path, true);
  return builder.take();
}

int KinematicTree::find_link(const std::string& name) const {
  for (size_t i = 0; i < links.size(); ++i) {
    if (links[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

std::vector<std::string> KinematicTree::link_names() const {
  std::vector<std::string> names;
  for (const Link& link : links) names.push_back(link.name);
  return names;
}

bool KinematicTree::is_robot_link(const std::string& link) const {
  const int index = find_link(link);
  return index >= 0 && index < num_robot_links;
}

bool KinematicTree::is_movable_joint(const std::string& joint) const {
  return std::find(movable_joint_names.begin(), movable_joint_names.end(), joint) !=
         movable_joint_names.end();
}

std::vector<int> KinematicTree::chain_to_root(const std::string& link) const {
  std::vector<int> chain;
  for (int at = find_link(link); at >= 0;) {
    chain.push_back(at);
    const int joint = links[at].parent_joint;
    at = joint >= 0 ? joints[joint].parent_link : -1;
  }
  return chain;
}

bool KinematicTree::is_descendant_or_self(const std::string& link, const std::string& ancestor) const {
  for (const int at : chain_to_root(link)) {
    if (links[at].name == ancestor) return true;
  }
  return false;
}

std::string KinematicTree::lowest_common_ancestor(const std::vector<std::string>& names) const {
  if (names.empty()) return "";
  // Walk the first link's chain from the link up; the first entry that is an
  // ancestor-or-self of every link is the deepest common one.
  for (const int candidate : chain_to_root(names.front())) {
    const bool common = std::all_of(names.begin(), names.end(), [&](const std::string& l) {
      return is_descendant_or_self(l, links[candidate].name);
    });
    if (common) return links[candidate].name;
  }
  return "";
}

std::string KinematicTree::nearest_movable_joint_above(const std::string& link) const {
  for (const int at : chain_to_root(link)) {
    const int joint = links[at].parent_joint;
    if (joint >= 0 && joints[joint].type != JointType::kFixed) return joints[joint].name;
  }
  return "";
}

std::vector<std::string> KinematicTree::chain_from_root(const std::string& link) const {
  std::vector<std::string> chain;
  for (const int at : chain_to_root(link)) chain.push_back(links[at].name);
  std::reverse(chain.begin(), chain.end());
  return chain;
}

std::string KinematicTree::child_link(const std::string& joint) const {
  for (const Joint& j : joints) {
    if (j.name == joint) return links[j.child_link].name;
  }
  return "";
}

double moving_mass_kg(const KinematicTree& tree) {
  double mass_kg = 0;
  for (int i = 0; i < tree.num_robot_links; ++i) {
    const Link& link = tree.links[i];
    if (tree.nearest_movable_joint_above(link.name).empty()) continue;  // fixed to the root
    // A link with no geometry and no <inertial> is a frame (a tool point).
    if (!link.mass_kg && link.visuals.empty() && link.collisions.empty()) continue;
    if (!link.mass_kg) {
      throw ModelError(link.file + ": link '" + link.name +
                       "' moves and has no <inertial><mass> (the arm's moving mass sizes the contact "
                       "speeds the user's body regions allow; expected a mass in kg)");
    }
    mass_kg += *link.mass_kg;
  }
  return mass_kg;
}

}  // namespace tofguard::robot_model
