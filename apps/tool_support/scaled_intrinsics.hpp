#pragma once
// A camera's intrinsics at another image size with the same field of view,
// for the test tools and benchmarks that run one camera at several sizes.
#include "tofguard/common/camera_geometry.hpp"

namespace tofguard::test {

// `base` scaled to width x height: fx, cx with the width; fy, cy with the
// height. A pixel's centre is at (u, v), its edges at +-0.5: the image's
// edges stay at the same rays when (c + 0.5) scales with the size.
inline Intrinsics scaled_intrinsics(const Intrinsics& base, int width, int height) {
  const double sx = static_cast<double>(width) / base.width;
  const double sy = static_cast<double>(height) / base.height;
  return Intrinsics(width, height, base.fx * sx, base.fy * sy, (base.cx + 0.5) * sx - 0.5,
                    (base.cy + 0.5) * sy - 0.5);
}

}  // namespace tofguard::test
