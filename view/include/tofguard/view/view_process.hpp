#pragma once
// tofguard-view: camera depth, rendered depth and the colour discrepancy
// image side by side with the verdict, live in a window (OpenCV highgui), or
// exported from a log for people without a display:
//   tofguard-view --config FILE                         live window
//   tofguard-view --config FILE --log FILE --out DIR    one PNG per camera frame
//   tofguard-view --config FILE --log FILE --out F.mp4  a video
#include <string>
#include <vector>

#include "tofguard/common/process.hpp"
#include "tofguard/settings/view_settings.hpp"

namespace tofguard::view {

ProcessInfo process_info();

// Exit code 0 done, 1 cannot read or write, 2 usage error, 3 cannot open LCM.
int run_view(const ViewSettings& settings, const std::vector<std::string>& arguments);

}  // namespace tofguard::view
