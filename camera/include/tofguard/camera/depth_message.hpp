#pragma once
// Packing a depth frame into the wire type depth_image_t.
#include <cstdint>
#include <vector>

#include "tofguard/common/camera_settings.hpp"
#include "tofguard/depth_image_t.hpp"

namespace tofguard::camera {

// Z depths in metres (0 = invalid) -> depth_mm, rounded to the nearest
// millimetre. A depth beyond the int16 range (32.767 m) becomes invalid
// rather than clipped: a clipped value would be a made-up distance.
// `amplitude` is empty (no amplitude) or one value per pixel, clamped to
// [0, 32767].
depth_image_t make_depth_image(const CameraSettings& camera, int64_t utime, int64_t seq,
                               bool calibrated, const std::vector<float>& depth_m,
                               const std::vector<float>& amplitude);

}  // namespace tofguard::camera
