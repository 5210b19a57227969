#include "tofguard/common/depth_frame.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace tofguard {

int16_t depth_mm_from_m(double depth_m) {
  const double mm = std::round(depth_m * 1000.0);
  // NaN fails both comparisons: no return.
  return (mm > 0 && mm <= kMaxDepthMm) ? static_cast<int16_t>(mm) : int16_t{0};
}

std::vector<int16_t> depth_mm_from_m(const std::vector<float>& depth_m) {
  std::vector<int16_t> depth_mm(depth_m.size());
  for (size_t i = 0; i < depth_m.size(); ++i) depth_mm[i] = depth_mm_from_m(static_cast<double>(depth_m[i]));
  return depth_mm;
}

std::vector<float> depth_m_from_mm(const std::vector<int16_t>& depth_mm) {
  std::vector<float> depth_m(depth_mm.size());
  for (size_t i = 0; i < depth_mm.size(); ++i) {
    depth_m[i] = depth_mm[i] > 0 ? static_cast<float>(metres_from_mm(depth_mm[i])) : 0.0f;
  }
  return depth_m;
}

Intrinsics intrinsics_of(const depth_image_t& image) {
  Intrinsics in;
  in.width = image.width;
  in.height = image.height;
  in.fx = image.fx;
  in.fy = image.fy;
  in.cx = image.cx;
  in.cy = image.cy;
  return in;
}

depth_image_t make_depth_image(const std::string& camera_id, const Intrinsics& intrinsics, int64_t utime,
                               int64_t seq, bool calibrated, const std::vector<float>& depth_m,
                               const std::vector<float>& amplitude) {
  const size_t n = static_cast<size_t>(std::max(intrinsics.width, 0)) *
                   static_cast<size_t>(std::max(intrinsics.height, 0));
  if (depth_m.size() != n || (!amplitude.empty() && amplitude.size() != n)) {
    throw std::invalid_argument("make_depth_image: " + std::to_string(depth_m.size()) + " depths / " +
                                std::to_string(amplitude.size()) + " amplitudes, expected " +
                                std::to_string(n) + " (" + std::to_string(intrinsics.width) + "x" +
                                std::to_string(intrinsics.height) + ")");
  }
  depth_image_t image;
  image.utime = utime;
  image.seq = seq;
  image.camera_id = camera_id;
  image.width = intrinsics.width;
  image.height = intrinsics.height;
  image.fx = intrinsics.fx;
  image.fy = intrinsics.fy;
  image.cx = intrinsics.cx;
  image.cy = intrinsics.cy;
  image.calibrated = calibrated;
  image.num_pixels = static_cast<int32_t>(n);
  image.depth_mm = depth_mm_from_m(depth_m);
  image.num_amplitude = static_cast<int32_t>(amplitude.size());
  image.amplitude.resize(amplitude.size());
  for (size_t i = 0; i < amplitude.size(); ++i) {
    const float a = std::isfinite(amplitude[i]) ? amplitude[i] : 0.0f;
    image.amplitude[i] = static_cast<int16_t>(std::lround(std::clamp(a, 0.0f, 32767.0f)));
  }
  return image;
}

std::vector<float> depth_m_of(const depth_image_t& image) { return depth_m_from_mm(image.depth_mm); }

namespace {

link_labels_t labels_header(const depth_image_t& frame, int num_robot_links,
                            std::vector<std::string> link_names) {
  if (num_robot_links < 0 || static_cast<size_t>(num_robot_links) > link_names.size()) {
    throw std::invalid_argument("make_link_labels: num_robot_links " + std::to_string(num_robot_links) +
                                ", expected 0.." + std::to_string(link_names.size()));
  }
  link_labels_t m{};
  m.utime = frame.utime;
  m.seq = frame.seq;
  m.camera_id = frame.camera_id;
  m.width = frame.width;
  m.height = frame.height;
  m.num_robot_links = num_robot_links;
  m.link_name = std::move(link_names);
  m.num_links = static_cast<int32_t>(m.link_name.size());
  m.usable = false;
  m.num_pixels = 0;
  // No kinematics (the renderer adds them: renderer/rendered_kinematics.hpp).
  m.num_joints = 0;
  m.num_axes = 0;
  m.num_link_axes = 0;
  return m;
}

}  // namespace

link_labels_t make_link_labels(const depth_image_t& frame, int num_robot_links,
                               std::vector<std::string> link_names, std::vector<int16_t> labels) {
  const size_t n =
      static_cast<size_t>(std::max(frame.width, 0)) * static_cast<size_t>(std::max(frame.height, 0));
  if (labels.size() != n) {
    throw std::invalid_argument("make_link_labels: " + std::to_string(labels.size()) + " labels, expected " +
                                std::to_string(n) + " (" + std::to_string(frame.width) + "x" +
                                std::to_string(frame.height) + ")");
  }
  link_labels_t m = labels_header(frame, num_robot_links, std::move(link_names));
  m.usable = true;
  m.num_pixels = static_cast<int32_t>(labels.size());
  m.label = std::move(labels);
  return m;
}

link_labels_t make_unusable_link_labels(const depth_image_t& frame, int num_robot_links,
                                        std::vector<std::string> link_names, const std::string& reason) {
  link_labels_t m = labels_header(frame, num_robot_links, std::move(link_names));
  m.unusable_reason = reason;
  return m;
}

}  // namespace tofguard
