// The renderer against a ray-cast computed here: a sphere, a box and a
// cylinder at known poses, seen by a camera with fx != fy and an off-centre
// principal point. Every pixel away from a silhouette must agree in depth to
// 1 mm (or 0.1 % of depth) and in label; silhouettes to one pixel.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <limits>
#include <sstream>

#include "renderer_test_util.hpp"

namespace tofguard::renderer::test {
namespace {

constexpr double kNoHit = std::numeric_limits<double>::infinity();

// Smallest t > 0 with o + t*d inside the primitive's surface, in the
// primitive's own frame; kNoHit when the ray misses.
double ray_sphere(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double r) {
  const double a = d.dot(d), b = 2 * o.dot(d), c = o.dot(o) - r * r;
  const double disc = b * b - 4 * a * c;
  if (disc < 0) return kNoHit;
  const double t = (-b - std::sqrt(disc)) / (2 * a);
  return t > 0 ? t : kNoHit;
}

double ray_box(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& half) {
  double t_in = -kNoHit, t_out = kNoHit;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(d[k]) < 1e-15) {
      if (std::abs(o[k]) > half[k]) return kNoHit;
      continue;
    }
    double t1 = (-half[k] - o[k]) / d[k], t2 = (half[k] - o[k]) / d[k];
    if (t1 > t2) std::swap(t1, t2);
    t_in = std::max(t_in, t1);
    t_out = std::min(t_out, t2);
  }
  return (t_in <= t_out && t_in > 0) ? t_in : kNoHit;
}

double ray_cylinder(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double r, double length) {
  const double h = length / 2;
  double best = kNoHit;
  // Side: (ox + t dx)^2 + (oy + t dy)^2 = r^2 with |z| <= h.
  const double a = d.x() * d.x() + d.y() * d.y();
  const double b = 2 * (o.x() * d.x() + o.y() * d.y());
  const double c = o.x() * o.x() + o.y() * o.y() - r * r;
  const double disc = b * b - 4 * a * c;
  if (a > 0 && disc >= 0) {
    for (double t : {(-b - std::sqrt(disc)) / (2 * a), (-b + std::sqrt(disc)) / (2 * a)}) {
      if (t > 0 && std::abs(o.z() + t * d.z()) <= h) best = std::min(best, t);
    }
  }
  // Caps.
  if (std::abs(d.z()) > 0) {
    for (double z : {-h, h}) {
      const double t = (z - o.z()) / d.z();
      const Eigen::Vector3d p = o + t * d;
      if (t > 0 && p.x() * p.x() + p.y() * p.y() <= r * r) best = std::min(best, t);
    }
  }
  return best;
}

struct Primitive {
  std::string link;
  std::string geometry_xml;
  Eigen::Vector3d xyz;  // in world
  Eigen::Vector3d rpy;
  std::function<double(const Eigen::Vector3d&, const Eigen::Vector3d&)> ray;  // in the primitive's frame
};

std::string urdf_for(const std::vector<Primitive>& primitives) {
  std::ostringstream urdf;
  urdf.precision(17);
  urdf << "<?xml version=\"1.0\"?>\n<robot name=\"analytic\">\n  <link name=\"world\"/>\n";
  for (const Primitive& p : primitives) {
    urdf << "  <joint name=\"" << p.link << "_joint\" type=\"fixed\"><parent link=\"world\"/><child link=\""
         << p.link << "\"/><origin xyz=\"" << p.xyz.transpose() << "\" rpy=\"" << p.rpy.transpose()
         << "\"/></joint>\n"
         << "  <link name=\"" << p.link << "\"><visual><geometry>" << p.geometry_xml
         << "</geometry></visual></link>\n";
  }
  urdf << "</robot>\n";
  return urdf.str();
}

struct Expected {
  std::vector<double> depth_m;  // 0 = nothing
  std::vector<int> labels;
};

// Ray-casts pixel centres (u, v) through the OpenCV model; labels from
// `link_index` (the renderer's link order).
Expected ray_cast(const std::vector<Primitive>& primitives, const Eigen::Isometry3d& world_from_optical,
                  const Intrinsics& k, double far_m,
                  const std::function<int(const std::string&)>& link_index) {
  Expected e;
  e.depth_m.assign(static_cast<size_t>(k.width) * k.height, 0);
  e.labels.assign(e.depth_m.size(), 0);
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      // With d's optical z = 1, the ray parameter t is the depth Z.
      const Eigen::Vector3d d_optical((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1);
      double best = kNoHit;
      int label = 0;
      for (size_t i = 0; i < primitives.size(); ++i) {
        const Eigen::Isometry3d world_from_shape = pose(primitives[i].xyz, primitives[i].rpy);
        const Eigen::Isometry3d shape_from_optical = world_from_shape.inverse() * world_from_optical;
        const double t =
            primitives[i].ray(shape_from_optical.translation(), shape_from_optical.linear() * d_optical);
        if (t < best) {
          best = t;
          label = static_cast<int>(i);
        }
      }
      if (best <= far_m) {
        e.depth_m[v * k.width + u] = best;
        e.labels[v * k.width + u] = kLabelRobotFirst + link_index(primitives[label].link);
      }
    }
  }
  return e;
}

struct Comparison {
  int interior_pixels = 0;
  int interior_depth_failures = 0;
  int interior_label_failures = 0;
  int silhouette_failures = 0;
  double worst_depth_error_m = 0;
  std::string first_failure;
};

Comparison compare(const RenderResult& r, const Expected& e, const Intrinsics& k) {
  Comparison c;
  const auto at = [&](int u, int v) { return static_cast<size_t>(v) * k.width + u; };
  const auto fail = [&](const std::string& what, int u, int v) {
    if (c.first_failure.empty()) {
      std::ostringstream s;
      s << what << " at (" << u << ", " << v << "): rendered label " << r.labels[at(u, v)] << " depth "
        << r.depth_m[at(u, v)] << ", expected label " << e.labels[at(u, v)] << " depth "
        << e.depth_m[at(u, v)];
      c.first_failure = s.str();
    }
  };
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const int expected = e.labels[at(u, v)];
      bool interior = u > 0 && v > 0 && u + 1 < k.width && v + 1 < k.height;
      bool rendered_label_nearby = false;
      for (int dv = -1; dv <= 1; ++dv) {
        for (int du = -1; du <= 1; ++du) {
          const int uu = u + du, vv = v + dv;
          if (uu < 0 || vv < 0 || uu >= k.width || vv >= k.height) continue;
          interior = interior && e.labels[at(uu, vv)] == expected;
          rendered_label_nearby = rendered_label_nearby || e.labels[at(uu, vv)] == r.labels[at(u, v)];
        }
      }
      if (interior) {
        ++c.interior_pixels;
        if (r.labels[at(u, v)] != expected) {
          ++c.interior_label_failures;
          fail("label", u, v);
        }
        if (expected != 0) {
          const double error = std::abs(r.depth_m[at(u, v)] - e.depth_m[at(u, v)]);
          c.worst_depth_error_m = std::max(c.worst_depth_error_m, error);
          if (error > std::max(0.001, 0.001 * e.depth_m[at(u, v)])) {
            ++c.interior_depth_failures;
            fail("depth", u, v);
          }
        } else if (r.depth_m[at(u, v)] != 0) {
          ++c.interior_depth_failures;
          fail("depth where nothing is", u, v);
        }
      } else if (!rendered_label_nearby) {
        ++c.silhouette_failures;
        fail("silhouette off by more than one pixel", u, v);
      }
    }
  }
  return c;
}

// The scene: a sphere, a rotated box and a rotated cylinder, placed in the
// optical frame's view and given in world coordinates (the camera is not
// at the world origin and is rotated too).
class AnalyticRender : public ::testing::Test {
 protected:
  static std::function<int(const std::string&)> index_in(const RenderResult& r) {
    return [names = r.link_names](const std::string& name) {
      const auto it = std::find(names.begin(), names.end(), name);
      EXPECT_NE(it, names.end()) << name;
      return static_cast<int>(it - names.begin());
    };
  }

  static Eigen::Isometry3d world_from_optical() {
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.translation() = Eigen::Vector3d(0.3, -0.2, 1.1);
    t.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    return t;
  }

  static std::vector<Primitive> primitives() {
    const Eigen::Isometry3d w = world_from_optical();
    std::vector<Primitive> p;
    p.push_back({"sphere", "<sphere radius=\"0.12\"/>", w * Eigen::Vector3d(-0.25, -0.12, 1.3),
                 Eigen::Vector3d(0.3, 0.2, 0.1),
                 [](const Eigen::Vector3d& o, const Eigen::Vector3d& d) { return ray_sphere(o, d, 0.12); }});
    p.push_back({"box", "<box size=\"0.3 0.15 0.2\"/>", w * Eigen::Vector3d(0.2, 0.1, 1.1),
                 Eigen::Vector3d(0.5, -0.3, 0.8), [](const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
                   return ray_box(o, d, Eigen::Vector3d(0.15, 0.075, 0.1));
                 }});
    p.push_back(
        {"cylinder", "<cylinder radius=\"0.08\" length=\"0.5\"/>", w * Eigen::Vector3d(0.05, 0.25, 1.6),
         Eigen::Vector3d(1.2, 0.4, -0.3),
         [](const Eigen::Vector3d& o, const Eigen::Vector3d& d) { return ray_cylinder(o, d, 0.08, 0.5); }});
    return p;
  }

  static robot_model::SceneModel scene() {
    return robot_model::load_scene(write_test_file("analytic.urdf", urdf_for(primitives())), {},
                                   robot_model::SceneOptions{});
  }
};

TEST_F(AnalyticRender, MatchesRayCastWithOffCentrePrincipalPointAndUnequalFocalLengths) {
  DepthRenderer renderer(scene(), 0.1, 5.0);
  const Intrinsics k{200, 150, 215.0, 190.0, 91.3, 83.7};
  const RenderResult r = renderer.render({}, camera_pose_in("world", world_from_optical()), k);
  ASSERT_TRUE(r.usable) << r.unusable_reason;
  ASSERT_EQ(r.width, k.width);
  ASSERT_EQ(r.height, k.height);
  const Expected e = ray_cast(primitives(), world_from_optical(), k, 5.0, index_in(r));
  // Each object covers a good part of the image, so the check has teeth.
  for (const Primitive& p : primitives()) {
    const int label = kLabelRobotFirst + index_in(r)(p.link);
    EXPECT_GT(std::count(e.labels.begin(), e.labels.end(), label), 800) << p.link;
  }
  const Comparison c = compare(r, e, k);
  EXPECT_GT(c.interior_pixels, 25000);
  EXPECT_EQ(c.interior_depth_failures, 0) << c.first_failure;
  EXPECT_EQ(c.interior_label_failures, 0) << c.first_failure;
  EXPECT_EQ(c.silhouette_failures, 0) << c.first_failure;
  EXPECT_LT(c.worst_depth_error_m, 0.001);
  std::cout << "interior pixels " << c.interior_pixels << ", worst depth error "
            << c.worst_depth_error_m * 1000 << " mm\n";
  // Nothing rendered has depth outside what it could have.
  for (size_t i = 0; i < r.labels.size(); ++i) {
    if (r.labels[i] == 0) {
      EXPECT_EQ(r.depth_m[i], 0.0f);
    } else {
      EXPECT_GT(r.depth_m[i], 0.5f);
    }
  }
}

TEST_F(AnalyticRender, SameSceneAtAnotherSizeAndPrincipalPoint) {
  // The framebuffer is reallocated for the new size; the projection
  // follows the new intrinsics.
  DepthRenderer renderer(scene(), 0.1, 5.0);
  const Intrinsics small{64, 48, 70.0, 61.0, 30.2, 25.9};
  ASSERT_TRUE(renderer.render({}, camera_pose_in("world", world_from_optical()), small).usable);
  const Intrinsics k{96, 128, 90.0, 140.0, 52.5, 58.0};  // portrait: a transposition would not fit
  const RenderResult r = renderer.render({}, camera_pose_in("world", world_from_optical()), k);
  ASSERT_TRUE(r.usable) << r.unusable_reason;
  const Comparison c = compare(r, ray_cast(primitives(), world_from_optical(), k, 5.0, index_in(r)), k);
  EXPECT_GT(c.interior_pixels, 8000);
  EXPECT_EQ(c.interior_depth_failures + c.interior_label_failures + c.silhouette_failures, 0)
      << c.first_failure;
}

TEST(AnalyticRenderOrientation, AsymmetricSceneIsNeitherMirroredNorTransposed) {
  // Three small cubes in the optical frame: top-left near, top-right
  // further, bottom-left further still. u grows to the right (optical +x),
  // v downwards (optical +y). A mirrored or transposed image puts the cubes'
  // labels in the wrong corners and moves their centroids.
  const std::vector<Eigen::Vector3d> centres = {{-0.3, -0.2, 1.0}, {0.35, -0.2, 1.5}, {-0.3, 0.25, 2.0}};
  std::ostringstream urdf;
  urdf << "<robot name=\"corners\"><link name=\"world\"/>";
  for (size_t i = 0; i < centres.size(); ++i) {
    urdf << "<joint name=\"j" << i << "\" type=\"fixed\"><parent link=\"world\"/><child link=\"cube" << i
         << "\"/><origin xyz=\"" << centres[i].transpose() << "\"/></joint><link name=\"cube" << i
         << "\"><visual><geometry><box size=\"0.1 0.1 0.1\"/></geometry></visual></link>";
  }
  urdf << "</robot>";
  const robot_model::SceneModel scene =
      robot_model::load_scene(write_test_file("corners.urdf", urdf.str()), {}, robot_model::SceneOptions{});
  DepthRenderer renderer(scene, 0.1, 5.0);
  const Intrinsics k{160, 100, 120.0, 110.0, 70.4, 45.6};
  // The camera's optical frame is the world frame here.
  const RenderResult r = renderer.render({}, camera_pose_in("world", Eigen::Isometry3d::Identity()), k);
  ASSERT_TRUE(r.usable) << r.unusable_reason;
  ASSERT_EQ(r.link_names, (std::vector<std::string>{"world", "cube0", "cube1", "cube2"}));
  for (size_t i = 0; i < centres.size(); ++i) {
    const int label = kLabelRobotFirst + 1 + static_cast<int>(i);
    // The pixel nearest the projected centre of the cube's front face (at
    // z - 0.05) sees that face; its mirror images in u and in v, and its
    // transposed position, do not.
    const Eigen::Vector3d c = centres[i];
    const double z_front = c.z() - 0.05;
    const int u0 = static_cast<int>(std::lround(k.fx * c.x() / z_front + k.cx));
    const int v0 = static_cast<int>(std::lround(k.fy * c.y() / z_front + k.cy));
    EXPECT_EQ(r.labels[v0 * k.width + u0], label) << "cube " << i;
    EXPECT_NEAR(r.depth_m[v0 * k.width + u0], z_front, 1e-4) << "cube " << i;
    EXPECT_NE(r.labels[v0 * k.width + (k.width - 1 - u0)], label) << "cube " << i;
    EXPECT_NE(r.labels[(k.height - 1 - v0) * k.width + u0], label) << "cube " << i;
    if (u0 < k.height && v0 < k.width) {
      EXPECT_NE(r.labels[u0 * k.width + v0], label) << "cube " << i;
    }
    // The front face's left and right edges project to u = fx*(x -+ 0.05)/z_front + cx:
    // the pixels 1.5 pixels inside them along row v0 see the cube.
    const double u_left = k.fx * (c.x() - 0.05) / z_front + k.cx;
    const double u_right = k.fx * (c.x() + 0.05) / z_front + k.cx;
    EXPECT_EQ(r.labels[v0 * k.width + static_cast<int>(std::ceil(u_left + 1))], label) << "cube " << i;
    EXPECT_EQ(r.labels[v0 * k.width + static_cast<int>(std::floor(u_right - 1))], label) << "cube " << i;
  }
  // Row 0 is the top of the image: the top-left quadrant holds cube 0.
  EXPECT_GT(count_label(r, kLabelRobotFirst + 1), 0);
  int top_left = 0;
  for (int v = 0; v < k.height / 2; ++v) {
    for (int u = 0; u < k.width / 2; ++u) top_left += r.labels[v * k.width + u] == kLabelRobotFirst + 1;
  }
  EXPECT_EQ(top_left, count_label(r, kLabelRobotFirst + 1));
}

}  // namespace
}  // namespace tofguard::renderer::test
