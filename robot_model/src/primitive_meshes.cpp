#include "tofguard/robot_model/primitive_meshes.hpp"

#include <cmath>

namespace tofguard::robot_model {
namespace {

uint32_t add_vertex(TriangleMesh& mesh, double x, double y, double z) {
  mesh.vertices.emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
  return static_cast<uint32_t>(mesh.vertices.size() - 1);
}

void add_triangle(TriangleMesh& mesh, uint32_t a, uint32_t b, uint32_t c) {
  mesh.indices.insert(mesh.indices.end(), {a, b, c});
}

}  // namespace

TriangleMesh unit_box() {
  TriangleMesh mesh;
  mesh.source = "unit box";
  for (int i = 0; i < 8; ++i) {
    add_vertex(mesh, (i & 1) ? 0.5 : -0.5, (i & 2) ? 0.5 : -0.5, (i & 4) ? 0.5 : -0.5);
  }
  // Corner index = x + 2y + 4z (bits). Each face as a quad a, b, c, d
  // counter-clockwise seen from outside, so that (b - a) x (c - a) points out.
  const uint32_t faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : faces) {
    add_triangle(mesh, f[0], f[1], f[2]);
    add_triangle(mesh, f[0], f[2], f[3]);
  }
  mesh.closed_outward = true;
  return mesh;
}

TriangleMesh unit_sphere() {
  TriangleMesh mesh;
  mesh.source = "unit sphere";
  const int rings = kSphereSegments / 2;
  // Ring i at polar angle pi*i/rings; the poles are single vertices.
  const uint32_t north = add_vertex(mesh, 0, 0, 1);
  std::vector<uint32_t> ring_start;
  for (int i = 1; i < rings; ++i) {
    const double polar = M_PI * i / rings;
    ring_start.push_back(static_cast<uint32_t>(mesh.vertices.size()));
    for (int j = 0; j < kSphereSegments; ++j) {
      const double azimuth = 2 * M_PI * j / kSphereSegments;
      add_vertex(mesh, std::sin(polar) * std::cos(azimuth), std::sin(polar) * std::sin(azimuth),
                 std::cos(polar));
    }
  }
  const uint32_t south = add_vertex(mesh, 0, 0, -1);
  const auto at = [&](int ring, int j) {
    return ring_start[ring] + static_cast<uint32_t>(j % kSphereSegments);
  };
  for (int j = 0; j < kSphereSegments; ++j) {
    add_triangle(mesh, north, at(0, j), at(0, j + 1));
    add_triangle(mesh, south, at(rings - 2, j + 1), at(rings - 2, j));
    for (int i = 0; i + 1 < rings - 1; ++i) {
      add_triangle(mesh, at(i, j), at(i + 1, j), at(i + 1, j + 1));
      add_triangle(mesh, at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  }
  mesh.closed_outward = true;
  return mesh;
}

TriangleMesh unit_cylinder() {
  TriangleMesh mesh;
  mesh.source = "unit cylinder";
  const uint32_t top_centre = add_vertex(mesh, 0, 0, 0.5);
  const uint32_t bottom_centre = add_vertex(mesh, 0, 0, -0.5);
  const uint32_t first = static_cast<uint32_t>(mesh.vertices.size());
  for (int j = 0; j < kCylinderSegments; ++j) {
    const double azimuth = 2 * M_PI * j / kCylinderSegments;
    add_vertex(mesh, std::cos(azimuth), std::sin(azimuth), 0.5);
    add_vertex(mesh, std::cos(azimuth), std::sin(azimuth), -0.5);
  }
  const auto top = [&](int j) { return first + 2 * static_cast<uint32_t>(j % kCylinderSegments); };
  const auto bottom = [&](int j) { return top(j) + 1; };
  for (int j = 0; j < kCylinderSegments; ++j) {
    add_triangle(mesh, top_centre, top(j), top(j + 1));
    add_triangle(mesh, bottom_centre, bottom(j + 1), bottom(j));
    add_triangle(mesh, top(j), bottom(j), bottom(j + 1));
    add_triangle(mesh, top(j), bottom(j + 1), top(j + 1));
  }
  mesh.closed_outward = true;
  return mesh;
}

}  // namespace tofguard::robot_model
