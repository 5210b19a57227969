#include "tofguard/tune/camera_profile_fit.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "tofguard/common/depth_frame.hpp"
#include "tofguard/discrepancy/evidence.hpp"
#include "tofguard/tune/noise_fit.hpp"

namespace tofguard::tune {

std::vector<uint8_t> noise_pixels(const RenderedPair& frame, double silhouette_jump_mm) {
  const std::vector<uint8_t> silhouette = discrepancy::silhouette_mask(frame.rendered, silhouette_jump_mm);
  const size_t n = frame.camera.depth_mm.size();
  std::vector<uint8_t> used(n, 0);
  for (size_t i = 0; i < n; ++i) {
    const bool on_link =
        link_of_label(frame.labels.label[i], frame.labels.num_robot_links, frame.labels.num_links) >= 0;
    used[i] = frame.camera.depth_mm[i] > 0 && frame.rendered.depth_mm[i] > 0 && !silhouette[i] && on_link;
  }
  return used;
}

namespace {

// Z per unit of radial distance of each pixel of `frame`'s camera.
std::vector<double> z_per_radial_image(const depth_image_t& frame) {
  std::vector<double> f(static_cast<size_t>(frame.width) * frame.height);
  for (int v = 0; v < frame.height; ++v) {
    for (int u = 0; u < frame.width; ++u) {
      f[static_cast<size_t>(v) * frame.width + u] =
          z_per_radial(frame.fx, frame.fy, frame.cx, frame.cy, u, v);
    }
  }
  return f;
}

bool same_camera(const depth_image_t& a, const depth_image_t& b) {
  return a.camera_id == b.camera_id && a.width == b.width && a.height == b.height && a.fx == b.fx &&
         a.fy == b.fy && a.cx == b.cx && a.cy == b.cy;
}

// Step 0's sums: the normal equations of I_dis_i = -J_i p + f_i c(r_i) over
// the static pixels, c piecewise linear on knots first_m + k step_m.
struct PoseDepthSums {
  PoseDepthSums(double first, double step, int knots)
      : first_m(first),
        step_m(step),
        normal(Eigen::MatrixXd::Zero(6 + knots, 6 + knots)),
        right(Eigen::VectorXd::Zero(6 + knots)),
        row(Eigen::VectorXd::Zero(6 + knots)) {}
  void add(const double camera_jacobian[6], double f, double r_m, double dis_mm, double weight) {
    row.setZero();
    for (int a = 0; a < 6; ++a) row[a] = -camera_jacobian[a];
    const int knots = static_cast<int>(row.size()) - 6;
    const double k = std::clamp((r_m - first_m) / step_m, 0.0, knots - 1.0);
    const int below = std::min(static_cast<int>(k), knots - 2);
    const double w = k - below;
    row[6 + below] = f * (1 - w);
    row[6 + below + 1] = f * w;
    normal.selfadjointView<Eigen::Upper>().rankUpdate(row, weight);
    right += weight * dis_mm * row;
    chi2_zero += weight * dis_mm * dis_mm;
    ++pixels;
  }
  double first_m, step_m;
  Eigen::MatrixXd normal;  // upper triangle
  Eigen::VectorXd right;
  Eigen::VectorXd row;
  double chi2_zero = 0;
  int64_t pixels = 0;
};

// Step 0's pixels: static (the camera Jacobian applies), compared, and
// within 100 mm (beyond, not the small pose and depth errors the linear
// model is for).
constexpr double kPoseFitMaxDisMm = 100;

PoseDepthSums sum_pose_against_depth(const std::vector<RenderedPair>& frames, const std::vector<double>& f,
                                     const discrepancy::Tolerance& tolerance, double silhouette_jump_mm,
                                     const ProfileFitOptions& options, double first_m, int knots) {
  PoseDepthSums sums(first_m, options.pose_knot_m, knots);
  for (size_t n = 0; n < frames.size(); n += static_cast<size_t>(std::max(options.pose_frame_stride, 1))) {
    const RenderedPair& frame = frames[n];
    const discrepancy::EvidenceJacobian jacobian(frame.rendered, frame.labels, silhouette_jump_mm);
    if (!jacobian.available()) continue;
    const std::vector<uint8_t> used = noise_pixels(frame, silhouette_jump_mm);
    std::vector<double> joints(static_cast<size_t>(std::max(jacobian.num_joints(), 1)));
    for (size_t i = 0; i < used.size(); ++i) {
      double camera[6];
      bool moved = false;
      int link = -1;
      if (!used[i] || !jacobian.at(static_cast<int>(i), camera, joints.data(), &moved, &link) || moved)
        continue;
      const int t = frame.camera.depth_mm[i];
      const double gen = frame.rendered.depth_mm[i];
      const double dis = gen - t;
      if (std::abs(dis) > kPoseFitMaxDisMm) continue;
      const double sigma = tolerance.noise.sigma_mm(t);
      sums.add(camera, f[i], gen / f[i] * 1e-3, dis, 1.0 / (sigma * sigma));
    }
  }
  return sums;
}

const char* const kPoseNames[6] = {
    "t_x (optical x)", "t_y (optical y)", "t_z (along the optical axis)", "r_x", "r_y", "r_z"};

std::string pose_figure(int a, double value) {
  std::ostringstream s;
  s.precision(a < 3 ? 2 : 3);
  s << std::fixed << (a < 3 ? value * 100 : value * 180 / M_PI) << (a < 3 ? " cm" : " deg");
  return s.str();
}

// Step 0's verdict: why the pose and the depth error cannot be learned
// apart (a pose error, or too little to tell), empty when they can.
std::string pose_verdict(const PoseAgainstDepth& pose, const ProfileFitOptions& options) {
  for (int a = 0; a < 6; ++a) {
    const double delta = a < 3 ? options.pose_translation_m : options.pose_rotation_rad;
    if (!(delta > 0)) continue;
    const double p = pose.correction[a], sigma = pose.sigma[a];
    // t_z against a common distance offset: told apart only by the scene's
    // slopes, and the camera's unmodelled static errors (amplitude bias,
    // multipath) shift its fit by up to 1.3 cm on pose-true cameras
    // (docs/camera.md, "Commissioning a camera"): refused from delta on.
    const double limit = a == 2 ? delta : delta / 2;
    if (std::abs(p) > limit && std::abs(p) > 3 * sigma) {
      return "the camera pose is off, not its depth: " + std::string(kPoseNames[a]) + " fitted " +
             pose_figure(a, p) + " +- " + pose_figure(a, sigma) + " (seen minus configured; beyond " +
             pose_figure(a, limit) + ", " + (a == 2 ? "the" : "half the") + " pose test's " +
             pose_figure(a, delta) +
             "): calibrate the extrinsics (tofguard-calibrate-extrinsics) and record again";
    }
    if (3 * sigma > delta / 2) {
      return "cannot tell a pose error from a depth error in " + std::string(kPoseNames[a]) +
             ": 3 sigma of the " + "fit is " + pose_figure(a, 3 * sigma) +
             ", more than half the pose test's " + pose_figure(a, delta) +
             ": record more depth range and surfaces at an angle to the camera";
    }
  }
  return "";
}

// Step 0: the pose against the depth error, into fit->pose; false (with
// the error) when they cannot be learned apart.
bool check_pose_against_depth(const std::vector<RenderedPair>& frames, const std::vector<double>& f,
                              const discrepancy::Tolerance& tolerance, double silhouette_jump_mm,
                              const ProfileFitOptions& options, ProfileFit* fit) {
  if (!(options.pose_translation_m > 0) && !(options.pose_rotation_rad > 0)) return true;
  // The knots over the radial distances the static pixels show.
  double r_min = 1e9, r_max = 0;
  for (const RenderedPair& frame : frames) {
    for (size_t i = 0; i < frame.rendered.depth_mm.size(); ++i) {
      if (frame.rendered.depth_mm[i] <= 0) continue;
      const double r = frame.rendered.depth_mm[i] / f[i] * 1e-3;
      r_min = std::min(r_min, r);
      r_max = std::max(r_max, r);
    }
    break;  // the static scene: the first frame shows its range
  }
  const int knots = std::max(2, static_cast<int>(std::ceil((r_max - r_min) / options.pose_knot_m)) + 1);
  PoseDepthSums sums =
      sum_pose_against_depth(frames, f, tolerance, silhouette_jump_mm, options, r_min, knots);
  const int dimension = 6 + knots;
  if (sums.pixels <= dimension) {
    fit->error = "too few static pixels to tell a pose error from a depth error";
    return false;
  }
  Eigen::MatrixXd normal = sums.normal.selfadjointView<Eigen::Upper>();
  // A knot no pixel reaches: a small ridge keeps it solvable (its c is 0).
  const double ridge = 1e-9 * normal.diagonal().maxCoeff();
  for (int k = 6; k < dimension; ++k) normal(k, k) += ridge;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(normal);
  const Eigen::VectorXd x = ldlt.solve(sums.right);
  const Eigen::MatrixXd covariance = ldlt.solve(Eigen::MatrixXd::Identity(dimension, dimension));
  PoseAgainstDepth& pose = fit->pose;
  pose.checked = true;
  pose.pixels = sums.pixels;
  pose.chi2_per_dof =
      std::max(0.0, sums.chi2_zero - x.dot(sums.right)) / static_cast<double>(sums.pixels - dimension);
  for (int a = 0; a < 6; ++a) {
    pose.correction[a] = x[a];
    pose.sigma[a] = std::sqrt(std::max(0.0, covariance(a, a)) * std::max(pose.chi2_per_dof, 1.0));
  }
  fit->error = pose_verdict(pose, options);
  return fit->error.empty();
}

// Step 1: the smooth correction per radial bin, into fit->profile.
bool fit_smooth_part(const std::vector<RenderedPair>& frames, const std::vector<double>& f,
                     double silhouette_jump_mm, const ProfileFitOptions& options, ProfileFit* fit) {
  NoiseFitOptions bins;
  bins.bin_m = options.bin_m;
  bins.min_bin_samples = options.min_bin_samples;
  NoiseSamples samples(bins);
  for (const RenderedPair& frame : frames) {
    const std::vector<uint8_t> used = noise_pixels(frame, silhouette_jump_mm);
    for (size_t i = 0; i < used.size(); ++i) {
      if (!used[i]) continue;
      const double gen = frame.rendered.depth_mm[i];
      samples.add(static_cast<int>(std::lround(gen / f[i])),
                  static_cast<int>(std::lround((gen - frame.camera.depth_mm[i]) / f[i])));
    }
  }
  const NoiseFit measured = samples.fit();
  if (measured.bins.size() < 2) {
    fit->error = "too few pixels to learn the distance correction: " + std::to_string(measured.bins.size()) +
                 " radial bins of " + std::to_string(options.bin_m) + " m with " +
                 std::to_string(options.min_bin_samples) + " samples; need 2";
    return false;
  }
  // Each measured bin's median belongs at its samples' mean distance, not
  // at the bin's centre: within a bin of 5 cm a wiggle of 25 mm over 1 m
  // changes by 8 mm, and a bin's samples often crowd at one end (a wall, the
  // table), so the centre's value would be off by millimetres there. The
  // grid (values at bin centres, read linearly between them) spans the
  // points and takes its values off the line through them, the end
  // segments extended to the grid's end centres (less than a bin beyond).
  //
  // And the profile is applied at the distance the camera measures
  // (camera_profile.hpp: r = Z / f of the camera's Z), which differs from
  // the rendered one by the error itself: up to 3 cm, where a wiggle's slope
  // of 0.1 mm per mm makes the correction 3 mm off. So each point sits at the
  // measured distance of its bin's pixels, their rendered mean less the
  // median residual (I_dis / f: rendered minus measured). A wiggle's slope
  // is far below 1 mm per mm, so the points keep their order; one that
  // would not is left out.
  std::vector<double> at_m, median;
  for (const DepthBin& b : measured.bins) {
    const double measured_m = b.depth_m - b.median_mm * 1e-3;
    if (!at_m.empty() && !(measured_m > at_m.back())) continue;
    at_m.push_back(measured_m);
    median.push_back(b.median_mm);
  }
  if (at_m.size() < 2) {
    fit->error = "the distance correction's bins do not keep their order at the measured distances";
    return false;
  }
  const int first_bin = static_cast<int>(std::floor(at_m.front() / options.bin_m - 0.5));
  const int last_bin = static_cast<int>(std::ceil(at_m.back() / options.bin_m - 0.5));
  CameraProfile& p = fit->profile;
  p.distance_bin_m = options.bin_m;
  p.distance_first_m = (first_bin + 0.5) * options.bin_m;
  p.distance_correction_mm.assign(static_cast<size_t>(last_bin - first_bin + 1), 0.0);
  size_t segment = 1;  // the segment between points segment - 1 and segment
  for (int b = first_bin; b <= last_bin; ++b) {
    const double centre_m = (b + 0.5) * options.bin_m;
    while (segment + 1 < at_m.size() && at_m[segment] < centre_m) ++segment;
    const double w = (centre_m - at_m[segment - 1]) / (at_m[segment] - at_m[segment - 1]);
    p.distance_correction_mm[static_cast<size_t>(b - first_bin)] =
        (1 - w) * median[segment - 1] + w * median[segment];
  }
  fit->measured_bins = static_cast<int>(at_m.size());
  fit->first_m = at_m.front();
  fit->last_m = at_m.back();
  fit->smallest_correction_mm = *std::min_element(median.begin(), median.end());
  fit->largest_correction_mm = *std::max_element(median.begin(), median.end());
  return true;
}

// Step 2: the per-pixel offsets after the smooth part, on the pixels of
// surfaces no joint moves, into fit->profile.
void fit_pixel_part(const std::vector<RenderedPair>& frames, const std::vector<double>& f,
                    const discrepancy::Tolerance& tolerance, double silhouette_jump_mm,
                    const ProfileFitOptions& options, ProfileFit* fit) {
  CameraProfile& p = fit->profile;
  const size_t n = f.size();
  std::vector<int32_t> within(n, 0), beyond(n, 0);
  std::vector<double> sum(n, 0.0);
  for (const RenderedPair& frame : frames) {
    const std::vector<uint8_t> used = noise_pixels(frame, silhouette_jump_mm);
    for (size_t i = 0; i < n; ++i) {
      // The pixels of surfaces no joint moves only: a moving link's own
      // multipath and reflectivity move with it (the fixed pattern serves
      // its pixels).
      if (!used[i] || on_moving_link(frame.labels, frame.labels.label[i])) continue;
      const double gen = frame.rendered.depth_mm[i];
      const int t = frame.camera.depth_mm[i];
      // The smooth part as it is applied: at the measured distance.
      const double e = gen - t - f[i] * p.distance_correction_at(t / f[i] * 1e-3);
      if (std::abs(e) > tolerance.at(t)) {
        ++beyond[i];
        continue;
      }
      ++within[i];
      sum[i] += e;
    }
  }
  p.pixel_correction_mm.assign(n, 0.0f);
  double sum_squares = 0;
  for (size_t i = 0; i < n; ++i) {
    const int seen = within[i] + beyond[i];
    if (seen == 0) continue;
    if (beyond[i] > options.max_outlier_fraction * seen) {
      ++fit->outlier_pixels;
      continue;
    }
    if (within[i] < options.min_pixel_frames) continue;
    const double offset = sum[i] / within[i];
    p.pixel_correction_mm[i] = static_cast<float>(offset);
    sum_squares += offset * offset;
    ++fit->mapped_pixels;
  }
  if (fit->mapped_pixels > 0)
    fit->pixel_sigma_mm = std::sqrt(sum_squares / static_cast<double>(fit->mapped_pixels));
  derive_fixed_pattern(&p);
}

}  // namespace

ProfileCoverage profile_coverage(const CameraProfile& profile, const std::vector<RenderedPair>& frames,
                                 double silhouette_jump_mm) {
  ProfileCoverage coverage;
  for (const RenderedPair& frame : frames) {
    if (!profile_mismatch(profile, frame.camera).empty()) continue;
    add_profile_coverage(profile, frame.rendered, frame.labels, noise_pixels(frame, silhouette_jump_mm),
                         &coverage);
  }
  return coverage;
}

ProfileFit fit_camera_profile(const std::vector<RenderedPair>& frames,
                              const discrepancy::Tolerance& tolerance, double silhouette_jump_mm,
                              const ProfileFitOptions& options) {
  ProfileFit fit;
  if (frames.empty()) {
    fit.error = "no frames to learn a camera profile from";
    return fit;
  }
  const depth_image_t& first = frames.front().camera;
  for (const RenderedPair& frame : frames) {
    if (!same_camera(frame.camera, first)) {
      fit.error =
          "the frames come from more than one camera (id, size or intrinsics differ): one profile per camera";
      return fit;
    }
  }
  CameraProfile& p = fit.profile;
  p.camera_id = first.camera_id;
  p.width = first.width;
  p.height = first.height;
  p.fx = first.fx;
  p.fy = first.fy;
  p.cx = first.cx;
  p.cy = first.cy;
  const std::vector<double> f = z_per_radial_image(first);
  if (!check_pose_against_depth(frames, f, tolerance, silhouette_jump_mm, options, &fit)) return fit;
  if (!fit_smooth_part(frames, f, silhouette_jump_mm, options, &fit)) return fit;
  fit_pixel_part(frames, f, tolerance, silhouette_jump_mm, options, &fit);
  fit.ok = true;
  return fit;
}

}  // namespace tofguard::tune
