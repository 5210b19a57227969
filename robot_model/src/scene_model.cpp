#include "tofguard/robot_model/scene_model.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <tuple>

#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <meshoptimizer.h>
#include <assimp/Importer.hpp>

#include "tofguard/common/error_log.hpp"
#include "tofguard/robot_model/primitive_meshes.hpp"

namespace tofguard::robot_model {
namespace {

namespace fs = std::filesystem;

bool positive_finite(double v) { return std::isfinite(v) && v > 0; }

std::string geometry_word(GeometrySource source) {
  return source == GeometrySource::kVisual ? "visual" : "collision";
}

// Turns the tree's geometry elements of one source into meshes and shapes.
class SceneBuilder {
 public:
  explicit SceneBuilder(const SceneOptions& options) : options_(options) {
    if (!std::isfinite(options.padding_m) || options.padding_m < 0) {
      throw ModelError("renderer padding_m must be a finite value >= 0, got " +
                       std::to_string(options.padding_m));
    }
    if (!std::isfinite(options.simplify_error_m) || options.simplify_error_m < 0) {
      throw ModelError("renderer simplify_error_mm must be a finite value >= 0, got " +
                       std::to_string(1000 * options.simplify_error_m) + " mm");
    }
    scene_.meshes.push_back(unit_box());
    scene_.meshes.push_back(unit_sphere());
    scene_.meshes.push_back(unit_cylinder());
  }

  SceneModel build(KinematicTree tree) {
    static_cast<KinematicTree&>(scene_) = std::move(tree);
    for (size_t i = 0; i < scene_.links.size(); ++i) add_geometry(static_cast<int>(i));
    return std::move(scene_);
  }

 private:
  void add_geometry(int link_index) {
    const Link& link = scene_.links[link_index];
    const fs::path urdf_folder = fs::absolute(fs::path(link.file)).parent_path();
    const double pad = options_.padding_m;
    const std::string where = link.file + ": link '" + link.name + "': ";
    const auto& elements = options_.geometry == GeometrySource::kVisual ? link.visuals : link.collisions;
    for (const GeometryElement& geometry : elements) {
      Shape shape;
      shape.link_index = link_index;
      shape.link_from_shape = geometry.link_from_geometry;
      switch (geometry.kind) {
        case GeometryElement::Kind::kMissing:
          throw ModelError(where + geometry_word(options_.geometry) + " without geometry");
        case GeometryElement::Kind::kBox: {
          const Eigen::Vector3d& size = geometry.box_size_m;
          if (!positive_finite(size.x()) || !positive_finite(size.y()) || !positive_finite(size.z())) {
            throw ModelError(where + "box size must be three positive lengths");
          }
          shape.mesh_index = kUnitBox;
          shape.scale = size.array() + 2 * pad;
          break;
        }
        case GeometryElement::Kind::kSphere: {
          if (!positive_finite(geometry.radius_m)) throw ModelError(where + "sphere radius must be positive");
          shape.mesh_index = kUnitSphere;
          shape.scale = Eigen::Vector3d::Constant(geometry.radius_m + pad);
          break;
        }
        case GeometryElement::Kind::kCylinder: {
          if (!positive_finite(geometry.radius_m) || !positive_finite(geometry.length_m)) {
            throw ModelError(where + "cylinder radius and length must be positive");
          }
          shape.mesh_index = kUnitCylinder;
          shape.scale =
              Eigen::Vector3d(geometry.radius_m + pad, geometry.radius_m + pad, geometry.length_m + 2 * pad);
          break;
        }
        case GeometryElement::Kind::kMesh: {
          const Eigen::Vector3d& scale = geometry.mesh_scale;
          if (!std::isfinite(scale.sum()) || scale.cwiseAbs().minCoeff() <= 0) {
            throw ModelError(where + "mesh '" + geometry.mesh_uri +
                             "': scale must be three non-zero numbers");
          }
          shape.mesh_index =
              mesh_for(resolve_uri(geometry.mesh_uri, urdf_folder, where), geometry.mesh_uri, scale, where);
          break;
        }
        case GeometryElement::Kind::kUnknown:
          throw ModelError(where + "unknown geometry type (box, sphere, cylinder and mesh are supported)");
      }
      scene_.shapes.push_back(shape);
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

  int mesh_for(const fs::path& path, const std::string& uri, const Eigen::Vector3d& scale,
               const std::string& where) {
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
    importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS,
                                aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS |
                                    aiComponent_COLORS | aiComponent_TEXCOORDS | aiComponent_BONEWEIGHTS |
                                    aiComponent_ANIMATIONS | aiComponent_TEXTURES | aiComponent_MATERIALS);
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
    mesh.source_triangles = mesh.num_triangles();
    if (options_.simplify_error_m > 0) simplify(mesh, options_.simplify_error_m);
    orient(mesh);
    if (options_.padding_m > 0) pad_along_normals(mesh, options_.padding_m);
    return mesh;
  }

  // Collapses edges while the surface stays within error_m of the
  // original (meshopt_simplify's error is relative to the mesh's extent,
  // meshopt_simplifyScale), borders locked so that an open mesh keeps its
  // outline; then drops the vertices no triangle uses any more.
  static void simplify(TriangleMesh& mesh, double error_m) {
    static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float), "packed vertex positions");
    const float* positions = mesh.vertices.front().data();
    const size_t num_vertices = mesh.vertices.size();
    const float scale = meshopt_simplifyScale(positions, num_vertices, sizeof(Eigen::Vector3f));
    if (!(scale > 0)) return;  // every vertex at one point: nothing to simplify
    std::vector<uint32_t> simplified(mesh.indices.size());
    float relative_error = 0;
    simplified.resize(meshopt_simplify(simplified.data(), mesh.indices.data(), mesh.indices.size(), positions,
                                       num_vertices, sizeof(Eigen::Vector3f), 3,
                                       static_cast<float>(error_m / scale), meshopt_SimplifyLockBorder,
                                       &relative_error));
    if (simplified.empty()) return;  // keep the exact mesh rather than none
    std::vector<Eigen::Vector3f> vertices(num_vertices);
    vertices.resize(meshopt_optimizeVertexFetch(vertices.data(), simplified.data(), simplified.size(),
                                                mesh.vertices.data(), num_vertices, sizeof(Eigen::Vector3f)));
    mesh.vertices = std::move(vertices);
    mesh.indices = std::move(simplified);
    mesh.simplify_error_m = static_cast<double>(relative_error) * scale;
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
      if (count != 1 || reverse == directed_edges.end() || reverse->second != 1)
        return;  // open or inconsistent
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
      for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3)
        std::swap(mesh.indices[t + 1], mesh.indices[t + 2]);
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
  std::map<std::tuple<std::string, double, double, double>, int> mesh_cache_;
};

}  // namespace

GeometrySource parse_geometry_source(const std::string& text) {
  if (text == "visual") return GeometrySource::kVisual;
  if (text == "collision") return GeometrySource::kCollision;
  throw ModelError("geometry must be 'visual' or 'collision', got '" + text + "'");
}

size_t SceneModel::num_triangles() const {
  size_t total = 0;
  for (const Shape& shape : shapes) total += meshes[shape.mesh_index].num_triangles();
  return total;
}

size_t SceneModel::num_source_triangles() const {
  size_t total = 0;
  for (const Shape& shape : shapes) {
    const TriangleMesh& mesh = meshes[shape.mesh_index];
    total += mesh.source_triangles > 0 ? mesh.source_triangles : mesh.num_triangles();
  }
  return total;
}

std::vector<double> robot_link_areas_m2(const SceneModel& scene) {
  std::vector<double> area_m2(static_cast<size_t>(scene.num_robot_links), 0.0);
  for (const Shape& shape : scene.shapes) {
    if (shape.link_index < 0 || shape.link_index >= scene.num_robot_links) continue;
    const TriangleMesh& mesh = scene.meshes[shape.mesh_index];
    const Eigen::Vector3d scale = shape.scale;
    double sum_m2 = 0;
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
      const Eigen::Vector3d a = mesh.vertices[mesh.indices[t]].cast<double>().cwiseProduct(scale);
      const Eigen::Vector3d b = mesh.vertices[mesh.indices[t + 1]].cast<double>().cwiseProduct(scale);
      const Eigen::Vector3d c = mesh.vertices[mesh.indices[t + 2]].cast<double>().cwiseProduct(scale);
      sum_m2 += 0.5 * (b - a).cross(c - a).norm();
    }
    area_m2[static_cast<size_t>(shape.link_index)] += sum_m2;
  }
  return area_m2;
}

SceneModel load_scene(const std::string& robot_urdf, const std::vector<std::string>& environment_urdfs,
                      const SceneOptions& options) {
  SceneBuilder builder(options);  // checks the options before any file is read
  return builder.build(load_kinematic_tree(robot_urdf, environment_urdfs));
}

}  // namespace tofguard::robot_model
