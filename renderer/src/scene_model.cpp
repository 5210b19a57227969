#include "tofguard/renderer/scene_model.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <tuple>

#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include "tofguard/renderer/primitive_meshes.hpp"

namespace tofguard::renderer {
namespace {

namespace fs = std::filesystem;

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

std::string one_line(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

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
    throw ModelError(path + ": malformed URDF: " +
                     (handler.errors.empty() ? std::string("urdfdom could not parse it") : one_line(handler.errors)));
  }
  return model;
}

Eigen::Isometry3d to_isometry(const urdf::Pose& pose) {
  Eigen::Isometry3d result = Eigen::Isometry3d::Identity();
  result.translation() = Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z);
  // urdfdom turns rpy into this quaternion (R = Rz(yaw) * Ry(pitch) * Rx(roll)).
  result.linear() =
      Eigen::Quaterniond(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z)
          .normalized()
          .toRotationMatrix();
  return result;
}

bool positive_finite(double v) { return std::isfinite(v) && v > 0; }

std::string geometry_word(GeometrySource source) {
  return source == GeometrySource::kVisual ? "visual" : "collision";
}

class SceneBuilder {
 public:
  SceneBuilder(const SceneOptions& options) : options_(options) {
    if (!std::isfinite(options.padding_m) || options.padding_m < 0) {
      throw ModelError("renderer padding_m must be a finite value >= 0, got " +
                       std::to_string(options.padding_m));
    }
    scene_.meshes.push_back(unit_box());
    scene_.meshes.push_back(unit_sphere());
    scene_.meshes.push_back(unit_cylinder());
  }

  void add_urdf(const std::string& path, bool is_environment) {
    const urdf::ModelInterfaceSharedPtr model = parse_urdf_file(path);
    const urdf::LinkConstSharedPtr root = model->getRoot();
    if (!root) throw ModelError(path + ": malformed URDF: no root link");
    const std::string& file = path;  // as given, in every message
    const fs::path urdf_folder = fs::absolute(fs::path(path)).parent_path();
    std::map<std::string, int> joint_index;  // this file's joints, for mimic
    // Depth first from the root: every link after its parent, every joint
    // after the joint that moves its parent link.
    std::vector<std::pair<urdf::LinkConstSharedPtr, int>> stack{{root, -1}};
    while (!stack.empty()) {
      const auto [link, parent_link] = stack.back();
      stack.pop_back();
      const int link_index = static_cast<int>(scene_.links.size());
      Link entry;
      entry.name = link->name;
      entry.is_environment = is_environment;
      entry.file = path;
      if (parent_link >= 0) {
        entry.parent_joint = add_joint(*link->parent_joint, parent_link, link_index, path, is_environment);
        joint_index[link->parent_joint->name] = entry.parent_joint;
      }
      scene_.links.push_back(entry);
      add_geometry(*link, link_index, file, urdf_folder);
      // Siblings in the order of their names (urdfdom keeps no document
      // order), pushed in reverse so that the first is visited first.
      std::vector<urdf::LinkConstSharedPtr> children(link->child_links.begin(), link->child_links.end());
      std::sort(children.begin(), children.end(),
                [](const auto& a, const auto& b) { return a->name > b->name; });
      for (const auto& child : children) stack.emplace_back(child, link_index);
    }
    resolve_mimics(*model, joint_index, path);
    if (!is_environment) scene_.num_robot_links = static_cast<int>(scene_.links.size());
  }

  SceneModel take() { return std::move(scene_); }

 private:
  int add_joint(const urdf::Joint& source, int parent_link, int child_link, const std::string& path,
                bool is_environment) {
    Joint joint;
    joint.name = source.name;
    joint.parent_link = parent_link;
    joint.child_link = child_link;
    joint.parent_from_joint = to_isometry(source.parent_to_joint_origin_transform);
    switch (source.type) {
      case urdf::Joint::FIXED: joint.type = JointType::kFixed; break;
      case urdf::Joint::REVOLUTE: joint.type = JointType::kRevolute; break;
      case urdf::Joint::CONTINUOUS: joint.type = JointType::kContinuous; break;
      case urdf::Joint::PRISMATIC: joint.type = JointType::kPrismatic; break;
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
    if (source.mimic && joint.type != JointType::kFixed) {
      pending_mimics_.push_back({static_cast<int>(scene_.joints.size()), source.mimic->joint_name});
      joint.mimic_multiplier = source.mimic->multiplier;
      joint.mimic_offset = source.mimic->offset;
    }
    scene_.joints.push_back(joint);
    return static_cast<int>(scene_.joints.size() - 1);
  }

  void resolve_mimics(const urdf::ModelInterface&, const std::map<std::string, int>& joint_index,
                      const std::string& path) {
    for (const auto& [joint, leader_name] : pending_mimics_) {
      const auto leader = joint_index.find(leader_name);
      if (leader == joint_index.end() || scene_.joints[leader->second].type == JointType::kFixed) {
        throw ModelError(path + ": joint '" + scene_.joints[joint].name + "': mimics '" + leader_name +
                         "', which is not a moving joint of this URDF");
      }
      scene_.joints[joint].mimic_joint = leader->second;
    }
    for (const auto& [joint, leader_name] : pending_mimics_) {
      // A chain of mimics must end at an actuated joint.
      int at = joint;
      for (size_t steps = 0; scene_.joints[at].mimic_joint >= 0; ++steps) {
        if (steps > scene_.joints.size()) {
          throw ModelError(path + ": joint '" + scene_.joints[joint].name + "': mimic joints form a cycle");
        }
        at = scene_.joints[at].mimic_joint;
      }
    }
    for (const Joint& joint : scene_.joints) {
      if (joint.type != JointType::kFixed && joint.mimic_joint < 0 &&
          !scene_.links[joint.parent_link].is_environment) {
        bool known = false;
        for (const auto& name : scene_.actuated_joint_names) known = known || name == joint.name;
        if (!known) scene_.actuated_joint_names.push_back(joint.name);
      }
    }
    pending_mimics_.clear();
  }

  void add_geometry(const urdf::Link& link, int link_index, const std::string& file,
                    const fs::path& urdf_folder) {
    const double pad = options_.padding_m;
    const auto add = [&](const urdf::GeometrySharedPtr& geometry, const urdf::Pose& origin) {
      const std::string where = file + ": link '" + link.name + "': ";
      if (!geometry) throw ModelError(where + geometry_word(options_.geometry) + " without geometry");
      Shape shape;
      shape.link_index = link_index;
      shape.link_from_shape = to_isometry(origin);
      switch (geometry->type) {
        case urdf::Geometry::BOX: {
          const auto& box = static_cast<const urdf::Box&>(*geometry);
          if (!positive_finite(box.dim.x) || !positive_finite(box.dim.y) || !positive_finite(box.dim.z)) {
            throw ModelError(where + "box size must be three positive lengths");
          }
          shape.mesh_index = kUnitBox;
          shape.scale = Eigen::Vector3d(box.dim.x, box.dim.y, box.dim.z).array() + 2 * pad;
          break;
        }
        case urdf::Geometry::SPHERE: {
          const auto& sphere = static_cast<const urdf::Sphere&>(*geometry);
          if (!positive_finite(sphere.radius)) throw ModelError(where + "sphere radius must be positive");
          shape.mesh_index = kUnitSphere;
          shape.scale = Eigen::Vector3d::Constant(sphere.radius + pad);
          break;
        }
        case urdf::Geometry::CYLINDER: {
          const auto& cylinder = static_cast<const urdf::Cylinder&>(*geometry);
          if (!positive_finite(cylinder.radius) || !positive_finite(cylinder.length)) {
            throw ModelError(where + "cylinder radius and length must be positive");
          }
          shape.mesh_index = kUnitCylinder;
          shape.scale = Eigen::Vector3d(cylinder.radius + pad, cylinder.radius + pad, cylinder.length + 2 * pad);
          break;
        }
        case urdf::Geometry::MESH: {
          const auto& mesh = static_cast<const urdf::Mesh&>(*geometry);
          const Eigen::Vector3d scale(mesh.scale.x, mesh.scale.y, mesh.scale.z);
          if (!std::isfinite(scale.sum()) || scale.cwiseAbs().minCoeff() <= 0) {
            throw ModelError(where + "mesh '" + mesh.filename + "': scale must be three non-zero numbers");
          }
          shape.mesh_index = mesh_for(resolve_uri(mesh.filename, urdf_folder, where), mesh.filename, scale, where);
          break;
        }
        default:
          throw ModelError(where + "unknown geometry type (box, sphere, cylinder and mesh are supported)");
      }
      scene_.shapes.push_back(shape);
    };
    if (options_.geometry == GeometrySource::kVisual) {
      for (const auto& visual : link.visual_array) add(visual->geometry, visual->origin);
      if (link.visual_array.empty() && link.visual) add(link.visual->geometry, link.visual->origin);
    } else {
      for (const auto& collision : link.collision_array) add(collision->geometry, collision->origin);
      if (link.collision_array.empty() && link.collision) add(link.collision->geometry, link.collision->origin);
    }
  }

  fs::path resolve_uri(const std::string& uri, const fs::path& urdf_folder, const std::string& where) const {
    const std::string package_prefix = "package://";
    const std::string file_prefix = "file://";
    if (uri.rfind(package_prefix, 0) == 0) {
      const std::string rest = uri.substr(package_prefix.size());
      const size_t slash = rest.find('/');
      if (slash == std::string::npos || slash == 0) {
        throw ModelError(where + "mesh '" + uri + "': expected package://NAME/path");
      }
      const std::string package = rest.substr(0, slash);
      const std::string inside = rest.substr(slash + 1);
      std::string searched;
      for (const std::string& folder : options_.package_paths) {
        const fs::path candidate = fs::path(folder) / package / inside;
        if (fs::is_regular_file(candidate)) return candidate;
        searched += (searched.empty() ? "" : ", ") + candidate.string();
      }
      throw ModelError(where + "mesh '" + uri + "' not found (searched: " +
                       (searched.empty() ? std::string("no package_paths configured") : searched) + ")");
    }
    fs::path path = uri.rfind(file_prefix, 0) == 0 ? fs::path(uri.substr(file_prefix.size())) : fs::path(uri);
    if (path.is_relative()) path = urdf_folder / path;
    if (!fs::is_regular_file(path)) {
      throw ModelError(where + "mesh '" + uri + "' not found (resolved to " + path.string() + ")");
    }
    return path;
  }

  int mesh_for(const fs::path& path, const std::string& uri, const Eigen::Vector3d& scale, const std::string& where) {
    const auto key = std::make_tuple(fs::canonical(path).string(), scale.x(), scale.y(), scale.z());
    const auto cached = mesh_cache_.find(key);
    if (cached != mesh_cache_.end()) return cached->second;
    scene_.meshes.push_back(read_mesh(path, uri, scale, where));
    const int index = static_cast<int>(scene_.meshes.size() - 1);
    mesh_cache_[key] = index;
    return index;
  }

  TriangleMesh read_mesh(const fs::path& path, const std::string& uri, const Eigen::Vector3d& scale,
                         const std::string& where) const {
    Assimp::Importer importer;
    importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
    // Points and lines are dropped. Only positions matter: without normals,
    // texture coordinates and colours, vertices that share a position are
    // joined, so a closed surface is seen to be closed (see orient()).
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS |
                                                            aiComponent_COLORS | aiComponent_TEXCOORDS |
                                                            aiComponent_BONEWEIGHTS | aiComponent_ANIMATIONS |
                                                            aiComponent_TEXTURES | aiComponent_MATERIALS);
    const aiScene* scene = importer.ReadFile(
        path.string(), aiProcess_RemoveComponent | aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                           aiProcess_PreTransformVertices | aiProcess_SortByPType);
    if (scene == nullptr) {
      throw ModelError(where + "mesh '" + uri + "' (" + path.string() +
                       ") could not be read: " + one_line(importer.GetErrorString()));
    }
    TriangleMesh mesh;
    mesh.source = path.string();
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
      const aiMesh& part = *scene->mMeshes[m];
      const uint32_t base = static_cast<uint32_t>(mesh.vertices.size());
      for (unsigned v = 0; v < part.mNumVertices; ++v) {
        const aiVector3D& p = part.mVertices[v];
        mesh.vertices.emplace_back(static_cast<float>(p.x * scale.x()), static_cast<float>(p.y * scale.y()),
                                   static_cast<float>(p.z * scale.z()));
      }
      for (unsigned f = 0; f < part.mNumFaces; ++f) {
        const aiFace& face = part.mFaces[f];
        if (face.mNumIndices != 3) continue;
        mesh.indices.insert(mesh.indices.end(),
                            {base + face.mIndices[0], base + face.mIndices[1], base + face.mIndices[2]});
      }
    }
    if (mesh.num_triangles() == 0) {
      throw ModelError(where + "mesh '" + uri + "' (" + path.string() + ") has no triangles");
    }
    orient(mesh);
    if (options_.padding_m > 0) pad_along_normals(mesh, options_.padding_m);
    return mesh;
  }

  // Sets closed_outward, flipping a closed, consistently wound mesh that is
  // wound inside out (e.g. mirrored by a negative scale).
  static void orient(TriangleMesh& mesh) {
    std::map<std::pair<uint32_t, uint32_t>, int> directed_edges;
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
      for (int k = 0; k < 3; ++k) ++directed_edges[{mesh.indices[t + k], mesh.indices[t + (k + 1) % 3]}];
    }
    for (const auto& [edge, count] : directed_edges) {
      const auto reverse = directed_edges.find({edge.second, edge.first});
      if (count != 1 || reverse == directed_edges.end() || reverse->second != 1) return;  // open or inconsistent
    }
    // Signed volume by the divergence theorem: positive when wound outward.
    double volume6 = 0;
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
      const Eigen::Vector3d a = mesh.vertices[mesh.indices[t]].cast<double>();
      const Eigen::Vector3d b = mesh.vertices[mesh.indices[t + 1]].cast<double>();
      const Eigen::Vector3d c = mesh.vertices[mesh.indices[t + 2]].cast<double>();
      volume6 += a.dot(b.cross(c));
    }
    if (volume6 == 0) return;
    if (volume6 < 0) {
      for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) std::swap(mesh.indices[t + 1], mesh.indices[t + 2]);
    }
    mesh.closed_outward = true;
  }

  static void pad_along_normals(TriangleMesh& mesh, double padding_m) {
    // Area-weighted vertex normals (the cross product's length is twice the
    // area). Closed meshes are wound outward by now (orient()); an open mesh
    // is padded towards the side its winding calls outside.
    std::vector<Eigen::Vector3d> normals(mesh.vertices.size(), Eigen::Vector3d::Zero());
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
      const Eigen::Vector3d a = mesh.vertices[mesh.indices[t]].cast<double>();
      const Eigen::Vector3d b = mesh.vertices[mesh.indices[t + 1]].cast<double>();
      const Eigen::Vector3d c = mesh.vertices[mesh.indices[t + 2]].cast<double>();
      const Eigen::Vector3d n = (b - a).cross(c - a);
      for (int k = 0; k < 3; ++k) normals[mesh.indices[t + k]] += n;
    }
    for (size_t v = 0; v < mesh.vertices.size(); ++v) {
      if (normals[v].norm() > 0) {
        mesh.vertices[v] += (padding_m * normals[v].normalized()).cast<float>();
      }
    }
  }

  SceneOptions options_;
  SceneModel scene_;
  std::vector<std::pair<int, std::string>> pending_mimics_;
  std::map<std::tuple<std::string, double, double, double>, int> mesh_cache_;
};

}  // namespace

GeometrySource parse_geometry_source(const std::string& text) {
  if (text == "visual") return GeometrySource::kVisual;
  if (text == "collision") return GeometrySource::kCollision;
  throw ModelError("geometry must be 'visual' or 'collision', got '" + text + "'");
}

int SceneModel::find_link(const std::string& name) const {
  for (size_t i = 0; i < links.size(); ++i) {
    if (links[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

std::vector<std::string> SceneModel::link_names() const {
  std::vector<std::string> names;
  for (const Link& link : links) names.push_back(link.name);
  return names;
}

size_t SceneModel::num_triangles() const {
  size_t total = 0;
  for (const Shape& shape : shapes) total += meshes[shape.mesh_index].num_triangles();
  return total;
}

SceneModel load_scene(const std::string& robot_urdf, const std::vector<std::string>& environment_urdfs,
                      const SceneOptions& options) {
  SceneBuilder builder(options);
  builder.add_urdf(robot_urdf, false);
  for (const std::string& path : environment_urdfs) builder.add_urdf(path, true);
  return builder.take();
}

}  // namespace tofguard::renderer
