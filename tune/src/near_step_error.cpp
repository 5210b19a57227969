#include "tofguard/tune/near_step_error.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "tofguard/common/depth_frame.hpp"
#include "tofguard/discrepancy/evidence.hpp"

namespace tofguard::tune {
namespace {

// Count, sum and sum of squares of e.
using Sums = std::array<double, 3>;

// One link's near-step pixels, summed per ring and per second of the
// recording and ring.
struct LinkStepSums {
  std::vector<Sums> by_ring;
  std::vector<std::vector<Sums>> by_second;  // [second][ring]
};

void add(double e, Sums* s) {
  (*s)[0] += 1;
  (*s)[1] += e;
  (*s)[2] += e * e;
}

// Per link, the sums of the near side of silhouettes (rings by the
// distance to a rendered step over the silhouette jump) and of the arm's
// concave corners (pixels with no silhouette within kStepRingsPx, rings by
// the distance to a step over band_step_mm).
struct ClassSums {
  std::map<std::string, LinkStepSums> silhouettes;
  std::map<std::string, LinkStepSums> corners;
};

void add_pixel(double e, size_t second, size_t ring, LinkStepSums* link_sums) {
  constexpr size_t rings = kStepRingsPx;
  link_sums->by_ring.resize(rings, {0.0, 0.0, 0.0});
  if (link_sums->by_second.size() <= second) link_sums->by_second.resize(second + 1);
  link_sums->by_second[second].resize(rings, {0.0, 0.0, 0.0});
  add(e, &link_sums->by_ring[ring]);
  add(e, &link_sums->by_second[second][ring]);
}

ClassSums sum_near_step_error(const std::vector<RenderedPair>& frames, double silhouette_jump_mm,
                              double band_step_mm, double naming_gate_sigmas, const NoiseFit& smooth) {
  ClassSums sums;
  const int64_t first_utime = frames.empty() ? 0 : frames.front().camera.utime;
  for (const RenderedPair& frame : frames) {
    const auto second =
        static_cast<size_t>(std::max<int64_t>(0, frame.camera.utime - first_utime) / 1'000'000);
    const std::vector<uint8_t> used = noise_pixels(frame, silhouette_jump_mm);
    const std::vector<uint8_t> to_silhouette =
        discrepancy::step_distance_px(frame.rendered, kStepRingsPx, silhouette_jump_mm);
    const std::vector<uint8_t> to_corner =
        discrepancy::step_distance_px(frame.rendered, kStepRingsPx, band_step_mm);
    for (size_t i = 0; i < used.size() && i < to_silhouette.size() && i < to_corner.size(); ++i) {
      if (!used[i] || to_corner[i] == 0) continue;
      const int link =
          link_of_label(frame.labels.label[i], frame.labels.num_robot_links, frame.labels.num_links);
      if (link < 0 || link >= frame.labels.num_robot_links) continue;  // the arm's pixels only
      const int gen = frame.rendered.depth_mm[i];
      const double e = gen - frame.camera.depth_mm[i] - smooth.median_mm_at(gen);
      if (std::abs(e) > naming_gate_sigmas * smooth.sigma_mm(gen / 1000.0)) continue;
      const std::string& name = frame.labels.link_name[static_cast<size_t>(link)];
      if (to_silhouette[i] > 0)
        add_pixel(e, second, to_silhouette[i] - 1u, &sums.silhouettes[name]);
      else
        add_pixel(e, second, to_corner[i] - 1u, &sums.corners[name]);
    }
  }
  return sums;
}

// A link's largest |mean e| within `band_px` over any one second with at
// least kMinStepRingSamples pixels there; 0 when none has.
double largest_second_mean_mm(const LinkStepSums& link, int band_px) {
  double largest = 0;
  for (const std::vector<Sums>& second : link.by_second) {
    double n = 0, sum = 0;
    for (size_t k = 0; k < second.size() && k < static_cast<size_t>(band_px); ++k) {
      n += second[k][0];
      sum += second[k][1];
    }
    if (n >= kMinStepRingSamples) largest = std::max(largest, std::abs(sum / n));
  }
  return largest;
}

// One class's measure (NearStepError's fields but band_step_mm).
NearStepError measure_class(const std::map<std::string, LinkStepSums>& sums, double smooth_allowance_mm) {
  NearStepError error;
  error.ring_mean_mm.assign(kStepRingsPx, 0.0);
  error.ring_samples.assign(kStepRingsPx, 0);
  // Each measured link's largest ring bound (|mean| + 2 standard errors).
  std::map<std::string, double> ring_bound_by_link;
  for (const auto& [link, link_sums] : sums) {
    bool measured = false;
    double link_largest_mm = smooth_allowance_mm;
    for (int k = 0; k < kStepRingsPx; ++k) {
      const auto& [n, sum, sum_squares] = link_sums.by_ring[static_cast<size_t>(k)];
      if (n < kMinStepRingSamples) continue;
      measured = true;
      const double mean = sum / n;
      const double variance = std::max(0.0, (sum_squares - n * mean * mean) / (n - 1));
      if (std::abs(mean) > std::abs(error.ring_mean_mm[k])) {
        error.ring_mean_mm[k] = mean;
        error.ring_samples[k] = static_cast<int64_t>(n);
      }
      const double bound = std::abs(mean) + 2 * std::sqrt(variance / n);
      if (bound <= smooth_allowance_mm) continue;
      error.band_px = std::max(error.band_px, k + 1);
      link_largest_mm = std::max(link_largest_mm, bound);
    }
    if (measured) ring_bound_by_link[link] = link_largest_mm;
  }
  if (error.band_px == 0) return error;
  double largest_mm = 0;
  for (const auto& [link, ring_bound_mm] : ring_bound_by_link) {
    const double link_mm = std::max(ring_bound_mm, largest_second_mean_mm(sums.at(link), error.band_px));
    error.bias_by_link_mm[link] = std::max(0.0, link_mm - smooth_allowance_mm);
    if (link_mm > largest_mm) {
      largest_mm = link_mm;
      error.link = link;
    }
  }
  error.bias_mm = std::max(0.0, largest_mm - smooth_allowance_mm);
  return error;
}

}  // namespace

NearStepError measure_near_step_error(const std::vector<RenderedPair>& frames, double silhouette_jump_mm,
                                      double band_step_mm, double naming_gate_sigmas, const NoiseFit& smooth,
                                      double smooth_allowance_mm) {
  const ClassSums sums =
      sum_near_step_error(frames, silhouette_jump_mm, band_step_mm, naming_gate_sigmas, smooth);
  NearStepError error = measure_class(sums.silhouettes, smooth_allowance_mm);
  const NearStepError corners = measure_class(sums.corners, smooth_allowance_mm);
  error.band_step_mm = band_step_mm;
  error.silhouette_band_px = error.band_px;
  error.corner_band_px = corners.band_px;
  error.corner_bias_mm = corners.bias_mm;
  // One band over both: each link takes the larger of its two classes'
  // allowances, so that neither class's pixels dilute the other's.
  error.band_px = std::max(error.band_px, corners.band_px);
  for (const auto& [link, bias_mm] : corners.bias_by_link_mm) {
    double& own = error.bias_by_link_mm[link];
    own = std::max(own, bias_mm);
    if (own > error.bias_mm) {
      error.bias_mm = own;
      error.link = link;
    }
  }
  return error;
}

}  // namespace tofguard::tune
