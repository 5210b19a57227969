#include "tofguard/common/camera_geometry.hpp"

#include <cmath>
#include <sstream>
#include <utility>

#include "tofguard/common/demand.hpp"

namespace tofguard {
namespace {

std::string text(double value) {
  std::ostringstream s;
  s << value;
  return s.str();
}

std::optional<Violation> refuse(std::string field, std::string expected, std::string got) {
  return Violation{std::move(field), std::move(expected), std::move(got)};
}

std::optional<Violation> check_side(const char* field, int pixels) {
  if (pixels < 1 || pixels > kMaxImageSide) {
    return refuse(field, "1.." + std::to_string(kMaxImageSide), std::to_string(pixels));
  }
  return std::nullopt;
}

}  // namespace

std::string Violation::line() const { return field + ": expected " + expected + ", got " + got; }

Intrinsics::Intrinsics(int width_px, int height_px, double fx_px, double fy_px, double cx_px, double cy_px)
    : width(width_px), height(height_px), fx(fx_px), fy(fy_px), cx(cx_px), cy(cy_px) {
  const std::optional<Violation> v = check();
  TOFGUARD_DEMAND(!v, "intrinsics: " + v->line());
}

std::optional<Violation> Intrinsics::check(int width_px, int height_px, double fx_px, double fy_px,
                                           double cx_px, double cy_px) {
  if (auto v = check_side("width", width_px)) return v;
  if (auto v = check_side("height", height_px)) return v;
  // Written so that NaN fails too.
  if (!(std::isfinite(fx_px) && fx_px > 0)) return refuse("fx", "a focal length > 0 px", text(fx_px));
  if (!(std::isfinite(fy_px) && fy_px > 0)) return refuse("fy", "a focal length > 0 px", text(fy_px));
  if (!std::isfinite(cx_px)) return refuse("cx", "a finite principal point", text(cx_px));
  if (!std::isfinite(cy_px)) return refuse("cy", "a finite principal point", text(cy_px));
  return std::nullopt;
}

std::optional<Intrinsics> Intrinsics::make(int width_px, int height_px, double fx_px, double fy_px,
                                           double cx_px, double cy_px, std::string* why) {
  if (auto v = check(width_px, height_px, fx_px, fy_px, cx_px, cy_px)) {
    if (why) *why = v->line();
    return std::nullopt;
  }
  return Intrinsics(width_px, height_px, fx_px, fy_px, cx_px, cy_px);
}

UnitQuaternion::UnitQuaternion(const Eigen::Quaterniond& q, double tolerance) {
  const std::optional<Violation> v = check(q, tolerance, "quaternion");
  TOFGUARD_DEMAND(!v, v->line());
  q_ = q.normalized();
}

std::optional<Violation> UnitQuaternion::check(const Eigen::Quaterniond& q, double tolerance,
                                               const std::string& field) {
  const double wxyz[4] = {q.w(), q.x(), q.y(), q.z()};
  for (int i = 0; i < 4; ++i) {
    if (!std::isfinite(wxyz[i]))
      return refuse(field + "[" + std::to_string(i) + "]", "a finite number", text(wxyz[i]));
  }
  const double norm = q.norm();
  if (!(std::abs(norm - 1.0) <= tolerance)) {
    return refuse(field, "a unit quaternion w, x, y, z (norm 1 within " + text(tolerance) + ")",
                  "norm " + text(norm));
  }
  return std::nullopt;
}

std::optional<UnitQuaternion> UnitQuaternion::make(const Eigen::Quaterniond& q, double tolerance,
                                                   const std::string& field, std::string* why) {
  if (auto v = check(q, tolerance, field)) {
    if (why) *why = v->line();
    return std::nullopt;
  }
  return UnitQuaternion(q, tolerance);
}

CameraPose::CameraPose(std::string frame, const Eigen::Vector3d& translation,
                       const UnitQuaternion& rotation_in_frame)
    : frame_id(std::move(frame)), translation_m(translation), rotation(rotation_in_frame.quaternion()) {
  const std::optional<Violation> v = check(frame_id, translation_m, rotation, kConfigQuaternionTolerance);
  TOFGUARD_DEMAND(!v, "camera pose: " + v->line());
}

std::optional<Violation> CameraPose::check(const std::string& frame, const Eigen::Vector3d& translation,
                                           const Eigen::Quaterniond& rotation_in_frame, double tolerance) {
  if (frame.empty()) return refuse("frame_id", "a URDF link name", "an empty string");
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(translation[i])) {
      return refuse("translation[" + std::to_string(i) + "]", "a finite number of metres",
                    text(translation[i]));
    }
  }
  return UnitQuaternion::check(rotation_in_frame, tolerance, "rotation");
}

std::optional<CameraPose> CameraPose::make(const std::string& frame, const Eigen::Vector3d& translation,
                                           const Eigen::Quaterniond& rotation_in_frame, double tolerance,
                                           std::string* why) {
  if (auto v = check(frame, translation, rotation_in_frame, tolerance)) {
    if (why) *why = v->line();
    return std::nullopt;
  }
  return CameraPose(frame, translation, UnitQuaternion(rotation_in_frame, tolerance));
}

}  // namespace tofguard
