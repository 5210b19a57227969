#pragma once
// tofguard-renderer's settings (config section `renderer`, docs/renderer.md)
// and what the process needs besides them. Durations are integer
// microseconds, converted once when the file is read (YamlMap::milliseconds_as_us).
#include <cstdint>
#include <optional>
#include <string>

#include "tofguard/common/camera_settings.hpp"
#include "tofguard/common/lcm_settings.hpp"
#include "tofguard/common/robot_settings.hpp"
#include "tofguard/common/yaml_reader.hpp"
#include "tofguard/settings/occupant_settings.hpp"

namespace tofguard::settings {

struct RendererSettings {
  // geometry: which URDF geometry to render: "visual" or "collision".
  std::string geometry;
  // padding_m: every shape is inflated by this much, metres.
  double padding_m = 0;
  // simplify_error_mm (optional; absent: 0, the exact meshes): mesh files
  // are simplified at load until the surface would move by more than this,
  // millimetres (robot_model::SceneOptions::simplify_error_m,
  // docs/renderer.md "Simplified meshes").
  double simplify_error_mm = 0;
  // near_m, far_m: clip distances along the optical axis, metres.
  double near_m = 0;
  double far_m = 0;
  // arm_cover_cell_m: the cell of the arm's cover of spheres that goes out
  // with every frame's labels for the 3-D protective fields
  // (robot_model/arm_spheres.hpp): the cover's distances err towards the
  // arm by at most twice its largest sphere (about the cell's diagonal),
  // metres.
  double arm_cover_cell_m = 0;
  // max_extrapolation_ms: a camera frame whose utime lies further than this
  // beyond the newest joint state is marked unusable instead of
  // extrapolated; microseconds.
  int64_t max_extrapolation_us = 0;
  // camera_pose.{history_ms, max_extrapolation_ms, max_gap_ms}: camera poses
  // (CAMERA_POSE) are kept per camera_id for camera_pose_history and looked
  // up at each frame's utime (CameraPoseHistory, docs/renderer.md). Two
  // differing poses at most camera_pose_max_gap apart are a motion
  // (interpolated); a frame further than camera_pose_max_extrapolation
  // beyond a moving camera's newest pose is unusable. Poses further apart
  // are steps (a calibration published now and then): each holds until the
  // next. Microseconds.
  int64_t camera_pose_history_us = 0;
  int64_t camera_pose_max_extrapolation_us = 0;
  int64_t camera_pose_max_gap_us = 0;
  // prediction.*: prediction from PLANNED_TRAJECTORY (docs/renderer.md): the
  // next frame is rendered ahead at the plan's joints for its expected
  // utime; when the frame comes and every joint interpolated at its utime is
  // within prediction_joint_tolerance_deg (metres for prismatic joints:
  // prediction_joint_tolerance_m) of the prediction, and its camera pose
  // within the pose tolerances, the image rendered ahead is published.
  bool prediction_enabled = false;
  // prediction.from_joint_states (optional, default false: the plan only):
  // where no plan covers the next frame's expected utime, its joints are
  // guessed from JOINT_STATE instead, extrapolated linearly from the two
  // newest messages when the render ahead starts, at most one camera period
  // beyond the newest. The guess is held to the same tolerances as a plan's.
  bool prediction_from_joint_states = false;
  double prediction_joint_tolerance_deg = 0;
  double prediction_joint_tolerance_m = 0;
  double prediction_pose_tolerance_mm = 0;
  double prediction_pose_tolerance_deg = 0;
};

// Reads (and finishes) the `renderer` section.
RendererSettings read_renderer_settings(YamlMap section);

// Everything tofguard-renderer needs: its section, the model, the camera,
// the wiring.
struct RendererProcessSettings {
  LcmSettings lcm;
  ChannelNames channels;
  RobotSettings robot;
  EnvironmentSettings environment;
  // The wheelchair's occupant (absent: none): the renderer places it and
  // sends each body region's separation from the arm with the labels.
  std::optional<OccupantSettings> occupant;
  CameraSettings camera;
  RendererSettings renderer;
};

}  // namespace tofguard::settings

// The component's own names for its settings (tofguard::renderer::RendererSettings, ...).
namespace tofguard::renderer {
using settings::read_renderer_settings;
using settings::RendererProcessSettings;
using settings::RendererSettings;
}  // namespace tofguard::renderer
