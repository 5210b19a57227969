#pragma once
// One depth frame on the wire, in one place: depth_image_t (TOF_DEPTH,
// TOF_RENDERED) and link_labels_t (TOF_LABELS) packed from and unpacked to
// what the libraries work with (Z depths in metres, link indices,
// Intrinsics). lcmtypes/depth_image_t.lcm and link_labels_t.lcm define the
// fields; this file says how every process reads and writes them.
//
// Units: inside the libraries depths are Z along the optical axis in metres
// (float, 0 = no return); on the wire whole millimetres (int16, <= 0 = no
// return). Pixels are row-major, index v*width + u (OpenCV convention).
#include <cstdint>
#include <string>
#include <vector>

#include "tofguard/common/camera_geometry.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/link_labels_t.hpp"

namespace tofguard {

// ---- Millimetres <-> metres ----

// The largest depth the wire carries: depth_mm is int16 (32.767 m).
constexpr int kMaxDepthMm = 32767;

// Wire millimetres -> metres. (x * 1e-3, the one conversion every reader
// uses: the same bits wherever a depth is turned into metres.)
constexpr double metres_from_mm(double depth_mm) { return depth_mm * 1e-3; }

// Z in metres -> the wire's depth_mm, rounded to the nearest millimetre.
// 0 ("no return") for Z <= 0, NaN, or beyond kMaxDepthMm: a depth clipped
// to the int16 range would be a made-up distance.
int16_t depth_mm_from_m(double depth_m);

// A whole image: metres (float, 0 = no return) <-> the wire's depth_mm.
std::vector<int16_t> depth_mm_from_m(const std::vector<float>& depth_m);
std::vector<float> depth_m_from_mm(const std::vector<int16_t>& depth_mm);

// ---- depth_image_t ----

// The pinhole intrinsics (size and fx, fy, cx, cy in pixels) a frame was
// taken or rendered with.
Intrinsics intrinsics_of(const depth_image_t& image);

// Packs one frame: Z depths in metres (depth_mm_from_m) and `amplitude`
// (empty for none, else one value per pixel in the camera's units, clamped
// to [0, 32767], NaN -> 0). Throws std::invalid_argument when depth_m (or a
// non-empty amplitude) does not hold width*height values.
depth_image_t make_depth_image(const std::string& camera_id, const Intrinsics& intrinsics, int64_t utime,
                               int64_t seq, bool calibrated, const std::vector<float>& depth_m,
                               const std::vector<float>& amplitude = {});

// The frame's depth in metres (depth_m_from_mm of its depth_mm).
std::vector<float> depth_m_of(const depth_image_t& image);

// ---- Label values (link_labels_t::label) ----

// 0: nothing modelled at the pixel.
constexpr int16_t kLabelNothing = link_labels_t::NOTHING;
// 1..999: robot link (label - kLabelRobotFirst) of link_name.
constexpr int16_t kLabelRobotFirst = link_labels_t::ROBOT_FIRST;
// 1000..1999: environment link num_robot_links + (label -
// kLabelEnvironmentFirst) of link_name.
constexpr int16_t kLabelEnvironmentFirst = link_labels_t::ENVIRONMENT_FIRST;
// 2000..: the renderer's per-call extra objects, index label -
// kLabelExtraObjectFirst: the monitor's occupant shapes (on the wire as
// link_labels_t::OCCUPANT_FIRST + shape index) or the simulated camera's
// people and objects (never on the wire).
constexpr int16_t kLabelExtraObjectFirst = link_labels_t::OCCUPANT_FIRST;
constexpr int16_t kLabelOccupantFirst = link_labels_t::OCCUPANT_FIRST;

// How many robot and environment links the label values can name.
constexpr int kMaxLabelledRobotLinks = kLabelEnvironmentFirst - kLabelRobotFirst;
constexpr int kMaxLabelledEnvironmentLinks = kLabelExtraObjectFirst - kLabelEnvironmentFirst;

// The label of link `link` (its index in link_name: robot links first, then
// the environment's).
constexpr int16_t label_of_link(int link, int num_robot_links) {
  return static_cast<int16_t>(link < num_robot_links ? kLabelRobotFirst + link
                                                     : kLabelEnvironmentFirst + (link - num_robot_links));
}

// The link a label names: its index in link_name (0..num_links-1), or -1
// for kLabelNothing, an extra object, or a value outside the links there
// are (num_robot_links robot links, num_links - num_robot_links environment
// links). Called per pixel: inline.
// The occupant shape a label value names (kLabelOccupantFirst + k, k <
// num_occupant_shapes of the labels); -1 for any other value.
constexpr int occupant_shape_of_label(int label, int num_occupant_shapes) {
  return label >= kLabelOccupantFirst && label < kLabelOccupantFirst + num_occupant_shapes
             ? label - kLabelOccupantFirst
             : -1;
}

constexpr int link_of_label(int label, int num_robot_links, int num_links) {
  if (label >= kLabelRobotFirst && label < kLabelRobotFirst + num_robot_links)
    return label - kLabelRobotFirst;
  if (label >= kLabelEnvironmentFirst && label < kLabelEnvironmentFirst + (num_links - num_robot_links)) {
    return num_robot_links + (label - kLabelEnvironmentFirst);
  }
  return -1;
}

// Whether `label` is a robot link that a joint moves: its link_axis (the
// nearest moving axis above it) is >= 0. The environment's links, the
// robot's links fixed to its root (a base), nothing and extra objects are
// not. Labels without a link_axis per robot link: every robot link moves.
// Called per pixel: inline.
inline bool on_moving_link(const link_labels_t& labels, int label) {
  const int link = link_of_label(label, labels.num_robot_links, labels.num_robot_links);
  if (link < 0) return false;
  if (labels.link_axis.size() != static_cast<size_t>(labels.num_robot_links)) return true;
  return labels.link_axis[static_cast<size_t>(link)] >= 0;
}

// A robot link's label / an environment link's label (whatever the number
// of links).
constexpr bool is_robot_label(int label) {
  return label >= kLabelRobotFirst && label < kLabelEnvironmentFirst;
}
constexpr bool is_environment_label(int label) {
  return label >= kLabelEnvironmentFirst && label < kLabelExtraObjectFirst;
}

// ---- link_labels_t ----

// The TOF_LABELS message of `frame` (its utime, seq, camera_id and size):
// usable, with one label per pixel. Throws std::invalid_argument when
// `labels` does not hold width*height values or num_robot_links is not in
// 0..link_names.size().
link_labels_t make_link_labels(const depth_image_t& frame, int num_robot_links,
                               std::vector<std::string> link_names, std::vector<int16_t> labels);
// The same, unusable: no pixels, and why (one line; check_link_labels
// drops an unusable frame without a reason).
link_labels_t make_unusable_link_labels(const depth_image_t& frame, int num_robot_links,
                                        std::vector<std::string> link_names, const std::string& reason);

}  // namespace tofguard
