#pragma once
// The scene tofguard renders: the robot's URDF (moving links) plus any number
// of static-environment URDFs (fixed links only: floor, table, wheelchair),
// reduced to what a depth renderer needs: the kinematic tree
// (kinematic_tree.hpp) and, per link, a list of triangle meshes at fixed
// poses in that link's frame.
//
// Frames and units as in kinematic_tree.hpp: URDF link frames, the world
// is the robot's root link; metres and radians.
//
// Loading happens once, at start; everything that can be wrong with a model
// (malformed XML, a mesh that cannot be found or read, a geometry type the
// renderer does not know, a moving joint in an environment) is a ModelError
// there, never a surprise later. Meshes are read with assimp: this part of
// robot_model is its own library (tofguard_scene_model), so that users of
// the tree alone (the risk classifier) do not link assimp.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tofguard/robot_model/kinematic_tree.hpp"

namespace tofguard::robot_model {

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
  // Mesh files are simplified at load (meshoptimizer's meshopt_simplify,
  // borders locked) until a further edge collapse would move the surface
  // by more than this, metres (its quadric error: the distance of the
  // simplified surface from the planes of the original triangles it
  // replaced), measured after the URDF's scale and before padding. 0: the
  // exact meshes. Primitives (boxes, spheres, cylinders) are never
  // simplified. docs/renderer.md, "Simplified meshes".
  double simplify_error_m = 0;
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
  // The file's triangles before simplification (SceneOptions::
  // simplify_error_m; num_triangles() when not simplified), and the error
  // the simplifier reports for the result, metres (0 when not simplified).
  size_t source_triangles = 0;
  double simplify_error_m = 0;
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

// The kinematic tree with the geometry of the source chosen
// (SceneOptions::geometry) as meshes and shapes.
struct SceneModel : KinematicTree {
  // Unit primitives first (UnitMesh), then one mesh per distinct
  // (file, scale, padding).
  std::vector<TriangleMesh> meshes;
  std::vector<Shape> shapes;

  // Triangles drawn per render (every shape, scaled meshes counted once per
  // shape that uses them).
  size_t num_triangles() const;
  // The same count with every mesh file's triangles before simplification.
  size_t num_source_triangles() const;
};

// Each robot link's surface area, m^2, as the scene draws it: the summed
// area of its shapes' triangles (a shape's scale applied per axis, a mesh
// counted once per shape that uses it, padding included). Indexed as
// KinematicTree::links, robot links only (num_robot_links entries); 0 for
// a link without geometry, such as a root frame.
std::vector<double> robot_link_areas_m2(const SceneModel& scene);

// Loads the robot and the environments. Mesh URIs: package://NAME/rest
// through options.package_paths, file:///abs, absolute paths, and paths
// relative to the URDF's folder. Meshes are read with assimp (STL, OBJ, DAE,
// and whatever else assimp reads); a Collada file's up-axis is ignored (URDF
// meshes are authored in the link frame) but its unit is honoured.
// Throws ModelError.
SceneModel load_scene(const std::string& robot_urdf, const std::vector<std::string>& environment_urdfs,
                      const SceneOptions& options);

}  // namespace tofguard::robot_model
