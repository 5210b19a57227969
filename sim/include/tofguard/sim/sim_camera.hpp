#pragma once
// The simulated ToF camera's logic, apart from the renderer and LCM: which
// scene to render for a frame (the arm at its true joint angles interpolated
// at the capture time, the camera pose with any drift, intruding objects),
// the ToF error model, and the injected faults.
//
// Frames: the camera pose is the optical frame's pose in the config's
// camera.pose.frame_id; intruding boxes are given in the world frame (the
// robot's root link).
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tofguard/common/camera_settings.hpp"
#include "tofguard/robot_state/joint_history.hpp"
#include "tofguard/settings/sim_settings.hpp"
#include "tofguard/sim/simulated_user.hpp"
#include "tofguard/sim/tof_error_model.hpp"

namespace tofguard::sim {

// An axis-aligned box in the world frame.
struct SimBox {
  Eigen::Vector3d size_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
};

struct RenderedDepth {
  bool usable = false;
  std::string unusable_reason;  // one line when !usable
  // Z along the optical axis, metres, row-major; 0 = nothing in range.
  std::vector<float> depth_m;
};

// What the simulated camera needs from the renderer (the real one renders
// the URDF scene with tofguard::renderer::DepthRenderer; tests use fakes).
class SceneRenderer {
 public:
  virtual ~SceneRenderer() = default;
  virtual RenderedDepth render(const std::map<std::string, double>& joint_positions,
                               const CameraPose& camera_pose, const Intrinsics& intrinsics,
                               const std::vector<SimBox>& boxes, const std::vector<RegionShape>& user) = 0;
};

// One injected fault with absolute times (microseconds since the epoch).
struct ActiveSimFault {
  SimCameraFaultSettings fault;
  int64_t start_utime = 0;
  int64_t end_utime = 0;
};

class SimulatedCamera {
 public:
  // `start_utime`: when the camera started (config faults count from it).
  // `user`: the simulated wheelchair user (camera.sim.user), none for an
  // empty chair.
  SimulatedCamera(const CameraSettings& camera, const SimCameraSettings& sim, SceneRenderer* renderer,
                  int64_t start_utime, std::optional<SimulatedUser> user = std::nullopt);

  // A true joint state of the simulated arm (SIM_TRUE_JOINT_STATE). The
  // frame's joints are interpolated between the states around its capture
  // time, extrapolated at most 50 ms past the newest (renderer's
  // JointHistory). Returns false for a state not newer than the newest.
  bool add_true_joint_state(int64_t utime, const std::vector<std::string>& names,
                            const std::vector<double>& positions);
  // A run-time fault, starting at `fault.start_utime`.
  void inject(const ActiveSimFault& fault) { faults_.push_back(fault); }
  // Ends every fault active or pending at `utime`.
  void clear_faults(int64_t utime);

  struct Frame {
    enum class Outcome {
      kImage,         // image is valid
      kStalled,       // stall fault: no frame
      kNoJointState,  // no true joint state near the capture time
      kRenderFailed,  // the renderer said the image is unusable
    };
    Outcome outcome = Outcome::kImage;
    std::string why;  // one line unless kImage
    TofImage image;   // uncalibrated ToF image when kImage
    bool frozen = false;
  };
  // The frame whose mid-exposure time is `capture_utime`; `frame_index`
  // selects the noise (the same index gives the same noise).
  Frame capture(int64_t capture_utime, uint64_t frame_index);

  // The camera pose the scene is rendered from at `utime`: the config's
  // pose turned by the pan-tilt head's true pan and tilt (camera.sim.pan_tilt),
  // plus any pose drift.
  CameraPose true_pose(int64_t utime) const;
  // What the pan-tilt head reports at `utime` (published on CAMERA_POSE
  // with each frame): the config's pose turned by the head's reading, i.e.
  // the true pan and tilt plus any pan_tilt_offset fault (a drift is not
  // seen by the head). nullopt for a camera without a pan-tilt head.
  std::optional<CameraPose> reported_pose(int64_t utime) const;
  // Intruding boxes at `utime`.
  std::vector<SimBox> boxes(int64_t utime) const;
  // The simulated user's shapes at `utime` (world frame); none without one.
  std::vector<RegionShape> user_shapes(int64_t utime) const;

 private:
  bool active(const ActiveSimFault& f, int64_t utime) const {
    return utime >= f.start_utime && utime < f.end_utime;
  }

  // The config's pose turned by `pan_rad` about the pose frame's z axis and
  // `tilt_rad` about the optical x axis (SimCameraSettings).
  CameraPose turned_pose(double pan_rad, double tilt_rad) const;
  // The head's true pan and tilt at `utime`, radians.
  double true_pan_rad(int64_t utime) const;
  double true_tilt_rad(int64_t utime) const;

  CameraSettings camera_;
  SimCameraSettings sim_;
  SceneRenderer* renderer_;
  int64_t start_utime_;
  TofErrorModel model_;
  robot_state::JointHistory joints_;
  std::vector<ActiveSimFault> faults_;
  std::optional<TofImage> last_image_;
  std::optional<SimulatedUser> user_;
};

}  // namespace tofguard::sim
