#pragma once
// tofguard-calibrate-extrinsics: the camera's pose from an LCM log of the arm
// moving with known joint angles (extrinsics_calibration.hpp); prints the
// YAML block for camera.pose.
#include <string>
#include <vector>

#include "tofguard/common/process.hpp"
#include "tofguard/settings/estimator_settings.hpp"

namespace tofguard::estimator {

ProcessInfo calibrate_extrinsics_info();

// `arguments`: LOG [--out FILE] [--frames N]. Exit code 0 done, 1 no
// calibration, 2 usage error.
int run_calibrate_extrinsics(const EstimatorProcessSettings& settings,
                             const std::vector<std::string>& arguments);

}  // namespace tofguard::estimator
