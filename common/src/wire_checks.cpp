#include "tofguard/common/wire_checks.hpp"

#include "tofguard/common/body_region.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>
#include <tuple>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace tofguard {
namespace {

std::string expected(const std::string& field, const std::string& what, double got) {
  std::ostringstream s;
  s << field << ": expected " << what << ", got " << got;
  return s.str();
}

std::string check_size(int32_t width, int32_t height) {
  if (width <= 0 || width > kMaxImageSide) {
    return expected("width", "1.." + std::to_string(kMaxImageSide), width);
  }
  if (height <= 0 || height > kMaxImageSide) {
    return expected("height", "1.." + std::to_string(kMaxImageSide), height);
  }
  return "";
}

// "" when names are non-empty and unique.
std::string check_names(const std::vector<std::string>& names, const std::string& field) {
  std::set<std::string> seen;
  for (size_t i = 0; i < names.size(); ++i) {
    const std::string at = field + "[" + std::to_string(i) + "]";
    if (names[i].empty()) return at + ": expected a joint name, got an empty string";
    if (!seen.insert(names[i]).second)
      return at + ": expected unique joint names, got '" + names[i] + "' twice";
  }
  return "";
}

// The rule is UnitQuaternion::check (camera_geometry.hpp).
std::string check_unit_quaternion(const double q[4], const std::string& field) {
  const auto v =
      UnitQuaternion::check(Eigen::Quaterniond(q[0], q[1], q[2], q[3]), kWireQuaternionTolerance, field);
  return v ? v->line() : "";
}

// A moving axis' direction must be a unit vector within this.
constexpr double kAxisDirectionTolerance = 1e-6;

template <typename T>
std::string check_count(int32_t n, const std::vector<T>& array, const std::string& field,
                        const std::string& count) {
  if (n < 0) return expected(count, "a count >= 0", n);
  if (array.size() != static_cast<size_t>(n)) {
    return field + ": expected " + count + " = " + std::to_string(n) + " entries, got " +
           std::to_string(array.size());
  }
  return "";
}

// A per-joint array of discrepancy_t's evidence: num_joints entries, each
// finite (and >= 0 when `non_negative`).
std::string check_joint_values(int32_t num_joints, const std::vector<double>& values,
                               const std::string& field, bool non_negative) {
  if (auto p = check_count(num_joints, values, field, "num_joints"); !p.empty()) return p;
  for (int j = 0; j < num_joints; ++j) {
    if (!std::isfinite(values[j]) || (non_negative && values[j] < 0)) {
      return expected(field + "[" + std::to_string(j) + "]",
                      non_negative ? "a finite number >= 0" : "a finite number", values[j]);
    }
  }
  return "";
}

// link_labels_t's kinematics (num_joints .. link_axis).
std::string check_kinematics(const link_labels_t& l) {
  if (auto p = check_count(l.num_joints, l.joint_name, "joint_name", "num_joints"); !p.empty()) return p;
  if (auto p = check_names(l.joint_name, "joint_name"); !p.empty()) return p;
  for (const auto& [size, field] : {std::pair<size_t, const char*>{l.axis_joint.size(), "axis_joint"},
                                    {l.axis_multiplier.size(), "axis_multiplier"},
                                    {l.axis_prismatic.size(), "axis_prismatic"},
                                    {l.axis_origin_m.size(), "axis_origin_m"},
                                    {l.axis_direction.size(), "axis_direction"},
                                    {l.axis_parent.size(), "axis_parent"}}) {
    if (l.num_axes < 0) return expected("num_axes", "a count >= 0", l.num_axes);
    if (size != static_cast<size_t>(l.num_axes)) {
      return std::string(field) + ": expected num_axes = " + std::to_string(l.num_axes) + " entries, got " +
             std::to_string(size);
    }
  }
  if (auto p = check_count(l.num_link_axes, l.link_axis, "link_axis", "num_link_axes"); !p.empty()) return p;
  if (l.num_axes == 0) {
    if (l.num_link_axes != 0) return expected("num_link_axes", "0 when num_axes is 0", l.num_link_axes);
    return "";
  }
  if (l.num_link_axes != l.num_robot_links) {
    return expected("num_link_axes", "num_robot_links = " + std::to_string(l.num_robot_links),
                    l.num_link_axes);
  }
  for (int m = 0; m < l.num_axes; ++m) {
    const std::string at = "[" + std::to_string(m) + "]";
    if (l.axis_joint[m] < 0 || l.axis_joint[m] >= l.num_joints) {
      return expected("axis_joint" + at,
                      "a joint index 0..num_joints-1 = " + std::to_string(l.num_joints - 1), l.axis_joint[m]);
    }
    if (!std::isfinite(l.axis_multiplier[m])) {
      return expected("axis_multiplier" + at, "a finite number", l.axis_multiplier[m]);
    }
    if (l.axis_origin_m[m].size() != 3 || l.axis_direction[m].size() != 3) {
      return "axis_origin_m" + at + " / axis_direction" + at + ": expected 3 coordinates";
    }
    double norm2 = 0;
    for (int c = 0; c < 3; ++c) {
      if (!std::isfinite(l.axis_origin_m[m][c])) {
        return expected("axis_origin_m" + at, "finite coordinates (m)", l.axis_origin_m[m][c]);
      }
      if (!std::isfinite(l.axis_direction[m][c])) {
        return expected("axis_direction" + at, "a finite unit vector", l.axis_direction[m][c]);
      }
      norm2 += l.axis_direction[m][c] * l.axis_direction[m][c];
    }
    if (!(std::abs(std::sqrt(norm2) - 1) <= kAxisDirectionTolerance)) {
      return expected("axis_direction" + at, "a unit vector (length 1 within 1e-6)", std::sqrt(norm2));
    }
    if (l.axis_parent[m] < -1 || l.axis_parent[m] >= m) {
      return expected("axis_parent" + at, "-1 or an axis index below " + std::to_string(m), l.axis_parent[m]);
    }
  }
  for (int i = 0; i < l.num_link_axes; ++i) {
    if (l.link_axis[i] < -1 || l.link_axis[i] >= l.num_axes) {
      return expected("link_axis[" + std::to_string(i) + "]",
                      "-1 or an axis index 0..num_axes-1 = " + std::to_string(l.num_axes - 1),
                      l.link_axis[i]);
    }
  }
  return "";
}

// discrepancy_t's protective-field fields (field_bin_m ..
// unexplained_area_within_m2).
std::string check_field(const discrepancy_t& d) {
  if (auto p = check_count(d.num_field_bins, d.unexplained_area_within_m2, "unexplained_area_within_m2",
                           "num_field_bins");
      !p.empty())
    return p;
  if (d.num_field_bins > 0 && !(std::isfinite(d.field_bin_m) && d.field_bin_m > 0)) {
    return expected("field_bin_m", "a bin width > 0 (m)", d.field_bin_m);
  }
  float previous = 0;
  for (int k = 0; k < d.num_field_bins; ++k) {
    const float area = d.unexplained_area_within_m2[k];
    if (!(std::isfinite(area) && area >= previous)) {
      return expected("unexplained_area_within_m2[" + std::to_string(k) + "]",
                      "a finite cumulative area >= the previous bin's " + std::to_string(previous) + " m^2",
                      area);
    }
    previous = area;
  }
  return "";
}

// discrepancy_t's evidence fields.
std::string check_evidence(const discrepancy_t& d) {
  const auto finite_array = [](const double* v, int n, const std::string& field) -> std::string {
    for (int i = 0; i < n; ++i) {
      if (!std::isfinite(v[i]))
        return expected(field + "[" + std::to_string(i) + "]", "a finite number", v[i]);
    }
    return "";
  };
  if (auto p = check_count(d.num_link_bias, d.link_bias_mm, "link_bias_mm", "num_link_bias"); !p.empty())
    return p;
  if (auto p = check_count(d.num_link_bias, d.link_bias_sigma_mm, "link_bias_sigma_mm", "num_link_bias");
      !p.empty()) {
    return p;
  }
  if (d.num_link_bias != 0 && d.num_link_bias != d.num_links) {
    return expected("num_link_bias", "0 or num_links = " + std::to_string(d.num_links), d.num_link_bias);
  }
  for (int i = 0; i < d.num_link_bias; ++i) {
    if (!std::isfinite(d.link_bias_mm[i])) {
      return expected("link_bias_mm[" + std::to_string(i) + "]", "a finite bias (mm)", d.link_bias_mm[i]);
    }
    if (!(std::isfinite(d.link_bias_sigma_mm[i]) && d.link_bias_sigma_mm[i] >= 0)) {
      return expected("link_bias_sigma_mm[" + std::to_string(i) + "]", "a finite sigma >= 0 (mm)",
                      d.link_bias_sigma_mm[i]);
    }
  }
  if (d.camera_fit_pixels < 0) return expected("camera_fit_pixels", "a count >= 0", d.camera_fit_pixels);
  if (auto p = finite_array(d.camera_score, 6, "camera_score"); !p.empty()) return p;
  if (auto p = finite_array(d.camera_information, 36, "camera_information"); !p.empty()) return p;
  if (auto p = finite_array(d.camera_correction, 6, "camera_correction"); !p.empty()) return p;
  for (int k = 0; k < 6; ++k) {
    if (d.camera_information[7 * k] < 0) {
      return expected("camera_information[" + std::to_string(7 * k) + "]", "a diagonal entry >= 0",
                      d.camera_information[7 * k]);
    }
  }
  if (!(std::isfinite(d.static_chi2) && d.static_chi2 >= 0)) {
    return expected("static_chi2", "a finite sum >= 0", d.static_chi2);
  }
  for (int r = 0; r < 4; ++r) {
    if (d.camera_region_fit_pixels[r] < 0) {
      return expected("camera_region_fit_pixels[" + std::to_string(r) + "]", "a count >= 0",
                      d.camera_region_fit_pixels[r]);
    }
  }
  if (auto p = finite_array(d.camera_region_score, 24, "camera_region_score"); !p.empty()) return p;
  if (auto p = finite_array(d.camera_region_information, 24, "camera_region_information"); !p.empty())
    return p;
  for (int k = 0; k < 24; ++k) {
    if (d.camera_region_information[k] < 0) {
      return expected("camera_region_information[" + std::to_string(k) + "]", "an information >= 0",
                      d.camera_region_information[k]);
    }
  }
  if (!std::isfinite(d.distance_offset_score))
    return expected("distance_offset_score", "a finite score", d.distance_offset_score);
  if (!(std::isfinite(d.distance_offset_information) && d.distance_offset_information >= 0)) {
    return expected("distance_offset_information", "a finite information >= 0",
                    d.distance_offset_information);
  }
  if (auto p = finite_array(d.distance_offset_cross, 6, "distance_offset_cross"); !p.empty()) return p;
  for (int k = 0; k < 24; ++k) {
    if (k < 6 && !(std::isfinite(d.camera_static_bound[k]) && d.camera_static_bound[k] >= 0)) {
      return expected("camera_static_bound[" + std::to_string(k) + "]", "a finite bound >= 0",
                      d.camera_static_bound[k]);
    }
    if (!(std::isfinite(d.camera_region_static_bound[k]) && d.camera_region_static_bound[k] >= 0)) {
      return expected("camera_region_static_bound[" + std::to_string(k) + "]", "a finite bound >= 0",
                      d.camera_region_static_bound[k]);
    }
  }
  if (auto p = check_count(d.num_joints, d.joint_name, "joint_name", "num_joints"); !p.empty()) return p;
  if (auto p = check_count(d.num_joints, d.joint_fit_pixels, "joint_fit_pixels", "num_joints"); !p.empty())
    return p;
  if (auto p = check_names(d.joint_name, "joint_name"); !p.empty()) return p;
  for (int j = 0; j < d.num_joints; ++j) {
    if (d.joint_fit_pixels[j] < 0) {
      return expected("joint_fit_pixels[" + std::to_string(j) + "]", "a count >= 0", d.joint_fit_pixels[j]);
    }
  }
  // Scores and offsets may have either sign; information and gains not.
  for (const auto& [values, field, non_negative] :
       {std::tuple{&d.joint_score, "joint_score", false},
        std::tuple{&d.joint_information, "joint_information", true},
        std::tuple{&d.joint_naming_score, "joint_naming_score", false},
        std::tuple{&d.joint_naming_information, "joint_naming_information", true},
        std::tuple{&d.joint_static_bound, "joint_static_bound", true},
        std::tuple{&d.joint_search_offset, "joint_search_offset", false},
        std::tuple{&d.joint_search_gain, "joint_search_gain", true},
        std::tuple{&d.joint_reach_m, "joint_reach_m", true}}) {
    if (auto p = check_joint_values(d.num_joints, *values, field, non_negative); !p.empty()) return p;
  }
  if (d.robot_fit_pixels < 0) return expected("robot_fit_pixels", "a count >= 0", d.robot_fit_pixels);
  if (!(std::isfinite(d.robot_chi2) && d.robot_chi2 >= 0)) {
    return expected("robot_chi2", "a finite sum >= 0", d.robot_chi2);
  }
  if (d.search_points < 0) return expected("search_points", "a count >= 0", d.search_points);
  if (d.camera_search_static_points < 0) {
    return expected("camera_search_static_points", "a count >= 0", d.camera_search_static_points);
  }
  if (d.camera_search_axis < -1 || d.camera_search_axis > 5) {
    return expected("camera_search_axis", "-1 (none) or an optical axis 0..5", d.camera_search_axis);
  }
  if (!std::isfinite(d.camera_search_offset)) {
    return expected("camera_search_offset", "a finite number", d.camera_search_offset);
  }
  if (!(std::isfinite(d.camera_search_gain) && d.camera_search_gain >= 0)) {
    return expected("camera_search_gain", "a finite gain >= 0", d.camera_search_gain);
  }
  return "";
}

// num_body_regions .. body_region_separation_m (link_labels_t and
// discrepancy_t alike): counts, a known body region each, once, and a
// finite separation >= 0.
std::string check_body_regions(int32_t n, const std::vector<std::string>& names,
                               const std::vector<float>& separations_m) {
  if (auto p = check_count(n, names, "body_region", "num_body_regions"); !p.empty()) return p;
  if (auto p = check_count(n, separations_m, "body_region_separation_m", "num_body_regions"); !p.empty())
    return p;
  for (int k = 0; k < n; ++k) {
    const std::string at = "[" + std::to_string(k) + "]";
    if (!body_region_named(names[k]) || std::count(names.begin(), names.begin() + k, names[k]) > 0) {
      return "body_region" + at + ": expected a body region named once (one of " + body_region_names() +
             "), got '" + names[k] + "'";
    }
    if (!(std::isfinite(separations_m[k]) && separations_m[k] >= 0)) {
      return expected("body_region_separation_m" + at, "a finite separation >= 0 (m)", separations_m[k]);
    }
  }
  return "";
}

// A vector of `n` entries of `width` finite floats each.
std::string check_rows(const std::vector<std::vector<float>>& rows, int32_t n, size_t width,
                       const std::string& field, const std::string& count) {
  if (auto p = check_count(n, rows, field, count); !p.empty()) return p;
  for (int32_t k = 0; k < n; ++k) {
    if (rows[k].size() != width) {
      return field + "[" + std::to_string(k) + "]: expected " + std::to_string(width) + " entries, got " +
             std::to_string(rows[k].size());
    }
    for (float x : rows[k]) {
      if (!std::isfinite(x)) return expected(field + "[" + std::to_string(k) + "]", "finite numbers", x);
    }
  }
  return "";
}

// link_labels_t's body_region_envelope_m and occupant_shape_*: an
// envelope >= 0 per region; per shape a known kind, a region index, a
// finite centre, sizes >= 0 and a rotation (orthonormal, det +1, to 1e-3).
std::string check_occupant_shapes(const link_labels_t& labels) {
  const int32_t regions = labels.num_body_regions;
  if (auto p =
          check_count(regions, labels.body_region_envelope_m, "body_region_envelope_m", "num_body_regions");
      !p.empty())
    return p;
  for (int32_t k = 0; k < regions; ++k) {
    const float e = labels.body_region_envelope_m[k];
    if (!(std::isfinite(e) && e >= 0)) {
      return expected("body_region_envelope_m[" + std::to_string(k) + "]", "a finite envelope >= 0 (m)", e);
    }
  }
  const int32_t n = labels.num_occupant_shapes;
  const std::string count = "num_occupant_shapes";
  if (auto p = check_count(n, labels.occupant_shape_kind, "occupant_shape_kind", count); !p.empty()) return p;
  if (auto p = check_count(n, labels.occupant_shape_region, "occupant_shape_region", count); !p.empty())
    return p;
  if (auto p = check_rows(labels.occupant_shape_center_m, n, 3, "occupant_shape_center_m", count); !p.empty())
    return p;
  if (auto p = check_rows(labels.occupant_shape_rotation, n, 9, "occupant_shape_rotation", count); !p.empty())
    return p;
  if (auto p = check_rows(labels.occupant_shape_size_m, n, 3, "occupant_shape_size_m", count); !p.empty())
    return p;
  for (int32_t k = 0; k < n; ++k) {
    const std::string at = "[" + std::to_string(k) + "]";
    const int kind = labels.occupant_shape_kind[k];
    if (kind < link_labels_t::SHAPE_BOX || kind > link_labels_t::SHAPE_CYLINDER) {
      return expected("occupant_shape_kind" + at, "SHAPE_BOX, SHAPE_SPHERE or SHAPE_CYLINDER", kind);
    }
    const int region = labels.occupant_shape_region[k];
    if (region < 0 || region >= regions) {
      return expected("occupant_shape_region" + at, "a body_region index 0.." + std::to_string(regions - 1),
                      region);
    }
    for (float x : labels.occupant_shape_size_m[k]) {
      if (x < 0) return expected("occupant_shape_size_m" + at, "sizes >= 0 (m)", x);
    }
    Eigen::Matrix3d r;
    for (int i = 0; i < 9; ++i) r(i / 3, i % 3) = labels.occupant_shape_rotation[k][i];
    const double off = (r * r.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (!(off <= 1e-3 && r.determinant() > 0)) {
      return expected("occupant_shape_rotation" + at, "a rotation (R R^T = I to 1e-3, det +1): largest error",
                      off);
    }
  }
  return "";
}

// discrepancy_t's per-region sightings: counts per region, 0 <= missing <=
// modelled, seen >= 0, and a seen separation that is -1 or finite >= 0;
// the robot pixels hidden by the user 0..num_pixels.
std::string check_region_sightings(const discrepancy_t& d) {
  const int32_t n = d.num_body_regions;
  const std::string count = "num_body_regions";
  if (auto p = check_count(n, d.body_region_modelled_pixels, "body_region_modelled_pixels", count);
      !p.empty())
    return p;
  if (auto p = check_count(n, d.body_region_missing_pixels, "body_region_missing_pixels", count); !p.empty())
    return p;
  if (auto p = check_count(n, d.body_region_seen_pixels, "body_region_seen_pixels", count); !p.empty())
    return p;
  if (auto p = check_count(n, d.body_region_seen_separation_m, "body_region_seen_separation_m", count);
      !p.empty())
    return p;
  for (int32_t k = 0; k < n; ++k) {
    const std::string at = "[" + std::to_string(k) + "]";
    if (!(d.body_region_missing_pixels[k] >= 0 &&
          d.body_region_missing_pixels[k] <= d.body_region_modelled_pixels[k])) {
      return expected("body_region_missing_pixels" + at, "0..body_region_modelled_pixels",
                      d.body_region_missing_pixels[k]);
    }
    if (d.body_region_seen_pixels[k] < 0) {
      return expected("body_region_seen_pixels" + at, "a count >= 0", d.body_region_seen_pixels[k]);
    }
    const float sep = d.body_region_seen_separation_m[k];
    if (!(sep == -1.0f || (std::isfinite(sep) && sep >= 0))) {
      return expected("body_region_seen_separation_m" + at, "-1 (none seen) or a finite separation >= 0 (m)",
                      sep);
    }
  }
  if (!(d.num_robot_hidden_by_user >= 0 && d.num_robot_hidden_by_user <= d.num_pixels)) {
    return expected("num_robot_hidden_by_user", "0..num_pixels", d.num_robot_hidden_by_user);
  }
  if (!(d.registration_points >= 0 && d.registration_points <= d.num_pixels)) {
    return expected("registration_points", "0..num_pixels", d.registration_points);
  }
  if (!(d.registration_mismatch_fraction >= 0 && d.registration_mismatch_fraction <= 1)) {
    return expected("registration_mismatch_fraction", "a fraction 0..1", d.registration_mismatch_fraction);
  }
  if (!std::isfinite(d.registration_median_mm)) {
    return expected("registration_median_mm", "a finite number (mm)", d.registration_median_mm);
  }
  if (!(d.num_robot_hidden_by_objects >= 0 && d.num_robot_hidden_by_objects <= d.num_pixels)) {
    return expected("num_robot_hidden_by_objects", "0..num_pixels", d.num_robot_hidden_by_objects);
  }
  return "";
}

}  // namespace

std::string check_arm_cover(const link_labels_t& l) {
  if (auto p = check_count(l.num_arm_spheres, l.arm_sphere_link, "arm_sphere_link", "num_arm_spheres");
      !p.empty())
    return p;
  if (auto p =
          check_count(l.num_arm_spheres, l.arm_sphere_center_m, "arm_sphere_center_m", "num_arm_spheres");
      !p.empty())
    return p;
  if (auto p =
          check_count(l.num_arm_spheres, l.arm_sphere_radius_m, "arm_sphere_radius_m", "num_arm_spheres");
      !p.empty())
    return p;
  if (!std::isfinite(l.arm_cover_max_radius_m) || l.arm_cover_max_radius_m < 0) {
    return expected("arm_cover_max_radius_m", "a finite radius >= 0 (m)", l.arm_cover_max_radius_m);
  }
  for (int k = 0; k < l.num_arm_spheres; ++k) {
    const std::string at = "[" + std::to_string(k) + "]";
    if (l.arm_sphere_link[k] < 0 || l.arm_sphere_link[k] >= l.num_robot_links) {
      return expected("arm_sphere_link" + at,
                      "a robot link index 0..num_robot_links-1 = " + std::to_string(l.num_robot_links - 1),
                      l.arm_sphere_link[k]);
    }
    if (l.arm_sphere_center_m[k].size() != 3) return "arm_sphere_center_m" + at + ": expected 3 coordinates";
    for (int c = 0; c < 3; ++c) {
      if (!std::isfinite(l.arm_sphere_center_m[k][c])) {
        return expected("arm_sphere_center_m" + at, "finite coordinates (m)", l.arm_sphere_center_m[k][c]);
      }
    }
    const double r = l.arm_sphere_radius_m[k];
    // (float radii against a double maximum: one float rounding allowed)
    if (!std::isfinite(r) || r < 0 || r > l.arm_cover_max_radius_m * (1 + 1e-6)) {
      return expected("arm_sphere_radius_m" + at,
                      "a radius 0..arm_cover_max_radius_m = " + std::to_string(l.arm_cover_max_radius_m), r);
    }
  }
  return "";
}

std::string check_depth_image(const depth_image_t& image) {
  if (image.camera_id.empty()) return "camera_id: expected a camera name, got an empty string";
  if (image.utime <= 0) return expected("utime", "a capture time > 0", static_cast<double>(image.utime));
  if (image.seq < 0) return expected("seq", "a frame number >= 0", static_cast<double>(image.seq));
  if (auto problem = check_size(image.width, image.height); !problem.empty()) return problem;
  const int64_t pixels = int64_t{image.width} * image.height;
  if (image.num_pixels != pixels) {
    return expected("num_pixels", "width*height = " + std::to_string(pixels), image.num_pixels);
  }
  if (image.num_amplitude != 0 && image.num_amplitude != pixels) {
    return expected("num_amplitude", "0 or width*height = " + std::to_string(pixels), image.num_amplitude);
  }
  if (auto v = Intrinsics::check(image.width, image.height, image.fx, image.fy, image.cx, image.cy))
    return v->line();
  return "";
}

std::string check_depth_image_from(const depth_image_t& image, const std::string& camera_id) {
  std::string problem = check_depth_image(image);
  if (problem.empty() && image.camera_id != camera_id) {
    problem = "camera_id: expected '" + camera_id + "', got '" + image.camera_id + "'";
  }
  return problem;
}

std::string check_joint_state(const joint_state_t& state) {
  if (state.num_joints < 0) return expected("num_joints", "a count >= 0", state.num_joints);
  if (auto problem = check_names(state.name, "name"); !problem.empty()) return problem;
  for (int i = 0; i < state.num_joints; ++i) {
    const std::string at = "[" + std::to_string(i) + "]";
    if (!std::isfinite(state.position[i])) {
      return expected("position" + at + " (" + state.name[i] + ")", "a finite number", state.position[i]);
    }
    if (!std::isfinite(state.velocity[i])) {
      return expected("velocity" + at + " (" + state.name[i] + ")", "a finite number", state.velocity[i]);
    }
  }
  return "";
}

std::string check_camera_pose(const camera_pose_t& pose) {
  const auto v = CameraPose::check(
      pose.frame_id, Eigen::Vector3d(pose.translation[0], pose.translation[1], pose.translation[2]),
      Eigen::Quaterniond(pose.rotation[0], pose.rotation[1], pose.rotation[2], pose.rotation[3]),
      kWireQuaternionTolerance);
  return v ? v->line() : "";
}

namespace {

// link_labels_t's world_from_optical, when given: finite, its rotation
// orthonormal with det +1 (to 1e-6: written from doubles).
std::string check_optical_pose(const link_labels_t& labels) {
  if (!labels.optical_pose_given) return "";
  for (int k = 0; k < 12; ++k) {
    if (!std::isfinite(labels.world_from_optical[k])) {
      return expected("world_from_optical[" + std::to_string(k) + "]", "finite numbers",
                      labels.world_from_optical[k]);
    }
  }
  const double* m = labels.world_from_optical;
  double worst = 0;
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      // Column a . column b of R (R = m[4 r + c], c < 3).
      const double dot = m[a] * m[b] + m[4 + a] * m[4 + b] + m[8 + a] * m[8 + b];
      worst = std::max(worst, std::abs(dot - (a == b ? 1.0 : 0.0)));
    }
  }
  const double det = m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) +
                     m[2] * (m[4] * m[9] - m[5] * m[8]);
  if (worst > 1e-6 || std::abs(det - 1.0) > 1e-6) {
    return expected("world_from_optical", "a rotation (orthonormal, det +1, to 1e-6) beside the translation",
                    worst > 1e-6 ? worst : det);
  }
  return "";
}

}  // namespace

std::string check_link_labels(const link_labels_t& labels) {
  if (labels.utime <= 0) return expected("utime", "a capture time > 0", static_cast<double>(labels.utime));
  if (labels.num_robot_links < 0 || labels.num_robot_links > labels.num_links) {
    return expected("num_robot_links", "0..num_links", labels.num_robot_links);
  }
  if (!labels.usable) {
    if (labels.unusable_reason.empty()) {
      return "unusable_reason: expected a reason for an unusable frame, got an empty string";
    }
    return "";
  }
  if (auto problem = check_size(labels.width, labels.height); !problem.empty()) return problem;
  const int64_t pixels = int64_t{labels.width} * labels.height;
  if (labels.num_pixels != pixels) {
    return expected("num_pixels", "width*height = " + std::to_string(pixels), labels.num_pixels);
  }
  if (auto problem = check_kinematics(labels); !problem.empty()) return problem;
  if (auto problem = check_arm_cover(labels); !problem.empty()) return problem;
  if (auto problem = check_optical_pose(labels); !problem.empty()) return problem;
  if (auto problem =
          check_body_regions(labels.num_body_regions, labels.body_region, labels.body_region_separation_m);
      !problem.empty())
    return problem;
  return check_occupant_shapes(labels);
}

std::string check_risk(const risk_t& risk) {
  if (risk.level < risk_t::SAFE || risk.level > risk_t::DANGEROUS) {
    return expected("level", "SAFE (0), WARNING (1) or DANGEROUS (2)", risk.level);
  }
  if (risk.cause < risk_t::CAUSE_NONE || risk.cause > risk_t::CAUSE_UNCLASSIFIED) {
    return expected("cause", "one of risk_t's CAUSE_ constants (0..6)", risk.cause);
  }
  if (!std::isfinite(risk.score)) return expected("score", "a finite number", risk.score);
  if (!std::isfinite(risk.threshold)) return expected("threshold", "a finite number", risk.threshold);
  return "";
}

std::string check_speed_limit(const speed_limit_t& limit) {
  if (!(std::isfinite(limit.max_arm_speed_m_s) && limit.max_arm_speed_m_s >= 0)) {
    return expected("max_arm_speed_m_s", "a finite speed >= 0 (m/s)", limit.max_arm_speed_m_s);
  }
  if (limit.set_by < speed_limit_t::SET_BY_RANGE || limit.set_by > speed_limit_t::SET_BY_NO_JUDGEMENT) {
    return expected("set_by", "one of speed_limit_t's SET_BY_ constants (0..3)", limit.set_by);
  }
  if (!(limit.arm_speed_m_s == -1 || (std::isfinite(limit.arm_speed_m_s) && limit.arm_speed_m_s >= 0))) {
    return expected("arm_speed_m_s", "a finite speed >= 0 (m/s) or -1 (not bounded)", limit.arm_speed_m_s);
  }
  if (limit.valid_for_ms <= 0) return expected("valid_for_ms", "a validity > 0 (ms)", limit.valid_for_ms);
  return "";
}

std::string check_safety_status(const safety_status_t& status) {
  if (status.stop < safety_status_t::STOP_NONE || status.stop > safety_status_t::STOP_POWER_CUT) {
    return expected("stop", "one of safety_status_t's STOP_ constants (0..2)", status.stop);
  }
  if (status.cause < risk_t::CAUSE_NONE || status.cause > risk_t::CAUSE_UNCLASSIFIED) {
    return expected("cause", "one of risk_t's CAUSE_ constants (0..6)", status.cause);
  }
  if (status.motion_allowed && status.stop != safety_status_t::STOP_NONE) {
    return expected("stop", "STOP_NONE while motion_allowed is true", status.stop);
  }
  return "";
}

std::string check_motion_estimate(const motion_estimate_t& e) {
  if (e.utime <= 0) return expected("utime", "a capture time > 0", static_cast<double>(e.utime));
  if (e.seq < 0) return expected("seq", "a frame number >= 0", static_cast<double>(e.seq));
  if (e.camera_id.empty()) return "camera_id: expected a camera name, got an empty string";
  if (e.trigger < motion_estimate_t::TRIGGER_PERIODIC || e.trigger > motion_estimate_t::TRIGGER_REQUEST) {
    return expected("trigger", "one of the TRIGGER_ constants (0..2)", e.trigger);
  }
  if (!e.usable) {
    if (e.unusable_reason.empty())
      return "unusable_reason: expected a reason for an unusable estimate, got an empty string";
    return "";
  }
  if (e.num_frames < 1) return expected("num_frames", "a count of frames >= 1", e.num_frames);
  if (e.num_joints < 0) return expected("num_joints", "a count >= 0", e.num_joints);
  if (auto problem = check_names(e.joint_name, "joint_name"); !problem.empty()) return problem;
  for (int i = 0; i < e.num_joints; ++i) {
    const std::string at = "[" + std::to_string(i) + "] (" + e.joint_name[i] + ")";
    if (!std::isfinite(e.reported_position[i])) {
      return expected("reported_position" + at, "a finite number", e.reported_position[i]);
    }
    if (!std::isfinite(e.estimated_position[i])) {
      return expected("estimated_position" + at, "a finite number", e.estimated_position[i]);
    }
    if (!std::isfinite(e.position_sigma[i]) || e.position_sigma[i] < 0) {
      return expected("position_sigma" + at, "a finite sigma >= 0", e.position_sigma[i]);
    }
  }
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(e.correction_translation[i])) {
      return expected("correction_translation[" + std::to_string(i) + "]", "a finite number of metres",
                      e.correction_translation[i]);
    }
    if (!std::isfinite(e.estimated_translation[i])) {
      return expected("estimated_translation[" + std::to_string(i) + "]", "a finite number of metres",
                      e.estimated_translation[i]);
    }
  }
  if (auto problem = check_unit_quaternion(e.correction_rotation, "correction_rotation"); !problem.empty()) {
    return problem;
  }
  if (auto problem = check_unit_quaternion(e.estimated_rotation, "estimated_rotation"); !problem.empty()) {
    return problem;
  }
  if (!std::isfinite(e.correction_translation_sigma_m) || e.correction_translation_sigma_m < 0) {
    return expected("correction_translation_sigma_m", "a finite sigma >= 0",
                    e.correction_translation_sigma_m);
  }
  if (!std::isfinite(e.correction_rotation_sigma_rad) || e.correction_rotation_sigma_rad < 0) {
    return expected("correction_rotation_sigma_rad", "a finite sigma >= 0", e.correction_rotation_sigma_rad);
  }
  if (e.frame_id.empty()) return "frame_id: expected a URDF link name, got an empty string";
  if (e.num_points < 0 || e.num_inliers < 0 || e.num_inliers > e.num_points) {
    return expected("num_inliers", "0..num_points = " + std::to_string(e.num_points), e.num_inliers);
  }
  if (!std::isfinite(e.residual_before_mm) || e.residual_before_mm < 0) {
    return expected("residual_before_mm", "a finite residual >= 0", e.residual_before_mm);
  }
  if (!std::isfinite(e.residual_after_mm) || e.residual_after_mm < 0) {
    return expected("residual_after_mm", "a finite residual >= 0", e.residual_after_mm);
  }
  return "";
}

std::string check_planned_trajectory(const planned_trajectory_t& plan) {
  if (plan.num_joints <= 0) return expected("num_joints", "a count >= 1", plan.num_joints);
  if (plan.num_points <= 0) return expected("num_points", "a count >= 1", plan.num_points);
  if (auto problem = check_names(plan.joint_name, "joint_name"); !problem.empty()) return problem;
  for (int i = 0; i < plan.num_points; ++i) {
    const std::string at = "[" + std::to_string(i) + "]";
    if (plan.point_utime[i] <= 0) {
      return expected("point_utime" + at, "a time > 0", static_cast<double>(plan.point_utime[i]));
    }
    if (i > 0 && plan.point_utime[i] <= plan.point_utime[i - 1]) {
      return expected(
          "point_utime" + at,
          "strictly increasing times, previous " + std::to_string(plan.point_utime[i - 1]) + ", got",
          static_cast<double>(plan.point_utime[i]));
    }
    for (int j = 0; j < plan.num_joints; ++j) {
      if (!std::isfinite(plan.position[i][j])) {
        return expected("position" + at + "[" + std::to_string(j) + "] (" + plan.joint_name[j] + ")",
                        "a finite number", plan.position[i][j]);
      }
    }
  }
  return "";
}

std::string check_discrepancy(const discrepancy_t& d) {
  if (d.utime <= 0) return expected("utime", "a capture time > 0", static_cast<double>(d.utime));
  if (d.seq < 0) return expected("seq", "a frame number >= 0", static_cast<double>(d.seq));
  if (d.num_robot_links < 0 || d.num_robot_links > d.num_links) {
    return expected("num_robot_links", "0..num_links = " + std::to_string(d.num_links), d.num_robot_links);
  }
  if (!(d.invalid_fraction >= 0 && d.invalid_fraction <= 1)) {
    return expected("invalid_fraction", "a fraction in [0, 1]", d.invalid_fraction);
  }
  if (!(d.mismatch_fraction >= 0 && d.mismatch_fraction <= 1)) {
    return expected("mismatch_fraction", "a fraction in [0, 1]", d.mismatch_fraction);
  }
  if (!std::isfinite(d.p95_abs_dis_mm) || d.p95_abs_dis_mm < 0) {
    return expected("p95_abs_dis_mm", "a finite value >= 0 mm", d.p95_abs_dis_mm);
  }
  for (int i = 0; i < d.num_links; ++i) {
    if (d.link_compared[i] < 0 || d.link_match[i] < 0 || d.link_farther[i] < 0 ||
        d.link_match[i] > d.link_compared[i] || d.link_farther[i] > d.link_compared[i]) {
      return "link_compared[" + std::to_string(i) + "]: expected counts with 0 <= match, farther <= compared";
    }
  }
  if (!std::isfinite(d.near_arm_area_m2) || !std::isfinite(d.largest_blob_area_m2)) {
    return "near_arm_area_m2 / largest_blob_area_m2: expected finite areas";
  }
  if (auto p = check_field(d); !p.empty()) return p;
  if (auto p = check_body_regions(d.num_body_regions, d.body_region, d.body_region_separation_m);
      !p.empty()) {
    return p;
  }
  if (auto p = check_region_sightings(d); !p.empty()) return p;
  return check_evidence(d);
}

std::string check_heartbeat(const heartbeat_t& hb) {
  if (hb.process.empty()) return "process: expected a process name, got an empty string";
  return "";
}

std::string check_sim_camera_fault(const sim_camera_fault_t& f) {
  auto finite3 = [](const double v[3]) {
    return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
  };
  if (f.kind < sim_camera_fault_t::CLEAR || f.kind > sim_camera_fault_t::INTRUDING_OBJECT) {
    return "kind: expected 0..4, got " + std::to_string(f.kind);
  }
  if (f.kind != sim_camera_fault_t::CLEAR && !(f.duration_s > 0 && f.duration_s < 1e6)) {
    return "duration_s: expected a duration in (0, 1e6) s, got " + std::to_string(f.duration_s);
  }
  if (!finite3(f.drift_translation_m_per_s) || !finite3(f.drift_rotation_rad_per_s) ||
      !finite3(f.object_size_m) || !finite3(f.object_position_m) || !finite3(f.object_velocity_m_per_s)) {
    return "vectors: expected finite numbers";
  }
  if (f.kind == sim_camera_fault_t::INTRUDING_OBJECT &&
      !(f.object_size_m[0] > 0 && f.object_size_m[1] > 0 && f.object_size_m[2] > 0)) {
    return "object_size_m: expected 3 sizes > 0";
  }
  return "";
}

std::string check_sim_controller_fault(const sim_controller_fault_t& f) {
  if (f.utime <= 0) return expected("utime", "a time > 0 (us since the epoch)", static_cast<double>(f.utime));
  if (!std::isfinite(f.drive_rad_s))
    return expected("drive_rad_s", "a finite speed (rad/s, or m/s for a prismatic joint)", f.drive_rad_s);
  if (f.drive_joint.empty() && f.drive_rad_s != 0)
    return expected("drive_rad_s", "0 when drive_joint is empty (no drive)", f.drive_rad_s);
  return "";
}

std::string check_sim_joint_fault(const sim_joint_fault_t& f) {
  if (f.joint.empty()) return "joint: expected a joint name, got an empty string";
  if (!std::isfinite(f.offset))
    return expected("offset", "a finite offset (rad, or m for a prismatic joint)", f.offset);
  return "";
}

}  // namespace tofguard
