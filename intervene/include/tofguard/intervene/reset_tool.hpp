#pragma once
// tofguard-reset --who NAME --why TEXT: asks tofguard-intervene to release a
// latched stop and prints whether it was accepted and why not. With
// --release-camera ID it first asks tofguard-risk to leave the lost camera
// ID out of its verdicts (camera_release_t; risk.camera_loss
// continue_after_named_reset) and waits for a SAFE verdict.
// Exit code: 0 accepted, 1 refused, 3 no answer within the deadline,
// 2 usage error.
#include <string>
#include <vector>

#include "tofguard/common/process.hpp"
#include "tofguard/settings/intervene_settings.hpp"

namespace tofguard::intervene {

// Runs with or without --config (then LCM_DEFAULT_URL and the default
// channel names).
ProcessInfo reset_info();

int run_reset(const ResetToolSettings& settings, const std::vector<std::string>& arguments);

}  // namespace tofguard::intervene
