#pragma once
// Synthetic camera / rendered / label frames for the safety-chain tests: a
// floor (environment link "floor") 2 m from the camera and boxes that stand
// for robot links, drawn with a z-buffer (nearer wins). Pixel footprint at
// depth Z is (Z/fx)^2 with fx = fy = 200 px.
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "tofguard/depth_image_t.hpp"
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
