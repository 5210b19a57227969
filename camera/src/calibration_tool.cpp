#include "tofguard/camera/calibration_tool.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <set>
#include <sstream>

#include <lcm/lcm-cpp.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "tofguard/camera/depth_calibration.hpp"
#include "tofguard/common/camera_geometry.hpp"
#include "tofguard/common/wire_checks.hpp"
#include "tofguard/depth_image_t.hpp"

namespace fs = std::filesystem;

namespace tofguard::camera {
namespace {

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  const size_t b = s.find_last_not_of(" \t\r");
  return s.substr(a, b - a + 1);
}

bool parse_double(const std::string& text, double* out) {
  std::istringstream in(text);
  in >> *out;
  return !in.fail() && in.eof() && std::isfinite(*out);
}

std::string roi_text(const Roi& roi) {
  return std::to_string(roi.u0) + "," + std::to_string(roi.v0) + "," + std::to_string(roi.width) + "," +
         std::to_string(roi.height);
}

// Checks the frame size against the capture's and the ROI.
void check_frame(const CaptureSpec& capture, const std::string& frame_name, int width, int height,
                 const Roi& roi, CaptureSamples* samples) {
  if (samples->frames == 0) {
    samples->width = width;
    samples->height = height;
    if (roi.u0 < 0 || roi.v0 < 0 || roi.u0 + roi.width > width || roi.v0 + roi.height > height) {
      throw CalibrationInputError(capture.where + ": ROI " + roi_text(roi) + " lies outside the " +
                                  std::to_string(width) + "x" + std::to_string(height) + " image of " +
                                  frame_name);
    }
  } else if (width != samples->width || height != samples->height) {
    throw CalibrationInputError(capture.where + ": " + frame_name + " is " + std::to_string(width) + "x" +
                                std::to_string(height) + ", expected " + std::to_string(samples->width) +
                                "x" + std::to_string(samples->height) + " like the capture's first frame");
  }
  ++samples->frames;
}

template <class Pixel>
void take_roi(const Pixel* data, int width, int height, const PixelRays& rays, const Roi& roi,
              CaptureSamples* samples) {
  Intrinsics intrinsics;
  intrinsics.width = width;
  intrinsics.height = height;
  intrinsics.fx = rays.fx;
  intrinsics.fy = rays.fy;
  intrinsics.cx = rays.cx;
  intrinsics.cy = rays.cy;
  const RadialToZ z_per_radial(intrinsics);
  for (int v = roi.v0; v < roi.v0 + roi.height; ++v) {
    for (int u = roi.u0; u < roi.u0 + roi.width; ++u) {
      const Pixel d = data[static_cast<size_t>(v) * width + u];
      if (d > 0) {
        samples->depth_mm.push_back(static_cast<float>(d));
        samples->z_per_radial.push_back(z_per_radial.factor(u, v));
      }
    }
  }
}

void load_png_folder(const CaptureSpec& capture, const Roi& roi, const std::optional<PixelRays>& rays,
                     CaptureSamples* samples) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(capture.path)) {
    if (entry.is_regular_file() && entry.path().extension() == ".png") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) {
    throw CalibrationInputError(capture.where + ": folder " + capture.path + " holds no .png frames");
  }
  if (!rays) {
    throw CalibrationInputError(capture.where + ": PNG frames in " + capture.path +
                                " carry no intrinsics: give --intrinsics FX,FY,CX,CY (pixels) to "
                                "fit the error along each pixel's ray");
  }
  for (const fs::path& file : files) {
    const cv::Mat image = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
    if (image.empty() || image.type() != CV_16UC1) {
      throw CalibrationInputError(capture.where + ": " + file.string() +
                                  ": expected a 16-bit single-channel PNG (depth in mm), got " +
                                  (image.empty() ? std::string("an unreadable file")
                                                 : "OpenCV type " + std::to_string(image.type())));
    }
    check_frame(capture, file.string(), image.cols, image.rows, roi, samples);
    const cv::Mat continuous = image.isContinuous() ? image : image.clone();
    take_roi(continuous.ptr<uint16_t>(), image.cols, image.rows, *rays, roi, samples);
  }
}

void load_lcm_log(const CaptureSpec& capture, const Roi& roi, const std::string& channel,
                  CaptureSamples* samples) {
  lcm::LogFile log(capture.path, "r");
  if (!log.good()) {
    throw CalibrationInputError(capture.where + ": cannot open LCM log " + capture.path);
  }
  int64_t event_index = 0;
  for (const lcm::LogEvent* event = log.readNextEvent(); event != nullptr;
       event = log.readNextEvent(), ++event_index) {
    if (event->channel != channel) continue;
    const std::string name = capture.path + " event " + std::to_string(event_index);
    depth_image_t frame;
    int decoded = -1;
    try {
      decoded = frame.decode(event->data, 0, event->datalen);
    } catch (const std::exception&) {
      decoded = -1;
    }
    if (decoded < 0) {
      throw CalibrationInputError(capture.where + ": " + name + " on " + channel +
                                  ": cannot decode as depth_image_t");
    }
    const std::string problem = check_depth_image(frame);
    if (!problem.empty()) throw CalibrationInputError(capture.where + ": " + name + ": " + problem);
    if (frame.calibrated) {
      throw CalibrationInputError(
          capture.where + ": " + name +
          ": calibrated is true; record calibration captures without camera.depth_calibration");
    }
    check_frame(capture, name, frame.width, frame.height, roi, samples);
    take_roi(frame.depth_mm.data(), frame.width, frame.height,
             PixelRays{frame.fx, frame.fy, frame.cx, frame.cy}, roi, samples);
  }
  if (samples->frames == 0) {
    throw CalibrationInputError(capture.where + ": LCM log " + capture.path +
                                " holds no depth_image_t on channel " + channel);
  }
}

}  // namespace

std::vector<CaptureSpec> read_capture_list(const std::string& csv_path) {
  std::ifstream in(csv_path);
  if (!in) throw CalibrationInputError(csv_path + ": cannot open the capture list");
  const fs::path base = fs::path(csv_path).parent_path();
  std::vector<CaptureSpec> captures;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const std::string where = csv_path + ":" + std::to_string(number);
    line = trim(line);
    if (line.empty() || line[0] == '#') continue;
    const size_t comma = line.rfind(',');
    CaptureSpec spec;
    spec.where = where;
    const bool parsed =
        comma != std::string::npos && parse_double(trim(line.substr(comma + 1)), &spec.true_distance_mm);
    if (!parsed) {
      if (number == 1) continue;  // a header
      throw CalibrationInputError(where + ": expected \"capture,true_distance_mm\", got \"" + line + "\"");
    }
    if (!(spec.true_distance_mm > 0 && spec.true_distance_mm < 32767)) {
      throw CalibrationInputError(where + ": true_distance_mm: expected a distance in (0, 32767) mm, got " +
                                  trim(line.substr(comma + 1)));
    }
    const fs::path path = trim(line.substr(0, comma));
    spec.path = (path.is_absolute() ? path : base / path).string();
    if (!fs::exists(spec.path)) {
      throw CalibrationInputError(where + ": " + spec.path + ": no such file or folder");
    }
    captures.push_back(spec);
  }
  if (captures.empty()) throw CalibrationInputError(csv_path + ": lists no captures");
  return captures;
}

Roi parse_roi(const std::string& text) {
  Roi roi;
  char c1 = 0, c2 = 0, c3 = 0;
  std::istringstream in(text);
  in >> roi.u0 >> c1 >> roi.v0 >> c2 >> roi.width >> c3 >> roi.height;
  if (in.fail() || !in.eof() || c1 != ',' || c2 != ',' || c3 != ',' || roi.width <= 0 || roi.height <= 0) {
    throw CalibrationInputError("--roi: expected U0,V0,WIDTH,HEIGHT in pixels (width, height > 0), got \"" +
                                text + "\"");
  }
  return roi;
}

PixelRays parse_pixel_rays(const std::string& text) {
  PixelRays rays;
  char c1 = 0, c2 = 0, c3 = 0;
  std::istringstream in(text);
  in >> rays.fx >> c1 >> rays.fy >> c2 >> rays.cx >> c3 >> rays.cy;
  // The image size is not known before the PNGs are read: Intrinsics' rule
  // on the rays alone (one pixel stands in for the size).
  if (in.fail() || !in.eof() || c1 != ',' || c2 != ',' || c3 != ',' ||
      Intrinsics::check(1, 1, rays.fx, rays.fy, rays.cx, rays.cy)) {
    throw CalibrationInputError("--intrinsics: expected FX,FY,CX,CY in pixels (fx, fy > 0), got \"" + text +
                                "\"");
  }
  return rays;
}

CaptureSamples load_capture(const CaptureSpec& capture, const Roi& roi, const std::string& channel,
                            const std::optional<PixelRays>& png_rays) {
  CaptureSamples samples;
  if (fs::is_directory(capture.path)) {
    load_png_folder(capture, roi, png_rays, &samples);
  } else {
    load_lcm_log(capture, roi, channel, &samples);
  }
  if (samples.depth_mm.empty()) {
    throw CalibrationInputError(capture.where + ": no valid depth in ROI " + roi_text(roi) +
                                " in any frame of " + capture.path);
  }
  return samples;
}

CalibrationResult calibrate(const std::vector<CaptureSpec>& captures,
                            const std::vector<CaptureSamples>& samples, int degree) {
  CalibrationResult result;
  result.degree = degree;
  std::set<double> distinct;
  for (const auto& c : captures) distinct.insert(c.true_distance_mm);
  if (distinct.size() < static_cast<size_t>(degree) + 1) {
    throw CalibrationInputError("a degree-" + std::to_string(degree) + " calibration needs at least " +
                                std::to_string(degree + 1) + " different distances, the list has " +
                                std::to_string(distinct.size()));
  }
  // Captures at the same distance are pooled.
  std::vector<double> measured_radial_m, radial_error_m;
  std::vector<std::vector<size_t>> groups;
  for (double d : distinct) {
    groups.emplace_back();
    for (size_t i = 0; i < captures.size(); ++i) {
      if (captures[i].true_distance_mm == d) groups.back().push_back(i);
    }
  }
  // Mean and standard deviation of calibrated_z(Z, f) - true Z over a group.
  auto stats = [&](const std::vector<size_t>& group, double truth_mm, auto calibrated_z, double* mean_error,
                   double* std_dev) {
    double sum = 0, sum2 = 0;
    int64_t n = 0;
    for (size_t i : group) {
      for (size_t k = 0; k < samples[i].depth_mm.size(); ++k) {
        const double e = calibrated_z(samples[i].depth_mm[k], samples[i].z_per_radial[k]) - truth_mm;
        sum += e;
        sum2 += e * e;
        ++n;
      }
    }
    *mean_error = sum / n;
    *std_dev = std::sqrt(std::max(0.0, sum2 / n - *mean_error * *mean_error));
    return n;
  };
  for (const auto& group : groups) {
    DistanceStats row;
    row.true_distance_mm = captures[group.front()].true_distance_mm;
    row.samples = stats(
        group, row.true_distance_mm, [](double z, double) { return z; }, &row.mean_error_mm, &row.std_mm);
    row.mean_measured_mm = row.true_distance_mm + row.mean_error_mm;
    // Along the rays: the plane at true Z lies at true Z / f on each ray.
    double radial_sum_mm = 0, radial_error_sum_mm = 0;
    int64_t n = 0;
    for (size_t i : group) {
      for (size_t k = 0; k < samples[i].depth_mm.size(); ++k) {
        const double f = samples[i].z_per_radial[k];
        radial_sum_mm += samples[i].depth_mm[k] / f;
        radial_error_sum_mm += (samples[i].depth_mm[k] - row.true_distance_mm) / f;
        ++n;
      }
    }
    measured_radial_m.push_back(radial_sum_mm / n * 1e-3);
    radial_error_m.push_back(radial_error_sum_mm / n * 1e-3);
    result.rows.push_back(row);
  }
  result.coefficients_m = fit_polynomial(measured_radial_m, radial_error_m, degree);
  const DepthCalibration calibration(result.coefficients_m);
  for (size_t g = 0; g < groups.size(); ++g) {
    DistanceStats& row = result.rows[g];
    stats(
        groups[g], row.true_distance_mm,
        [&](double z_mm, double f) {
          return 1e3 * calibration.apply_z(static_cast<float>(z_mm * 1e-3), static_cast<float>(f));
        },
        &row.mean_error_after_mm, &row.std_after_mm);
  }
  return result;
}

std::string format_table(const CalibrationResult& result) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(1);
  out << "true_mm   samples   measured_mm   error_mm   std_mm   error_after_mm   std_after_mm\n";
  for (const auto& r : result.rows) {
    out << std::setw(7) << r.true_distance_mm << std::setw(10) << r.samples << std::setw(14)
        << r.mean_measured_mm << std::setw(11) << r.mean_error_mm << std::setw(9) << r.std_mm << std::setw(17)
        << r.mean_error_after_mm << std::setw(15) << r.std_after_mm << "\n";
  }
  return out.str();
}

std::string yaml_snippet(const CalibrationResult& result) {
  std::ostringstream out;
  out << std::setprecision(9);
  out << "  # Fitted by tofguard-calibrate-depth: d_calibrated = d - p(d),\n"
      << "  # p(d) = sum_i c_i d^i, d the measured distance along the pixel's ray\n"
      << "  # (radial, not Z) in metres, p in metres.\n"
      << "  depth_calibration:\n"
      << "    degree: " << result.degree << "\n"
      << "    coefficients_m: [";
  for (size_t i = 0; i < result.coefficients_m.size(); ++i) {
    out << (i ? ", " : "") << result.coefficients_m[i];
  }
  out << "]\n";
  return out.str();
}

void draw_plot(const CalibrationResult& result, const std::string& png_path) {
  const int width = 900, height = 600;
  const int left = 90, right = 30, top = 50, bottom = 70;
  cv::Mat canvas(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  double x_min = 1e9, x_max = -1e9, y_min = 0, y_max = 0;
  for (const auto& r : result.rows) {
    x_min = std::min(x_min, r.true_distance_mm * 1e-3);
    x_max = std::max(x_max, r.true_distance_mm * 1e-3);
    y_min = std::min({y_min, r.mean_error_mm - r.std_mm, r.mean_error_after_mm - r.std_after_mm});
    y_max = std::max({y_max, r.mean_error_mm + r.std_mm, r.mean_error_after_mm + r.std_after_mm});
  }
  if (x_max <= x_min) x_max = x_min + 1;
  const double y_pad = 0.08 * (y_max - y_min + 1);
  y_min -= y_pad;
  y_max += y_pad;
  auto px = [&](double x_m, double y_mm) {
    return cv::Point(
        static_cast<int>(std::lround(left + (x_m - x_min) / (x_max - x_min) * (width - left - right))),
        static_cast<int>(std::lround(top + (y_max - y_mm) / (y_max - y_min) * (height - top - bottom))));
  };
  const cv::Scalar black(0, 0, 0), grey(200, 200, 200);
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  // Grid and ticks: every 0.5 m, and 8 steps of round size in y.
  for (double x = std::ceil(x_min * 2) / 2; x <= x_max + 1e-9; x += 0.5) {
    cv::line(canvas, px(x, y_min), px(x, y_max), grey, 1);
    std::ostringstream label;
    label << std::fixed << std::setprecision(1) << x;
    cv::putText(canvas, label.str(), px(x, y_min) + cv::Point(-12, 22), font, 0.5, black, 1);
  }
  const double raw_step = (y_max - y_min) / 8;
  const double magnitude = std::pow(10, std::floor(std::log10(raw_step)));
  const double step = magnitude * (raw_step / magnitude < 2 ? 2 : raw_step / magnitude < 5 ? 5 : 10);
  for (double k = std::ceil(y_min / step); k * step <= y_max; k += 1) {
    const double y = k == 0 ? 0.0 : k * step;  // no "-0" label
    cv::line(canvas, px(x_min, y), px(x_max, y), std::abs(y) < 1e-9 ? black : grey, 1);
    std::ostringstream label;
    label << std::fixed << std::setprecision(step < 1 ? 1 : 0) << y;
    cv::putText(canvas, label.str(), px(x_min, y) + cv::Point(-70, 5), font, 0.5, black, 1);
  }
  cv::rectangle(canvas, px(x_min, y_max), px(x_max, y_min), black, 1);
  cv::putText(canvas, "true distance [m]", cv::Point(width / 2 - 80, height - 20), font, 0.6, black, 1);
  cv::putText(canvas, "error [mm]", cv::Point(10, top - 15), font, 0.6, black, 1);

  auto series = [&](auto mean, auto spread, const cv::Scalar& colour) {
    std::vector<cv::Point> band, line;
    for (const auto& r : result.rows) band.push_back(px(r.true_distance_mm * 1e-3, mean(r) + spread(r)));
    for (auto it = result.rows.rbegin(); it != result.rows.rend(); ++it) {
      band.push_back(px(it->true_distance_mm * 1e-3, mean(*it) - spread(*it)));
    }
    cv::Mat overlay = canvas.clone();
    cv::fillPoly(overlay, std::vector<std::vector<cv::Point>>{band}, colour);
    cv::addWeighted(overlay, 0.25, canvas, 0.75, 0, canvas);
    for (const auto& r : result.rows) line.push_back(px(r.true_distance_mm * 1e-3, mean(r)));
    cv::polylines(canvas, line, false, colour, 2, cv::LINE_AA);
    for (const auto& p : line) cv::circle(canvas, p, 4, colour, cv::FILLED, cv::LINE_AA);
  };
  const cv::Scalar before_colour(40, 40, 220), after_colour(200, 90, 20);  // BGR: red, blue
  series([](const DistanceStats& r) { return r.mean_error_mm; },
         [](const DistanceStats& r) { return r.std_mm; }, before_colour);
  series([](const DistanceStats& r) { return r.mean_error_after_mm; },
         [](const DistanceStats& r) { return r.std_after_mm; }, after_colour);
  cv::putText(canvas, "before calibration (mean, +-1 std)", cv::Point(left + 10, top + 20), font, 0.55,
              before_colour, 2);
  cv::putText(canvas, "after calibration (mean, +-1 std)", cv::Point(left + 10, top + 45), font, 0.55,
              after_colour, 2);
  cv::putText(canvas, "ToF distance error vs distance", cv::Point(width / 2 - 150, 30), font, 0.7, black, 2);
  bool written = false;
  try {
    written = cv::imwrite(png_path, canvas);
  } catch (const cv::Exception&) {
    written = false;
  }
  if (!written) throw CalibrationInputError(png_path + ": cannot write the plot");
}

}  // namespace tofguard::camera
