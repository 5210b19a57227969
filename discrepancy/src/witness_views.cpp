#include "tofguard/discrepancy/witness_views.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>

#include "tofguard/discrepancy/discrepancy_image.hpp"

namespace tofguard::discrepancy {

Eigen::Isometry3d world_from_optical(const link_labels_t& labels) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) pose.matrix()(r, c) = labels.world_from_optical[4 * r + c];
  }
  return pose;
}

HiddenVolumeOptions hidden_volume_options(double detection_capability_m, double approach_speed_m_s) {
  HiddenVolumeOptions options;
  options.step_m = detection_capability_m / 4;
  options.layer_m = detection_capability_m / 2;
  options.approach_speed_m_s = approach_speed_m_s;
  return options;
}

namespace {

// The depth (mm; <= 0: no return) `w` measured at the pixel a point of
// its optical frame (m) projects to; nullopt at or behind its optical
// plane or outside its image.
std::optional<int16_t> witness_depth_mm(const WitnessView& w, const Eigen::Vector3d& p) {
  if (!(p.z() > 0)) return std::nullopt;
  const depth_image_t& d = w.depth;
  const long u = std::lround(d.fx * p.x() / p.z() + d.cx);
  const long v = std::lround(d.fy * p.y() / p.z() + d.cy);
  if (u < 0 || v < 0 || u >= d.width || v >= d.height) return std::nullopt;
  return d.depth_mm[static_cast<size_t>(v * d.width + u)];
}

// witness_saw for a point already in `w`'s optical frame (m).
bool witness_saw_optical(const WitnessView& w, const Eigen::Vector3d& p, const Tolerance& tolerance) {
  const std::optional<int16_t> depth_mm = witness_depth_mm(w, p);
  if (!depth_mm) return false;
  const int16_t seen_mm = *depth_mm;
  // No return: nothing along the ray that returned enough light to be
  // measured, whatever lies there is as unseen as it would be to the
  // judged camera's own rules (a pixel without a return shows no object).
  if (seen_mm <= 0) return true;
  const double point_mm = 1000.0 * p.z();
  return seen_mm >= point_mm - tolerance.at(point_mm);
}

// hidden_distance_m's lower bounds between computed distances: within this
// share of the last one computed.
constexpr double kEstimatedShare = 1.0 / 4;

// A hidden ray's points in one witness's optical frame: start + k * step.
struct RayInWitness {
  const WitnessView* witness;
  Eigen::Vector3d start;
  Eigen::Vector3d step;
};

}  // namespace

bool witness_saw(const WitnessView& w, const Eigen::Vector3d& point_world_m, const Tolerance& tolerance) {
  return witness_saw_optical(w, w.optical_from_world * point_world_m, tolerance);
}

double hidden_distance_m(const Eigen::Vector3d& surface_m, const Eigen::Vector3d& arm_m,
                         const Eigen::Isometry3d& world_from_optical,
                         const std::vector<WitnessView>& witnesses, const ArmDistance& arm,
                         const Tolerance& tolerance, const HiddenVolumeOptions& options, double up_to_m) {
  if (witnesses.empty()) return 0.0;
  const Eigen::Vector3d along = surface_m - arm_m;
  const int steps = std::max(1, static_cast<int>(std::ceil(along.norm() / options.step_m)));
  const Eigen::Vector3d step = along / steps;
  const double step_m = step.norm();
  int64_t oldest_us = 0;
  std::vector<RayInWitness> rays;
  rays.reserve(witnesses.size());
  for (const WitnessView& w : witnesses) {
    oldest_us = std::max(oldest_us, std::abs(w.offset_us));
    const Eigen::Isometry3d witness_from_camera = w.optical_from_world * world_from_optical;
    rays.push_back({&w, witness_from_camera * arm_m, witness_from_camera.linear() * step});
  }
  double nearest_m = std::numeric_limits<double>::infinity();
  // The distance to the cover changes by at most as much as the point
  // moves: an unseen point within kEstimatedShare of the last computed
  // distance of it is taken at that distance less how far it is from it (a
  // lower bound, at least 3/4 of the computed one), so that far from the
  // arm few distances are computed and near it every one.
  int computed_k = -1;
  double computed_m = 0;
  // From the arm's surface (k = 0) to the occluding surface (k = steps).
  for (int k = 0; k <= steps; ++k) {
    const bool seen = std::any_of(rays.begin(), rays.end(), [&](const RayInWitness& r) {
      return witness_saw_optical(*r.witness, r.start + static_cast<double>(k) * r.step, tolerance);
    });
    if (seen) continue;
    // A lower bound from the last computed distance; a point that cannot
    // be nearer than one found already changes nothing.
    const double bound_m = computed_k < 0 ? 0.0 : computed_m - (k - computed_k) * step_m;
    if (bound_m >= nearest_m) continue;
    double distance_m = bound_m;
    if (computed_k < 0 || bound_m < (1 - kEstimatedShare) * computed_m || bound_m < options.layer_m) {
      // Beyond up_to_m the search gives some value >= it: up_to_m, never
      // more than the truth. (Not searched only up to nearest_m: the bounds
      // that stand in for later points must rest on a full distance.)
      distance_m = std::min(arm.distance_m(arm_m + static_cast<double>(k) * step, up_to_m), up_to_m);
      computed_k = k;
      computed_m = distance_m;
    }
    if (distance_m < options.layer_m) continue;
    nearest_m = std::min(nearest_m, distance_m);
  }
  if (!std::isfinite(nearest_m)) return nearest_m;
  const double approach_m = options.approach_speed_m_s * 1e-6 * static_cast<double>(oldest_us);
  return std::max(0.0, nearest_m - approach_m);
}

Registration registration(const depth_image_t& camera, const link_labels_t& labels,
                          const uint8_t* pixel_class, const Eigen::Isometry3d& world_from_optical,
                          const std::vector<WitnessView>& witnesses, const Tolerance& tolerance) {
  constexpr int kStride = 4;
  constexpr uint8_t kMatch = 0;  // discrepancy_t::PIXEL_MATCH
  std::vector<double> differences_mm;
  int32_t mismatching = 0;
  for (const WitnessView& w : witnesses) {
    const Eigen::Isometry3d witness_from_camera = w.optical_from_world * world_from_optical;
    for (int v = 0; v < camera.height; v += kStride) {
      for (int u = 0; u < camera.width; u += kStride) {
        const int i = v * camera.width + u;
        const int16_t label = labels.label[static_cast<size_t>(i)];
        if (pixel_class[i] != kMatch || label < link_labels_t::ENVIRONMENT_FIRST ||
            label >= link_labels_t::OCCUPANT_FIRST || camera.depth_mm[static_cast<size_t>(i)] <= 0)
          continue;
        const Eigen::Vector3d p =
            witness_from_camera * optical_point_m(camera, i, 1e-3 * camera.depth_mm[static_cast<size_t>(i)]);
        const std::optional<int16_t> seen_mm = witness_depth_mm(w, p);
        if (!seen_mm || *seen_mm <= 0) continue;
        const double point_mm = 1000.0 * p.z();
        const double allowed_mm = tolerance.at(point_mm);
        const double difference_mm = *seen_mm - point_mm;
        if (std::abs(difference_mm) > 3 * allowed_mm) continue;
        differences_mm.push_back(difference_mm);
        if (std::abs(difference_mm) > allowed_mm) ++mismatching;
      }
    }
  }
  Registration r;
  r.points = static_cast<int32_t>(differences_mm.size());
  if (r.points == 0) return r;
  const auto middle = differences_mm.begin() + static_cast<std::ptrdiff_t>(differences_mm.size() / 2);
  std::nth_element(differences_mm.begin(), middle, differences_mm.end());
  r.median_mm = *middle;
  r.mismatch_fraction = static_cast<double>(mismatching) / r.points;
  return r;
}

}  // namespace tofguard::discrepancy
