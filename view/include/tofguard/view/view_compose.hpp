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
#include "tofguard/settings/view_settings.hpp"
#include "tofguard/speed_limit_t.hpp"

namespace tofguard::view {

struct FrameSet {
  depth_image_t camera;
  std::optional<depth_image_t> rendered;
  std::optional<link_labels_t> labels;
  std::optional<risk_t> risk;          // the verdict on this frame, if known
  std::optional<speed_limit_t> limit;  // the speed limit for this frame, if known
};

// Per camera pixel, where its surface lies (labels' arm cover; CV_8U):
// 2 inside the protective field (within protective_m of the arm), 1 inside
// the warning field, 0 beyond it, without a return, or when the labels
// carry no cover.
cv::Mat1b field_classes(const depth_image_t& camera, const link_labels_t& labels, double protective_m,
                        double warning_m);

// Integer scale so that a panel is at least 320 pixels wide.
int panel_scale(int width);

// The three panels and the verdict line; `options` decide what is a
// match (the deployment's discrepancy tolerance). The camera panel shows
// the fields' outlines on the seen surfaces: red the protective field's,
// yellow the warning field's.
cv::Mat3b compose_view(const FrameSet& frames, const discrepancy::DiscrepancyOptions& options,
                       double max_depth_mm, double full_scale_mm, const FieldSizes& fields = {});

// The verdict line: e.g. "seq 42  DANGEROUS joint error, suspect a4 | ...",
// or "seq 42  no verdict".
std::string verdict_text(const FrameSet& frames);
// The user's line, under the verdict (docs/safety-chain.md, "The user"):
// the body region nearest the arm and its separation (the labels', from
// the model) and the frame's speed limit, e.g. "user: face nearest, 0.19 m
// | limit 0.38 m/s, set by face at 0.14 m"; "" when the labels carry no
// body regions.
std::string user_text(const FrameSet& frames);

// Reads a whole LCM log and groups its frames by camera seq: TOF_DEPTH
// (camera), TOF_RENDERED, TOF_LABELS, SAFETY_RISK and SAFETY_SPEED_LIMIT, by the channel names
// given. Messages that do not decode are skipped and counted.
struct LogFrames {
  std::map<int64_t, FrameSet> by_seq;
  int skipped = 0;
};
LogFrames read_log_frames(const std::string& path, const ChannelNames& channels, std::string* error);

}  // namespace tofguard::view
