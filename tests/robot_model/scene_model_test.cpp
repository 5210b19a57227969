// Loading models: meshes (STL, OBJ) against primitives, padding, package://
// and relative URIs, the real iiwa14, and bad models with their errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <thread>
#include <vector>

#include "renderer_test_util.hpp"

namespace tofguard::renderer::test {
namespace {

namespace fs = std::filesystem;

// A box with `n` x `n` quads per face, each split in two: the triangles of
// an axis-aligned box of half-extents `half`, centred.
std::vector<std::array<Eigen::Vector3d, 3>> tessellated_box(const Eigen::Vector3d& half, int n) {
  std::vector<std::array<Eigen::Vector3d, 3>> triangles;
  for (int axis = 0; axis < 3; ++axis) {
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    for (double side : {-1.0, 1.0}) {
      const auto corner = [&](int i, int j) {
        Eigen::Vector3d p;
        p[axis] = side * half[axis];
        p[a] = -half[a] + 2 * half[a] * i / n;
        p[b] = -half[b] + 2 * half[b] * j / n;
        return p;
      };
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
          // Outward winding: (a, b, axis) is right-handed.
          if (side > 0) {
            triangles.push_back({corner(i, j), corner(i + 1, j), corner(i + 1, j + 1)});
            triangles.push_back({corner(i, j), corner(i + 1, j + 1), corner(i, j + 1)});
          } else {
            triangles.push_back({corner(i, j), corner(i + 1, j + 1), corner(i + 1, j)});
            triangles.push_back({corner(i, j), corner(i, j + 1), corner(i + 1, j + 1)});
          }
        }
      }
    }
  }
  return triangles;
}

std::string ascii_stl(const std::vector<std::array<Eigen::Vector3d, 3>>& triangles) {
  std::ostringstream s;
  s.precision(9);
  s << "solid box\n";
  for (const auto& t : triangles) {
    const Eigen::Vector3d n = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
    s << " facet normal " << n.transpose() << "\n  outer loop\n";
    for (const auto& p : t) s << "   vertex " << p.transpose() << "\n";
    s << "  endloop\n endfacet\n";
  }
  s << "endsolid box\n";
  return s.str();
}

std::string obj(const std::vector<std::array<Eigen::Vector3d, 3>>& triangles) {
  std::ostringstream s;
  s.precision(9);
  for (const auto& t : triangles) {
    for (const auto& p : t) s << "v " << p.transpose() << "\n";
  }
  for (size_t i = 0; i < triangles.size(); ++i)
    s << "f " << 3 * i + 1 << " " << 3 * i + 2 << " " << 3 * i + 3 << "\n";
  return s.str();
}

std::string one_link_urdf(const std::string& geometry,
                          const std::string& origin = "xyz=\"0.1 -0.05 1.2\" rpy=\"0.4 0.3 0.2\"") {
  return "<?xml version=\"1.0\"?><robot name=\"one\"><link name=\"world\"/>"
         "<joint name=\"fix\" type=\"fixed\"><parent link=\"world\"/><child link=\"thing\"/><origin " +
         origin + "/></joint><link name=\"thing\"><visual><geometry>" + geometry +
         "</geometry></visual><collision><geometry>" + geometry + "</geometry></collision></link></robot>";
}

const Intrinsics kIntrinsics{160, 120, 150.0, 145.0, 78.6, 61.2};

RenderResult render_world_view(const robot_model::SceneModel& scene,
                               const robot_model::JointPositions& joints = {}) {
  DepthRenderer renderer(scene, 0.1, 5.0);
  return renderer.render(joints, camera_pose_in("world", Eigen::Isometry3d::Identity()), kIntrinsics);
}

// Pixels whose labels differ, and the largest depth difference where both
// images see the same label.
std::pair<int, double> difference(const RenderResult& a, const RenderResult& b) {
  int labels = 0;
  double depth = 0;
  for (size_t i = 0; i < a.labels.size(); ++i) {
    if (a.labels[i] != b.labels[i]) {
      ++labels;
    } else {
      depth = std::max(depth, static_cast<double>(std::abs(a.depth_m[i] - b.depth_m[i])));
    }
  }
  return {labels, depth};
}

TEST(SceneModel, TessellatedBoxAsStlAndObjRendersLikeThePrimitiveBox) {
  const Eigen::Vector3d size(0.3, 0.2, 0.25);
  const std::string stl_path =
      write_test_file("packages/testpkg/meshes/box.stl", ascii_stl(tessellated_box(size / 2, 4)));
  write_test_file("meshes/unit_box.obj", obj(tessellated_box(Eigen::Vector3d::Constant(0.5), 3)));
  const fs::path packages = fs::path(stl_path).parent_path().parent_path().parent_path();

  const robot_model::SceneModel primitive = robot_model::load_scene(
      write_test_file("box_primitive.urdf", one_link_urdf("<box size=\"0.3 0.2 0.25\"/>")), {}, {});
  robot_model::SceneOptions with_packages;
  with_packages.package_paths = {"/nonexistent", packages.string()};
  const robot_model::SceneModel stl = robot_model::load_scene(
      write_test_file("box_stl.urdf", one_link_urdf("<mesh filename=\"package://testpkg/meshes/box.stl\"/>")),
      {}, with_packages);
  const robot_model::SceneModel obj_scaled = robot_model::load_scene(
      write_test_file("box_obj.urdf",
                      one_link_urdf("<mesh filename=\"meshes/unit_box.obj\" scale=\"0.3 0.2 0.25\"/>")),
      {}, {});
  EXPECT_EQ(stl.meshes.back().num_triangles(), 6u * 4 * 4 * 2);
  EXPECT_EQ(obj_scaled.meshes.back().num_triangles(), 6u * 3 * 3 * 2);
  // The box's surface, 2 (0.3*0.2 + 0.3*0.25 + 0.2*0.25) = 0.37 m^2, from
  // each (the scaled unit primitive, the mesh in metres, the unit mesh
  // scaled per axis); the root frame has none.
  for (const robot_model::SceneModel* scene : {&primitive, &stl, &obj_scaled}) {
    const std::vector<double> area_m2 = robot_model::robot_link_areas_m2(*scene);
    ASSERT_EQ(area_m2.size(), 2u);
    EXPECT_EQ(area_m2[0], 0.0);
    EXPECT_NEAR(area_m2[1], 0.37, 1e-6);
  }

  const RenderResult a = render_world_view(primitive);
  const RenderResult b = render_world_view(stl);
  const RenderResult c = render_world_view(obj_scaled);
  ASSERT_TRUE(a.usable && b.usable && c.usable);
  const int box_pixels = count_label(a, kLabelRobotFirst + 1);
  EXPECT_GT(box_pixels, 1000);
  for (const RenderResult* mesh : {&b, &c}) {
    const auto [label_differences, depth_difference] = difference(a, *mesh);
    EXPECT_LE(label_differences, 4);  // a pixel centre exactly on an edge may go either way
    EXPECT_LT(depth_difference, 1e-4);
  }
}

TEST(SceneModel, PaddingInflatesPrimitivesAndMeshes) {
  // Seen head-on (no rotation), 1.2 m ahead: the front face moves 2 cm closer.
  const std::string origin = "xyz=\"0 0 1.2\" rpy=\"0 0 0\"";
  write_test_file("meshes/unit_box.obj", obj(tessellated_box(Eigen::Vector3d::Constant(0.5), 3)));
  const std::string box =
      write_test_file("pad_box.urdf", one_link_urdf("<box size=\"0.3 0.2 0.25\"/>", origin));
  const std::string mesh = write_test_file(
      "pad_mesh.urdf",
      one_link_urdf("<mesh filename=\"meshes/unit_box.obj\" scale=\"0.3 0.2 0.25\"/>", origin));
  const std::string bigger =
      write_test_file("pad_bigger.urdf", one_link_urdf("<box size=\"0.34 0.24 0.29\"/>", origin));
  robot_model::SceneOptions padded;
  padded.padding_m = 0.02;
  const RenderResult plain = render_world_view(robot_model::load_scene(box, {}, {}));
  const RenderResult padded_box = render_world_view(robot_model::load_scene(box, {}, padded));
  const RenderResult padded_mesh = render_world_view(robot_model::load_scene(mesh, {}, padded));
  const RenderResult reference = render_world_view(robot_model::load_scene(bigger, {}, {}));
  const size_t centre = static_cast<size_t>(std::lround(kIntrinsics.cy)) * kIntrinsics.width +
                        static_cast<size_t>(std::lround(kIntrinsics.cx));
  EXPECT_NEAR(plain.depth_m[centre], 1.2 - 0.125, 1e-5);
  EXPECT_NEAR(padded_box.depth_m[centre], 1.2 - 0.125 - 0.02, 1e-5);
  EXPECT_NEAR(padded_mesh.depth_m[centre], 1.2 - 0.125 - 0.02, 1e-5);
  const auto [label_differences, depth_difference] = difference(padded_box, reference);
  EXPECT_EQ(label_differences, 0);
  EXPECT_LT(depth_difference, 1e-5);
  EXPECT_GT(count_label(padded_box, 2), count_label(plain, 2) + 200);
}

TEST(SceneModel, ExtraObjectsGetTheirOwnLabelsAndExactDepth) {
  const robot_model::SceneModel scene = robot_model::load_scene(
      write_test_file("extra_base.urdf", one_link_urdf("<box size=\"0.1 0.1 0.1\"/>", "xyz=\"0.3 0 2\"")), {},
      {});
  DepthRenderer renderer(scene, 0.1, 5.0);
  Eigen::Isometry3d at = Eigen::Isometry3d::Identity();
  at.translation() = Eigen::Vector3d(-0.2, 0.1, 1.0);
  Eigen::Isometry3d cylinder_at = Eigen::Isometry3d::Identity();
  cylinder_at.translation() = Eigen::Vector3d(0.2, -0.15, 1.5);
  const std::vector<ExtraObject> extras = {ExtraObject::sphere(0.1, at),
                                           ExtraObject::cylinder(0.05, 0.3, cylinder_at)};
  const RenderResult r =
      renderer.render({}, camera_pose_in("world", Eigen::Isometry3d::Identity()), kIntrinsics, extras);
  ASSERT_TRUE(r.usable) << r.unusable_reason;
  const int u = static_cast<int>(std::lround(kIntrinsics.fx * -0.2 / 1.0 + kIntrinsics.cx));
  const int v = static_cast<int>(std::lround(kIntrinsics.fy * 0.1 / 1.0 + kIntrinsics.cy));
  EXPECT_EQ(r.labels[v * kIntrinsics.width + u], kLabelExtraObjectFirst);
  // The ray through that pixel centre is almost the one through the sphere's centre.
  const Eigen::Vector3d ray((u - kIntrinsics.cx) / kIntrinsics.fx, (v - kIntrinsics.cy) / kIntrinsics.fy, 1);
  const double b = -2 * ray.dot(at.translation()), c = at.translation().squaredNorm() - 0.01;
  const double z = (-b - std::sqrt(b * b - 4 * ray.squaredNorm() * c)) / (2 * ray.squaredNorm());
  EXPECT_NEAR(r.depth_m[v * kIntrinsics.width + u], z, 1e-4);
  EXPECT_GT(count_label(r, kLabelExtraObjectFirst + 1), 100);
  EXPECT_GT(count_label(r, kLabelRobotFirst + 1), 30);
  // Without them, only the model remains: nothing was uploaded for them.
  const RenderResult without =
      renderer.render({}, camera_pose_in("world", Eigen::Isometry3d::Identity()), kIntrinsics);
  EXPECT_EQ(count_label(without, kLabelExtraObjectFirst), 0);
  EXPECT_EQ(count_label(without, kLabelRobotFirst + 1), count_label(r, kLabelRobotFirst + 1));
}

TEST(SceneModel, DeviceAndSurfacelessPlatformsRenderTheSameImage) {
  const robot_model::SceneModel scene = robot_model::load_scene(
      write_test_file("platform.urdf", one_link_urdf("<sphere radius=\"0.2\"/>")), {}, {});
  std::vector<RenderResult> results;
  for (EglPlatform platform : {EglPlatform::kDevice, EglPlatform::kSurfaceless}) {
    try {
      DepthRenderer renderer(scene, 0.1, 5.0, platform);
      std::cout << renderer.description() << "\n";
      results.push_back(
          renderer.render({}, camera_pose_in("world", Eigen::Isometry3d::Identity()), kIntrinsics));
    } catch (const RenderError& e) {
      GTEST_SKIP() << "this machine lacks one of the EGL platforms: " << e.what();
    }
  }
  ASSERT_TRUE(results[0].usable && results[1].usable);
  EXPECT_GT(count_label(results[0], 2), 1000);
  EXPECT_EQ(results[0].labels, results[1].labels);
  EXPECT_EQ(results[0].depth_m, results[1].depth_m);
}

TEST(SceneModel, OneRendererPerThreadRendersConcurrently) {
  const robot_model::SceneModel scene = robot_model::load_scene(
      write_test_file("threads.urdf", one_link_urdf("<cylinder radius=\"0.1\" length=\"0.4\"/>")), {}, {});
  const RenderResult expected = render_world_view(scene);
  std::vector<RenderResult> results(2);
  std::vector<std::thread> threads;
  for (size_t t = 0; t < results.size(); ++t) {
    threads.emplace_back([&, t] {
      DepthRenderer renderer(scene, 0.1, 5.0);
      for (int i = 0; i < 5; ++i) {
        results[t] = renderer.render({}, camera_pose_in("world", Eigen::Isometry3d::Identity()), kIntrinsics);
      }
    });
  }
  for (auto& thread : threads) thread.join();
  for (const RenderResult& r : results) {
    ASSERT_TRUE(r.usable) << r.unusable_reason;
    EXPECT_EQ(r.depth_m, expected.depth_m);
  }
}

// --- the default arm and the real iiwa14 ---

robot_model::JointPositions friend_arm_joints() {
  return {{"a1", 0.3}, {"a2", 0.5}, {"a3", -0.2}, {"a4", 0.9}, {"a5", 0.1}, {"a6", 0.6}, {"a7", 0.0}};
}

CameraPose sim_camera_pose() {
  // config/sim.yaml's camera.
  CameraPose pose;
  pose.frame_id = "world";
  pose.translation_m = Eigen::Vector3d(-0.35, -0.20, 1.55);
  pose.rotation = Eigen::Quaterniond(0.298836239, -0.640856382, 0.640856382, -0.298836239);
  return pose;
}

TEST(SceneModel, DefaultArmAndEnvironmentLabelRanges) {
  const std::string models = tofguard::test::source_dir() + "/config/models/";
  const robot_model::SceneModel scene =
      robot_model::load_scene(models + "friend_arm.urdf", {models + "wheelchair_environment.urdf"}, {});
  EXPECT_EQ(scene.num_robot_links, 10);  // world, base_link, link1..7, gripper
  EXPECT_EQ(scene.actuated_joint_names.size(), 7u);
  DepthRenderer renderer(scene, 0.1, 8.0);
  const Intrinsics sim{176, 144, 221.0, 220.5, 87.3, 71.8};
  const RenderResult r = renderer.render(friend_arm_joints(), sim_camera_pose(), sim);
  ASSERT_TRUE(r.usable) << r.unusable_reason;
  ASSERT_EQ(r.link_names.size(), scene.links.size());
  EXPECT_EQ(r.link_names[0], "world");
  int robot = 0, environment = 0;
  for (int16_t label : r.labels) {
    ASSERT_TRUE(label == 0 || (label >= kLabelRobotFirst && label < kLabelRobotFirst + r.num_robot_links) ||
                (label >= kLabelEnvironmentFirst &&
                 label < kLabelEnvironmentFirst + static_cast<int>(r.link_names.size()) - r.num_robot_links))
        << label;
    robot += label >= kLabelRobotFirst && label < kLabelEnvironmentFirst;
    environment += label >= kLabelEnvironmentFirst;
  }
  EXPECT_GT(robot, 1000);
  EXPECT_GT(environment, 5000);
  // The floor (z = 0) is seen; its depth along the optical axis is at most
  // the camera's height over the floor divided by cos of the tilt... and at
  // least the height of the camera above the floor times sin(40 deg).
  const int floor_label = kLabelEnvironmentFirst + (scene.find_link("floor") - scene.num_robot_links);
  EXPECT_GT(count_label(r, floor_label), 1000);
}

TEST(SceneModel, JointMissingFromTheJointStateMakesTheFrameUnusable) {
  const std::string models = tofguard::test::source_dir() + "/config/models/";
  const robot_model::SceneModel scene = robot_model::load_scene(models + "friend_arm.urdf", {}, {});
  DepthRenderer renderer(scene, 0.1, 8.0);
  robot_model::JointPositions joints = friend_arm_joints();
  joints.erase("a4");
  const RenderResult r =
      renderer.render(joints, sim_camera_pose(), Intrinsics{176, 144, 221.0, 220.5, 87.3, 71.8});
  EXPECT_FALSE(r.usable);
  EXPECT_EQ(r.unusable_reason, "joint 'a4' missing from the joint state");
  EXPECT_TRUE(r.depth_m.empty());
  EXPECT_TRUE(r.labels.empty());
}

TEST(SceneModel, UnknownCameraFrameAndBadIntrinsicsAreUnusable) {
  const robot_model::SceneModel scene = robot_model::load_scene(
      write_test_file("frames.urdf", one_link_urdf("<sphere radius=\"0.2\"/>")), {}, {});
  DepthRenderer renderer(scene, 0.1, 5.0);
  CameraPose pose = camera_pose_in("nowhere", Eigen::Isometry3d::Identity());
  RenderResult r = renderer.render({}, pose, kIntrinsics);
  EXPECT_FALSE(r.usable);
  EXPECT_EQ(r.unusable_reason, "camera pose frame 'nowhere' is not a link of the model");
  pose.frame_id = "thing";  // a camera on a link: fine
  EXPECT_TRUE(renderer.render({}, pose, kIntrinsics).usable);
  pose.rotation = Eigen::Quaterniond(2, 0, 0, 0);
  r = renderer.render({}, pose, kIntrinsics);
  EXPECT_FALSE(r.usable);
  EXPECT_NE(r.unusable_reason.find("unit quaternion"), std::string::npos) << r.unusable_reason;
  Intrinsics bad = kIntrinsics;
  bad.fy = 0;
  r = renderer.render({}, camera_pose_in("world", Eigen::Isometry3d::Identity()), bad);
  EXPECT_FALSE(r.usable);
  EXPECT_EQ(r.unusable_reason, "intrinsics: fy: expected a focal length > 0 px, got 0") << r.unusable_reason;
}

class Iiwa14 : public ::testing::Test {
 protected:
  void SetUp() override {
    if (tofguard::test::shared_dir().empty())
      GTEST_SKIP() << "../shared is absent: the iiwa14 model is not available";
    root = fs::path(tofguard::test::shared_dir()) / "robots" / "iiwa14";
    if (!fs::is_directory(root)) GTEST_SKIP() << root << " is absent";
  }
  // Side view of the arm at zero configuration (straight up, 1.3 m): the
  // camera 2 m in front of it on +x, looking along -x, optical y down.
  static CameraPose side_view() {
    Eigen::Isometry3d world_from_optical = Eigen::Isometry3d::Identity();
    world_from_optical.translation() = Eigen::Vector3d(2.0, 0, 0.65);
    world_from_optical.linear().col(0) = Eigen::Vector3d(0, 1, 0);   // right
    world_from_optical.linear().col(1) = Eigen::Vector3d(0, 0, -1);  // down
    world_from_optical.linear().col(2) = Eigen::Vector3d(-1, 0, 0);  // forward
    return camera_pose_in("base", world_from_optical);
  }
  static robot_model::JointPositions joints() {
    robot_model::JointPositions q;
    const double values[7] = {0.2, 0.3, -0.1, -0.4, 0.3, 0.5, 0.1};
    for (int i = 0; i < 7; ++i) q["iiwa_joint_" + std::to_string(i + 1)] = values[i];
    return q;
  }
  void expect_every_link_with_geometry_labelled(const robot_model::SceneModel& scene) {
    DepthRenderer renderer(scene, 0.1, 5.0);
    const RenderResult r = renderer.render(joints(), side_view(), Intrinsics{320, 240, 300, 300, 160, 120});
    ASSERT_TRUE(r.usable) << r.unusable_reason;
    int checked = 0;
    for (size_t link = 0; link < scene.links.size(); ++link) {
      bool has_geometry = false;
      for (const robot_model::Shape& shape : scene.shapes)
        has_geometry = has_geometry || shape.link_index == static_cast<int>(link);
      if (!has_geometry) continue;
      EXPECT_GT(count_label(r, kLabelRobotFirst + static_cast<int>(link)), 20) << scene.links[link].name;
      ++checked;
    }
    EXPECT_GE(checked, 8) << "iiwa_link_0..7";
    for (size_t i = 0; i < r.labels.size(); ++i) {
      if (r.labels[i] != 0) {
        // The arm (reach 1.3 m around its base, 2 m away) is 1.2..2.8 m away.
        EXPECT_GT(r.depth_m[i], 1.2f);
        EXPECT_LT(r.depth_m[i], 2.8f);
      }
    }
  }
  fs::path root;
};

TEST_F(Iiwa14, VisualObjMeshesRenderWithEveryLinkLabelled) {
  const robot_model::SceneModel scene =
      robot_model::load_scene((root / "urdf" / "iiwa14_no_collision_relative.urdf").string(), {}, {});
  std::cout << "iiwa14 visual: " << scene.num_triangles() << " triangles\n";
  EXPECT_GT(scene.num_triangles(), 50000u);
  expect_every_link_with_geometry_labelled(scene);
}

TEST_F(Iiwa14, SphereCollisionsThroughPackageUrisRenderWithEveryLinkLabelled) {
  // package://drake_models/iiwa_description/... -> a link to the model's folder.
  const fs::path packages = fs::path(tofguard::test::output_dir()) / "renderer" / "iiwa_packages";
  fs::create_directories(packages / "drake_models");
  if (!fs::exists(packages / "drake_models" / "iiwa_description")) {
    fs::create_directory_symlink(root, packages / "drake_models" / "iiwa_description");
  }
  robot_model::SceneOptions options;
  options.geometry = robot_model::GeometrySource::kCollision;
  options.package_paths = {packages.string()};
  const robot_model::SceneModel scene =
      robot_model::load_scene((root / "urdf" / "iiwa14_spheres_collision.urdf").string(), {}, options);
  expect_every_link_with_geometry_labelled(scene);
  options.geometry = robot_model::GeometrySource::kVisual;
  EXPECT_GT(robot_model::load_scene((root / "urdf" / "iiwa14_spheres_collision.urdf").string(), {}, options)
                .num_triangles(),
            50000u);
}

// --- bad models ---

std::string model_error(const std::string& robot, const std::vector<std::string>& environments = {},
                        const robot_model::SceneOptions& options = {}) {
  try {
    robot_model::load_scene(robot, environments, options);
  } catch (const robot_model::ModelError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(SceneModelErrors, MalformedUrdf) {
  const std::string path =
      write_test_file("bad/malformed.urdf", "<robot name=\"x\"><link name=\"a\"></robot");
  const std::string error = model_error(path);
  EXPECT_EQ(error.rfind(path + ": malformed URDF: ", 0), 0u) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos);
  EXPECT_EQ(model_error("/nonexistent/robot.urdf"), "/nonexistent/robot.urdf: cannot read the URDF file");
}

TEST(SceneModelErrors, MissingMeshNamesLinkAndFile) {
  const std::string path =
      write_test_file("bad/missing_mesh.urdf", one_link_urdf("<mesh filename=\"meshes/missing.stl\"/>"));
  const std::string error = model_error(path);
  EXPECT_EQ(error, path + ": link 'thing': mesh 'meshes/missing.stl' not found (resolved to " +
                       (fs::path(path).parent_path() / "meshes/missing.stl").string() + ")");
  const std::string package = write_test_file("bad/missing_package.urdf",
                                              one_link_urdf("<mesh filename=\"package://nopkg/m.stl\"/>"));
  EXPECT_EQ(model_error(package), package +
                                      ": link 'thing': mesh 'package://nopkg/m.stl' not found "
                                      "(searched: no package_paths configured)");
  robot_model::SceneOptions options;
  options.package_paths = {"/tmp/a"};
  EXPECT_EQ(
      model_error(package, {}, options),
      package + ": link 'thing': mesh 'package://nopkg/m.stl' not found (searched: /tmp/a/nopkg/m.stl)");
}

TEST(SceneModelErrors, UnreadableMeshNamesLinkAndFile) {
  write_test_file("bad/meshes/garbage.stl", "this is not a mesh\n");
  const std::string path =
      write_test_file("bad/garbage_mesh.urdf", one_link_urdf("<mesh filename=\"meshes/garbage.stl\"/>"));
  const std::string error = model_error(path);
  EXPECT_EQ(error.rfind(path + ": link 'thing': mesh 'meshes/garbage.stl' (", 0), 0u) << error;
  EXPECT_NE(error.find("could not be read"), std::string::npos) << error;
}

TEST(SceneModelErrors, UnknownGeometryNamesFileAndLink) {
  const std::string path =
      write_test_file("bad/capsule.urdf", one_link_urdf("<capsule radius=\"0.1\" length=\"0.3\"/>"));
  const std::string error = model_error(path);
  EXPECT_EQ(error.rfind(path + ": malformed URDF: ", 0), 0u) << error;
  EXPECT_NE(error.find("thing"), std::string::npos) << error;
}

TEST(SceneModelErrors, MovingJointInTheEnvironment) {
  const std::string robot = write_test_file("bad/robot.urdf", one_link_urdf("<sphere radius=\"0.1\"/>"));
  const std::string environment =
      write_test_file("bad/moving_environment.urdf",
                      "<robot name=\"env\"><link name=\"world\"/><joint name=\"door\" "
                      "type=\"revolute\"><parent link=\"world\"/>"
                      "<child link=\"door\"/><axis xyz=\"0 0 1\"/><limit lower=\"0\" upper=\"1\" "
                      "effort=\"1\" velocity=\"1\"/></joint>"
                      "<link name=\"door\"/></robot>");
  EXPECT_EQ(model_error(robot, {environment}),
            environment + ": joint 'door': an environment URDF may only have fixed joints (it is static)");
}

TEST(SceneModelErrors, BadSizesAndPadding) {
  const std::string path = write_test_file("bad/zero_box.urdf", one_link_urdf("<box size=\"0.1 0 0.1\"/>"));
  EXPECT_EQ(model_error(path), path + ": link 'thing': box size must be three positive lengths");
  robot_model::SceneOptions options;
  options.padding_m = -0.01;
  EXPECT_NE(
      model_error(write_test_file("bad/ok.urdf", one_link_urdf("<sphere radius=\"0.1\"/>")), {}, options)
          .find("padding_m"),
      std::string::npos);
  options.padding_m = 0;
  options.simplify_error_m = -0.001;
  EXPECT_NE(
      model_error(write_test_file("bad/ok.urdf", one_link_urdf("<sphere radius=\"0.1\"/>")), {}, options)
          .find("simplify_error_mm must be a finite value >= 0, got -1.0"),
      std::string::npos);
}

// --- simplified meshes (SceneOptions::simplify_error_m, docs/renderer.md) ---

// The iiwa14's OBJ and the Kinova Gen3's STL visual meshes simplified to
// 0.1 mm (config/sim.yaml) and 1 mm: fewer triangles, every mesh within the
// bound by the simplifier's own measure, and the depth rendered at 640x480
// from 2 m (the camera's pixel is 3 mm there) against the exact meshes':
// the same pixels show the arm (but for a few at its outline) and the
// depths agree to the bound along the view (plus 1 mm for the rendered
// depth's whole millimetres, plus what a surface's slope adds along the
// ray).
struct SimplifiedArm {
  std::string name;
  std::string urdf;
  std::vector<std::string> package_paths;
  CameraPose camera;
};

void expect_simplified_like_exact(const SimplifiedArm& arm, double error_m, double max_triangle_fraction,
                                  double max_p99_mm) {
  robot_model::SceneOptions exact_options;
  exact_options.package_paths = arm.package_paths;
  robot_model::SceneOptions simplified_options = exact_options;
  simplified_options.simplify_error_m = error_m;
  const robot_model::SceneModel exact = robot_model::load_scene(arm.urdf, {}, exact_options);
  const robot_model::SceneModel simplified = robot_model::load_scene(arm.urdf, {}, simplified_options);
  EXPECT_EQ(simplified.num_source_triangles(), exact.num_triangles());
  EXPECT_EQ(exact.num_source_triangles(), exact.num_triangles());
  double largest_error_m = 0;
  for (const robot_model::TriangleMesh& mesh : simplified.meshes) {
    EXPECT_LE(mesh.simplify_error_m, error_m) << mesh.source;
    largest_error_m = std::max(largest_error_m, mesh.simplify_error_m);
  }
  std::cout << arm.name << ": " << exact.num_triangles() << " triangles exact, " << simplified.num_triangles()
            << " simplified to " << 1000 * error_m << " mm (largest reported error " << 1000 * largest_error_m
            << " mm)\n";
  EXPECT_LT(simplified.num_triangles(), max_triangle_fraction * exact.num_triangles()) << arm.name;

  const Intrinsics vga{640, 480, 525, 525, 319.5, 239.5};
  DepthRenderer exact_renderer(exact, 0.1, 5.0);
  DepthRenderer simplified_renderer(simplified, 0.1, 5.0);
  robot_model::JointPositions q;
  for (const std::string& joint : exact.movable_joint_names) q[joint] = 0.3;
  const RenderResult a = exact_renderer.render(q, arm.camera, vga);
  const RenderResult b = simplified_renderer.render(q, arm.camera, vga);
  ASSERT_TRUE(a.usable && b.usable) << a.unusable_reason << b.unusable_reason;
  // Pixels beside a step of more than 50 mm (config/sim.yaml's
  // discrepancy.silhouette_jump_mm: one link's outline over another or the
  // background) are silhouettes, which the discrepancy stage does not
  // compare: a ray there hits one surface or the other.
  const auto beside_a_step = [&](const RenderResult& r, int i) {
    const int u = i % r.width, v = i / r.width;
    for (int dv = -1; dv <= 1; ++dv) {
      for (int du = -1; du <= 1; ++du) {
        const int un = u + du, vn = v + dv;
        if (un < 0 || vn < 0 || un >= r.width || vn >= r.height) return true;
        const int j = vn * r.width + un;
        if (r.labels[j] == 0 || std::abs(r.depth_m[j] - r.depth_m[i]) > 0.05f) return true;
      }
    }
    return false;
  };
  int both = 0, only_one = 0, silhouette = 0, beyond_3mm = 0;
  std::vector<double> differences_mm;
  for (size_t i = 0; i < a.depth_m.size(); ++i) {
    const bool in_a = a.labels[i] != 0, in_b = b.labels[i] != 0;
    if (!in_a && !in_b) continue;
    if (in_a != in_b) {
      ++only_one;
      continue;
    }
    ++both;
    if (beside_a_step(a, static_cast<int>(i)) || beside_a_step(b, static_cast<int>(i))) {
      ++silhouette;
      continue;
    }
    const double d = 1000.0 * std::abs(a.depth_m[i] - b.depth_m[i]);
    differences_mm.push_back(d);
    beyond_3mm += d > 3.0;
  }
  ASSERT_GT(both, 5000) << arm.name << ": the arm must fill part of the image";
  std::sort(differences_mm.begin(), differences_mm.end());
  const double median = differences_mm[differences_mm.size() / 2];
  const double p99 = differences_mm[differences_mm.size() * 99 / 100];
  std::cout << arm.name << " at 640x480: " << both << " arm pixels in both (" << silhouette
            << " beside a step), " << only_one << " in one only; |depth difference| median " << median
            << " mm, p99 " << p99 << " mm, max " << differences_mm.back() << " mm, beyond 3 mm " << beyond_3mm
            << " of " << differences_mm.size() << "\n";
  EXPECT_LE(median, 1.0) << arm.name;
  EXPECT_LE(p99, max_p99_mm) << arm.name;
  EXPECT_LT(only_one, both / 100) << arm.name;
}

// The side view of Iiwa14: 2 m in front of the root on +x, looking along -x.
CameraPose side_view_from(double height_m) {
  Eigen::Isometry3d world_from_optical = Eigen::Isometry3d::Identity();
  world_from_optical.translation() = Eigen::Vector3d(2.0, 0, height_m);
  world_from_optical.linear().col(0) = Eigen::Vector3d(0, 1, 0);
  world_from_optical.linear().col(1) = Eigen::Vector3d(0, 0, -1);
  world_from_optical.linear().col(2) = Eigen::Vector3d(-1, 0, 0);
  CameraPose pose = camera_pose_in("", world_from_optical);
  return pose;
}

TEST(SimplifiedMeshes, TheIiwa14AndTheKinovaGen3RenderAsTheExactMeshesDo) {
  if (tofguard::test::shared_dir().empty())
    GTEST_SKIP() << "../shared is absent: the iiwa14 and Kinova Gen3 models are not available";
  const std::string robots = tofguard::test::shared_dir() + "/robots";
  SimplifiedArm iiwa{
      "iiwa14", robots + "/iiwa14/urdf/iiwa14_no_collision_relative.urdf", {}, side_view_from(0.65)};
  iiwa.camera.frame_id = "base";
  SimplifiedArm kinova{"Kinova Gen3",
                       robots +
                           "/kinova_gen3/kortex_description/arms/gen3/7dof/urdf/"
                           "GEN3-7DOF-NOVISION_FOR_URDF_ARM_V12.urdf",
                       {robots + "/kinova_gen3"},
                       side_view_from(0.55)};
  kinova.camera.frame_id = "base_link";
  for (const SimplifiedArm& arm : {iiwa, kinova}) {
    if (!fs::exists(arm.urdf)) GTEST_SKIP() << arm.urdf << " is absent";
    // config/sim.yaml's bound, and 1 mm.
    expect_simplified_like_exact(arm, 0.0001, 0.7, 0.5);
    expect_simplified_like_exact(arm, 0.001, 0.25, 3.0);
  }
}

}  // namespace
}  // namespace tofguard::renderer::test
