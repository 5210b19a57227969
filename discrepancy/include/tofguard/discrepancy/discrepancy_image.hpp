#pragma once
// The discrepancy image of one camera frame: I_dis = I_gen - I_ToF per pixel
// (the seed's formula 4.1), in millimetres, with I_gen the depth rendered
// from the model at the reported joint angles and I_ToF the camera's. Every
// pixel is classified (discrepancy_t::PIXEL_*), counted per model link
// through the label image, and the frame is scored (docs/safety-chain.md).
//
// Pure computation: no LCM, no clocks. Images are row-major (v*width + u),
// depth is Z along the camera's optical axis in millimetres, <= 0 = none.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "tofguard/common/camera_profile.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/common/worker_pool.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/discrepancy/evidence.hpp"
#include "tofguard/discrepancy/witness_views.hpp"
#include "tofguard/discrepancy_image_t.hpp"
#include "tofguard/discrepancy_t.hpp"
#include "tofguard/link_labels_t.hpp"
#include "tofguard/settings/discrepancy_settings.hpp"

namespace tofguard::discrepancy {

// When |I_dis| is a mismatch rather than camera noise.
struct Tolerance {
  DepthNoise noise;
  double sigmas = 4.0;
  // Added to k*sigma: the model's own inaccuracy, millimetres.
  double model_mm = 15.0;

  // Largest |I_dis| still a match at camera depth `depth_mm`, millimetres.
  double at(double depth_mm) const { return sigmas * noise.sigma_mm(depth_mm) + model_mm; }
};

struct DiscrepancyOptions {
  Tolerance tolerance;
  // Radius of the square opening of the mismatch masks, pixels (0 = none).
  int opening_radius_px = 1;
  // Rendered depth steps over this (and the model's outline) are
  // silhouettes, where ToF pixels mix both surfaces: the pixels beside them
  // are left out of link counts and blobs, mm. 0 = no silhouettes.
  double silhouette_jump_mm = 0;
  // Distance from the modelled arm within which nearer surfaces count as
  // near it (discrepancy_t.near_arm_*), m.
  double near_arm_m = 0.2;
  // The protective fields' distances (discrepancy_t.field_*): counted up
  // to field_range_m in bins of field_bin_m, m.
  double field_range_m = 1.5;
  double field_bin_m = 0.01;
  // Logical maximum of |I_dis| per pixel for the normalised seed score, mm.
  double max_depth_mm = 8000;
  // The evidence stage (evidence.hpp).
  EvidenceOptions evidence;
  // How the volume behind an occluded pixel is examined in other cameras'
  // frames (witness_views.hpp).
  HiddenVolumeOptions hidden_volume;
  // The deployment has other cameras (tofguard-discrepancy: other cameras
  // configured), whose frames may look through this one's: a robot pixel
  // hidden by a surface beyond near_arm_m of the arm is taken as one
  // without a return (discrepancy_t.num_robot_hidden_by_objects) in every
  // frame, whether or not another camera's frame was at hand for it.
  bool other_cameras = false;
  // The camera's commissioned profile (camera_profile.hpp; null: none):
  // every camera frame is corrected by it before it is compared, and a
  // frame it does not fit (camera id, size, intrinsics) is unusable.
  std::shared_ptr<const CameraProfile> camera_profile;
};

DiscrepancyOptions discrepancy_options(const DiscrepancySettings& config);

// The result for one frame: the summary that goes on the wire, and the
// images (for the colour image and for tests).
struct DiscrepancyFrame {
  discrepancy_t summary;
  // discrepancy_t::PIXEL_* per pixel (CV_8U), empty when unusable.
  cv::Mat1b pixel_class;
  // I_dis in millimetres where both images have a surface, 0 elsewhere.
  cv::Mat1i dis_mm;
};

// Compares a camera frame with its rendered frame and labels. The messages
// have passed their wire checks. When the labels are unusable, or the three
// do not fit each other (size, intrinsics, camera, label values), the
// summary is unusable and says why; `rendered` is not read when the labels
// are unusable.
//
// workers (optional): the threads the naming search shares its joints
// among (joint_search.hpp); nullptr runs it on the caller's thread. The
// summary is the same either way.
//
// witnesses: other cameras' frames of about this frame's time
// (witness_views.hpp). Where the labels carry the camera's pose and the
// arm's cover, an occluded pixel is at the distance of what the witnesses
// did not see behind it (discrepancy_t.occluded_seen_by_witnesses), not 0.
DiscrepancyFrame compute_discrepancy(const depth_image_t& camera, const depth_image_t& rendered,
                                     const link_labels_t& labels, const DiscrepancyOptions& options,
                                     WorkerPool* workers = nullptr,
                                     const std::vector<WitnessView>& witnesses = {});

// compute_discrepancy's silhouette mask (row-major, 1 = beside a
// silhouette): the pixels beside a rendered depth step larger than
// `silhouette_jump_mm` (silhouette_step: in whole millimetres, one less) or
// the model's outline, 4-neighbours. A ToF pixel there mixes both surfaces,
// so its I_dis says nothing about a link's pose (on a thin link, a finger
// three pixels wide, it would otherwise be most of the link) nor about the
// camera's noise (tofguard-tune leaves them out of its fit).
// `silhouette_jump_mm` <= 0: no silhouettes.
std::vector<uint8_t> silhouette_mask(const depth_image_t& rendered, double silhouette_jump_mm);

// The summary of a camera frame that cannot be compared (`kind` is one of
// discrepancy_t::UNUSABLE_*): identity, calibrated flag and invalid pixels
// filled in, everything else zero (depth_hash and repeat_count are the
// caller's).
discrepancy_t unusable_summary(const depth_image_t& camera, int8_t kind, const std::string& reason);

// The point pixel i (row-major) of `camera` sees at Z = `z_m` along the
// optical axis: the camera's optical frame (x right, y down, z forward),
// metres.
Eigen::Vector3d optical_point_m(const depth_image_t& camera, int i, double z_m);

// FNV-1a 64-bit hash of a depth array's bytes (little-endian int16).
int64_t depth_hash(const std::vector<int16_t>& depth_mm);

// Counts how many camera frames in a row repeated the previous image.
class RepeatCounter {
 public:
  // The number of frames immediately before this one with the same hash.
  int32_t update(int64_t hash);

 private:
  bool has_previous_ = false;
  int64_t previous_ = 0;
  int32_t repeats_ = 0;
};

// The colour discrepancy image: red where I_dis > 0 (the camera sees
// nearer than the model: something is there that the model does not
// have), blue where I_dis < 0 (the camera sees farther: the model's surface
// is missing), black where the pixel matches or is not compared;
// brightness |I_dis| / full_scale_mm, saturating at 255. (The tofguard
// issues disagree on the sign convention; this follows the one with a
// physical definition and a test: "nearer in the camera is red".)
discrepancy_image_t colour_image(const DiscrepancyFrame& frame, double full_scale_mm);

}  // namespace tofguard::discrepancy
