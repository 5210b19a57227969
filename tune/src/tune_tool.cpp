#include "tofguard/tune/tune_tool.hpp"

#include <ctime>
#include <fstream>
#include <iostream>

namespace tofguard::tune {
namespace {

// Today's date (UTC), for the config lines' comment.
std::string today() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[16];
  std::strftime(text, sizeof text, "%Y-%m-%d", &utc);
  return text;
}

bool write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  return static_cast<bool>(out);
}

}  // namespace

ProcessInfo tune_info() {
  ProcessInfo info{
      "tofguard-tune",
      "Fits the camera's noise model sigma(d) = a + b d^2 (discrepancy.noise) and pixels_per_sample from a "
      "nominal LCM log (TOF_DEPTH, JOINT_STATE, CAMERA_POSE: the arm moving, nothing else in view), "
      "rendering "
      "each frame as tofguard-renderer does, and reports the false-alarm margin of the sequential tests with "
      "it. Prints the report and the lines for the config. Usage: tofguard-tune --config FILE --log "
      "NOMINAL.lcmlog [--out FILE] [--profile-out PROFILE.yaml]. --profile-out: learn the camera's profile "
      "(its static distance error: a correction by radial distance and per pixel; docs/camera.md, "
      "\"Commissioning a camera\") from the recording, tune on the corrected frames and write it. Exit "
      "code 1 when the recording is not usable."};
  info.takes_arguments = true;
  info.per_camera = true;
  return info;
}

int run_tune(const TuneSettings& settings, const std::vector<std::string>& arguments) {
  const std::string name = tune_info().name;
  std::string log_path, out_path, profile_path;
  for (size_t i = 0; i < arguments.size(); ++i) {
    if (arguments[i] == "--log" && i + 1 < arguments.size()) {
      log_path = arguments[++i];
    } else if (arguments[i] == "--out" && i + 1 < arguments.size()) {
      out_path = arguments[++i];
    } else if (arguments[i] == "--profile-out" && i + 1 < arguments.size()) {
      profile_path = arguments[++i];
    } else {
      std::cerr << name << ": unexpected argument '" << arguments[i] << "' (see --help)\n";
      return 2;
    }
  }
  if (log_path.empty()) {
    std::cerr << name << ": no --log FILE given (see --help)\n";
    return 2;
  }
  TuneOptions options;
  options.learn_profile = !profile_path.empty();
  const TuneResult result = tune_recording(settings, log_path, options);
  std::cout << tune_report(result, settings);
  if (!result.usable) {
    std::cerr << name << ": " << result.error << "\n";
    return 1;
  }
  if (result.has_profile && !write_text(profile_path, camera_profile_yaml(result.profile_fit.profile))) {
    std::cerr << name << ": cannot write " << profile_path << "\n";
    return 1;
  }
  std::string lines = tuned_config_lines(result, today());
  if (result.has_profile) {
    lines +=
        "  # The profile learned from this recording (check it on a second one before deploying:\n"
        "  # its static error here is what the profile was fitted to).\n"
        "  camera_profile: " +
        profile_path + "\n";
  }
  std::cout << "\n" << lines;
  if (!out_path.empty() && !write_text(out_path, lines)) {
    std::cerr << name << ": cannot write " << out_path << "\n";
    return 1;
  }
  return 0;
}

}  // namespace tofguard::tune
