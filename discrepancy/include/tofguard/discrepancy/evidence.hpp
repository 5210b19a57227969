#pragma once
// The evidence stage of compute_discrepancy (docs/safety-chain.md,
// "Evidence"): a one-step, noise-weighted linear fit of the residual
// I_dis = I_gen - I_ToF to the hypotheses "the camera pose is off" (six
// parameters, on the static pixels) and "joint j reads other than seen"
// (one parameter per joint, on the pixels of the links it moves), and each
// link's shared bias. Fills discrepancy_t's evidence fields.
//
// J_i, how the rendered depth at pixel i changes per unit of a parameter,
// comes from the rendered surface's slope and the labels' kinematics
// (link_labels_t's axes, optical frame): a surface point p moving with
// velocity v changes the depth at its fixed pixel by g . v with
//   g = (-Gu fx / Z, -Gv fy / Z, 1 + (Gu fx X + Gv fy Y) / Z^2),
// Gu = dZ/du, Gv = dZ/dv the rendered depth's slope (central differences
// over neighbours of the same label and no silhouette jump).
//
// Units: J in millimetres per radian (revolute joints, camera rotation) or
// per metre (prismatic joints, camera translation). Frames: the camera's
// optical frame (x right, y down, z forward).
//
// Pure computation: no LCM, no clocks; one pass over the pixels, nothing
// allocated per pixel.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "tofguard/common/depth_frame.hpp"
#include "tofguard/common/depth_noise.hpp"
#include "tofguard/common/worker_pool.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/discrepancy_t.hpp"
#include "tofguard/link_labels_t.hpp"

namespace tofguard::discrepancy {

// discrepancy.evidence.* (DiscrepancySettings).
struct EvidenceOptions {
  // The model's own inaccuracy per pixel, mm: sigma_i = sqrt(sigma(d)^2 +
  // model_sigma_mm^2).
  double model_sigma_mm = 3.0;
  // Residuals are clipped to +-clip_sigmas * sigma_i.
  double clip_sigmas = 4.0;
  // Pixels per independent noise sample (1: independent per pixel; a
  // camera with spatial filtering: its filter's footprint): w_i =
  // 1 / (pixels_per_sample * sigma_i^2).
  double pixels_per_sample = 1.0;
  // At most this many pixels enter the evidence sums: above it every k-th
  // pixel in u and v, k the smallest that keeps to it (evidence_stride);
  // 0: every pixel. The sampled pixels keep their own weight (see
  // sampled_pixels_per_sample), so the scores stay N(0, information)
  // under no fault and the risk's thresholds hold unchanged: a sampled
  // frame has less information (detection power) than the full one, never
  // a higher false-stop rate.
  int max_pixels = 0;
  // The naming fit (discrepancy_t.joint_naming_*) takes the robot's pixels
  // whose residual is within naming_gate_sigmas * sigma_i.
  double naming_gate_sigmas = 6.0;
  // The naming search (joint_search.hpp): trial offsets within
  // +-search_range_rad (revolute) / search_range_m (prismatic) in steps of
  // search_step_rad / search_step_m, then a quarter step either side of
  // the best; at most search_max_points robot points (every k-th pixel in u
  // and v, k the smallest that keeps to it).
  double search_range_rad = 20.0 * M_PI / 180.0;
  double search_step_rad = 1.0 * M_PI / 180.0;
  double search_range_m = 0.05;
  double search_step_m = 0.0025;
  int search_max_points = 3000;
  // The static error the camera and the model keep after calibration (or
  // commissioning), which does not average away from frame to frame
  // (docs/safety-chain.md, "Static error: the composite null"), mm:
  //  - static_bias_mm: a bound b on a smooth error shared by many pixels
  //    (a residual distance error, a warm-up drift, a calibration's
  //    tolerance): every pixel's static error within +-b, of any sign;
  //  - fixed_pattern_sigma_mm: per-pixel offsets, independent between
  //    pixels and fixed over frames, with this sigma.
  // Each score s of the fits is shrunk towards 0 by the most that such an
  // error can give it, B = b sum w |J| + fixed_pattern_sigmas *
  // fixed_pattern_sigma_mm * sqrt(sum w^2 J^2), so that under every error
  // within the bound |s_shrunk| <= |noise part of s| and the risk's tests
  // keep their false-stop rate. 0 and 0: an ideal camera, the plain scores.
  double static_bias_mm = 0.0;
  double fixed_pattern_sigma_mm = 0.0;
  //  - silhouette_bias_mm within silhouette_band_px: a bound on the error
  //    of the pixels on the near side of a rendered step (within
  //    silhouette_band_px of a surface farther by more than the silhouette
  //    jump), beyond static_bias_mm. What a ToF camera's multipath gives a
  //    surface in front of another (a link before a wall, the gripper
  //    before the arm): it moves with the arm, so no per-pixel profile
  //    learns it. Such pixels add silhouette_bias_mm * w |J| to B.
  //    0 and 0: none.
  //    silhouette_bias_by_link_mm: the bound of a link's own pixels (by
  //    link name), where commissioning measured it; the other links' and
  //    the scene's pixels take silhouette_bias_mm (the largest measured).
  double silhouette_bias_mm = 0.0;
  int silhouette_band_px = 0;
  std::map<std::string, double> silhouette_bias_by_link_mm;
  //  - silhouette_band_step_mm: the rendered step that opens the band (a
  //    surface farther by more than this within silhouette_band_px), mm;
  //    <= 0: the silhouette jump. Multipath needs only a surface behind
  //    the pixel, not a silhouette: a wrist before its own forearm is a
  //    concave corner of a few cm.
  double silhouette_band_step_mm = 0.0;
};

// The pixels on the near side of a rendered step (row-major, 1 = within
// `band_px` pixels, Chebyshev, of a rendered surface farther by more than
// silhouette_step's jump): EvidenceOptions::silhouette_band_px. All 0 for
// band_px <= 0. A pixel without a rendered surface is no step.
// With `farther_from` (one per pixel), only its pixels set to 1 count as
// the farther surface.
std::vector<uint8_t> near_side_of_steps(const depth_image_t& rendered, int band_px, double silhouette_jump_mm,
                                        const std::vector<uint8_t>* farther_from = nullptr);
// Per pixel (row-major), the silhouette allowance of `rendered`'s pixels on
// the near side of a step (near_side_of_steps within silhouette_band_px, of
// a step larger than silhouette_band_step_mm, or silhouette_jump_mm when
// that is <= 0):
// silhouette_bias_by_link_mm of its link where given, silhouette_bias_mm
// otherwise; 0 elsewhere. A pixel of the static scene takes
// silhouette_bias_mm only where the farther surface within the band is the
// arm's: before a farther static surface its multipath is as static as
// the surfaces, and the camera's profile learned it per pixel
// (docs/camera.md); only the arm moving behind it changes it. (Given the
// scene's pixels before every step, the largest link's allowance blinded
// the camera's own test: at 1 cm steps most of the scene is in the band.)
// Without labels every pixel in the band takes silhouette_bias_mm. Empty
// when silhouette_band_px <= 0.
std::vector<float> near_step_allowance_mm(const depth_image_t& rendered, const link_labels_t& labels,
                                          const EvidenceOptions& options, double silhouette_jump_mm);
// Per pixel, how far (pixels, Chebyshev, 1..max_px) the nearest rendered
// surface farther than it by more than silhouette_step's jump is; 0: none
// within max_px (or no rendered surface). max_px at most 255.
std::vector<uint8_t> step_distance_px(const depth_image_t& rendered, int max_px, double silhouette_jump_mm);

// How many sigmas of a fixed pattern's score offset the shrinking allows
// (EvidenceOptions::fixed_pattern_sigma_mm): the offset is one draw per
// camera and geometry, N(0, fixed_pattern_sigma^2 sum w^2 J^2), and persists
// over frames; 5 sigma leaves a chance of 5.7e-7 per parameter that a
// camera's pattern exceeds it (docs/safety-chain.md).
constexpr double kFixedPatternSigmas = 5.0;

// s shrunk towards 0 by `bound` (>= 0): sign(s) max(0, |s| - bound).
inline double shrink_score(double s, double bound) {
  if (s > bound) return s - bound;
  if (s < -bound) return s + bound;
  return 0.0;
}

// (The camera's noise model, DepthNoise, is common/depth_noise.hpp: the
// pixel tolerance, these evidence weights and the motion estimator share it.)

// compute_evidence's sampling stride k >= 1 for a width x height frame: the
// smallest k with ceil(width / k) * ceil(height / k) <= max_pixels (1 when
// max_pixels <= 0).
int evidence_stride(int width, int height, int max_pixels);

// The pixels per independent noise sample among the pixels of a stride-k
// grid: a camera whose noise is correlated over `pixels_per_sample` pixels
// (a filter's footprint) has samples k pixels apart correlated over
// pixels_per_sample / k^2 of them, and never fewer than 1 (independent).
// Weights are 1 / (this * sigma_i^2): with independent noise (1) sampling
// leaves each pixel's weight as it was.
inline double sampled_pixels_per_sample(double pixels_per_sample, int stride) {
  return std::max(1.0, pixels_per_sample / (static_cast<double>(stride) * stride));
}

// One moving axis of link_labels_t's kinematics (optical frame, mm).
struct LabelAxis {
  int joint = 0;  // index into link_labels_t.joint_name
  double multiplier = 1;
  bool prismatic = false;
  Eigen::Vector3d origin_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
  int parent = -1;  // the next moving axis towards the root, -1: none
};

// link_labels_t's kinematics, checked: every index in range, parents
// before children.
struct LabelKinematics {
  int num_joints = 0;
  int num_robot_links = 0;
  int num_links = 0;
  std::vector<LabelAxis> axes;
  // Per robot link: the nearest moving axis above it (-1: fixed to the
  // robot's root).
  std::vector<int> link_axis;
};

// False when `labels` carry no kinematics (num_axes = 0) or they do not fit
// together or the labels (`pixels` labels expected).
bool read_label_kinematics(const link_labels_t& labels, size_t pixels, LabelKinematics* out);

// Whether two neighbouring rendered depths (whole millimetres, both > 0)
// lie across a silhouette: a step in the scene larger than
// `silhouette_jump_mm`, where a ToF pixel mixes both surfaces. Each rendered
// depth is rounded to the millimetre, so a scene step just over the jump
// (50.4 mm over 50) can read one millimetre less in whole millimetres (50):
// a rendered step over silhouette_jump_mm - 1 counts. Missing one leaves a
// mixed pixel in the evidence with a slope taken across the step: on a
// still arm the same pixel, the same bias in every frame (a 23 mm mixed
// pixel beside a 50 mm step carried most of a7's score on the default arm).
inline bool silhouette_step(int a_mm, int b_mm, double silhouette_jump_mm) {
  return std::abs(a_mm - b_mm) > silhouette_jump_mm - 1.0;
}

// silhouette_step's test in whole millimetres: silhouette_step(a, b, j) is
// std::abs(a - b) > silhouette_step_limit_mm(j) (an integer is above x
// exactly when it is above floor(x)); a NaN or huge jump never steps, a
// jump of at most 1 mm always does.
inline int silhouette_step_limit_mm(double silhouette_jump_mm) {
  const double x = silhouette_jump_mm - 1.0;
  if (!(x < 1e9)) return 1000000000;  // above any step of two int16 depths
  return x > -1.0 ? static_cast<int>(std::floor(x)) : -1;
}

// The rendered step that opens the silhouette allowance's band (mm):
// EvidenceOptions::silhouette_band_step_mm where set (> 0), the silhouette
// jump otherwise.
inline double silhouette_band_step_or_jump_mm(double silhouette_band_step_mm, double silhouette_jump_mm) {
  return silhouette_band_step_mm > 0 ? silhouette_band_step_mm : silhouette_jump_mm;
}

// Per-pixel Jacobians of a rendered frame and its labels' kinematics.
// Keeps pointers into `rendered` and `labels`: they must outlive it.
class EvidenceJacobian {
 public:
  EvidenceJacobian(const depth_image_t& rendered, const link_labels_t& labels, double silhouette_jump_mm);

  // False when the labels carry no kinematics (num_axes = 0) or they do not
  // fit the labels (then at() is never true).
  bool available() const { return available_; }
  int num_joints() const { return kinematics_.num_joints; }
  // The labels' kinematics (valid when available()).
  const LabelKinematics& kinematics() const { return kinematics_; }

  // The Jacobian of pixel i (row-major index): mm per unit of each camera
  // parameter (t_x, t_y, t_z per metre, w_x, w_y, w_z per radian; the seen
  // optical frame in the reported one) into camera[6], and of each joint
  // into joints[num_joints()] (every entry written). *moved: whether some
  // joint moves the pixel's link (then camera[] is zero: not a static
  // pixel), *link the pixel's link (link_name index). False (nothing
  // written) when the pixel takes no part: no rendered depth, no link, or
  // no slope (no qualifying neighbour in u or in v).
  bool at(int i, double camera[6], double* joints, bool* moved, int* link) const;
  // The same for the pixel in column u, row v (i = v * width + u; both in
  // range): compute_evidence's loop, which knows them.
  bool at(int u, int v, double camera[6], double* joints, bool* moved, int* link) const;

 private:
  // Both at()s' body, defined inline in evidence.cpp so that
  // compute_evidence's loop has it without a call per pixel. Writes only
  // the Jacobian that applies: camera[] for a static pixel, joints[] for
  // a moved one (at() zeroes the other).
  bool at_pixel(int u, int v, double camera[6], double* joints, bool* moved, int* link) const;
  bool at_zeroing_the_other(int u, int v, double camera[6], double* joints, bool* moved, int* link) const;
  // compute_evidence's per-pixel step (evidence.cpp) calls at_pixel().
  friend struct EvidencePixelAccess;

  bool available_ = false;
  int width_ = 0;
  int height_ = 0;
  double fx_ = 1, fy_ = 1, cx_ = 0, cy_ = 0;
  int jump_limit_mm_ = 0;  // silhouette_step_limit_mm of the jump
  const int16_t* depth_ = nullptr;
  const int16_t* label_ = nullptr;
  LabelKinematics kinematics_;
};

// Fills `summary`'s evidence fields (evidence_available .. robot_chi2) for a
// usable, compared frame; `silhouette` is compute_discrepancy's mask (1 =
// beside a silhouette), `silhouette_jump_mm` its threshold (no slope is
// taken across a larger rendered step). Leaves them zero
// (evidence_available false) when the labels carry no kinematics.
// `workers` as compute_discrepancy's; `beside` (optional) as
// search_joint_offsets': it may run during the call, and the caller runs it
// after it (SideTask::run_once) when it did not.
void compute_evidence(const depth_image_t& camera, const depth_image_t& rendered, const link_labels_t& labels,
                      const std::vector<uint8_t>& silhouette, double silhouette_jump_mm,
                      const DepthNoise& noise, const EvidenceOptions& options, discrepancy_t* summary,
                      WorkerPool* workers = nullptr, SideTask* beside = nullptr);

// Clears the evidence fields (evidence_available false, everything zero).
void clear_evidence(discrepancy_t* summary);

}  // namespace tofguard::discrepancy
