#pragma once
// tofguard-discrepancy's settings (config section `discrepancy`,
// docs/safety-chain.md): how camera and rendered frames are paired and
// compared. Durations are integer microseconds, converted once when the file
// is read.
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "tofguard/common/camera_profile.hpp"
#include "tofguard/common/lcm_settings.hpp"
#include "tofguard/common/yaml_reader.hpp"

namespace tofguard::settings {

struct DiscrepancySettings {
  // noise.{sigma_at_0m_mm, sigma_per_m2_mm}: camera noise model:
  // sigma(d) = noise_sigma_at_0m_mm + noise_sigma_per_m2_mm * d^2, d the
  // camera's depth in metres, sigma in mm.
  double noise_sigma_at_0m_mm = 0;
  double noise_sigma_per_m2_mm = 0;
  // tolerance_sigmas, model_tolerance_mm: a pixel matches when
  // |I_dis| <= tolerance_sigmas * sigma(d) + model_tolerance_mm (the
  // model's own inaccuracy), millimetres.
  double tolerance_sigmas = 0;
  double model_tolerance_mm = 0;
  // pair_timeout_ms: a camera frame waits this long (monotonic) for its
  // rendered frame and labels before it is published as unusable;
  // microseconds.
  int64_t pair_timeout_us = 0;
  // max_pending_frames: at most this many frames of each kind wait for
  // their partners.
  int max_pending_frames = 0;
  // opening_radius_px: radius of the morphological opening applied to the
  // mismatch mask before blobs and near-arm surfaces are measured, pixels
  // (0 = none).
  int opening_radius_px = 0;
  // silhouette_jump_mm: rendered depth steps larger than this (and the
  // model's outline) are silhouettes, where a ToF camera mixes foreground
  // and background (mixed pixels): the pixels on either side of one are
  // left out of the per-link counts and the blobs, millimetres.
  double silhouette_jump_mm = 0;
  // near_arm_m: surfaces nearer than the model within this 3-D distance of
  // the modelled arm count as near the arm (discrepancy_t.near_arm_*),
  // metres.
  double near_arm_m = 0;
  // field.{range_m, bin_m}: unexplained nearer surfaces are counted by
  // their distance to the arm up to range_m, in bins of bin_m, for the
  // protective and warning fields (discrepancy_t.field_*), metres.
  double field_range_m = 0;
  double field_bin_m = 0;
  // max_depth_mm: the seed score's logical maximum per pixel, millimetres.
  double max_depth_mm = 0;
  // colour_image.{enabled, channel, full_scale_mm}: the optional colour
  // discrepancy image for viewers.
  bool colour_image_enabled = false;
  std::string colour_image_channel;
  double colour_image_full_scale_mm = 0;
  // evidence.{model_sigma_mm, clip_sigmas, pixels_per_sample}: the evidence
  // stage (docs/safety-chain.md, "Evidence"): the model's own inaccuracy per
  // pixel (mm, added in quadrature to sigma(d)), the residual clip in sigmas,
  // and how many pixels make one independent noise sample.
  double evidence_model_sigma_mm = 0;
  double evidence_clip_sigmas = 0;
  double evidence_pixels_per_sample = 0;
  // evidence.naming_gate_sigmas: the naming fit's gate in sigmas (the
  // suspect joint is named from the pixels within it).
  double evidence_naming_gate_sigmas = 0;
  // evidence.{static_bias_mm, fixed_pattern_sigma_mm}: the static error the
  // camera and the model keep after calibration, which frames do not
  // average away: a bound on the smooth error shared by many pixels and the
  // sigma of independent per-pixel offsets, mm (EvidenceOptions; the
  // derivation: docs/safety-chain.md, "Static error: the composite null").
  double evidence_static_bias_mm = 0;
  double evidence_fixed_pattern_sigma_mm = 0;
  // evidence.silhouette_allowance (optional; absent: none, band 0): the
  // error of the pixels on the near side of a rendered step, within
  // band_px of it, beyond static_bias_mm (a camera's multipath in front of
  // a farther surface: it moves with the arm, no profile learns it), mm.
  // by_link (optional): a link's own bound, by link name, where
  // commissioning measured it; other links and the scene take bias_mm.
  // step_mm (optional; absent: 0, silhouette_jump_mm): the rendered step
  // that opens the band, mm.
  int evidence_silhouette_band_px = 0;
  double evidence_silhouette_bias_mm = 0;
  std::map<std::string, double> evidence_silhouette_bias_by_link_mm;
  double evidence_silhouette_band_step_mm = 0;
  // camera_profile (optional; absent: none): the camera's commissioned
  // profile file (tofguard-tune --profile-out; docs/camera.md,
  // "Commissioning a camera"), read with the config: every frame is
  // corrected by it before it is compared. The evidence's static_bias_mm
  // and fixed_pattern_sigma_mm are then what is left with it applied.
  std::shared_ptr<const CameraProfile> camera_profile;
  // evidence.max_pixels (optional; absent: 0, every pixel): at most this
  // many pixels in the evidence sums, every k-th in u and v above it
  // (EvidenceOptions::max_pixels: less information, the same false-stop
  // rate).
  int evidence_max_pixels = 0;
  // evidence.search.{range_deg, step_deg, range_mm, step_mm, max_points}:
  // the naming search (joint_search.hpp): trial offsets of each revolute
  // joint within +-range_deg in steps of step_deg (prismatic: range_mm,
  // step_mm), over at most max_points rendered robot points. Radians and
  // metres here.
  double evidence_search_range_rad = 0;
  double evidence_search_step_rad = 0;
  double evidence_search_range_m = 0;
  double evidence_search_step_m = 0;
  int evidence_search_max_points = 0;
  // worker_threads (optional, default 1): the threads compute_discrepancy's
  // naming search shares its joints among, the process's own included
  // (WorkerPool; docs/benchmarks.md, "The hot paths"). A speed setting
  // only: the summary is the same for any value. 1: no worker thread.
  // `auto`: the CPUs the reading process may run on, at most
  // kMaxAutoWorkerThreads (auto_worker_threads).
  int worker_threads = 1;
};

// `worker_threads: auto`'s limit: compute_discrepancy's evidence sums run in
// 8 fixed bands of rows and its naming search in a task per joint (6-7 for
// the arms here), so a ninth thread would find no task. On a 16-core
// machine 8 met the latency targets where 2 did not (docs/benchmarks.md, "On
// an NVIDIA H200 machine").
inline constexpr int kMaxAutoWorkerThreads = 8;

// `worker_threads: auto`: min(allowed_cpu_count(), kMaxAutoWorkerThreads),
// for the calling thread's CPUs when it is called.
int auto_worker_threads();

// Reads (and finishes) the `discrepancy` section.
DiscrepancySettings read_discrepancy_settings(YamlMap section);

// Another camera of the deployment, whose frames this camera's occluded
// pixels are looked through (docs/safety-chain.md, "Several cameras: the
// volume behind an occlusion").
struct WitnessCameraSettings {
  std::string id;
  // Its TOF_DEPTH and TOF_LABELS (with its "/<id>" where it has one).
  std::string depth_channel;
  std::string labels_channel;
  // camera.rate_hz: a frame of it is used within one frame period of the
  // judged frame's capture.
  double rate_hz = 0;
  // Its commissioned profile (null: none): its frames are corrected by it
  // before they are looked through.
  std::shared_ptr<const CameraProfile> profile;
};

// Everything tofguard-discrepancy needs.
struct DiscrepancyProcessSettings {
  LcmSettings lcm;
  ChannelNames channels;
  // camera.id: frames from another camera are rejected.
  std::string camera_id;
  DiscrepancySettings discrepancy;
  // Every other camera of the deployment (none with one camera).
  std::vector<WitnessCameraSettings> witnesses;
  // The risk's detection capability, sqrt(risk.unknown_object_min_area_m2),
  // m, and risk.field.approach_speed_m_s, m/s: how the volume behind an
  // occlusion is examined (witness_views.hpp, hidden_volume_options).
  double detection_capability_m = 0;
  double approach_speed_m_s = 0;
};

}  // namespace tofguard::settings

// The component's own names for its settings (tofguard::discrepancy::DiscrepancySettings, ...).
namespace tofguard::discrepancy {
using settings::auto_worker_threads;
using settings::DiscrepancyProcessSettings;
using settings::DiscrepancySettings;
using settings::kMaxAutoWorkerThreads;
using settings::read_discrepancy_settings;
}  // namespace tofguard::discrepancy
