#pragma once
// The camera's geometry as value types that check their invariants when they
// are constructed: Intrinsics, UnitQuaternion, CameraPose.
//
// Two ways to make each, one rule:
// - From untrusted input (the config's YAML, an LCM message, a command line):
//   check(...) returns the Violation (field, expectation, value) so that the
//   reader writes its own one-line error naming its file or channel (a
//   ConfigError, a wire-check message); make(...) returns std::nullopt and
//   the reason as one line.
// - Inside tofguard, from values already checked or computed: the
//   constructor, which TOFGUARD_DEMANDs the same rule and aborts on a bug
//   (tofguard/common/demand.hpp says why dying is the safe outcome).
//
// Intrinsics and CameraPose keep their data members public: well over a hundred lines
// in every component read them (k.fx, pose.rotation); the constructor is the
// checked way in, and a reader of a value that may have been assembled by
// hand (e.g. the renderer's public API) calls check().
#include <optional>
#include <string>

#include <Eigen/Geometry>

namespace tofguard {

// Largest image side accepted, pixels (config, wire checks, renderer).
constexpr int kMaxImageSide = 8192;

// How far a quaternion's norm may be from 1 (dimensionless).
// A config is written by a person or a calibration tool with enough digits,
// so a norm off by more than this is a typo, not rounding.
constexpr double kConfigQuaternionTolerance = 1e-6;
// A message's quaternion may come from float arithmetic in another program
// (a pan-tilt head, a calibration tool); it is normalised on arrival. Off by
// more than this is a fault, and normalising it would hide it.
constexpr double kWireQuaternionTolerance = 1e-3;

// Why a value was refused: `field` as the YAML key and the wire field name it
// ("fx", "translation[1]", "rotation"), `expected` what was expected,
// `got` what was there.
struct Violation {
  std::string field;
  std::string expected;
  std::string got;
  // "<field>: expected <expected>, got <got>" (the wire checks' format).
  std::string line() const;
};

// Pinhole intrinsics, OpenCV convention (pixel (u, v) has its centre at
// (u, v), u right, v down), in pixels.
// Invariant: 1 <= width, height <= kMaxImageSide; fx, fy finite and > 0;
// cx, cy finite.
struct Intrinsics {
  int width = 0;
  int height = 0;
  double fx = 0;
  double fy = 0;
  double cx = 0;
  double cy = 0;

  // Not set yet (0x0): what a settings or frame struct holds before it is
  // filled; check() refuses it.
  Intrinsics() = default;
  // For values already checked (a config, a message that passed its wire
  // check) or computed inside tofguard: TOFGUARD_DEMANDs the invariant.
  Intrinsics(int width_px, int height_px, double fx_px, double fy_px, double cx_px, double cy_px);

  static std::optional<Violation> check(int width_px, int height_px, double fx_px, double fy_px, double cx_px,
                                        double cy_px);
  // The same rule on the current values.
  std::optional<Violation> check() const { return check(width, height, fx, fy, cx, cy); }
  // std::nullopt and `*why` = Violation::line() when the values break the rule.
  static std::optional<Intrinsics> make(int width_px, int height_px, double fx_px, double fy_px, double cx_px,
                                        double cy_px, std::string* why);

  // width * height.
  size_t pixel_count() const { return static_cast<size_t>(width) * static_cast<size_t>(height); }
};

// The point that pixel (u, v) of a pinhole camera `k` sees at depth z_m,
// in the camera's optical frame (x right, y down, z along the optical axis;
// metres): ((u - cx) z / fx, (v - cy) z / fy, z). z_m is the Z
// coordinate, not the distance along the ray. `k` is anything with fx, fy,
// cx, cy in pixels (Intrinsics, a depth_image_t's header), unchecked: the
// back-projection every component does per pixel, in one place.
template <class Pinhole>
Eigen::Vector3d optical_point_m(const Pinhole& k, double u, double v, double z_m) {
  return Eigen::Vector3d((u - k.cx) * z_m / k.fx, (v - k.cy) * z_m / k.fy, z_m);
}

// A rotation as a quaternion of norm 1, stored normalised.
// Invariant: finite components; the norm it was made from was within a
// tolerance of 1 (a quaternion far from unit is refused, never normalised:
// normalising would hide the fault that produced it).
class UnitQuaternion {
 public:
  // The identity rotation.
  UnitQuaternion() = default;
  // TOFGUARD_DEMANDs check(q, tolerance, ...) and normalises.
  explicit UnitQuaternion(const Eigen::Quaterniond& q, double tolerance = kWireQuaternionTolerance);

  // `field` names the quaternion in the error ("rotation", "rotation_wxyz");
  // a non-finite component is reported as field[i], i in w, x, y, z order.
  static std::optional<Violation> check(const Eigen::Quaterniond& q, double tolerance,
                                        const std::string& field);
  static std::optional<UnitQuaternion> make(const Eigen::Quaterniond& q, double tolerance,
                                            const std::string& field, std::string* why);

  const Eigen::Quaterniond& quaternion() const { return q_; }
  operator const Eigen::Quaterniond&() const { return q_; }  // NOLINT: a unit quaternion is a quaternion

 private:
  Eigen::Quaterniond q_ = Eigen::Quaterniond::Identity();
};

// Pose of the camera's optical frame (x right, y down, z forward) in URDF
// link `frame_id`: p_frame = rotation * p_optical + translation_m.
// Invariant: frame_id non-empty (the renderer looks the link up by name),
// translation_m finite (metres), rotation a unit quaternion.
struct CameraPose {
  std::string frame_id;
  Eigen::Vector3d translation_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();

  // Not set yet (no frame_id): check() refuses it.
  CameraPose() = default;
  // TOFGUARD_DEMANDs a non-empty frame_id and a finite translation.
  CameraPose(std::string frame, const Eigen::Vector3d& translation, const UnitQuaternion& rotation_in_frame);

  // Fields named as on the wire: frame_id, translation[i], rotation.
  static std::optional<Violation> check(const std::string& frame, const Eigen::Vector3d& translation,
                                        const Eigen::Quaterniond& rotation_in_frame, double tolerance);
  std::optional<Violation> check(double tolerance = kWireQuaternionTolerance) const {
    return check(frame_id, translation_m, rotation, tolerance);
  }
  // The rotation is normalised when accepted.
  static std::optional<CameraPose> make(const std::string& frame, const Eigen::Vector3d& translation,
                                        const Eigen::Quaterniond& rotation_in_frame, double tolerance,
                                        std::string* why);

  // The optical frame's pose in frame_id as a transform:
  // p_frame = frame_from_optical() * p_optical (rotation normalised).
  Eigen::Isometry3d frame_from_optical() const {
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.linear() = rotation.normalized().toRotationMatrix();
    t.translation() = translation_m;
    return t;
  }
};

}  // namespace tofguard
