#include "tofguard/estimator/calibrate_extrinsics_tool.hpp"

#include <cstdlib>
#include <fstream>
#include <iostream>

#include "tofguard/estimator/extrinsics_calibration.hpp"

namespace tofguard::estimator {

ProcessInfo calibrate_extrinsics_info() {
  ProcessInfo info{
      "tofguard-calibrate-extrinsics",
      "Estimates the camera's pose (extrinsic calibration) from an LCM log with TOF_DEPTH and JOINT_STATE of "
      "the "
      "arm moving with known joint angles, starting from the config's camera.pose; prints the YAML block for "
      "camera.pose. Usage: tofguard-calibrate-extrinsics --config FILE LOG [--out FILE] [--frames N]"};
  info.takes_arguments = true;
  info.per_camera = true;
  return info;
}

int run_calibrate_extrinsics(const EstimatorProcessSettings& settings, const std::vector<std::string>& rest) {
  const std::string name = calibrate_extrinsics_info().name;
  std::string log_path, out_path;
  CalibrationOptions options;
  for (size_t i = 0; i < rest.size(); ++i) {
    if (rest[i] == "--out" && i + 1 < rest.size()) {
      out_path = rest[++i];
    } else if (rest[i] == "--frames" && i + 1 < rest.size()) {
      options.max_frames = std::atoi(rest[++i].c_str());
      if (options.max_frames < options.min_frames) {
        std::cerr << name << ": --frames: expected at least " << options.min_frames << "\n";
        return 2;
      }
    } else if (log_path.empty() && rest[i].rfind("--", 0) != 0) {
      log_path = rest[i];
    } else {
      std::cerr << name << ": unexpected argument '" << rest[i] << "' (see --help)\n";
      return 2;
    }
  }
  if (log_path.empty()) {
    std::cerr << name << ": no LCM log given (see --help)\n";
    return 2;
  }
  CalibrationResult result;
  try {
    result = calibrate_extrinsics(settings, log_path, options);
  } catch (const std::exception& e) {
    std::cerr << name << ": " << e.what() << "\n";
    return 1;
  }
  if (!result.error.empty()) {
    std::cerr << name << ": " << result.error << "\n";
    return 1;
  }
  const std::string yaml = pose_yaml(result.pose);
  std::cerr << name << ": " << result.frames_used << " of " << result.frames_in_log << " frames, "
            << result.iterations << " iterations, residual " << result.residual_before_mm << " -> "
            << result.residual_after_mm << " mm, sigma " << result.translation_sigma_m * 1000 << " mm / "
            << result.rotation_sigma_rad * 180 / 3.141592653589793 << " deg\n";
  std::cout << yaml;
  if (!out_path.empty()) {
    std::ofstream out(out_path);
    out << yaml;
    if (!out) {
      std::cerr << name << ": cannot write " << out_path << "\n";
      return 1;
    }
  }
  return 0;
}

}  // namespace tofguard::estimator
