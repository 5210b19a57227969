#include "tofguard/robot_model/arm_spheres.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>

#include "tofguard/common/demand.hpp"

namespace tofguard::robot_model {
namespace {

struct Triangle {
  Eigen::Vector3d a, b, c;
};

// Splits `t` at the midpoint of its longest edge until no edge is longer
// than max_edge_m, appending the pieces to `out`.
void split_triangle(const Triangle& t, double max_edge_m, std::vector<Triangle>* out) {
  std::vector<Triangle> pending{t};
  while (!pending.empty()) {
    const Triangle u = pending.back();
    pending.pop_back();
    const double ab = (u.a - u.b).norm(), bc = (u.b - u.c).norm(), ca = (u.c - u.a).norm();
    if (std::max({ab, bc, ca}) <= max_edge_m) {
      out->push_back(u);
    } else if (ab >= bc && ab >= ca) {
      const Eigen::Vector3d m = (u.a + u.b) / 2;
      pending.push_back({u.a, m, u.c});
      pending.push_back({m, u.b, u.c});
    } else if (bc >= ca) {
      const Eigen::Vector3d m = (u.b + u.c) / 2;
      pending.push_back({u.a, u.b, m});
      pending.push_back({u.a, m, u.c});
    } else {
      const Eigen::Vector3d m = (u.c + u.a) / 2;
      pending.push_back({u.a, u.b, m});
      pending.push_back({m, u.b, u.c});
    }
  }
}

// The corners of the triangles whose centroid falls in one cell.
struct Cell {
  Eigen::AlignedBox3d box;
  std::vector<Eigen::Vector3d> corners;
};

}  // namespace

ArmSpheres cover_arm_with_spheres(const SceneModel& scene, double cell_m) {
  TOFGUARD_DEMAND(std::isfinite(cell_m) && cell_m > 0, "the sphere cover's cell must be a positive length");
  // Key: link index, then the cell's integer coordinates in the link frame.
  std::map<std::array<int64_t, 4>, Cell> cells;
  std::vector<Triangle> pieces;
  for (const Shape& shape : scene.shapes) {
    if (shape.link_index < 0 || shape.link_index >= scene.num_robot_links) continue;
    const TriangleMesh& mesh = scene.meshes.at(static_cast<size_t>(shape.mesh_index));
    auto corner = [&](uint32_t index) -> Eigen::Vector3d {
      return shape.link_from_shape * shape.scale.cwiseProduct(mesh.vertices.at(index).cast<double>());
    };
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
      pieces.clear();
      split_triangle({corner(mesh.indices[t]), corner(mesh.indices[t + 1]), corner(mesh.indices[t + 2])},
                     cell_m, &pieces);
      for (const Triangle& piece : pieces) {
        const Eigen::Vector3d centroid = (piece.a + piece.b + piece.c) / 3;
        const std::array<int64_t, 4> key{shape.link_index,
                                         static_cast<int64_t>(std::floor(centroid.x() / cell_m)),
                                         static_cast<int64_t>(std::floor(centroid.y() / cell_m)),
                                         static_cast<int64_t>(std::floor(centroid.z() / cell_m))};
        Cell& cell = cells[key];
        for (const Eigen::Vector3d* p : {&piece.a, &piece.b, &piece.c}) {
          cell.box.extend(*p);
          cell.corners.push_back(*p);
        }
      }
    }
  }
  ArmSpheres cover;
  cover.cell_m = cell_m;
  cover.spheres.reserve(cells.size());
  for (const auto& [key, cell] : cells) {
    LinkSphere sphere;
    sphere.link_index = static_cast<int>(key[0]);
    sphere.center_link_m = cell.box.center();
    for (const Eigen::Vector3d& p : cell.corners) {
      sphere.radius_m = std::max(sphere.radius_m, (p - sphere.center_link_m).norm());
    }
    cover.max_radius_m = std::max(cover.max_radius_m, sphere.radius_m);
    cover.spheres.push_back(sphere);
  }
  return cover;
}

PlacedArmSpheres place_arm_spheres(const ArmSpheres& cover, const LinkPoses& poses) {
  TOFGUARD_DEMAND(poses.usable, "the arm's spheres placed at unusable link poses");
  PlacedArmSpheres placed;
  placed.reserve(cover.spheres.size());
  for (const LinkSphere& sphere : cover.spheres) {
    TOFGUARD_DEMAND(static_cast<size_t>(sphere.link_index) < poses.world_from_link.size(),
                    "the sphere cover and the link poses come from different models");
    placed.push_back({poses.world_from_link[static_cast<size_t>(sphere.link_index)] * sphere.center_link_m,
                      sphere.radius_m});
  }
  return placed;
}

double distance_to_arm_m(const PlacedArmSpheres& placed, const Eigen::Vector3d& point_world) {
  double nearest = std::numeric_limits<double>::infinity();
  for (const PlacedSphere& sphere : placed) {
    nearest =
        std::min(nearest, std::max(0.0, (point_world - sphere.center_world_m).norm() - sphere.radius_m));
  }
  return nearest;
}

double separation_from_arm_m(const PlacedArmSpheres& placed, const OccupantPart& part) {
  double nearest = std::numeric_limits<double>::infinity();
  for (const PlacedSphere& sphere : placed) {
    nearest =
        std::min(nearest, std::max(0.0, distance_to_part_m(part, sphere.center_world_m) - sphere.radius_m));
  }
  return nearest;
}

std::vector<std::pair<BodyRegion, double>> body_region_separations_m(const PlacedArmSpheres& placed,
                                                                     const OccupantModel& occupant) {
  std::vector<std::pair<BodyRegion, double>> out;
  for (const BodyRegion region : occupant.regions()) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const OccupantPart& part : occupant.parts) {
      if (part.region == region) nearest = std::min(nearest, separation_from_arm_m(placed, part));
    }
    out.emplace_back(region, nearest);
  }
  return out;
}

}  // namespace tofguard::robot_model
