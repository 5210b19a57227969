#pragma once
// tofguard-renderer's logic without LCM: for each TOF_DEPTH frame, the
// model rendered at the joints interpolated at the frame's utime, from the
// camera pose at the frame's utime (CameraPoseHistory: CAMERA_POSE per
// camera_id, or the config's static pose), at the frame's own size and
// intrinsics.
//
// Outputs per frame (both carry the camera frame's utime, seq, camera_id):
//   TOF_LABELS   link_labels_t, always; usable=false with the reason when
//                the frame cannot be rendered trustworthily.
//   TOF_RENDERED depth_image_t, only for a usable frame, so that nothing
//                can mistake an unusable frame for an empty scene. depth_mm
//                is Z in millimetres rounded to the nearest; 0 = nothing
//                modelled there. Z above 32767 mm (int16) would also be 0;
//                the process refuses far_m > 32.767 at start so it cannot
//                happen. calibrated = true (a rendering is exact).
//
// Frames are rendered newest first: a frame that arrives while another is
// pending replaces it and counts as dropped, so the queue is never longer
// than one frame.
#include <memory>
#include <optional>
#include <string>

#include "camera_pose_history.hpp"
#include "depth_renderer.hpp"
#include "joint_history.hpp"
#include "tofguard/camera_pose_t.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/link_labels_t.hpp"
#include "tofguard/process.hpp"

namespace tofguard::renderer {

// What tofguard-renderer is, for --help.
ProcessInfo process_info();

// The largest far_m whose depth fits int16 millimetres.
constexpr double kMaxFarM = 32.767;

// The scene options of a config (geometry, padding, package paths). Throws
// ModelError for a bad geometry word.
SceneOptions scene_options(const Config& config);

struct RenderedFrame {
  link_labels_t labels;
  // Empty (nullopt) when the frame is unusable.
  std::optional<depth_image_t> depth;
};

class RendererService {
 public:
  // Loads the model and creates the renderer; throws ModelError,
  // RenderError or std::invalid_argument (e.g. far_m > kMaxFarM).
  explicit RendererService(const Config& config);

  // Returns false (and ignores it) for a message from another robot or not
  // newer than the last; the caller counts that.
  bool on_joint_state(const joint_state_t& state);
  // Returns false (and ignores it) for a pose not newer than the camera's
  // newest; the caller counts that.
  bool on_camera_pose(const camera_pose_t& pose);
  // Keeps the frame as the pending one; returns true when it replaced a
  // pending frame that was never rendered (one dropped frame).
  bool on_depth(const depth_image_t& frame);

  bool has_pending() const { return pending_.has_value(); }
  // Renders the pending frame (if any) and clears it.
  std::optional<RenderedFrame> render_pending();

  // Renders `frame` now (what render_pending does), for tests.
  RenderedFrame render(const depth_image_t& frame);

  const std::string& description() const { return renderer_->description(); }

 private:
  Config config_;
  SceneModel scene_;
  std::unique_ptr<DepthRenderer> renderer_;
  JointHistory history_;
  CameraPoseHistory camera_poses_;
  std::optional<depth_image_t> pending_;
};

}  // namespace tofguard::renderer
