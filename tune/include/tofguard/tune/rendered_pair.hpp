#pragma once
// A recorded camera frame with what tofguard-renderer made of it, as
// tofguard-tune's passes read them (recording_tuner.hpp).
#include <cstdint>
#include <vector>

#include "tofguard/depth_image_t.hpp"
#include "tofguard/link_labels_t.hpp"

namespace tofguard::tune {

struct RenderedPair {
  depth_image_t camera;
  depth_image_t rendered;
  link_labels_t labels;
};

// The pixels the noise and the static error are measured on: compared
// (camera and model both have a surface), not beside a silhouette
// (compute_discrepancy's mask: mixed pixels), on a modelled link. 1 = used.
std::vector<uint8_t> noise_pixels(const RenderedPair& frame, double silhouette_jump_mm);

}  // namespace tofguard::tune
