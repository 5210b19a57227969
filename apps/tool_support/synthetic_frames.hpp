#pragma once
// Synthetic camera / rendered / label frames for the safety-chain tests: a
// floor (environment link "floor") 2 m from the camera and boxes that stand
// for robot links, drawn with a z-buffer (nearer wins). Pixel footprint at
// depth Z is (Z/fx)^2 with fx = fy = 200 px.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "tofguard/depth_image_t.hpp"
#include "tofguard/discrepancy_t.hpp"
#include "tofguard/link_labels_t.hpp"

namespace tofguard::test {

constexpr int kWidth = 176;
constexpr int kHeight = 144;
constexpr double kFocalPx = 200;
constexpr int16_t kFloorMm = 2000;
constexpr int16_t kArmMm = 1500;

// A box in image space: columns u0..u1-1, rows v0..v1-1, at depth_mm,
// with label `label` (0 for something the model does not know).
struct Box {
  int u0, v0, u1, v1;
  int16_t depth_mm;
  int16_t label;
};

struct SyntheticImage {
  std::vector<int16_t> depth_mm;
  std::vector<int16_t> label;
};

// The default arm: base_link (label 1), link1 (2), link2 (3).
inline std::vector<Box> default_arm(int link2_shift_px = 0) {
  return {{40, 100, 60, 140, kArmMm, 1},
          {40, 60, 60, 100, kArmMm, 2},
          {60 + link2_shift_px, 60, 100 + link2_shift_px, 80, kArmMm, 3}};
}

inline SyntheticImage draw(const std::vector<Box>& boxes, int width = kWidth, int height = kHeight) {
  SyntheticImage image;
  image.depth_mm.assign(width * height, kFloorMm);
  image.label.assign(width * height, link_labels_t::ENVIRONMENT_FIRST);
  for (const Box& b : boxes) {
    for (int v = b.v0; v < b.v1; ++v) {
      for (int u = b.u0; u < b.u1; ++u) {
        const int i = v * width + u;
        if (b.depth_mm < image.depth_mm[i]) {
          image.depth_mm[i] = b.depth_mm;
          image.label[i] = b.label;
        }
      }
    }
  }
  return image;
}

inline depth_image_t depth_frame(const std::vector<int16_t>& depth_mm, int64_t seq, int width = kWidth,
                                 int height = kHeight) {
  depth_image_t m;
  m.utime = 1'600'000'000'000'000 + seq * 33'333;  // an old utime, as in a replayed log
  m.seq = seq;
  m.camera_id = "tof-mast";
  m.width = width;
  m.height = height;
  m.fx = kFocalPx;
  m.fy = kFocalPx;
  m.cx = width / 2.0;
  m.cy = height / 2.0;
  m.calibrated = true;
  m.num_pixels = width * height;
  m.depth_mm = depth_mm;
  m.num_amplitude = 0;
  return m;
}

inline link_labels_t labels_frame(const std::vector<int16_t>& label, int64_t seq, int width = kWidth,
                                  int height = kHeight) {
  link_labels_t m{};
  m.utime = 1'600'000'000'000'000 + seq * 33'333;
  m.seq = seq;
  m.camera_id = "tof-mast";
  m.usable = true;
  m.width = width;
  m.height = height;
  m.num_robot_links = 3;
  m.num_links = 4;
  m.link_name = {"base_link", "link1", "link2", "floor"};
  m.num_pixels = width * height;
  m.label = label;
  m.num_joints = 0;
  m.num_axes = 0;
  m.num_link_axes = 0;
  return m;
}

// Gives `labels` the default arm's kinematics as rendered (link_labels_t's
// axes, optical frame, m), so that the evidence stage runs: link1 turns
// about a vertical axis through the base (joint a1), link2 about a
// horizontal one at link1's top (a2); base_link is fixed. The axes sit at
// default_arm()'s boxes for fx = fy = 200 px per 176 columns (any size
// whose focal length scales with its width).
inline void add_default_arm_kinematics(link_labels_t* labels) {
  labels->num_joints = 2;
  labels->joint_name = {"a1", "a2"};
  labels->num_axes = 2;
  labels->axis_joint = {0, 1};
  labels->axis_multiplier = {1, 1};
  labels->axis_prismatic = {false, false};
  labels->axis_origin_m = {{-0.3, 0.3, 1.5}, {-0.3, -0.1, 1.5}};
  labels->axis_direction = {{0, -1, 0}, {0, 0, 1}};
  labels->axis_parent = {-1, 0};
  labels->num_link_axes = 3;
  labels->link_axis = {-1, 0, 1};
}

// Gives `labels` a cover of the model's robot surface (link_labels_t.arm_*):
// one sphere per robot pixel of the model, at the pixel's ray
// back-projected to its depth `model_depth_mm` (optical frame, fx = fy =
// kFocalPx, principal point at the image centre), holding the pixel's
// square patch of the box face (radius: half its diagonal).
inline void add_pixel_cover(link_labels_t* labels, const std::vector<int16_t>& model_depth_mm) {
  const int width = labels->width;
  const double cx = width / 2.0;
  const double cy = labels->height / 2.0;
  labels->arm_sphere_link.clear();
  labels->arm_sphere_center_m.clear();
  labels->arm_sphere_radius_m.clear();
  labels->arm_cover_max_radius_m = 0;
  for (size_t i = 0; i < labels->label.size(); ++i) {
    const int l = labels->label[i];
    if (l < link_labels_t::ROBOT_FIRST || l >= link_labels_t::ROBOT_FIRST + labels->num_robot_links) continue;
    const double z = model_depth_mm[i] * 1e-3;
    // Pixel (u, v) is the ray through (u, v) (OpenCV's convention: integer
    // coordinates are pixel centres).
    const double u = static_cast<double>(i % width);
    const double v = static_cast<double>(i / width);
    const double radius = std::sqrt(2.0) / 2 * z / kFocalPx + 1e-6;
    labels->arm_sphere_link.push_back(static_cast<int16_t>(l - link_labels_t::ROBOT_FIRST));
    labels->arm_sphere_center_m.push_back({static_cast<float>((u - cx) * z / kFocalPx),
                                           static_cast<float>((v - cy) * z / kFocalPx),
                                           static_cast<float>(z)});
    labels->arm_sphere_radius_m.push_back(static_cast<float>(radius));
    labels->arm_cover_max_radius_m = std::max(labels->arm_cover_max_radius_m, radius + 1e-6);
  }
  labels->num_arm_spheres = static_cast<int32_t>(labels->arm_sphere_link.size());
}

// Adds an unexplained nearer surface of `area_m2` at `distance_m` from the
// arm to d's cumulative areas by distance (discrepancy_t.field_*); a frame
// without bins gets sim.yaml's (1 cm up to 2 m). Also counts it in
// near_arm_* when within 0.2 m (sim.yaml's discrepancy.near_arm_m).
inline void place_unexplained_surface(discrepancy_t* d, double distance_m, double area_m2) {
  if (d->num_field_bins == 0) {
    d->field_bin_m = 0.01f;
    d->num_field_bins = 200;
    d->unexplained_area_within_m2.assign(200, 0.0f);
  }
  for (int k = 0; k < d->num_field_bins; ++k) {
    if ((k + 1) * static_cast<double>(d->field_bin_m) >= distance_m - 1e-6) {
      d->unexplained_area_within_m2[k] += static_cast<float>(area_m2);
    }
  }
  if (distance_m <= 0.2) {
    d->near_arm_area_m2 += static_cast<float>(area_m2);
    d->near_arm_pixels += 1;
    d->near_arm_min_distance_m = d->near_arm_min_distance_m < 0
                                     ? static_cast<float>(distance_m)
                                     : std::min(d->near_arm_min_distance_m, static_cast<float>(distance_m));
  }
}

inline link_labels_t unusable_labels(int64_t seq, const std::string& reason) {
  link_labels_t m = labels_frame({}, seq);
  m.usable = false;
  m.unusable_reason = reason;
  m.num_pixels = 0;
  m.width = 0;
  m.height = 0;
  return m;
}

// Adds Gaussian noise sigma(d) = 4 + 1.2 d^2 mm (d in m), the sim camera's.
inline std::vector<int16_t> with_noise(std::vector<int16_t> depth_mm, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> unit(0.0, 1.0);
  for (int16_t& d : depth_mm) {
    if (d <= 0) continue;
    const double m = d * 1e-3;
    d = static_cast<int16_t>(std::lround(d + unit(rng) * (4.0 + 1.2 * m * m)));
  }
  return depth_mm;
}

}  // namespace tofguard::test
