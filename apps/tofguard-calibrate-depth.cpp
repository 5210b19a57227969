// tofguard-calibrate-depth: fits the distance calibration polynomial from
// captures of a planar target (see src/calibration_tool.hpp and
// docs/camera.md).
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "tofguard/camera/calibration_tool.hpp"

namespace {

const char* kUsage =
    "usage: tofguard-calibrate-depth --captures LIST.csv --roi U0,V0,WIDTH,HEIGHT\n"
    "                                [--intrinsics FX,FY,CX,CY]\n"
    "                                [--degree N] [--channel TOF_DEPTH]\n"
    "                                [--yaml OUT.yaml] [--plot OUT.png]\n"
    "\n"
    "Distance calibration of a ToF camera from captures of a planar target seen\n"
    "perpendicularly. LIST.csv has one line per capture: 'capture,true_distance_mm',\n"
    "a capture being a folder of 16-bit PNGs (depth Z in mm) or an LCM log of\n"
    "uncalibrated depth_image_t on --channel. Per distance it prints the mean Z error\n"
    "and its standard deviation over the ROI and all frames, before and after the\n"
    "fitted correction d - p(d) (p of degree N, default 5, d the distance along the\n"
    "pixel's ray in metres: Z / f with f from the intrinsics; LCM frames carry\n"
    "theirs, PNG captures need --intrinsics in pixels), writes the\n"
    "config snippet camera.depth_calibration to --yaml and the error plot to --plot\n"
    "(default: beside LIST.csv, LIST_calibration.yaml / .png).\n"
    "Exit codes: 0 done, 2 bad input (one line on stderr).\n";

}  // namespace

int main(int argc, char** argv) {
  using namespace tofguard::camera;
  std::string captures_path, roi_text, intrinsics_text, channel = "TOF_DEPTH", yaml_path, plot_path;
  int degree = 5;
  const std::vector<std::string> args(argv + 1, argv + argc);
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--help" || a == "-h") {
      std::cout << kUsage;
      return 0;
    }
    if (i + 1 >= args.size()) {
      std::cerr << "tofguard-calibrate-depth: " << a << ": unknown option or missing value\n" << kUsage;
      return 2;
    }
    const std::string& value = args[++i];
    if (a == "--captures") {
      captures_path = value;
    } else if (a == "--roi") {
      roi_text = value;
    } else if (a == "--intrinsics") {
      intrinsics_text = value;
    } else if (a == "--channel") {
      channel = value;
    } else if (a == "--yaml") {
      yaml_path = value;
    } else if (a == "--plot") {
      plot_path = value;
    } else if (a == "--degree") {
      char* end = nullptr;
      const long d = std::strtol(value.c_str(), &end, 10);
      if (*end != '\0' || d < 0 || d > 9) {
        std::cerr << "tofguard-calibrate-depth: --degree: expected an integer in [0, 9], got \"" << value
                  << "\"\n";
        return 2;
      }
      degree = static_cast<int>(d);
    } else {
      std::cerr << "tofguard-calibrate-depth: " << a << ": unknown option\n" << kUsage;
      return 2;
    }
  }
  if (captures_path.empty() || roi_text.empty()) {
    std::cerr << "tofguard-calibrate-depth: --captures and --roi are required\n" << kUsage;
    return 2;
  }
  const std::filesystem::path stem =
      std::filesystem::path(captures_path).replace_extension("").string() + "_calibration";
  if (yaml_path.empty()) yaml_path = stem.string() + ".yaml";
  if (plot_path.empty()) plot_path = stem.string() + ".png";
  try {
    const Roi roi = parse_roi(roi_text);
    std::optional<PixelRays> png_rays;
    if (!intrinsics_text.empty()) png_rays = parse_pixel_rays(intrinsics_text);
    const auto captures = read_capture_list(captures_path);
    std::vector<CaptureSamples> samples;
    for (const auto& capture : captures) {
      samples.push_back(load_capture(capture, roi, channel, png_rays));
    }
    const CalibrationResult result = calibrate(captures, samples, degree);
    std::cout << format_table(result);
    const std::string snippet = yaml_snippet(result);
    std::ofstream yaml(yaml_path);
    if (!(yaml << snippet)) throw CalibrationInputError(yaml_path + ": cannot write the YAML snippet");
    draw_plot(result, plot_path);
    std::cout << "\n" << snippet << "\nwrote " << yaml_path << " and " << plot_path << "\n";
  } catch (const CalibrationInputError& e) {
    std::cerr << "tofguard-calibrate-depth: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "tofguard-calibrate-depth: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
