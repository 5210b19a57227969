#include "tofguard/common/process.hpp"

namespace tofguard {

const std::vector<std::string>& per_camera_process_names() {
  static const std::vector<std::string> names = {
      "tofguard-camera", "tofguard-renderer", "tofguard-discrepancy",         "tofguard-estimator",
      "tofguard-view",   "tofguard-tune",     "tofguard-calibrate-extrinsics"};
  return names;
}

}  // namespace tofguard
