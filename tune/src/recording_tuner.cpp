#include "tofguard/tune/recording_tuner.hpp"

#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <iomanip>
#include <map>
#include <sstream>

#include "tofguard/camera_pose_t.hpp"
#include "tofguard/common/decode.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/common/wire_checks.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/discrepancy/discrepancy_image.hpp"
#include "tofguard/discrepancy/evidence.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/renderer/renderer_service.hpp"
#include "tofguard/risk/sequential_evidence.hpp"
#include "tofguard/robot_model/kinematic_tree.hpp"
#include "tofguard/tune/camera_profile_fit.hpp"

namespace tofguard::tune {
namespace {

const char* const kCameraParameters[6] = {"camera t_x", "camera t_y", "camera t_z",
                                          "camera r_x", "camera r_y", "camera r_z"};

// The sequential tests over every frame with `noise` and `pixels_per_sample`.
// `model`: the noise model and static-error allowance to run with (its
// sigma_*, pixels_per_sample, static_bias_mm, fixed_pattern_sigma_mm).
EvidenceRun run_evidence(const std::vector<RenderedPair>& frames, const TuneSettings& settings,
                         const robot_model::KinematicTree& tree, const EvidenceRun& model) {
  EvidenceRun run = model;
  discrepancy::DiscrepancyOptions options = discrepancy::discrepancy_options(settings.discrepancy);
  options.tolerance.noise.sigma_at_0m_mm = model.sigma_at_0m_mm;
  options.tolerance.noise.sigma_per_m2_mm = model.sigma_per_m2_mm;
  options.evidence.pixels_per_sample = model.pixels_per_sample;
  options.evidence.static_bias_mm = model.static_bias_mm;
  options.evidence.fixed_pattern_sigma_mm = model.fixed_pattern_sigma_mm;
  options.evidence.silhouette_band_px = model.silhouette_band_px;
  options.evidence.silhouette_bias_mm = model.silhouette_bias_mm;
  options.evidence.silhouette_bias_by_link_mm = model.silhouette_bias_by_link_mm;
  options.evidence.silhouette_band_step_mm = model.silhouette_band_step_mm;
  // The frames are corrected already (correct_frames).
  options.camera_profile = nullptr;
  risk::SequentialEvidence evidence(settings.risk, tree, settings.renderer.camera.rate_hz);
  std::map<std::string, ScoreStatistics> statistics;
  std::map<std::string, double> max_cusum;
  std::vector<std::string> order;
  auto statistics_of = [&](const std::string& name) -> ScoreStatistics& {
    if (!statistics.count(name)) order.push_back(name);
    return statistics[name];
  };
  for (const RenderedPair& frame : frames) {
    const discrepancy::DiscrepancyFrame result =
        discrepancy::compute_discrepancy(frame.camera, frame.rendered, frame.labels, options);
    // The false mismatches on the fitted pixels.
    const std::vector<uint8_t> used = noise_pixels(frame, settings.discrepancy.silhouette_jump_mm);
    for (size_t i = 0; i < used.size(); ++i) {
      if (!used[i]) continue;
      const int t = frame.camera.depth_mm[i];
      ++run.pixels;
      if (std::abs(frame.rendered.depth_mm[i] - t) > options.tolerance.at(t)) ++run.mismatches;
    }
    const discrepancy_t& d = result.summary;
    if (!d.usable || !d.evidence_available) continue;
    for (int j = 0; j < d.num_joints; ++j)
      statistics_of(d.joint_name[j]).add(d.joint_score[j], d.joint_information[j]);
    for (int a = 0; a < 6; ++a)
      statistics_of(kCameraParameters[a]).add(d.camera_score[a], d.camera_information[7 * a]);
    const risk::EvidenceStep step = evidence.update(d);
    if (step.crossed) {
      if (run.frames_crossed == 0) {
        run.first_crossing = "frame seq " + std::to_string(d.seq) + ": " + step.finding.detail;
      }
      ++run.frames_crossed;
    }
    auto note = [&](const std::string& hypothesis, double cusum) {
      max_cusum[hypothesis] = std::max(max_cusum[hypothesis], cusum);
      if (cusum > run.max_cusum) {
        run.max_cusum = cusum;
        run.max_cusum_hypothesis = hypothesis;
      }
    };
    note("camera", evidence.camera_cusum());
    for (int j = 0; j < d.num_joints; ++j) note(d.joint_name[j], evidence.joint_cusum(d.joint_name[j]));
  }
  for (const std::string& name : order) {
    const ScoreStatistics& s = statistics.at(name);
    ParameterScores p;
    p.name = name;
    p.scores = s.count();
    p.variance = s.variance();
    p.frame_to_frame_variance = s.frame_to_frame_variance();
    p.max_abs_t = s.max_abs();
    p.max_cusum = max_cusum[name.rfind("camera", 0) == 0 ? std::string("camera") : name];
    run.parameters.push_back(p);
  }
  return run;
}

std::string fixed(double value, int decimals) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(decimals) << value;
  return s.str();
}

// Reads a recording's joint states, camera poses and depth frames, and
// renders each frame as tofguard-renderer would: the counts and the joints'
// ranges go into the result.
class RecordingRenderer {
 public:
  RecordingRenderer(const TuneSettings& settings, const TuneOptions& options, TuneResult* result)
      : channels_(settings.renderer.channels),
        camera_id_(settings.renderer.camera.id),
        options_(options),
        result_(*result),
        service_(settings.renderer) {}

  // Every event of the log, then the frames still waiting.
  std::vector<RenderedPair> read(lcm::LogFile* log) {
    for (const lcm::LogEvent* event = log->readNextEvent(); event != nullptr; event = log->readNextEvent()) {
      if (event->channel == channels_.joint_state) {
        on_joint_state(*event);
      } else if (event->channel == channels_.camera_pose) {
        const auto pose = decode_message<camera_pose_t>(event->data, event->datalen);
        if (pose && check_camera_pose(*pose).empty()) service_.on_camera_pose(*pose);
      } else if (event->channel == channels_.depth) {
        if (result_.depth_frames < options_.max_frames) {
          on_depth(*event);
        } else {
          ++result_.frames_left_out;
        }
      }
    }
    render_waiting(INT64_MAX);
    finish();
    return std::move(frames_);
  }

 private:
  void on_joint_state(const lcm::LogEvent& event) {
    const auto state = decode_message<joint_state_t>(event.data, event.datalen);
    if (!state || !check_joint_state(*state).empty() || !service_.on_joint_state(*state)) return;
    ++result_.joint_states;
    newest_joint_utime_ = std::max(newest_joint_utime_, state->utime);
    for (int j = 0; j < state->num_joints; ++j) {
      auto [it, fresh] = joint_range_.try_emplace(state->name[j], state->position[j], state->position[j]);
      if (!fresh) {
        it->second.first = std::min(it->second.first, state->position[j]);
        it->second.second = std::max(it->second.second, state->position[j]);
      }
    }
    render_waiting(newest_joint_utime_);
  }

  void on_depth(const lcm::LogEvent& event) {
    const auto frame = decode_message<depth_image_t>(event.data, event.datalen);
    if (!frame || !check_depth_image_from(*frame, camera_id_).empty()) return;
    if (result_.depth_frames++ == 0) first_utime_ = frame->utime;
    last_utime_ = frame->utime;
    waiting_.push_back(*frame);
  }

  // Frames wait until a joint state at or after their utime has come (the
  // joints are then interpolated, never extrapolated) or the log ends:
  // renders those at or before `utime`.
  void render_waiting(int64_t utime) {
    while (!waiting_.empty() && waiting_.front().utime <= utime) {
      render(waiting_.front());
      waiting_.pop_front();
    }
  }

  void render(const depth_image_t& camera) {
    renderer::RenderedFrame rendered = service_.render(camera);
    if (!rendered.depth) {
      if (result_.unusable_frames++ == 0) result_.first_unusable_reason = rendered.labels.unusable_reason;
      return;
    }
    RenderedPair pair{camera, std::move(*rendered.depth), std::move(rendered.labels)};
    // The amplitude is not compared: not kept.
    pair.camera.num_amplitude = 0;
    pair.camera.amplitude.clear();
    frames_.push_back(std::move(pair));
  }

  // The frame counts, the measured rate and the most moving joint.
  void finish() {
    result_.used_frames = static_cast<int>(frames_.size());
    result_.seconds = (last_utime_ - first_utime_) * 1e-6;
    if (result_.depth_frames > 1 && last_utime_ > first_utime_) {
      result_.measured_rate_hz = (result_.depth_frames - 1) / result_.seconds;
    }
    for (const auto& [joint, range] : joint_range_) {
      if (range.second - range.first > result_.largest_motion) {
        result_.largest_motion = range.second - range.first;
        result_.most_moving_joint = joint;
      }
    }
  }

  const ChannelNames& channels_;
  const std::string& camera_id_;
  const TuneOptions& options_;
  TuneResult& result_;
  renderer::RendererService service_;
  std::deque<depth_image_t> waiting_;
  std::vector<RenderedPair> frames_;
  int64_t newest_joint_utime_ = INT64_MIN;
  int64_t first_utime_ = 0, last_utime_ = 0;
  std::map<std::string, std::pair<double, double>> joint_range_;  // min, max
};

// Why the configured `profile` does not cover the distances of `frames`
// (ProfileCoverage, into result->profile_coverage); empty when it does.
std::string coverage_error(const CameraProfile& profile, const std::vector<RenderedPair>& frames,
                           const TuneSettings& settings, TuneResult* result) {
  const ProfileCoverage c = profile_coverage(profile, frames, settings.discrepancy.silhouette_jump_mm);
  result->profile_coverage = c;
  if (c.outside_share() <= kMaxShareOutsideProfile) return "";
  std::ostringstream why;
  why << std::fixed << std::setprecision(2) << result->log_path << ": "
      << (profile.file.empty() ? std::string("the camera profile (in memory)") : profile.file)
      << ": its distance correction was measured over " << c.first_m << "-" << c.last_m << " m (radial), and "
      << std::setprecision(1) << 100 * c.outside_share()
      << " % of this recording's arm pixels lie more than a bin (" << std::setprecision(2)
      << profile.distance_bin_m << " m) outside it (" << std::setprecision(2) << c.nearest_m << "-"
      << c.farthest_m << " m; at most " << std::setprecision(1) << 100 * kMaxShareOutsideProfile
      << " %): learn the profile on a recording that takes the arm through its whole workspace";
  return why.str();
}

// The camera's profile applied to every frame: the one learned from the
// frames (options.learn_profile) or the config's (discrepancy.camera_profile);
// frames as recorded without either. Why it cannot be; empty when it can.
std::string correct_frames(const TuneSettings& settings, const TuneOptions& options,
                           std::vector<RenderedPair>* frames, TuneResult* result) {
  const std::shared_ptr<const CameraProfile>& configured = settings.discrepancy.camera_profile;
  if (options.learn_profile) {
    if (configured) {
      return "a profile is learned from the camera's own frames: remove discrepancy.camera_profile (" +
             configured->file + ") from the config first";
    }
    ProfileFitOptions fit_options = options.profile;
    fit_options.pose_translation_m = settings.risk.evidence_camera_translation_m;
    fit_options.pose_rotation_rad = settings.risk.evidence_camera_rotation_rad;
    result->profile_fit =
        fit_camera_profile(*frames, discrepancy::discrepancy_options(settings.discrepancy).tolerance,
                           settings.discrepancy.silhouette_jump_mm, fit_options);
    if (!result->profile_fit.ok) return result->log_path + ": " + result->profile_fit.error;
    result->profile_fit.profile.measured_on =
        result->log_path + ", " + std::to_string(frames->size()) + " frames";
    result->has_profile = true;
  }
  const CameraProfile* profile = result->has_profile ? &result->profile_fit.profile : configured.get();
  if (profile == nullptr) return "";
  if (!result->has_profile) {
    if (const std::string why = coverage_error(*profile, *frames, settings, result); !why.empty()) return why;
  }
  for (RenderedPair& frame : *frames) {
    if (const std::string why = profile_mismatch(*profile, frame.camera); !why.empty()) {
      return result->log_path + ": " + why;
    }
    apply_camera_profile(*profile, &frame.camera, &frame.labels);
  }
  result->profile_applied = profile->file.empty() ? "learned from this recording" : profile->file;
  return "";
}

// Why the recording is too short or too still to tune on; empty when it
// is not.
std::string recording_error(const TuneSettings& settings, const TuneOptions& options,
                            const TuneResult& result) {
  const ChannelNames& channels = settings.renderer.channels;
  if (result.used_frames < options.min_frames) {
    std::ostringstream why;
    why << result.log_path << ": too few frames to tune on: " << result.used_frames << " rendered of "
        << result.depth_frames << " " << channels.depth << " frames of camera '"
        << settings.renderer.camera.id << "' (" << result.joint_states << " " << channels.joint_state
        << " messages";
    if (result.unusable_frames > 0) why << "; first unusable: " << result.first_unusable_reason;
    why << "); need " << options.min_frames;
    return why.str();
  }
  if (result.largest_motion < options.min_motion) {
    return result.log_path + ": no motion: no joint moved more than " + fixed(options.min_motion, 3) +
           " rad (m) over the recording (largest: " + fixed(result.largest_motion, 4) +
           "); record the arm moving through its workspace";
  }
  return "";
}

// Pass 1: the samples and the fit.
NoiseFit fit_noise(const std::vector<RenderedPair>& frames, const TuneSettings& settings,
                   const TuneOptions& options) {
  NoiseSamples samples(options.fit);
  const double jump_mm = settings.discrepancy.silhouette_jump_mm;
  for (const RenderedPair& frame : frames) {
    const std::vector<uint8_t> used = noise_pixels(frame, jump_mm);
    for (size_t i = 0; i < used.size(); ++i) {
      if (used[i])
        samples.add(frame.camera.depth_mm[i], frame.rendered.depth_mm[i] - frame.camera.depth_mm[i]);
    }
  }
  return samples.fit();
}

// Pass 2: the neighbours' correlation of the standardised residuals'
// frame-to-frame differences, (z_k - z_k-1) / sqrt(2) on the pixels used
// in both frames: a bias fixed to a pixel (the distance calibration's
// residual, the model's) cancels, as in the frame-to-frame var(t), and
// only the noise's own correlation is left (measured on the residuals
// themselves, the default scene's static bias gave rho 0.011 and 1.17).
SpatialCorrelation measure_correlation(const std::vector<RenderedPair>& frames, const TuneSettings& settings,
                                       const NoiseFit& fit) {
  SpatialCorrelation correlation;
  std::vector<float> previous_z;
  std::vector<uint8_t> previous_used;
  for (const RenderedPair& frame : frames) {
    const std::vector<uint8_t> used = noise_pixels(frame, settings.discrepancy.silhouette_jump_mm);
    std::vector<float> z(used.size(), 0.0f);
    for (size_t i = 0; i < used.size(); ++i) {
      if (!used[i]) continue;
      const int t = frame.camera.depth_mm[i];
      const double dis = frame.rendered.depth_mm[i] - t;
      z[i] = static_cast<float>((dis - fit.median_mm_at(t)) / fit.sigma_mm(metres_from_mm(t)));
    }
    if (previous_z.size() == z.size()) {
      std::vector<float> difference(z.size(), 0.0f);
      std::vector<uint8_t> both(z.size(), 0);
      for (size_t i = 0; i < z.size(); ++i) {
        both[i] = used[i] && previous_used[i];
        if (both[i]) difference[i] = static_cast<float>((z[i] - previous_z[i]) / std::sqrt(2.0));
      }
      correlation.add_frame(difference, both, frame.camera.width, frame.camera.height);
    }
    previous_z = std::move(z);
    previous_used = used;
  }
  return correlation;
}

// The measured pixels per independent sample, and the one the tuned run
// uses: the measured one (to a tenth) when it differs enough from the
// configured one.
void choose_pixels_per_sample(const SpatialCorrelation& correlation, const TuneSettings& settings,
                              const TuneOptions& options, TuneResult* result) {
  result->measured_pixels_per_sample = correlation.pixels_per_sample();
  result->rho_u1 = correlation.rho(0, 1);
  result->rho_v1 = correlation.rho(1, 1);
  const double configured_pps = settings.discrepancy.evidence_pixels_per_sample;
  result->pixels_per_sample_changed = std::abs(result->measured_pixels_per_sample - configured_pps) >
                                      options.pixels_per_sample_change * configured_pps;
  result->pixels_per_sample = result->pixels_per_sample_changed
                                  ? std::round(result->measured_pixels_per_sample * 10) / 10
                                  : configured_pps;
}

// The smooth part of the static error: per depth bin of the rendered
// depth (noise-free: binned by the camera's depth, a bin at the edge of the
// scene's range holds the pixels whose noise carried them there, and its
// median is the noise's, 15 mm at 3 m for the 8 mm + 2 mm/m^2 camera), the
// median I_dis of the bins holding at least 1 % of the samples, plus twice
// its standard error.
NoiseFit measure_smooth_error(const std::vector<RenderedPair>& frames, const TuneSettings& settings,
                              const TuneOptions& options, StaticError* error) {
  NoiseSamples by_rendered_depth(options.fit);
  for (const RenderedPair& frame : frames) {
    const std::vector<uint8_t> used = noise_pixels(frame, settings.discrepancy.silhouette_jump_mm);
    for (size_t i = 0; i < used.size(); ++i) {
      if (used[i])
        by_rendered_depth.add(frame.rendered.depth_mm[i],
                              frame.rendered.depth_mm[i] - frame.camera.depth_mm[i]);
    }
  }
  const NoiseFit smooth = by_rendered_depth.fit();
  for (const DepthBin& b : smooth.bins) {
    if (b.samples * 100 < smooth.samples) continue;
    const double standard_error = 1.2533 * b.sigma_mm / std::sqrt(static_cast<double>(b.samples));
    const double bound = std::abs(b.median_mm) + 2 * standard_error;
    if (bound > error->smooth_bound_mm) {
      error->smooth_bound_mm = bound;
      error->smooth_depth_m = b.depth_m;
    }
  }
  return smooth;
}

// A measured allowance as the config carries it: rounded up to 0.1 mm.
double rounded_up_mm(double value_mm) { return std::max(0.0, std::ceil(value_mm * 10 - 1e-9) / 10); }

// Pass 2b: the static error (StaticError): the smooth part by rendered
// depth, the fixed pattern from the environment pixels' means over the
// frames less the smooth part, the near side of steps on the arm's pixels.
StaticError measure_static_error(const std::vector<RenderedPair>& frames, const TuneSettings& settings,
                                 const TuneOptions& options) {
  StaticError error;
  const NoiseFit smooth = measure_smooth_error(frames, settings, options, &error);
  // Per pixel: count, sum and sum of squares of I_dis less the smooth part.
  std::vector<int32_t> count;
  std::vector<double> sum, sum_squares;
  for (const RenderedPair& frame : frames) {
    const std::vector<uint8_t> used = noise_pixels(frame, settings.discrepancy.silhouette_jump_mm);
    if (count.size() != used.size()) {
      count.assign(used.size(), 0);
      sum.assign(used.size(), 0.0);
      sum_squares.assign(used.size(), 0.0);
    }
    for (size_t i = 0; i < used.size(); ++i) {
      const int link =
          link_of_label(frame.labels.label[i], frame.labels.num_robot_links, frame.labels.num_links);
      if (!used[i] || link < frame.labels.num_robot_links) continue;  // environment pixels only
      const int gen = frame.rendered.depth_mm[i];
      const double e = gen - frame.camera.depth_mm[i] - smooth.median_mm_at(gen);
      ++count[i];
      sum[i] += e;
      sum_squares[i] += e * e;
    }
  }
  double pattern_variance = 0;
  for (size_t i = 0; i < count.size(); ++i) {
    if (count[i] < std::max(options.min_pattern_frames, 2)) continue;
    const double n = count[i];
    const double mean = sum[i] / n;
    const double noise_variance = (sum_squares[i] - n * mean * mean) / (n - 1);
    pattern_variance += mean * mean - noise_variance / n;
    ++error.pattern_pixels;
  }
  if (error.pattern_pixels > 0) {
    error.fixed_pattern_sigma_mm =
        std::sqrt(std::max(0.0, pattern_variance / static_cast<double>(error.pattern_pixels)));
  }
  error.near_steps = measure_near_step_error(frames, settings.discrepancy.silhouette_jump_mm, kBandStepMm,
                                             settings.discrepancy.evidence_naming_gate_sigmas, smooth,
                                             rounded_up_mm(error.smooth_bound_mm));
  return error;
}

// Pass 3b: the allowance the recording's tests need (StaticError's
// limits, docs/safety-chain.md, "Static error: the composite null"). The
// measured static error is the environment's and the depth bins'; the
// robot's own pixels keep errors that move with the arm (multipath beside
// its silhouettes, its surfaces' reflectivity), which no bin's median shows.
// With an allowance that covers the static error, a test's CUSUM reaches
// the warning level w h within n frames with probability at most
// n e^(-w h) (Ville's inequality from each start: 0.9 % for 360 frames at
// h 21.2, w 0.5): a test that reaches it on a nominal recording shows an
// error the allowance does not cover. The allowance is then raised, by
// bisection to 0.1 mm, to the smallest that keeps every test below the
// warning level, up to half the camera test's translation (beyond it a
// camera pose error of the test's size would hide in the allowance): a
// recording that needs more stays not nominal (its tests are reported with
// the largest allowance).
void raise_allowance_to_the_warning_level(const std::vector<RenderedPair>& frames,
                                          const TuneSettings& settings,
                                          const robot_model::KinematicTree& tree, TuneResult* result) {
  if (result->tuned.max_cusum < result->warning_level) return;
  const double largest_mm = 1000 * settings.risk.evidence_camera_translation_m / 2;
  const std::string reached = result->tuned.max_cusum_hypothesis + "'s test reached " +
                              fixed(result->tuned.max_cusum, 1) + " of h " + fixed(result->threshold_h, 1) +
                              " (warning level " + fixed(result->warning_level, 1) + ") with " +
                              fixed(result->tuned.static_bias_mm, 1) + " mm";
  EvidenceRun candidate = result->tuned;
  candidate.static_bias_mm = rounded_up_mm(largest_mm);
  EvidenceRun holding = run_evidence(frames, settings, tree, candidate);
  if (holding.max_cusum >= result->warning_level) {
    result->tuned = holding;
    result->allowance_raised = reached + "; even " + fixed(holding.static_bias_mm, 1) +
                               " mm (half the camera test's translation) does not hold it below";
    return;
  }
  double failing_mm = result->tuned.static_bias_mm;
  while (holding.static_bias_mm - failing_mm > 0.1 + 1e-9) {
    candidate.static_bias_mm = rounded_up_mm((failing_mm + holding.static_bias_mm) / 2);
    if (candidate.static_bias_mm >= holding.static_bias_mm) break;
    EvidenceRun run = run_evidence(frames, settings, tree, candidate);
    if (run.max_cusum < result->warning_level) {
      holding = std::move(run);
    } else {
      failing_mm = candidate.static_bias_mm;
    }
  }
  result->tuned = holding;
  result->allowance_raised = reached + "; " + fixed(holding.static_bias_mm, 1) +
                             " mm holds every test below it (largest " + holding.max_cusum_hypothesis +
                             "'s " + fixed(holding.max_cusum, 1) + ")";
}

// Pass 3: the sequential tests with the fitted model and the measured
// static error (and with the config's).
void run_sequential_tests(const std::vector<RenderedPair>& frames, const TuneSettings& settings,
                          const TuneOptions& options, TuneResult* result) {
  const robot_model::KinematicTree tree = robot_model::load_kinematic_tree(settings.renderer.robot.urdf_path);
  const risk::SequentialEvidence reference(settings.risk, tree, settings.renderer.camera.rate_hz);
  result->threshold_h = reference.threshold();
  result->warning_level = reference.warning_level();
  result->hypotheses = reference.hypotheses();
  EvidenceRun tuned;
  tuned.sigma_at_0m_mm = result->fit.sigma_at_0m_mm;
  tuned.sigma_per_m2_mm = result->fit.sigma_per_m2_mm;
  tuned.pixels_per_sample = result->pixels_per_sample;
  tuned.static_bias_mm = rounded_up_mm(result->static_error.smooth_bound_mm);
  tuned.fixed_pattern_sigma_mm = rounded_up_mm(result->static_error.fixed_pattern_sigma_mm);
  const NearStepError& near_steps = result->static_error.near_steps;
  tuned.silhouette_band_px = near_steps.band_px;
  tuned.silhouette_band_step_mm = near_steps.band_step_mm;
  tuned.silhouette_bias_mm = rounded_up_mm(near_steps.bias_mm);
  for (const auto& [link, bias_mm] : near_steps.bias_by_link_mm)
    tuned.silhouette_bias_by_link_mm[link] = rounded_up_mm(bias_mm);
  result->tuned = run_evidence(frames, settings, tree, tuned);
  result->measured_static_bias_mm = tuned.static_bias_mm;
  raise_allowance_to_the_warning_level(frames, settings, tree, result);
  if (options.compare_with_config) {
    result->has_config_run = true;
    EvidenceRun configured;
    configured.sigma_at_0m_mm = settings.discrepancy.noise_sigma_at_0m_mm;
    configured.sigma_per_m2_mm = settings.discrepancy.noise_sigma_per_m2_mm;
    configured.pixels_per_sample = settings.discrepancy.evidence_pixels_per_sample;
    configured.static_bias_mm = settings.discrepancy.evidence_static_bias_mm;
    configured.fixed_pattern_sigma_mm = settings.discrepancy.evidence_fixed_pattern_sigma_mm;
    configured.silhouette_band_px = settings.discrepancy.evidence_silhouette_band_px;
    configured.silhouette_bias_mm = settings.discrepancy.evidence_silhouette_bias_mm;
    configured.silhouette_bias_by_link_mm = settings.discrepancy.evidence_silhouette_bias_by_link_mm;
    configured.silhouette_band_step_mm = settings.discrepancy.evidence_silhouette_band_step_mm;
    result->configured = run_evidence(frames, settings, tree, configured);
  }
}

// Usable only when the tuned model makes the recording look nominal: why
// it does not; empty when it does.
std::string not_nominal_error(const TuneOptions& options, const TuneResult& result) {
  const std::string& log_path = result.log_path;
  if (result.tuned.mismatch_fraction() > options.max_mismatch_fraction) {
    return log_path + ": not nominal: " + fixed(100 * result.tuned.mismatch_fraction(), 2) +
           " % of the compared pixels mismatch even with the fitted noise (allowed " +
           fixed(100 * options.max_mismatch_fraction, 2) +
           " %): an object, a fault or a model that does not fit the scene";
  }
  if (result.tuned.frames_crossed > 0) {
    return log_path + ": not nominal: a sequential test crossed h = " + fixed(result.threshold_h, 2) +
           " with the fitted noise, " + result.tuned.first_crossing;
  }
  if (result.tuned.max_cusum >= result.warning_level) {
    return log_path + ": not nominal: a sequential test reached its warning level with the largest static " +
           "allowance: " + result.allowance_raised;
  }
  for (const ParameterScores& p : result.tuned.parameters) {
    if (p.scores >= options.min_scores && p.frame_to_frame_variance > options.max_frame_to_frame_variance) {
      return log_path + ": the fitted noise does not make the scores N(0, 1): " + p.name +
             "'s frame-to-frame var(t) is " + fixed(p.frame_to_frame_variance, 2) + " (allowed " +
             fixed(options.max_frame_to_frame_variance, 2) +
             "): spatially correlated noise (pixels_per_sample) or a bias that changes every frame";
    }
  }
  return "";
}

}  // namespace

namespace {

// The passes on rendered frames (the recording's checks passed).
void tune_frames(const TuneSettings& settings, const TuneOptions& options, std::vector<RenderedPair>* frames,
                 TuneResult* result) {
  result->error = correct_frames(settings, options, frames, result);
  if (!result->error.empty()) return;
  result->fit = fit_noise(*frames, settings, options);
  if (!result->fit.ok) {
    result->error = result->log_path + ": cannot fit the noise: " + result->fit.error;
    return;
  }
  choose_pixels_per_sample(measure_correlation(*frames, settings, result->fit), settings, options, result);
  result->static_error = measure_static_error(*frames, settings, options);
  run_sequential_tests(*frames, settings, options, result);
  result->error = not_nominal_error(options, *result);
  result->usable = result->error.empty();
}

}  // namespace

TuneResult tune_recording(const TuneSettings& settings, const std::string& log_path,
                          const TuneOptions& options) {
  TuneResult result;
  result.log_path = log_path;
  lcm::LogFile log(log_path, "r");
  if (!log.good()) {
    result.error = log_path + ": cannot open as an LCM log";
    return result;
  }
  std::vector<RenderedPair> frames = RecordingRenderer(settings, options, &result).read(&log);
  result.error = recording_error(settings, options, result);
  if (!result.error.empty()) return result;
  tune_frames(settings, options, &frames, &result);
  return result;
}

TuneResult tune_rendered_frames(const TuneSettings& settings, std::vector<RenderedPair> frames,
                                const std::string& source, const TuneOptions& options) {
  TuneResult result;
  result.log_path = source;
  result.depth_frames = result.used_frames = static_cast<int>(frames.size());
  if (result.used_frames < options.min_frames) {
    result.error = source + ": too few frames to tune on: " + std::to_string(result.used_frames) + "; need " +
                   std::to_string(options.min_frames);
    return result;
  }
  tune_frames(settings, options, &frames, &result);
  return result;
}

// The report's lines on the static error: the smooth part, the fixed
// pattern and the near side of steps.
void describe_static_error(const TuneResult& r, const TuneSettings& settings, std::ostringstream& out) {
  const StaticError& e = r.static_error;
  out << "static error (the same in every frame): smooth part within " << fixed(e.smooth_bound_mm, 1)
      << " mm (largest at " << fixed(e.smooth_depth_m, 2)
      << " m rendered depth: the bin's median I_dis + 2 standard errors), "
      << "fixed pattern sigma " << fixed(e.fixed_pattern_sigma_mm, 1) << " mm over " << e.pattern_pixels
      << " environment pixels (config: static_bias_mm " << settings.discrepancy.evidence_static_bias_mm
      << ", fixed_pattern_sigma_mm " << settings.discrepancy.evidence_fixed_pattern_sigma_mm << ")\n";
  const NearStepError& steps = e.near_steps;
  out << "near rendered steps over " << fixed(steps.band_step_mm, 0)
      << " mm, the arm's pixels' mean I_dis less the smooth part by distance, the largest of a link (px: mm, "
         "samples):";
  for (size_t k = 0; k < steps.ring_samples.size(); ++k)
    out << " " << k + 1 << ": " << fixed(steps.ring_mean_mm[k], 1) << " (" << steps.ring_samples[k] << ")";
  out << "; allowance beyond the smooth one (a link's larger of its rings' bounds and its largest "
         "one-second mean, of silhouettes and of its concave corners each) "
      << fixed(steps.bias_mm, 1) << " mm within " << steps.band_px << " px"
      << (steps.link.empty() ? "" : " (set by " + steps.link + ")") << " (silhouettes "
      << steps.silhouette_band_px << " px; corners " << steps.corner_band_px << " px, up to "
      << fixed(steps.corner_bias_mm, 1) << " mm)";
  if (!steps.bias_by_link_mm.empty()) {
    out << "; by link:";
    for (const auto& [link, bias_mm] : steps.bias_by_link_mm) out << " " << link << " " << fixed(bias_mm, 1);
  }
  out << "\n";
}

std::string tune_report(const TuneResult& r, const TuneSettings& settings) {
  std::ostringstream out;
  out << "recording: " << r.log_path << "\n"
      << "  " << r.depth_frames << " frames of camera '" << settings.renderer.camera.id << "' over "
      << fixed(r.seconds, 1) << " s (" << fixed(r.measured_rate_hz, 1) << " Hz measured, camera.rate_hz "
      << settings.renderer.camera.rate_hz << "), " << r.used_frames << " rendered, " << r.unusable_frames
      << " unusable" << (r.unusable_frames > 0 ? " (" + r.first_unusable_reason + ")" : "") << "; "
      << r.joint_states << " joint states, most moving joint " << r.most_moving_joint << " over "
      << fixed(r.largest_motion, 3) << " rad (m)\n";
  if (r.frames_left_out > 0) {
    out << "  note: " << r.frames_left_out << " later frames of the recording were left out (after the first "
        << r.depth_frames << ")\n";
  }
  if (r.measured_rate_hz > 0 && settings.renderer.camera.rate_hz > 0 &&
      std::abs(r.measured_rate_hz / settings.renderer.camera.rate_hz - 1) > 0.1) {
    out << "  note: the frames came at " << fixed(r.measured_rate_hz, 1)
        << " Hz, not camera.rate_hz; h is computed from camera.rate_hz\n";
  }
  if (r.fit.bins.empty()) return out.str();
  const NoiseFit& f = r.fit;
  out << "noise fit: sigma(d) = " << fixed(f.sigma_at_0m_mm, 2) << " + " << fixed(f.sigma_per_m2_mm, 3)
      << " d^2 mm (config: " << settings.discrepancy.noise_sigma_at_0m_mm << " + "
      << settings.discrepancy.noise_sigma_per_m2_mm << " d^2), on " << f.samples << " pixels in "
      << f.bins.size() << " depth bins " << fixed(f.min_depth_m, 2) << ".." << fixed(f.max_depth_m, 2)
      << " m; bins holding 1 % of them within " << fixed(100 * f.worst_bin_ratio_error, 1)
      << " % of the model\n"
      << "  method: per " << fixed(f.bin_m, 2) << " m depth bin the median of I_dis (a bias) removed, "
      << "sigma = 1.4826 MAD; a, b by least squares of sigma on d^2 weighted n / sigma^2\n"
      << "  depth_m   pixels  median_mm  sigma_mm  model_mm\n";
  for (const DepthBin& b : f.bins) {
    out << "  " << std::setw(7) << fixed(b.depth_m, 2) << std::setw(9) << b.samples << std::setw(11)
        << fixed(b.median_mm, 2) << std::setw(10) << fixed(b.sigma_mm, 2) << std::setw(10)
        << fixed(f.sigma_mm(b.depth_m), 2) << "\n";
  }
  if (r.tuned.parameters.empty() && r.tuned.pixels == 0) return out.str();
  out << "spatial correlation of neighbouring residuals (frame-to-frame differences): rho_u(1) "
      << fixed(r.rho_u1, 3) << ", rho_v(1) " << fixed(r.rho_v1, 3) << " -> pixels_per_sample "
      << fixed(r.measured_pixels_per_sample, 2) << " (config "
      << settings.discrepancy.evidence_pixels_per_sample
      << (r.pixels_per_sample_changed ? ", replaced" : ", kept") << ")\n";
  if (r.profile_fit.pose.checked) {
    const ProfileFit& p = r.profile_fit;
    out << "the pose against the depth error (" << p.pose.pixels << " static pixels, chi^2/dof "
        << fixed(p.pose.chi2_per_dof, 2) << "): t " << fixed(100 * p.pose.correction[0], 2) << ", "
        << fixed(100 * p.pose.correction[1], 2) << ", " << fixed(100 * p.pose.correction[2], 2) << " cm (+- "
        << fixed(100 * p.pose.sigma[0], 2) << ", " << fixed(100 * p.pose.sigma[1], 2) << ", "
        << fixed(100 * p.pose.sigma[2], 2) << "), r " << fixed(p.pose.correction[3] * 180 / M_PI, 3) << ", "
        << fixed(p.pose.correction[4] * 180 / M_PI, 3) << ", " << fixed(p.pose.correction[5] * 180 / M_PI, 3)
        << " deg (+- " << fixed(p.pose.sigma[3] * 180 / M_PI, 3) << ", "
        << fixed(p.pose.sigma[4] * 180 / M_PI, 3) << ", " << fixed(p.pose.sigma[5] * 180 / M_PI, 3) << ")\n";
  }
  if (r.has_profile) {
    const ProfileFit& p = r.profile_fit;
    out << "camera profile learned: distance correction " << fixed(p.smallest_correction_mm, 1) << ".."
        << fixed(p.largest_correction_mm, 1) << " mm over " << fixed(p.first_m, 2) << ".."
        << fixed(p.last_m, 2) << " m radial (" << p.measured_bins << " bins of "
        << fixed(p.profile.distance_bin_m, 2) << " m), per-pixel offsets on " << p.mapped_pixels
        << " pixels (sigma " << fixed(p.pixel_sigma_mm, 1) << " mm), " << p.outlier_pixels
        << " pixels left out (beyond the tolerance in over "
        << fixed(100 * ProfileFitOptions{}.max_outlier_fraction, 0) << " % of their frames)\n"
        << "  the figures below are on the recording it was learned from: check it on a second recording "
        << "(name it in discrepancy.camera_profile, run tofguard-tune on that recording, deploy its lines)\n";
  } else if (!r.profile_applied.empty()) {
    const ProfileCoverage& c = r.profile_coverage;
    out << "camera profile applied: " << r.profile_applied << "; its distance correction covers "
        << fixed(c.first_m, 2) << ".." << fixed(c.last_m, 2) << " m radial, "
        << fixed(100 * c.outside_share(), 2)
        << " % of the arm's compared pixels more than a bin outside it (at most "
        << fixed(100 * kMaxShareOutsideProfile, 1) << " %)\n";
  }
  describe_static_error(r, settings, out);
  if (!r.allowance_raised.empty()) {
    out << "static allowance raised from " << fixed(r.measured_static_bias_mm, 1) << " mm to "
        << fixed(r.tuned.static_bias_mm, 1) << " mm: " << r.allowance_raised << "\n";
  }
  auto describe = [&](const std::string& label, const EvidenceRun& run) {
    out << label << ": sigma(d) = " << fixed(run.sigma_at_0m_mm, 2) << " + " << fixed(run.sigma_per_m2_mm, 3)
        << " d^2, pixels_per_sample " << run.pixels_per_sample << ", static error allowed "
        << fixed(run.static_bias_mm, 1) << " mm + fixed pattern " << fixed(run.fixed_pattern_sigma_mm, 1)
        << " mm + " << fixed(run.silhouette_bias_mm, 1) << " mm within " << run.silhouette_band_px
        << " px of a step over "
        << fixed(discrepancy::silhouette_band_step_or_jump_mm(run.silhouette_band_step_mm,
                                                              settings.discrepancy.silhouette_jump_mm),
                 0)
        << " mm\n"
        << "  false-mismatch rate per pixel at |I_dis| > " << settings.discrepancy.tolerance_sigmas
        << " sigma + " << settings.discrepancy.model_tolerance_mm << " mm: " << run.mismatches << " of "
        << run.pixels << " (" << std::setprecision(3) << run.mismatch_fraction() << ")\n"
        << "  largest CUSUM " << fixed(run.max_cusum, 2) << " (" << run.max_cusum_hypothesis << ") against h "
        << fixed(r.threshold_h, 2) << " (" << r.hypotheses << " hypotheses, warning at "
        << fixed(r.warning_level, 2) << "); frames at h: " << run.frames_crossed << "\n"
        << "  parameter     scores   var(t)  frame-to-frame  max|t|  max CUSUM\n";
    for (const ParameterScores& p : run.parameters) {
      out << "  " << std::left << std::setw(12) << p.name << std::right << std::setw(8) << p.scores
          << std::setw(9) << fixed(p.variance, 2) << std::setw(16) << fixed(p.frame_to_frame_variance, 2)
          << std::setw(8) << fixed(p.max_abs_t, 2) << std::setw(11) << fixed(p.max_cusum, 2) << "\n";
    }
  };
  describe("with the fitted noise", r.tuned);
  if (r.has_config_run) describe("with the config's noise (before tuning)", r.configured);
  return out.str();
}

std::string tuned_config_lines(const TuneResult& r, const std::string& date) {
  const NoiseFit& f = r.fit;
  std::ostringstream out;
  out << "# tofguard-tune " << date << " on " << r.log_path << ": " << r.used_frames << " frames ("
      << fixed(r.seconds, 1) << " s), " << f.samples << " pixels off silhouettes, depth "
      << fixed(f.min_depth_m, 2) << ".." << fixed(f.max_depth_m, 2) << " m.\n"
      << "# Paste under `discrepancy:`, replacing the lines of the same keys.\n"
      << "  # Fitted: per 0.1 m depth bin 1.4826 MAD of I_dis about the bin's median, least squares\n"
      << "  # in d^2 (bins holding 1 % of the pixels within " << fixed(100 * f.worst_bin_ratio_error, 1)
      << " % of it). With it on this\n"
      << "  # recording: per-pixel false-mismatch rate " << std::setprecision(2)
      << r.tuned.mismatch_fraction() << ", largest frame-to-frame var(t) ";
  double worst = 0;
  std::string worst_name;
  for (const ParameterScores& p : r.tuned.parameters) {
    if (p.frame_to_frame_variance > worst) {
      worst = p.frame_to_frame_variance;
      worst_name = p.name;
    }
  }
  out << fixed(worst, 2) << " (" << worst_name << "),\n"
      << "  # largest CUSUM " << fixed(r.tuned.max_cusum, 1) << " of h " << fixed(r.threshold_h, 1) << ".\n"
      << "  noise: {sigma_at_0m_mm: " << fixed(f.sigma_at_0m_mm, 2)
      << ", sigma_per_m2_mm: " << fixed(f.sigma_per_m2_mm, 3) << "}\n";
  out << "  # under `evidence:`.\n";
  if (r.pixels_per_sample_changed) {
    out << "    # Measured from the residuals' correlation between neighbours\n"
        << "    # (rho_u(1) " << fixed(r.rho_u1, 3) << ", rho_v(1) " << fixed(r.rho_v1, 3)
        << "), same pixels.\n"
        << "    pixels_per_sample: " << r.pixels_per_sample << "\n";
  } else {
    out << "    # pixels_per_sample: the config's " << r.pixels_per_sample << " stands (measured "
        << fixed(r.measured_pixels_per_sample, 2) << "; rho_u(1) " << fixed(r.rho_u1, 3) << ", rho_v(1) "
        << fixed(r.rho_v1, 3) << ").\n";
  }
  const StaticError& e = r.static_error;
  out << "    # The static error on this recording (docs/safety-chain.md, \"Static error: the\n"
      << "    # composite null\"): the depth bins' largest median I_dis + 2 standard errors ("
      << fixed(e.smooth_depth_m, 2) << " m),\n"
      << "    # and the fixed pattern over " << e.pattern_pixels << " environment pixels; rounded up.\n";
  if (!r.allowance_raised.empty()) {
    out << "    # Raised from " << fixed(r.measured_static_bias_mm, 1)
        << " mm: the smallest that holds every test below its warning level here\n"
        << "    # (the error on the arm's own pixels): " << r.allowance_raised << ".\n";
  }
  out << "    static_bias_mm: " << fixed(r.tuned.static_bias_mm, 1) << "\n"
      << "    fixed_pattern_sigma_mm: " << fixed(r.tuned.fixed_pattern_sigma_mm, 1) << "\n";
  if (r.tuned.silhouette_band_px > 0) {
    out << "    # The arm's pixels within band_px of a surface farther by step_mm read this much\n"
        << "    # more (multipath), beyond static_bias_mm: each measured link's rings' largest\n"
        << "    # |mean| + 2 standard errors or its largest one-second mean, whichever is larger,\n"
        << "    # beside its silhouettes and its concave corners each, the larger of the two;\n"
        << "    # by_link: each measured link's own, bias_mm the largest (other links, the scene).\n"
        << "    silhouette_allowance: {band_px: " << r.tuned.silhouette_band_px
        << ", step_mm: " << fixed(r.tuned.silhouette_band_step_mm, 0)
        << ", bias_mm: " << fixed(r.tuned.silhouette_bias_mm, 1);
    if (!r.tuned.silhouette_bias_by_link_mm.empty()) {
      out << ", by_link: {";
      const char* separator = "";
      for (const auto& [link, bias_mm] : r.tuned.silhouette_bias_by_link_mm) {
        out << separator << link << ": " << fixed(bias_mm, 1);
        separator = ", ";
      }
      out << "}";
    }
    out << "}\n";
  }
  return out.str();
}

}  // namespace tofguard::tune
