#pragma once
// tofguard-calibrate-depth's logic: from captures of a planar target seen
// perpendicularly at known distances to the distance calibration polynomial
// (depth_calibration.hpp) and its report.
//
// The captures hold Z; the polynomial is fitted over the radial distance
// along each pixel's ray (d = Z / f, f = Z / r from the intrinsics), where
// a ToF camera's systematic error lives. LCM frames carry their intrinsics;
// PNG frames carry none, so PNG captures need them from the command line.
//
// A capture is either a folder of 16-bit single-channel PNGs (one frame
// each, depth in millimetres, 0 = invalid) or an LCM log file whose
// depth_image_t messages on one channel are the frames (uncalibrated). The
// captures are listed in a CSV file, one per line:
//   capture,true_distance_mm
// with paths relative to the CSV's folder; a first line that does not parse
// (a header) and lines starting with '#' are skipped.
//
// Every input error is a CalibrationInputError whose message is one line
// naming the file (and line) and what was expected.
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace tofguard::camera {

class CalibrationInputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct CaptureSpec {
  std::string path;  // resolved against the CSV's folder
  double true_distance_mm = 0;
  std::string where;  // "captures.csv:3", for messages
};

// Reads the capture list; checks that every capture exists.
std::vector<CaptureSpec> read_capture_list(const std::string& csv_path);

// Region of interest in pixels: columns u0..u0+width-1, rows v0..v0+height-1.
struct Roi {
  int u0 = 0;
  int v0 = 0;
  int width = 0;
  int height = 0;
};

// "U0,V0,WIDTH,HEIGHT", all integers, width and height > 0.
Roi parse_roi(const std::string& text);

// Pinhole intrinsics in pixels (OpenCV convention), for the rays of PNG
// captures.
struct PixelRays {
  double fx = 0;
  double fy = 0;
  double cx = 0;
  double cy = 0;
};

// "FX,FY,CX,CY", fx and fy > 0.
PixelRays parse_pixel_rays(const std::string& text);

// The ROI's valid depths (Z, millimetres) of every frame of one capture,
// with each sample's ray factor Z / r.
struct CaptureSamples {
  int width = 0;  // image size of the capture's frames
  int height = 0;
  int frames = 0;
  std::vector<float> depth_mm;
  std::vector<float> z_per_radial;  // parallel to depth_mm, in (0, 1]
};

// Loads a capture (PNG folder or LCM log; `channel` for logs). PNG frames
// take their rays from `png_rays`, LCM frames from their own intrinsics.
// Throws CalibrationInputError for an unreadable or empty capture, frames
// of different sizes, the ROI outside the image, a frame that is already
// calibrated, a PNG capture without `png_rays`, or no valid pixel in the
// ROI.
CaptureSamples load_capture(const CaptureSpec& capture, const Roi& roi, const std::string& channel,
                            const std::optional<PixelRays>& png_rays);

// Per distance: error = measured Z - true Z, over the ROI and all frames.
struct DistanceStats {
  double true_distance_mm = 0;
  int64_t samples = 0;
  double mean_measured_mm = 0;
  double mean_error_mm = 0;  // before calibration
  double std_mm = 0;         // standard deviation of the error before
  double mean_error_after_mm = 0;
  double std_after_mm = 0;
};

struct CalibrationResult {
  int degree = 0;
  // p(d) = sum_i coefficients_m[i] * d^i, d the measured radial distance
  // in metres, p in metres (the config's camera.depth_calibration).
  std::vector<double> coefficients_m;
  std::vector<DistanceStats> rows;  // sorted by true distance
};

// Fits p by least squares to the mean radial errors (Z error / f, the true
// plane's radial distance being true Z / f) at the mean measured radial
// distances, then calibrates every sample along its ray for the "after"
// columns (in Z, like the table's other columns).
// Throws CalibrationInputError for fewer distinct distances than degree + 1.
CalibrationResult calibrate(const std::vector<CaptureSpec>& captures,
                            const std::vector<CaptureSamples>& samples, int degree);

// A fixed-width text table, one line per distance.
std::string format_table(const CalibrationResult& result);
// The config snippet (camera.depth_calibration) to paste under `camera:`.
std::string yaml_snippet(const CalibrationResult& result);
// Error vs distance before and after calibration, mean with a +-1 std band
// (the seed paper's figures 3.5 and 3.6), as a PNG. Throws
// CalibrationInputError when the file cannot be written.
void draw_plot(const CalibrationResult& result, const std::string& png_path);

}  // namespace tofguard::camera
