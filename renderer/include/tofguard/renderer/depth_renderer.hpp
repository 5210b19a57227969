#pragma once
// Renders a SceneModel into a metric depth image and a link-label image from
// exactly a camera's view: OpenGL ES 3 through EGL, headless (see
// egl_context.hpp), on Mesa llvmpipe or a GPU alike.
//
// Frames:
//   world   - the robot's root link (SceneModel).
//   optical - the camera's optical frame: x right, y down, z forward.
// Image: OpenCV pinhole convention. Pixel (u, v) has its centre at (u, v),
// u to the right, v down; a point (X, Y, Z) in the optical frame lands at
// u = fx*X/Z + cx, v = fy*Y/Z + cy. Images are row-major, index v*width + u,
// row 0 at the top.
//
// Cost model: the constructor creates the GL context and uploads every mesh
// once; render() changes only uniforms (one 4x4 matrix and one label per
// shape), clears, draws and reads back. The framebuffer is reallocated only
// when the image size changes.
//
// Thread-compatible: one DepthRenderer per thread (each has its own context;
// render() binds it to the calling thread).
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tofguard/common/camera_geometry.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/renderer/egl_context.hpp"
#include "tofguard/robot_model/kinematics.hpp"
#include "tofguard/robot_model/scene_model.hpp"

namespace tofguard::renderer {

// A primitive that is not part of the model, given per render() call (e.g.
// the simulated camera's person's arm). Drawn with the unit primitives that
// are already uploaded: nothing is uploaded per call. Not padded.
struct ExtraObject {
  enum class Kind { kBox, kSphere, kCylinder };
  Kind kind = Kind::kBox;
  // Box: edge lengths along the object's x, y, z. Sphere: radius in x().
  // Cylinder: radius in x(), length (along the object's z) in z(). Metres.
  Eigen::Vector3d size_m = Eigen::Vector3d::Zero();
  // Pose of the object's centre in the world frame.
  Eigen::Isometry3d world_from_object = Eigen::Isometry3d::Identity();

  static ExtraObject box(const Eigen::Vector3d& edges_m, const Eigen::Isometry3d& world_from_object);
  static ExtraObject sphere(double radius_m, const Eigen::Isometry3d& world_from_object);
  static ExtraObject cylinder(double radius_m, double length_m, const Eigen::Isometry3d& world_from_object);
};

struct RenderResult {
  // False when the image must not be used (a joint missing from the joint
  // state, unknown camera frame, bad intrinsics, GL failure); then
  // unusable_reason says why in one line and depth_m and labels are empty.
  bool usable = false;
  std::string unusable_reason;
  int width = 0;
  int height = 0;
  // Z along the optical axis of the nearest surface, metres, row-major;
  // 0 where nothing is seen within [near_m, far_m].
  std::vector<float> depth_m;
  // Which link (or extra object) is seen at each pixel: the label values
  // of common/depth_frame.hpp (label_of_link, kLabelExtraObjectFirst +
  // index in render()'s extra_objects). Row-major like depth_m.
  std::vector<int16_t> labels;
  // SceneModel::links' names: robot links first, then the environment's.
  std::vector<std::string> link_names;
  int num_robot_links = 0;
  // Where it was rendered from (usable results only): every link's pose and
  // the optical frame's pose in the world (rendered_kinematics.hpp turns
  // them into link_labels_t's kinematics).
  std::vector<Eigen::Isometry3d> world_from_link;
  Eigen::Isometry3d world_from_optical = Eigen::Isometry3d::Identity();
};

// The matrix that takes optical-frame points (X, Y, Z, 1) to GL clip
// coordinates such that pixel (u, v) of the result (row v counted from the
// top, as glReadPixels stores it from window row 0) sees exactly the OpenCV
// ray through (u, v), and window depth is -1..1 over near_m..far_m. Exposed
// for tests.
Eigen::Matrix4d clip_from_optical(const Intrinsics& intrinsics, double near_m, double far_m);

class DepthRenderer {
 public:
  // Creates the context (TOFGUARD_EGL_PLATFORM picks the platform, default
  // device then surfaceless) and uploads the scene. 0 < near_m < far_m.
  // Throws RenderError (no context, GL failure) or std::invalid_argument.
  DepthRenderer(const robot_model::SceneModel& scene, double near_m, double far_m);
  DepthRenderer(const robot_model::SceneModel& scene, double near_m, double far_m, EglPlatform platform);
  ~DepthRenderer();
  DepthRenderer(const DepthRenderer&) = delete;
  DepthRenderer& operator=(const DepthRenderer&) = delete;

  // `camera_pose` is the optical frame's pose in link camera_pose.frame_id
  // (resolved through forward kinematics, so a camera on the arm moves with
  // it). Never throws for bad input: the result is then unusable.
  RenderResult render(const robot_model::JointPositions& joints, const CameraPose& camera_pose,
                      const Intrinsics& intrinsics, const std::vector<ExtraObject>& extra_objects = {});

  // Same, with the camera pose already in the world frame and the links'
  // poses already known (e.g. a motion estimator trying many candidates).
  RenderResult render_at(const robot_model::LinkPoses& link_poses,
                         const Eigen::Isometry3d& world_from_optical, const Intrinsics& intrinsics,
                         const std::vector<ExtraObject>& extra_objects = {});

  // Which EGL platform and GL renderer is in use, for logs.
  const std::string& description() const;
  // Triangles drawn per render for the model alone.
  size_t num_triangles() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tofguard::renderer
