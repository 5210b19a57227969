#include "tofguard/common/camera_profile.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "tofguard/common/depth_frame.hpp"
#include "tofguard/common/yaml_reader.hpp"

namespace tofguard {
namespace {

// Intrinsics agree when they differ by less than this (pixels): the
// profile's pixel map and rays are the camera's own.
constexpr double kIntrinsicsTolerancePx = 1e-3;

std::string number(double value) {
  std::ostringstream s;
  s << std::setprecision(10) << value;
  return s.str();
}

}  // namespace

double CameraProfile::distance_correction_at(double r_m) const {
  const auto n = static_cast<int>(distance_correction_mm.size());
  if (n == 0) return 0;
  const double k = (r_m - distance_first_m) / distance_bin_m;
  if (!(k > 0)) return distance_correction_mm.front();
  if (k >= n - 1) return distance_correction_mm.back();
  const int below = static_cast<int>(k);
  const double w = k - below;
  return (1 - w) * distance_correction_mm[static_cast<size_t>(below)] +
         w * distance_correction_mm[static_cast<size_t>(below + 1)];
}

std::string profile_mismatch(const CameraProfile& p, const depth_image_t& frame) {
  return profile_mismatch(p, frame.camera_id, intrinsics_of(frame));
}

std::string profile_mismatch(const CameraProfile& p, const std::string& camera_id, const Intrinsics& in) {
  const std::string head = "camera profile " + (p.file.empty() ? std::string("(in memory)") : p.file) + ": ";
  if (camera_id != p.camera_id) {
    return head + "made for camera_id '" + p.camera_id + "', the frame is from '" + camera_id + "'";
  }
  if (in.width != p.width || in.height != p.height) {
    return head + "made for " + std::to_string(p.width) + "x" + std::to_string(p.height) + ", the frame is " +
           std::to_string(in.width) + "x" + std::to_string(in.height);
  }
  const double mine[4] = {p.fx, p.fy, p.cx, p.cy};
  const double theirs[4] = {in.fx, in.fy, in.cx, in.cy};
  const char* names[4] = {"fx", "fy", "cx", "cy"};
  for (int k = 0; k < 4; ++k) {
    if (!(std::abs(mine[k] - theirs[k]) < kIntrinsicsTolerancePx)) {
      return head + "made for " + names[k] + " " + number(mine[k]) + ", the frame has " + number(theirs[k]);
    }
  }
  return "";
}

namespace {

// CameraProfile::fixed_pattern_mm of a width x height map.
std::vector<float> fixed_pattern_of(const std::vector<float>& map, int width, int height) {
  std::vector<float> pattern(map.size(), 0.0f);
  if (map.size() != static_cast<size_t>(width) * static_cast<size_t>(height)) return pattern;
  std::vector<float> window;
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const size_t i = static_cast<size_t>(v) * width + u;
      if (map[i] == 0.0f) continue;
      window.clear();
      for (int b = std::max(v - 2, 0); b <= std::min(v + 2, height - 1); ++b) {
        for (int a = std::max(u - 2, 0); a <= std::min(u + 2, width - 1); ++a) {
          const float c = map[static_cast<size_t>(b) * width + a];
          if (c != 0.0f) window.push_back(c);
        }
      }
      if (static_cast<int>(window.size()) < kFixedPatternMinNeighbours) continue;
      const auto middle = window.begin() + static_cast<std::ptrdiff_t>(window.size() / 2);
      std::nth_element(window.begin(), middle, window.end());
      pattern[i] = map[i] - *middle;
    }
  }
  return pattern;
}

}  // namespace

void derive_fixed_pattern(CameraProfile* p) {
  p->fixed_pattern_mm = fixed_pattern_of(p->pixel_correction_mm, p->width, p->height);
}

void apply_camera_profile(const CameraProfile& p, depth_image_t* frame, const link_labels_t* labels) {
  const size_t pixels = static_cast<size_t>(p.width) * static_cast<size_t>(p.height);
  if (frame->depth_mm.size() != pixels || p.pixel_correction_mm.size() != pixels) return;
  const bool by_label = labels != nullptr && labels->label.size() == pixels;
  const bool derive_here = by_label && p.fixed_pattern_mm.size() != pixels;
  const std::vector<float> derived =
      derive_here ? fixed_pattern_of(p.pixel_correction_mm, p.width, p.height) : std::vector<float>();
  const std::vector<float>& fixed_pattern = derive_here ? derived : p.fixed_pattern_mm;
  for (int v = 0; v < p.height; ++v) {
    for (int u = 0; u < p.width; ++u) {
      const size_t i = static_cast<size_t>(v) * p.width + u;
      const int z_mm = frame->depth_mm[i];
      if (z_mm <= 0) continue;
      const double f = z_per_radial(p.fx, p.fy, p.cx, p.cy, u, v);
      const double r_m = z_mm * 1e-3 / f;
      const bool moving = by_label && on_moving_link(*labels, labels->label[i]);
      const double pixel_mm = moving ? fixed_pattern[i] : p.pixel_correction_mm[i];
      const double corrected = z_mm + f * p.distance_correction_at(r_m) + pixel_mm;
      frame->depth_mm[i] =
          corrected >= 1 && corrected <= 32767 ? static_cast<int16_t>(std::lround(corrected)) : 0;
    }
  }
}

void add_profile_coverage(const CameraProfile& p, const depth_image_t& rendered, const link_labels_t& labels,
                          const std::vector<uint8_t>& used, ProfileCoverage* coverage) {
  coverage->first_m = p.distance_first_m;
  coverage->last_m =
      p.distance_first_m +
      p.distance_bin_m * static_cast<double>(std::max<size_t>(p.distance_correction_mm.size(), 1) - 1);
  const size_t pixels = static_cast<size_t>(p.width) * static_cast<size_t>(p.height);
  if (rendered.depth_mm.size() != pixels || labels.label.size() != pixels) return;
  if (!used.empty() && used.size() != pixels) return;
  const double lowest_m = coverage->first_m - p.distance_bin_m;
  const double highest_m = coverage->last_m + p.distance_bin_m;
  for (int v = 0; v < p.height; ++v) {
    for (int u = 0; u < p.width; ++u) {
      const size_t i = static_cast<size_t>(v) * p.width + u;
      const int z_mm = rendered.depth_mm[i];
      if (z_mm <= 0 || (!used.empty() && !used[i]) || !on_moving_link(labels, labels.label[i])) continue;
      const double r_m = z_mm * 1e-3 / z_per_radial(p.fx, p.fy, p.cx, p.cy, u, v);
      ++coverage->pixels;
      if (r_m >= lowest_m && r_m <= highest_m) continue;
      ++coverage->outside;
      if (coverage->nearest_m == 0 || r_m < coverage->nearest_m) coverage->nearest_m = r_m;
      coverage->farthest_m = std::max(coverage->farthest_m, r_m);
    }
  }
}

CameraProfile read_camera_profile(const std::string& path) {
  YamlMap map = load_yaml_file(path);
  CameraProfile p;
  p.file = path;
  p.camera_id = map.string("camera_id");
  p.width = static_cast<int>(map.integer("width", 1, 10000));
  p.height = static_cast<int>(map.integer("height", 1, 10000));
  const std::vector<double> intrinsics = map.numbers("intrinsics_fx_fy_cx_cy", 4);
  p.fx = intrinsics[0];
  p.fy = intrinsics[1];
  p.cx = intrinsics[2];
  p.cy = intrinsics[3];
  if (!(p.fx > 0) || !(p.fy > 0)) map.fail("intrinsics_fx_fy_cx_cy", "fx and fy > 0");
  p.distance_first_m = map.number("distance_first_m", 0, 100);
  p.distance_bin_m = map.number("distance_bin_m", 0.001, 10);
  p.distance_correction_mm = map.numbers("distance_correction_mm", -1);
  if (p.distance_correction_mm.empty()) map.fail("distance_correction_mm", "at least one bin");
  for (double c : p.distance_correction_mm) {
    if (std::abs(c) > 1000) map.fail("distance_correction_mm", "corrections within +-1000 mm", number(c));
  }
  const std::vector<double> pixels = map.numbers("pixel_correction_mm", p.width * p.height);
  p.pixel_correction_mm.assign(pixels.begin(), pixels.end());
  for (double c : pixels) {
    if (std::abs(c) > 1000) map.fail("pixel_correction_mm", "corrections within +-1000 mm", number(c));
  }
  p.measured_on = map.string("measured_on");
  map.finish();
  derive_fixed_pattern(&p);
  return p;
}

std::string camera_profile_yaml(const CameraProfile& p) {
  std::ostringstream out;
  out << "# A ToF camera's profile (docs/camera.md, \"Commissioning a camera\"): added to each frame's\n"
      << "# depth Z where frames are compared: Z' = Z + f * c(r) + pixel_correction_mm,\n"
      << "# r = Z / f the radial distance, c interpolated between the bins of distance_correction_mm.\n"
      << "camera_id: " << p.camera_id << "\n"
      << "width: " << p.width << "\n"
      << "height: " << p.height << "\n"
      << "intrinsics_fx_fy_cx_cy: [" << number(p.fx) << ", " << number(p.fy) << ", " << number(p.cx) << ", "
      << number(p.cy) << "]\n"
      << "measured_on: \"" << p.measured_on << "\"\n"
      << "distance_first_m: " << number(p.distance_first_m) << "\n"
      << "distance_bin_m: " << number(p.distance_bin_m) << "\n"
      << "distance_correction_mm: [";
  for (size_t k = 0; k < p.distance_correction_mm.size(); ++k) {
    out << (k ? ", " : "") << std::fixed << std::setprecision(2) << p.distance_correction_mm[k];
  }
  out << "]\n# Row-major, width x height, mm; 0 where not measured.\npixel_correction_mm: [";
  for (size_t i = 0; i < p.pixel_correction_mm.size(); ++i) {
    if (i > 0) out << (i % static_cast<size_t>(std::max(p.width, 1)) == 0 ? ",\n  " : ", ");
    out << std::fixed << std::setprecision(1) << p.pixel_correction_mm[i];
  }
  out << "]\n";
  return out.str();
}

}  // namespace tofguard
