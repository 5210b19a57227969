// tofguard-calibrate-depth recovers a known systematic error: planar
// captures simulated with the ToF error model (a 5th-order error of
// 58..148 mm over 0.5..5 m along each pixel's ray) are calibrated, along
// the rays, to a mean error below 2 mm at every distance, frames it has not
// seen to below 3 mm at the image centre and in a corner, and the reported
// standard deviations match the simulator's noise within 10 %.
#include "tofguard/camera/calibration_tool.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "sim_test_config.hpp"
#include "tofguard/camera/depth_calibration.hpp"
#include "tofguard/sim/tof_error_model.hpp"
#include "tool_support.hpp"

namespace tofguard::camera {
namespace {

namespace fs = std::filesystem;

constexpr int kFramesPerDistance = 8;
const Roi kRoi{67, 52, 40, 40};  // around the principal point (87.3, 71.8)
// A corner, where Z and the radial distance differ by 10 %.
const Roi kCornerRoi{0, 0, 30, 30};
// The test camera's rays, for the PNG captures.
const PixelRays kRays{221.0, 220.5, 87.3, 71.8};
const char* kRaysText = "221.0,220.5,87.3,71.8";

std::string calibration_dir() { return test::output_dir() + "/calibration"; }

// Writes one PNG folder per distance and the capture list; returns its path.
std::string write_captures(const std::vector<double>& distances_m, const std::string& name, uint64_t seed) {
  const Intrinsics in = sim::sim_test::test_intrinsics();
  sim::SimCameraSettings config = sim::sim_test::test_sim_config();
  config.seed = seed;
  config.dark_pixel_probability = 0.002;
  const sim::TofErrorModel model(config, in);
  const std::string dir = calibration_dir() + "/" + name;
  fs::remove_all(dir);
  std::string csv = "capture,true_distance_mm\n";
  uint64_t frame_index = 0;
  for (const double d : distances_m) {
    const std::string folder = "plane_" + std::to_string(static_cast<int>(d * 1000));
    fs::create_directories(dir + "/" + folder);
    const std::vector<float> plane(static_cast<size_t>(in.width) * in.height, static_cast<float>(d));
    for (int f = 0; f < kFramesPerDistance; ++f) {
      const sim::TofImage image = model.apply(plane, frame_index++, 0.0);
      cv::Mat png(in.height, in.width, CV_16UC1);
      for (int i = 0; i < in.width * in.height; ++i) {
        png.at<uint16_t>(i / in.width, i % in.width) =
            static_cast<uint16_t>(std::lround(image.depth_m[i] * 1000.0));
      }
      char file[32];
      std::snprintf(file, sizeof file, "/frame_%03d.png", f);
      EXPECT_TRUE(cv::imwrite(dir + "/" + folder + file, png));
    }
    csv += folder + "," + std::to_string(d * 1000) + "\n";
  }
  test::write_file(dir + "/captures.csv", csv);
  return dir + "/captures.csv";
}

std::vector<double> calibration_distances() {
  std::vector<double> d;
  for (int i = 1; i <= 10; ++i) d.push_back(0.5 * i);  // 0.5 .. 5 m
  return d;
}

CalibrationResult run_library(const std::string& csv, int degree) {
  const auto captures = read_capture_list(csv);
  std::vector<CaptureSamples> samples;
  for (const auto& c : captures) samples.push_back(load_capture(c, kRoi, "TOF_DEPTH", kRays));
  return calibrate(captures, samples, degree);
}

TEST(CalibrateDepth, RecoversAKnownFifthOrderSystematicError) {
  const std::string csv = write_captures(calibration_distances(), "fit", 11);
  const CalibrationResult result = run_library(csv, 5);
  ASSERT_EQ(result.rows.size(), 10u);
  const sim::TofErrorModel model(sim::sim_test::test_sim_config(), sim::sim_test::test_intrinsics());
  for (const auto& row : result.rows) {
    SCOPED_TRACE("at " + std::to_string(row.true_distance_mm) + " mm");
    EXPECT_GT(row.mean_error_mm, 50.0);
    EXPECT_LT(row.mean_error_mm, 150.0);
    EXPECT_LT(std::abs(row.mean_error_after_mm), 2.0);
    // The simulator's sigma at this distance (Z and r differ by < 0.2 % in
    // the ROI).
    const double sigma_mm = model.noise_sigma_m(row.true_distance_mm * 1e-3) * 1e3;
    EXPECT_NEAR(row.std_mm, sigma_mm, 0.10 * sigma_mm);
    // d - p(d) scales the noise by |1 - p'(d)|.
    double slope = 0;
    for (size_t i = 1; i < result.coefficients_m.size(); ++i) {
      slope += i * result.coefficients_m[i] * std::pow(row.mean_measured_mm * 1e-3, i - 1.0);
    }
    EXPECT_NEAR(row.std_after_mm, std::abs(1 - slope) * sigma_mm, 0.10 * sigma_mm);
    EXPECT_GT(row.samples, kFramesPerDistance * 1500);
  }
  // The fitted correction removes the error from frames it has not seen
  // (another seed), between the calibration distances too, and in a corner
  // of the image as well as at its centre (it works along the rays).
  const DepthCalibration calibration(result.coefficients_m);
  const std::string check_csv = write_captures({0.75, 1.75, 2.75, 3.75, 4.75}, "check", 99);
  for (const auto& capture : read_capture_list(check_csv)) {
    for (const Roi& roi : {kRoi, kCornerRoi}) {
      // The corner's rays are 12 % longer than Z: at 4.75 m they lie beyond
      // the calibrated 0.5..5 m, where a fitted polynomial means nothing.
      if (roi.u0 == kCornerRoi.u0 && capture.true_distance_mm > 4000) continue;
      const CaptureSamples s = load_capture(capture, roi, "TOF_DEPTH", kRays);
      double sum = 0;
      for (size_t k = 0; k < s.depth_mm.size(); ++k) {
        sum += calibration.apply_z(s.depth_mm[k] * 1e-3f, s.z_per_radial[k]) * 1e3;
      }
      EXPECT_LT(std::abs(sum / s.depth_mm.size() - capture.true_distance_mm), 3.0)
          << capture.path << " ROI at " << roi.u0 << "," << roi.v0;
    }
  }
}

TEST(CalibrateDepth, ToolWritesTableYamlAndPlot) {
  const std::string csv = write_captures(calibration_distances(), "tool", 12);
  const std::string yaml = calibration_dir() + "/tool/out.yaml";
  const std::string plot = calibration_dir() + "/tool/out.png";
  std::string out, err;
  ASSERT_EQ(test::run_command("calibrate_depth_tool",
                              {test::bin_dir() + "/tofguard-calibrate-depth", "--captures", csv, "--roi",
                               "67,52,40,40", "--intrinsics", kRaysText, "--yaml", yaml, "--plot", plot},
                              &out, &err),
            0)
      << err;
  EXPECT_NE(out.find("true_mm   samples   measured_mm"), std::string::npos) << out;
  EXPECT_NE(out.find("\n 5000.0"), std::string::npos) << out;
  const std::string snippet = test::read_file(yaml);
  EXPECT_NE(snippet.find("depth_calibration:\n    degree: 5\n    coefficients_m: ["), std::string::npos)
      << snippet;
  const cv::Mat image = cv::imread(plot, cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 900);
  EXPECT_EQ(image.rows, 600);
  int red = 0, blue = 0;
  for (int v = 0; v < image.rows; ++v) {
    for (int u = 0; u < image.cols; ++u) {
      const cv::Vec3b p = image.at<cv::Vec3b>(v, u);
      red += p == cv::Vec3b(40, 40, 220);
      blue += p == cv::Vec3b(200, 90, 20);
    }
  }
  EXPECT_GT(red, 200);   // the "before" curve
  EXPECT_GT(blue, 200);  // the "after" curve
}

std::string tool_error(const std::string& name, const std::vector<std::string>& args) {
  std::vector<std::string> argv = {test::bin_dir() + "/tofguard-calibrate-depth"};
  argv.insert(argv.end(), args.begin(), args.end());
  std::string err;
  EXPECT_EQ(test::run_command(name, argv, nullptr, &err), 2) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << "one line: " << err;
  return err;
}

TEST(CalibrateDepth, BadInputGivesOneClearLine) {
  const std::string csv = write_captures({1.0, 2.0, 3.0}, "few", 13);
  const std::string few =
      tool_error("calibrate_few", {"--captures", csv, "--roi", "67,52,40,40", "--intrinsics", kRaysText});
  EXPECT_NE(few.find("a degree-5 calibration needs at least 6 different distances, the list has 3"),
            std::string::npos)
      << few;
  const std::string outside =
      tool_error("calibrate_roi", {"--captures", csv, "--roi", "150,100,40,40", "--intrinsics", kRaysText});
  EXPECT_NE(outside.find("ROI 150,100,40,40 lies outside the 176x144 image"), std::string::npos) << outside;
  const std::string missing_csv = calibration_dir() + "/missing.csv";
  test::write_file(missing_csv, "capture,true_distance_mm\nnowhere,1000\n");
  const std::string missing =
      tool_error("calibrate_missing", {"--captures", missing_csv, "--roi", "0,0,4,4"});
  EXPECT_NE(missing.find("missing.csv:2: "), std::string::npos) << missing;
  EXPECT_NE(missing.find("nowhere: no such file or folder"), std::string::npos) << missing;
  const std::string roi = tool_error("calibrate_roi_text", {"--captures", csv, "--roi", "1,2,3"});
  EXPECT_NE(roi.find("--roi: expected U0,V0,WIDTH,HEIGHT"), std::string::npos) << roi;
  const std::string no_rays = tool_error("calibrate_no_rays", {"--captures", csv, "--roi", "67,52,40,40"});
  EXPECT_NE(no_rays.find("carry no intrinsics: give --intrinsics FX,FY,CX,CY"), std::string::npos) << no_rays;
  const std::string bad_rays = tool_error(
      "calibrate_bad_rays", {"--captures", csv, "--roi", "67,52,40,40", "--intrinsics", "221,0,87,71"});
  EXPECT_NE(bad_rays.find("--intrinsics: expected FX,FY,CX,CY in pixels"), std::string::npos) << bad_rays;
}

}  // namespace
}  // namespace tofguard::camera
