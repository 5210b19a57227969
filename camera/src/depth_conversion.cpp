#include "tofguard/camera/depth_conversion.hpp"

#include <cmath>
#include <stdexcept>

namespace tofguard::camera {

RawDepthFormat parse_raw_depth_format(const std::string& name) {
  if (name == "z16") return RawDepthFormat::kZ16;
  if (name == "y16") return RawDepthFormat::kY16;
  if (name == "gray16") return RawDepthFormat::kGray16;
  throw std::invalid_argument("depth format \"" + name + "\": expected z16, y16 or gray16");
}

const char* fourcc(RawDepthFormat format) {
  // GRAY16 is libuvc's name for the "Y16 " GUID.
  return format == RawDepthFormat::kZ16 ? "Z16 " : "Y16 ";
}

std::vector<float> raw16_to_distance_m(const uint8_t* bytes, size_t pixel_count, double depth_unit_mm) {
  std::vector<float> out(pixel_count);
  const double metres_per_count = depth_unit_mm * 1e-3;
  for (size_t i = 0; i < pixel_count; ++i) {
    const uint16_t count = static_cast<uint16_t>(bytes[2 * i] | bytes[2 * i + 1] << 8);
    out[i] = static_cast<float>(count * metres_per_count);
  }
  return out;
}

RadialToZ::RadialToZ(const Intrinsics& in) : width_(in.width) {
  factor_.resize(static_cast<size_t>(in.width) * in.height);
  for (int v = 0; v < in.height; ++v) {
    for (int u = 0; u < in.width; ++u) {
      const double x = (u - in.cx) / in.fx;
      const double y = (v - in.cy) / in.fy;
      factor_[static_cast<size_t>(v) * in.width + u] =
          static_cast<float>(1.0 / std::sqrt(1.0 + x * x + y * y));
    }
  }
}

void RadialToZ::apply(std::vector<float>* distance_m) const {
  if (distance_m->size() != factor_.size()) {
    throw std::invalid_argument("RadialToZ: image of " + std::to_string(distance_m->size()) +
                                " pixels, expected " + std::to_string(factor_.size()));
  }
  for (size_t i = 0; i < factor_.size(); ++i) (*distance_m)[i] *= factor_[i];
}

}  // namespace tofguard::camera
