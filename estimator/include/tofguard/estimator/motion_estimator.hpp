#pragma once
// The motion estimator: which joint angles and which camera pose
// best explain a camera's depth image? Articulated render-and-compare ICP
// (docs/estimator.md):
//   1. camera: Gauss-Newton on the camera correction alone, with the points
//      of links no joint moves (the environment, the robot's base), so that
//      a joint error cannot leak into the camera;
//   2. joints: a 1-D robust search per joint (the rendered model points
//      distal to the joint turned about its axis, projected into the image
//      and scored against the measured depth), the joint that explains the
//      most points moved first, to get 20 degree errors into the basin of
//   3. Gauss-Newton on joints and camera together: the model rendered at
//      the current estimate (visibility and data association from the
//      label image), point-to-plane residuals against the measured depth
//      with the rendered surface's normals, analytic Jacobians from the
//      kinematic chain, Tukey weights with a scale that shrinks from coarse
//      to fine, and a depth gate so that anything nearer than the model (a
//      person's hand) takes no part.
// No LCM in here; estimate_message.hpp turns a result into the wire type.
//
// Frames:
//   world            - the robot's root link (SceneModel).
//   reported optical - the camera's optical frame (x right, y down, z
//                      forward) where the reported pose puts it.
//   seen optical     - the optical frame where the image shows it.
// The camera correction is the seen optical frame's pose in the reported
// one: p_reported = correction * p_seen (motion_estimate_t's convention);
// the estimated pose is world_from_optical_reported * correction.
// Units: metres and radians (metres for prismatic joints).
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tofguard/common/camera_settings.hpp"
#include "tofguard/common/depth_noise.hpp"
#include "tofguard/renderer/depth_renderer.hpp"
#include "tofguard/robot_model/kinematics.hpp"
#include "tofguard/robot_model/scene_model.hpp"

namespace tofguard::estimator {

struct EstimatorOptions {
  // Which parameters are free.
  bool estimate_joints = true;
  bool estimate_camera = true;
  // Every pixel_stride-th pixel in u and v takes part (the model is always
  // rendered at the frame's full size: the normals need neighbours).
  int pixel_stride = 1;
  // A frame of more pixels is estimated at a working resolution: every
  // k-th pixel in u and v, k the smallest integer that brings it to at most
  // this many (30000: 176x144 as it is, 320x240 as 160x120). The time per
  // frame then hardly grows with the camera's resolution.
  int64_t max_working_pixels = 30000;
  // The same for the static links' pixels (the environment) in the
  // iterations at a coarse robust scale (not the final one).
  int coarse_pixel_stride = 2;
  // A model pixel whose measured depth is nearer than the rendered one by
  // more than this (metres) is hidden by a surface no moved link can be
  // (discrepancy.near_arm_m with several cameras): it takes no part,
  // neither its depth nor its contour, so that an object before the arm
  // does not turn the joints (another camera judges the arm there). 0:
  // every pixel takes part.
  double hidden_nearer_than_m = 0;
  // The camera's noise model (common/depth_noise.hpp, millimetres as the
  // config states it): residuals are weighted by (sigma(1 m) / sigma(Z))^2.
  DepthNoise noise{4.0, 1.2};
  // The model's and the calibration's own inaccuracy, metres: added (in
  // quadrature) to every depth residual's sigma. Such errors do not
  // average out over pixels the way noise does.
  double model_sigma_m = 0.01;
  // With the joints: estimate one depth offset for all the robot's
  // measured surfaces (a ToF camera's systematic error), so that it does
  // not turn the distal joints.
  bool estimate_robot_depth_offset = true;
  // Tukey scale of the point-to-plane residual, metres: starts at
  // initial_robust_scale_m and shrinks by robust_scale_factor per
  // iteration to final_robust_scale_m. A point whose rendered and measured
  // depth differ by more than gate_scales * scale takes no part.
  double initial_robust_scale_m = 0.25;
  double final_robust_scale_m = 0.04;
  double robust_scale_factor = 0.6;
  double gate_scales = 2.0;
  // Gauss-Newton iterations (one render each) per stage: camera alone,
  // then joints and camera together.
  int max_camera_iterations = 12;
  int max_iterations = 10;
  // Converged when, at the final scale, no parameter moves more than this
  // (radians / metres) in one step.
  double step_tolerance = 1e-3;
  // A step smaller than this (rad / m) at a coarse robust scale moves on
  // to the final scale at once: the estimate is already in its basin.
  double coarse_skip_step = 5e-3;
  // Levenberg-Marquardt damping (relative to the diagonal) at the final
  // scale: contour associations move in whole pixels, and a weakly seen
  // joint would otherwise swing about its optimum.
  double final_damping = 1.0;
  // Largest step per iteration: joints (rad or m), camera (m, rad).
  double max_joint_step = 0.1;
  double max_camera_translation_step_m = 0.05;
  double max_camera_rotation_step_rad = 0.05;
  // The joint search: offsets -range..range in steps, rounds (a round moves
  // the one joint that explains the most points, then the model is
  // re-rendered). A move must explain min_search_gain_fraction of the
  // joint's distal points more than the current estimate, and at least
  // min_joint_points.
  double joint_search_range_rad = 0.52;  // 30 degrees
  double joint_search_step_rad = 0.07;   // 4 degrees
  int joint_search_rounds = 2;
  double min_search_gain_fraction = 0.08;
  // A joint is observable (and estimated) when at least this many model
  // points on links it moves take part...
  int min_joint_points = 30;
  // ...and its 1-sigma uncertainty is at most this (rad or m).
  double max_joint_sigma = 0.05;
  // Neighbouring pixels' residuals are correlated (the same surface, the
  // same model error): the least-squares sigmas are multiplied by this.
  double sigma_scale = 2.5;
  // residual_before/after: RMS of the point-to-plane residuals with each
  // residual (and each gated-out point) counted as at most this, metres.
  double residual_clip_m = 0.1;
  // Occluding contours (depth steps larger than contour_jump_fraction
  // times the depth, near side) of the rendering are pulled onto the
  // nearest ones of the measured image: Tukey scale final_contour_scale_px
  // (growing with the depth scale while that is coarser), residual sigma
  // contour_sigma_px. This pins the directions a depth residual hardly
  // sees (sliding along a surface).
  double contour_jump_fraction = 0.1;
  double final_contour_scale_px = 3.0;
  // 2 px: a ToF camera's mixed pixels (a silhouette pixel measuring a
  // distance between the two surfaces) move a measured contour by up to a
  // pixel, and not evenly: with 0.5 px the contours outweighed the depth
  // residuals and biased the wrist joints (a5, a7) by 2-3 degrees on the
  // simulated camera; at 2 px the bias is below 1 degree and the sigmas
  // match the errors seen (docs/estimator.md).
  double contour_sigma_px = 2.0;
  // Neighbouring rendered pixels further apart in depth than this are a
  // silhouette (no normal there), metres.
  double normal_jump_m = 0.03;
};

// One camera frame and what was reported for it.
struct EstimatorFrame {
  // Measured Z along the optical axis, metres, row-major, width * height
  // of `intrinsics`; 0 (or not finite) = no return.
  std::vector<float> depth_m;
  Intrinsics intrinsics;
  // The reported joint positions (every actuated joint of the model).
  robot_model::JointPositions reported_joints;
  // The reported camera pose: p_world = world_from_optical * p_optical.
  Eigen::Isometry3d world_from_optical = Eigen::Isometry3d::Identity();
};

struct JointEstimate {
  std::string name;
  double reported = 0;
  double estimated = 0;
  // 1-sigma of `estimated`; kUnobservableSigma when !observable.
  double sigma = 0;
  // False when the image cannot see the joint (too few visible points on
  // the links it moves, or too uncertain): then estimated == reported.
  bool observable = false;
  // estimated - reported: positive = the joint is seen further along its
  // axis (right hand rule) than it reports.
  double offset() const { return estimated - reported; }
};

// The sigma of a joint the image cannot see (rad or m): anything.
constexpr double kUnobservableSigma = 3.141592653589793;

struct EstimateResult {
  // False when no estimate could be made; unusable_reason says why.
  bool usable = false;
  std::string unusable_reason;
  // The last step was below the step tolerance at the final robust scale
  // before the iteration limit.
  bool converged = false;
  // Gauss-Newton iterations (renders) in all stages, and the joint search's
  // moves.
  int iterations = 0;
  int search_moves = 0;
  // Camera frames estimated jointly (estimate(frames)); 1 for one frame.
  int num_frames = 1;
  // Per actuated joint, in URDF order (SceneModel::actuated_joint_names).
  std::vector<JointEstimate> joints;
  // reported optical <- seen optical (identity when not estimated).
  Eigen::Isometry3d correction = Eigen::Isometry3d::Identity();
  // 1-sigma of the correction: largest axis, metres and radians (0 when
  // the camera was not estimated).
  double correction_translation_sigma_m = 0;
  double correction_rotation_sigma_rad = 0;
  bool camera_estimated = false;
  // The robot's depth offset (EstimatorOptions::estimate_robot_depth_offset):
  // metres added to the measured Z of the robot's surfaces.
  double robot_depth_offset_m = 0;
  // Model points that took part at the end, and the inliers among them.
  int num_points = 0;
  int num_inliers = 0;
  // Clipped RMS of the point-to-plane residuals (EstimatorOptions::
  // residual_clip_m) at the reported values and at the estimate, metres.
  double residual_before_m = 0;
  double residual_after_m = 0;
  int64_t compute_us = 0;
};

// Rotation angle of the correction, radians.
double correction_angle_rad(const EstimateResult& result);

class MotionEstimator {
 public:
  // `renderer` must render `scene` (the same model) and outlive this.
  // `occupant`: the wheelchair user's shapes (renderer::
  // occupant_render_objects; empty: none), drawn into every render so that
  // the user hides what is behind them; their pixels are no link's and are
  // not fitted (the user is judged by envelopes, not by this model).
  // Throws std::invalid_argument for options out of range.
  MotionEstimator(const robot_model::SceneModel& scene, renderer::DepthRenderer* renderer,
                  const EstimatorOptions& options, std::vector<renderer::ExtraObject> occupant = {});

  // Estimates what `frame` shows, with the options' free parameters (at
  // the working resolution, EstimatorOptions::max_working_pixels).
  // Never throws for bad input: the result is then unusable.
  EstimateResult estimate(const EstimatorFrame& frame);

  // The same jointly over several frames of one camera: frames[0] is the
  // frame the estimate is about, the others are frames just before it
  // (each with its own reported joints and camera pose: the arm and a
  // pan-tilt head may move between them). The joint offsets and the camera
  // correction (in the optical frame) are common to all frames: an encoder
  // offset or a calibration error does not change within a few frames.
  // The camera's noise and mixed pixels differ from frame to frame, so the
  // estimate's random error shrinks about as 1/sqrt(frames). The joint
  // search runs on frames[0]; residual_before is frames[0]'s, the
  // result's joints are frames[0]'s. Frames must have the same image size.
  EstimateResult estimate(const std::vector<EstimatorFrame>& frames);

  // Camera pose only, jointly over several frames of one static camera
  // whose joint positions are exact (extrinsic calibration). Every frame's
  // world_from_optical must be the same initial pose. The result's joints
  // are the first frame's, as reported.
  EstimateResult estimate_camera(const std::vector<EstimatorFrame>& frames);

  const EstimatorOptions& options() const { return options_; }
  const robot_model::SceneModel& scene() const { return scene_; }

 private:
  struct ChainJoint {
    int scene_joint;  // index in scene.joints
    int param;        // index in actuated joints
    double multiplier;
  };
  struct State;
  struct Linearization;
  struct Sample;
  // The measured image's occluding contour pixels: per pixel the index
  // of the nearest one (-1 when the image has none).
  struct MeasuredEdges {
    std::vector<int> nearest;
  };
  const MeasuredEdges& edges_of(const EstimatorFrame& frame);
  enum class PointSet { kAll, kStatic };

  // Both estimate()s: frames[0] the estimate's own frame.
  EstimateResult estimate_frames(const std::vector<const EstimatorFrame*>& frames);
  std::string check_frame(const EstimatorFrame& frame) const;
  // Renders `frame` at `state` and adds its residuals to `lin`. Returns ""
  // or why the frame cannot be rendered.
  std::string linearize(const EstimatorFrame& frame, const State& state, double scale, int stride,
                        PointSet points, bool joints_free, Linearization* lin, std::vector<Sample>* samples);
  // linearize's stages, per rendered pixel of a link (`chain`: its movable
  // joints up to the root): the contour term (distance in pixels from a
  // rendered occluding contour to the nearest measured one) and the depth
  // term (point-to-plane distance in metres to the measured point), each
  // adding its residual through add_residual.
  struct RenderedView;
  void add_contour_term(const RenderedView& view, const std::vector<ChainJoint>& chain, int u, int v,
                        Linearization* lin) const;
  void add_depth_term(const RenderedView& view, const std::vector<ChainJoint>& chain, int link, int u, int v,
                      Linearization* lin, std::vector<Sample>* samples) const;
  // One residual whose derivative with respect to the model point (seen
  // optical frame) is `g`.
  void add_residual(const RenderedView& view, const std::vector<ChainJoint>& chain, const Eigen::Vector3d& m,
                    const Eigen::Vector3d& world, const Eigen::Vector3d& g, double residual, double weight,
                    bool count_joint_points, double d_depth_offset, Linearization* lin) const;
  // Gauss-Newton stage over `frames`; returns "" or an unusable reason.
  std::string solve(const std::vector<const EstimatorFrame*>& frames, bool joints_free, bool camera_free,
                    PointSet points, int max_iterations, State* state, Linearization* final_lin,
                    bool* converged, int* iterations);
  // The joint search on one frame; returns the number of joints moved.
  int search_joints(const EstimatorFrame& frame, State* state, std::string* error);
  // The samples on links that parameter k moves, thinned to about
  // kSearchPoints (every *every-th of them).
  std::vector<const Sample*> distal_samples(const std::vector<Sample>& samples, int k, size_t* every) const;
  EstimateResult finish(const EstimatorFrame& frame, const State& state, const Linearization& lin,
                        bool camera_free, bool joints_free) const;

  const robot_model::SceneModel& scene_;
  renderer::DepthRenderer* renderer_;
  std::vector<renderer::ExtraObject> occupant_;
  EstimatorOptions options_;
  int num_params_ = 0;  // actuated joints
  // Per link: the movable joints from the link up to the root.
  std::vector<std::vector<ChainJoint>> chains_;
  // Per frame being estimated (keyed by its depth data), cleared per call.
  std::map<const float*, MeasuredEdges> edges_;
};

}  // namespace tofguard::estimator
