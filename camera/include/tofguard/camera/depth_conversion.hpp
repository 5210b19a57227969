#pragma once
// From a 16-bit depth camera's counts to Z in metres.
//
// Z16, Y16 and GRAY16 frames all carry one little-endian unsigned 16-bit
// count per pixel, row-major; count * depth_unit_mm is the distance in
// millimetres and 0 means "no valid return". Some cameras report the radial
// distance r along each pixel's ray instead of Z along the optical axis;
// with pinhole intrinsics (OpenCV convention, pixel centres at integers)
//   Z = r / sqrt(1 + ((u - cx) / fx)^2 + ((v - cy) / fy)^2).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "tofguard/common/camera_settings.hpp"

namespace tofguard::camera {

// The stream formats tofguard reads; all three are 16 bits per pixel.
enum class RawDepthFormat { kZ16, kY16, kGray16 };

// "z16", "y16" or "gray16" (the config's camera.uvc.format); throws
// std::invalid_argument otherwise.
RawDepthFormat parse_raw_depth_format(const std::string& name);

// The UVC FourCC of the format's GUID ("Z16 " or "Y16 ").
const char* fourcc(RawDepthFormat format);

// Converts `pixel_count` little-endian counts at `bytes` to distances in
// metres (0 stays 0 = invalid). `bytes` must hold 2 * pixel_count bytes.
std::vector<float> raw16_to_distance_m(const uint8_t* bytes, size_t pixel_count, double depth_unit_mm);

// Converts radial distances to Z in place, for an image of the intrinsics'
// size. The per-pixel factors are computed once.
class RadialToZ {
 public:
  explicit RadialToZ(const Intrinsics& intrinsics);
  // `distance_m` has width * height entries; 0 (invalid) stays 0.
  void apply(std::vector<float>* distance_m) const;
  // Z / r for pixel (u, v).
  float factor(int u, int v) const { return factor_[static_cast<size_t>(v) * width_ + u]; }
  // Z / r for the pixel at row-major index i (v * width + u).
  float factor(size_t i) const { return factor_[i]; }
  size_t pixel_count() const { return factor_.size(); }

 private:
  int width_;
  std::vector<float> factor_;
};

}  // namespace tofguard::camera
