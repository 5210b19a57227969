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

}  // namespace

ProcessInfo tune_info() {
  ProcessInfo info{
      "tofguard-tune",
      "Fits the camera's noise model sigma(d) = a + b d^2 (discrepancy.noise) and pixels_per_sample from a "
      "nominal LCM log (TOF_DEPTH, JOINT_STATE, CAMERA_POSE: the arm moving, nothing else in view), "
      "rendering "
      "each frame as tofguard-renderer does, and reports the false-alarm margin of the sequential tests with "
      "it. Prints the report and the lines for the config. Usage: tofguard-tune --config FILE --log "
      "NOMINAL.lcmlog [--out FILE]. Exit code 1 when the recording is not usable."};
  info.takes_arguments = true;
  return info;
}

int run_tune(const TuneSettings& settings, const std::vector<std::string>& arguments) {
  const std::string name = tune_info().name;
  std::string log_path, out_path;
  for (size_t i = 0; i < arguments.size(); ++i) {
    if (arguments[i] == "--log" && i + 1 < arguments.size()) {
      log_path = arguments[++i];
    } else if (arguments[i] == "--out" && i + 1 < arguments.size()) {
      out_path = arguments[++i];
    } else {
      std::cerr << name << ": unexpected argument '" << arguments[i] << "' (see --help)\n";
      return 2;
    }
  }
  if (log_path.empty()) {
    std::cerr << name << ": no --log FILE given (see --help)\n";
    return 2;
  }
  const TuneResult result = tune_recording(settings, log_path);
  std::cout << tune_report(result, settings);
  if (!result.usable) {
    std::cerr << name << ": " << result.error << "\n";
    return 1;
  }
  const std::string lines = tuned_config_lines(result, today());
  std::cout << "\n" << lines;
  if (!out_path.empty()) {
    std::ofstream out(out_path);
    out << lines;
    if (!out) {
      std::cerr << name << ": cannot write " << out_path << "\n";
      return 1;
    }
  }
  return 0;
}

}  // namespace tofguard::tune
