#pragma once
// tofguard-renderer's logic without LCM (RendererService): for each TOF_DEPTH frame, the
// model rendered at the joints interpolated at the frame's utime, from the
// camera pose at the frame's utime (robot_state::StateHistory: CAMERA_POSE
// per camera_id, or the config's static pose), at the frame's own size and
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
//
// Prediction (renderer.prediction, docs/renderer.md): with a plan
// (PLANNED_TRAJECTORY), after each frame the next one is expected one
// camera period later (the median of the last frame intervals); while idle,
// the model is rendered ahead at the plan's joints and the camera pose for
// that time. Where no plan covers that time and prediction.from_joint_states
// is on, the joints are guessed from JOINT_STATE when the render starts
// (linear through the two newest, at most one period beyond them). When the
// frame comes, its joints (interpolated from JOINT_STATE at its utime, as
// always) and camera pose are compared with the prediction's: within the
// tolerances, the image rendered ahead is published at once (a hit);
// otherwise the frame is rendered as usual (a miss). The image is always the
// model at the frame's own joints within the tolerance, never the guess
// beyond it. After 5 misses in a row (an arm that does not follow its plan
// that closely, or a jittery camera) only every 8th frame is predicted until
// one hits, so that useless predictions do not double the rendering work.
// The process renders a prediction as late as still lets it finish before
// its frame is due (PredictionSchedule, prediction_schedule.hpp), not while
// the frame just published is being judged.
#include <deque>
#include <memory>
#include <optional>
#include <set>
#include <string>

#include "tofguard/camera_pose_t.hpp"
#include "tofguard/common/planned_trajectory.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/link_labels_t.hpp"
#include "tofguard/planned_trajectory_t.hpp"
#include "tofguard/renderer/depth_renderer.hpp"
#include "tofguard/renderer/rendered_kinematics.hpp"
#include "tofguard/robot_state/state_history.hpp"
#include "tofguard/settings/renderer_settings.hpp"

namespace tofguard::renderer {

// The largest far_m whose depth fits int16 millimetres.
constexpr double kMaxFarM = 32.767;

// The scene options of the renderer's settings (geometry, padding) and the
// robot's package paths. Throws ModelError for a bad geometry word.
robot_model::SceneOptions scene_options(const RendererSettings& renderer, const RobotSettings& robot);

struct RenderedFrame {
  link_labels_t labels;
  // Empty (nullopt) when the frame is unusable.
  std::optional<depth_image_t> depth;
};

class RendererService {
 public:
  // Loads the model and creates the renderer; throws ModelError,
  // RenderError or std::invalid_argument (e.g. far_m > kMaxFarM).
  explicit RendererService(const RendererProcessSettings& settings);

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

  // A plan that passed check_planned_trajectory.
  void on_plan(const planned_trajectory_t& plan);
  // True when a prediction for the next frame is due and not rendered yet
  // (a guess from the joint states that found them too old: once a newer
  // one has come).
  bool has_prediction_to_render() const;
  // Renders the due prediction (call while no frame is pending); false when
  // nothing was rendered (none due, or the joint states are too old for the
  // guess: then has_prediction_to_render() is false until a newer one).
  bool render_prediction();

  struct PredictionStats {
    int64_t rendered = 0;  // predictions rendered ahead
    int64_t hits = 0;      // frames published from a prediction
    int64_t misses = 0;    // frames with a prediction that did not match
    int64_t without = 0;   // frames with no prediction
  };
  const PredictionStats& prediction_stats() const { return prediction_stats_; }
  // The expected camera period learned from frame intervals, us (0: not yet).
  int64_t frame_period_us() const { return frame_period_us_; }

  const std::string& description() const { return renderer_->description(); }

  // The prediction counts as the process's heartbeat status carries them
  // ("prediction: N hits, M misses, W frames without one, R rendered
  // ahead"), and back from a status that contains that text (nullopt when
  // it does not: another process, or prediction off), for the tools and
  // tests that read the heartbeat.
  static std::string prediction_status(const PredictionStats& stats);
  static std::optional<PredictionStats> prediction_stats_from_status(const std::string& status);

 private:
  struct Prediction {
    std::string camera_id;
    int64_t utime = 0;
    Intrinsics intrinsics;
    robot_model::JointPositions joints;  // from the plan, or once rendered
    // Guessed from JOINT_STATE when the render starts (no plan for utime).
    bool from_joint_states = false;
    // The newest joint state's utime when the guess last found the joint
    // states too old (nullopt: it has not).
    std::optional<int64_t> joints_wanted_after_utime;
    CameraPose pose;
    bool rendered = false;
    RenderResult result;  // usable when rendered and worth using
  };
  RenderedFrame make_output(const depth_image_t& frame, RenderResult result,
                            const std::optional<RenderedKinematics>& kinematics,
                            const std::optional<RenderedArmCover>& arm_cover,
                            const std::optional<Eigen::Isometry3d>& world_from_optical) const;
  void learn_period(const depth_image_t& frame);
  void plan_prediction(const depth_image_t& frame);
  bool covers_actuated_joints(const robot_model::JointPositions& joints) const;
  // True when `prediction_` may stand for `frame` rendered at `joints` and `pose`.
  bool prediction_matches(const depth_image_t& frame, const robot_model::JointPositions& joints,
                          const CameraPose& pose) const;

  RendererProcessSettings settings_;
  robot_model::SceneModel scene_;
  // The robot's cover of spheres (renderer.arm_cover_cell_m), placed with
  // every frame's labels.
  robot_model::ArmSpheres arm_cover_;
  // The occupant (settings.occupant), seated where the config says.
  std::optional<robot_model::OccupantModel> occupant_;
  // Its shapes, drawn into every render (rendered_occupant.hpp).
  std::vector<ExtraObject> occupant_objects_;
  std::unique_ptr<DepthRenderer> renderer_;
  robot_state::StateHistory state_;
  std::optional<depth_image_t> pending_;
  PlannedTrajectory plan_;
  std::optional<int64_t> last_frame_utime_;
  std::deque<int64_t> frame_intervals_us_;
  int64_t frame_period_us_ = 0;  // their median (learn_period)
  std::optional<Prediction> prediction_;
  PredictionStats prediction_stats_;
  // Misses in a row, and frames since the last prediction while they are
  // many (then only every kProbeEveryFrames-th frame is predicted).
  int consecutive_misses_ = 0;
  int frames_since_probe_ = 0;
};

}  // namespace tofguard::renderer
