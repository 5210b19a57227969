#include "tofguard/tune/camera_profile_fit.hpp"

#include <algorithm>
#include <cmath>

#include "tofguard/common/depth_frame.hpp"
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
std::vector<double> z_per_radial(const depth_image_t& frame) {
  std::vector<double> f(static_cast<size_t>(frame.width) * frame.height);
  for (int v = 0; v < frame.height; ++v) {
    for (int u = 0; u < frame.width; ++u) {
      const double x = (u - frame.cx) / frame.fx;
      const double y = (v - frame.cy) / frame.fy;
      f[static_cast<size_t>(v) * frame.width + u] = 1.0 / std::sqrt(1.0 + x * x + y * y);
    }
  }
  return f;
}

bool same_camera(const depth_image_t& a, const depth_image_t& b) {
  return a.camera_id == b.camera_id && a.width == b.width && a.height == b.height && a.fx == b.fx &&
         a.fy == b.fy && a.cx == b.cx && a.cy == b.cy;
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
  // Bin index -> median for the bins with enough samples; the others
  // between them interpolated.
  std::vector<int> index;
  std::vector<double> median;
  for (const DepthBin& b : measured.bins) {
    index.push_back(static_cast<int>(std::floor(b.depth_m / options.bin_m)));
    median.push_back(b.median_mm);
  }
  CameraProfile& p = fit->profile;
  p.distance_bin_m = options.bin_m;
  p.distance_first_m = (index.front() + 0.5) * options.bin_m;
  p.distance_correction_mm.assign(static_cast<size_t>(index.back() - index.front() + 1), 0.0);
  for (size_t k = 0; k + 1 < index.size(); ++k) {
    for (int b = index[k]; b <= index[k + 1]; ++b) {
      const double w = static_cast<double>(b - index[k]) / std::max(1, index[k + 1] - index[k]);
      p.distance_correction_mm[static_cast<size_t>(b - index.front())] =
          (1 - w) * median[k] + w * median[k + 1];
    }
  }
  fit->measured_bins = static_cast<int>(index.size());
  fit->first_m = p.distance_first_m;
  fit->last_m = (index.back() + 0.5) * options.bin_m;
  fit->smallest_correction_mm = *std::min_element(median.begin(), median.end());
  fit->largest_correction_mm = *std::max_element(median.begin(), median.end());
  return true;
}

// Step 2: the per-pixel offsets after the smooth part, into fit->profile.
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
      if (!used[i]) continue;
      const double gen = frame.rendered.depth_mm[i];
      const int t = frame.camera.depth_mm[i];
      const double e = gen - t - f[i] * p.distance_correction_at(gen / f[i] * 1e-3);
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
}

}  // namespace

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
  const std::vector<double> f = z_per_radial(first);
  if (!fit_smooth_part(frames, f, silhouette_jump_mm, options, &fit)) return fit;
  fit_pixel_part(frames, f, tolerance, silhouette_jump_mm, options, &fit);
  fit.ok = true;
  return fit;
}

}  // namespace tofguard::tune
