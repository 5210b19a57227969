#include "tofguard/camera/depth_message.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace tofguard::camera {

depth_image_t make_depth_image(const CameraSettings& camera, int64_t utime, int64_t seq,
                               bool calibrated, const std::vector<float>& depth_m,
                               const std::vector<float>& amplitude) {
  const Intrinsics& in = camera.intrinsics;
  const size_t n = static_cast<size_t>(in.width) * in.height;
  if (depth_m.size() != n || (!amplitude.empty() && amplitude.size() != n)) {
    throw std::invalid_argument("make_depth_image: " + std::to_string(depth_m.size()) +
                                " depths / " + std::to_string(amplitude.size()) +
                                " amplitudes, expected " + std::to_string(n));
  }
  depth_image_t image;
  image.utime = utime;
  image.seq = seq;
  image.camera_id = camera.id;
  image.width = in.width;
  image.height = in.height;
  image.fx = in.fx;
  image.fy = in.fy;
  image.cx = in.cx;
  image.cy = in.cy;
  image.calibrated = calibrated;
  image.num_pixels = static_cast<int32_t>(n);
  image.depth_mm.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const double mm = std::round(depth_m[i] * 1000.0);
    image.depth_mm[i] = (mm > 0 && mm <= 32767) ? static_cast<int16_t>(mm) : int16_t{0};
  }
  image.num_amplitude = static_cast<int32_t>(amplitude.size());
  image.amplitude.resize(amplitude.size());
  for (size_t i = 0; i < amplitude.size(); ++i) {
    const float a = std::isfinite(amplitude[i]) ? amplitude[i] : 0.0f;
    image.amplitude[i] = static_cast<int16_t>(std::lround(std::clamp(a, 0.0f, 32767.0f)));
  }
  return image;
}

}  // namespace tofguard::camera
