#pragma once
// tofguard-tune's work on one nominal recording (docs/safety-chain.md,
// "Tuning a new camera: tofguard-tune"): every camera frame of an LCM log
// (TOF_DEPTH, with JOINT_STATE and CAMERA_POSE as scripts/record-scenario
// records them) is rendered as tofguard-renderer renders it (RendererService:
// the joints interpolated at the frame's utime, the camera pose at it), the
// noise model sigma(d) = a + b d^2 is fitted to I_dis on the pixels both
// surfaces cover away from silhouettes (noise_fit.hpp), the neighbouring
// residuals' correlation gives pixels_per_sample, and compute_discrepancy with
// the fitted model feeds the risk's sequential tests (SequentialEvidence) to
// measure what they assume: each parameter's t = s / sqrt(I) ~ N(0, 1).
//
// No LCM traffic (the log is read from its file), no clocks.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "tofguard/settings/discrepancy_settings.hpp"
#include "tofguard/settings/renderer_settings.hpp"
#include "tofguard/settings/risk_settings.hpp"
#include "tofguard/tune/camera_profile_fit.hpp"
#include "tofguard/tune/near_step_error.hpp"
#include "tofguard/tune/noise_fit.hpp"
#include "tofguard/tune/rendered_pair.hpp"

namespace tofguard::tune {

// The config sections tofguard-tune reads: what tofguard-renderer renders
// with (robot, environment, camera, renderer, channels), the discrepancy's
// rules and the risk's sequential tests.
struct TuneSettings {
  renderer::RendererProcessSettings renderer;
  discrepancy::DiscrepancySettings discrepancy;
  risk::RiskSettings risk;
};

struct TuneOptions {
  // Fewer rendered frames: the recording is not usable.
  int min_frames = 50;
  // At most this many camera frames are used (each is kept with its
  // rendering for the second pass: about 150 KB a frame at 176x144, 600 MB
  // in all): two minutes at 30 Hz, the recording docs/camera.md asks for
  // (the allowance's bounds are the worst the recording's poses show).
  // Frames beyond it are counted and reported, not used.
  int max_frames = 4000;
  // No joint moving more than this over the recording (rad; m for a
  // prismatic joint): not usable (the scores of one pose say little).
  double min_motion = 0.05;
  // More of the fitted pixels beyond the tolerance (with the fitted model):
  // not nominal (an object, a fault, a model that does not fit).
  double max_mismatch_fraction = 0.01;
  // A frame-to-frame variance of some parameter's t above this (with at
  // least min_scores scores): the fitted model does not make the scores
  // N(0, 1), so h would not hold its false-stop period.
  double max_frame_to_frame_variance = 1.5;
  int64_t min_scores = 30;
  // The fixed pattern is measured on environment pixels seen in at least
  // this many frames (StaticError).
  int min_pattern_frames = 20;
  // Learn the camera's profile from the recording (tofguard-tune
  // --profile-out; camera_profile_fit.hpp) and tune on the corrected
  // frames.
  bool learn_profile = false;
  ProfileFitOptions profile;
  // The measured pixels_per_sample replaces the config's when they differ
  // by more than this fraction.
  double pixels_per_sample_change = 0.2;
  // Also run the sequential tests with the config's own noise model, for
  // comparison (twice the work).
  bool compare_with_config = true;
  NoiseFitOptions fit;
};

// One hypothesis parameter's standardised scores over the recording.
struct ParameterScores {
  std::string name;  // a joint, or "camera t_x" .. "camera r_z"
  int64_t scores = 0;
  double variance = 0;
  double frame_to_frame_variance = 0;
  double max_abs_t = 0;
  // The largest CUSUM of its hypothesis (the camera's six share one).
  double max_cusum = 0;
};

// The error that stays from frame to frame, measured on the recording
// (docs/safety-chain.md, "Static error: the composite null"; the evidence's
// static_bias_mm and fixed_pattern_sigma_mm), mm. What the camera's
// calibration and the model leave, whatever its cause (a residual distance
// error, reflectivity, multipath, the model's own error); a camera pose off
// from the config shows here too, as an error the tests then tolerate:
// calibrate the extrinsics before (docs/camera.md).
struct StaticError {
  // The smooth part: the largest |median I_dis| over the bins of rendered
  // depth (noise-free, unlike the camera's) holding at least 1 % of the
  // samples, plus twice its standard error (1.2533 sigma / sqrt(n) for a
  // median); at rendered depth smooth_depth_m.
  double smooth_bound_mm = 0;
  double smooth_depth_m = 0;
  // The fixed pattern: on each environment pixel seen in at least
  // min_pattern_frames frames, the mean of I_dis less the smooth part at its
  // rendered depth; sigma^2 = the mean over those pixels of (mean^2 - s^2 / n), s^2
  // the pixel's own frame-to-frame variance (the noise's share of a mean of
  // n), kept >= 0.
  double fixed_pattern_sigma_mm = 0;
  int64_t pattern_pixels = 0;
  // The near side of rendered steps on the arm's links
  // (evidence.silhouette_allowance).
  NearStepError near_steps;
};

// The sequential tests over the recording with one noise model.
struct EvidenceRun {
  double sigma_at_0m_mm = 0;
  double sigma_per_m2_mm = 0;
  double pixels_per_sample = 1;
  // The static-error allowance the scores were shrunk by (mm).
  double static_bias_mm = 0;
  double fixed_pattern_sigma_mm = 0;
  int silhouette_band_px = 0;
  double silhouette_bias_mm = 0;
  std::map<std::string, double> silhouette_bias_by_link_mm;
  double silhouette_band_step_mm = 0;  // <= 0: the silhouette jump
  std::vector<ParameterScores> parameters;
  double max_cusum = 0;
  std::string max_cusum_hypothesis;
  int frames_crossed = 0;  // frames with some CUSUM at h
  std::string first_crossing;
  // Fitted pixels beyond tolerance_sigmas * sigma(d) + model_tolerance_mm.
  int64_t pixels = 0;
  int64_t mismatches = 0;
  double mismatch_fraction() const {
    return pixels > 0 ? static_cast<double>(mismatches) / static_cast<double>(pixels) : 0;
  }
};

struct TuneResult {
  // false: the recording is not usable or the fitted model not sound;
  // `error` says why in one line.
  bool usable = false;
  std::string error;
  std::string log_path;

  int depth_frames = 0;     // camera frames of camera.id in the log
  int frames_left_out = 0;  // camera frames beyond TuneOptions::max_frames, not used
  int used_frames = 0;      // rendered and compared
  int unusable_frames = 0;  // the renderer could not render them (first reason below)
  std::string first_unusable_reason;
  int joint_states = 0;
  double measured_rate_hz = 0;  // from the frames' utimes
  double seconds = 0;           // first to last frame
  double largest_motion = 0;    // the most moving joint's range (rad; m prismatic)
  std::string most_moving_joint;

  NoiseFit fit;
  double measured_pixels_per_sample = 1;
  // Neighbours' correlation at lag 1 of the residuals' frame-to-frame
  // differences (a bias fixed to a pixel cancels).
  double rho_u1 = 0, rho_v1 = 0;
  bool pixels_per_sample_changed = false;
  double pixels_per_sample = 1;  // what the tuned config gets
  StaticError static_error;
  // The allowance from static_error (static_bias_mm, rounded up), and why it
  // was raised to tuned.static_bias_mm (empty: it was not): a test reached
  // its warning level on this nominal recording, so the static error on
  // the arm's own pixels exceeds it (recording_tuner.cpp, "Pass 3b").
  double measured_static_bias_mm = 0;
  std::string allowance_raised;
  // The profile learned (has_profile: options.learn_profile), and which
  // profile the frames were corrected with (empty: none).
  bool has_profile = false;
  ProfileFit profile_fit;
  std::string profile_applied;
  // A configured profile's range against the recording's distances
  // (checking recordings only; pixels 0 when it was learned here).
  ProfileCoverage profile_coverage;

  double threshold_h = 0;
  double warning_level = 0;
  int hypotheses = 0;
  EvidenceRun tuned;  // with the fitted model
  bool has_config_run = false;
  EvidenceRun configured;  // with the config's model (compare_with_config)
};

// Reads the log and tunes; never throws for a bad recording (usable false,
// error set). Throws for a model that cannot be loaded or rendered
// (ModelError, RenderError).
TuneResult tune_recording(const TuneSettings& settings, const std::string& log_path,
                          const TuneOptions& options = {});

// The same passes on frames already rendered (as tofguard-renderer would
// render them; a tool's in-process frames), `source` naming them in
// messages: no recording checks beyond options.min_frames (the caller's
// frames move the arm).
TuneResult tune_rendered_frames(const TuneSettings& settings, std::vector<RenderedPair> frames,
                                const std::string& source, const TuneOptions& options = {});

// The report for people: the recording, the fit per depth bin against the
// model, the correlation, the per-pixel false-mismatch rate, and per
// hypothesis var(t), its frame-to-frame part and the largest CUSUM against h.
std::string tune_report(const TuneResult& result, const TuneSettings& settings);

// The lines to paste into the config's `discrepancy:` section (indented as
// in config/sim.yaml), each with a comment: where the number came from.
// `date`: e.g. "2026-11-30".
std::string tuned_config_lines(const TuneResult& result, const std::string& date);

}  // namespace tofguard::tune
