#pragma once
// The scene tofguard renders: the robot's URDF (moving links) plus any number
// of static-environment URDFs (fixed links only: floor, table, wheelchair),
// reduced to what a depth renderer needs: a kinematic tree and, per link, a
// list of triangle meshes at fixed poses in that link's frame.
//
// Frames: every URDF link frame as the URDF defines it. "World" is the robot's
// root link; every environment URDF's root link is placed at that same frame
// (config: "placed in the same world frame as the robot's root link").
// Units: metres and radians throughout.
//
// Loading happens once, at start; everything that can be wrong with a model
// (malformed XML, a mesh that cannot be found or read, a geometry type the
// renderer does not know, a moving joint in an environment) is a ModelError
// there, never a surprise later.
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace tofguard::renderer {

// A model that cannot be used. what() is one line naming the file and, where
// it applies, the link and the mesh, e.g.
//   "friend_arm.urdf: link 'link3': mesh 'package://arm/l3.stl' not found (searched: ...)".
class ModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class GeometrySource { kVisual, kCollision };

struct SceneOptions {
  // Which URDF geometry to render: <visual> or <collision> elements.
  GeometrySource geometry = GeometrySource::kVisual;
  // Every shape is inflated by this much, metres (>= 0): boxes grow by
  // 2*padding_m per edge, spheres and cylinders by padding_m in radius and
  // cylinders by 2*padding_m in length; mesh vertices move padding_m along
  // their (area-weighted, smoothed) vertex normals.
  double padding_m = 0;
  // Folders searched for package://NAME/rest URIs: NAME is looked up as a
  // sub-folder of each, in order.
  std::vector<std::string> package_paths;
};

// Parses "visual" / "collision"; throws ModelError for anything else.
GeometrySource parse_geometry_source(const std::string& text);

// Triangles in one frame, metres, indexed.
struct TriangleMesh {
  // Where it came from (a resolved mesh path, or "unit box" etc.), for
  // messages and the benchmark's triangle count.
  std::string source;
  std::vector<Eigen::Vector3f> vertices;
  std::vector<uint32_t> indices;  // 3 per triangle
  // True when the triangles form closed surfaces, every edge shared by
  // exactly two triangles that run it in opposite directions, wound
  // counter-clockwise seen from outside. Only then may the renderer skip
  // back faces (about half the triangle work on llvmpipe) without changing
  // the image seen from outside the mesh.
  bool closed_outward = false;
  size_t num_triangles() const { return indices.size() / 3; }
};

// Meshes every scene holds at these indices: the unit primitives that URDF
// boxes, spheres and cylinders (and per-call extra objects) are drawn with,
// scaled per shape. Box: edge 1, centred. Sphere: radius 1, centred.
// Cylinder: radius 1, length 1 along z, centred.
enum UnitMesh : int { kUnitBox = 0, kUnitSphere = 1, kUnitCylinder = 2, kNumUnitMeshes = 3 };

// One piece of geometry of one link: mesh `mesh_index`, scaled per axis by
// `scale` (in the mesh's own frame), placed at link_from_shape.
struct Shape {
  int link_index = -1;
  int mesh_index = -1;
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
  Eigen::Isometry3d link_from_shape = Eigen::Isometry3d::Identity();
};

enum class JointType { kFixed, kRevolute, kContinuous, kPrismatic };

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
  // Mimic: value = multiplier * value(mimicked joint) + offset.
  int mimic_joint = -1;
  double mimic_multiplier = 1;
  double mimic_offset = 0;
};

struct Link {
  std::string name;
  // The joint whose child this link is; -1 for a root (the robot's root and
  // every environment root, all at the world frame).
  int parent_joint = -1;
  bool is_environment = false;
  // The URDF file it came from, for messages.
  std::string file;
};

struct SceneModel {
  // Robot links first (index 0 is the robot's root), then each
  // environment's links, each URDF depth-first from its root with siblings
  // in the order of their names; so every link comes after its parent.
  std::vector<Link> links;
  int num_robot_links = 0;
  // Ordered so that a joint's parent link's pose is known before it.
  std::vector<Joint> joints;
  // The robot joints a joint state must provide (revolute, continuous,
  // prismatic, not mimic), in URDF order.
  std::vector<std::string> actuated_joint_names;
  // Unit primitives first (UnitMesh), then one mesh per distinct
  // (file, scale, padding).
  std::vector<TriangleMesh> meshes;
  std::vector<Shape> shapes;

  // Index of the link called `name` (robot links win over environment links
  // of the same name), -1 when there is none.
  int find_link(const std::string& name) const;
  std::vector<std::string> link_names() const;
  // Triangles drawn per render (every shape, scaled meshes counted once per
  // shape that uses them).
  size_t num_triangles() const;
};

// Loads the robot and the environments. Mesh URIs: package://NAME/rest
// through options.package_paths, file:///abs, absolute paths, and paths
// relative to the URDF's folder. Meshes are read with assimp (STL, OBJ, DAE,
// and whatever else assimp reads); a Collada file's up-axis is ignored (URDF
// meshes are authored in the link frame) but its unit is honoured.
// Throws ModelError.
SceneModel load_scene(const std::string& robot_urdf, const std::vector<std::string>& environment_urdfs,
                      const SceneOptions& options);

}  // namespace tofguard::renderer
