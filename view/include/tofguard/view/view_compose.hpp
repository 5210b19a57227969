#pragma once
// What tofguard-view shows for one camera frame: camera depth, rendered
// depth and the colour discrepancy image side by side (each scaled up by an
// integer factor, nearest neighbour), with the verdict written across the
// top. Depth panels map 0..max_depth_mm to a colour map, black = no return.
// Pure: no LCM, no window.
#include <map>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "tofguard/common/lcm_settings.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/discrepancy/discrepancy_image.hpp"
#include "tofguard/link_labels_t.hpp"
#include "tofguard/risk_t.hpp"

namespace tofguard::view {

struct FrameSet {
  depth_image_t camera;
  std::optional<depth_image_t> rendered;
  std::optional<link_labels_t> labels;
  std::optional<risk_t> risk;  // the verdict on this frame, if known
};

// Integer scale so that a panel is at least 320 pixels wide.
int panel_scale(int width);

// The three panels and the verdict line; `parameters` decide what is a
// match (the deployment's discrepancy tolerance).
cv::Mat3b compose_view(const FrameSet& frames, const discrepancy::Parameters& parameters, double max_depth_mm,
                       double full_scale_mm);

// The verdict line: e.g. "seq 42  DANGEROUS joint error, suspect a4 | ...",
// or "seq 42  no verdict".
std::string verdict_text(const FrameSet& frames);

// Reads a whole LCM log and groups its frames by camera seq: TOF_DEPTH
// (camera), TOF_RENDERED, TOF_LABELS and SAFETY_RISK, by the channel names
// given. Messages that do not decode are skipped and counted.
struct LogFrames {
  std::map<int64_t, FrameSet> by_seq;
  int skipped = 0;
};
LogFrames read_log_frames(const std::string& path, const ChannelNames& channels, std::string* error);

}  // namespace tofguard::view
