#include "tofguard/risk/frame_classifier.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <vector>

#include "tofguard/common/demand.hpp"
#include "tofguard/risk_t.hpp"

namespace tofguard::risk {
std::string fixed(double value, int decimals) {
  // std::to_chars: the text of printf's "%.*f" in the C locale, which is
  // what an ostream with std::fixed and std::setprecision writes, without
  // a stream and its locale per number (a verdict formats about ten: they
  // were 40 % of RiskMonitor::on_frame's time; docs/benchmarks.md,
  // "tofguard-risk's time per verdict"). A number too long for the buffer goes the stream's
  // way.
  char text[64];
  const std::to_chars_result r =
      std::to_chars(text, text + sizeof text, value, std::chars_format::fixed, decimals);
  if (r.ec == std::errc()) return std::string(text, r.ptr);
  std::ostringstream s;
  s << std::fixed << std::setprecision(decimals) << value;
  return s.str();
}

void FrameEvidence::build_link_views() const {
  if (built_) return;
  built_ = true;
  // The loop below indexes six per-link arrays by i < num_links and splits
  // robot from environment links at num_robot_links; a discrepancy that
  // passed its wire check has them consistent. (Checked here, after the
  // sensor rules: an unusable frame carries no per-link arrays.)
  TOFGUARD_DEMAND(frame.num_robot_links >= 0 && frame.num_robot_links <= frame.num_links &&
                      frame.num_links >= 0 &&
                      frame.link_name.size() == static_cast<size_t>(frame.num_links) &&
                      frame.link_compared.size() == static_cast<size_t>(frame.num_links) &&
                      frame.link_match.size() == static_cast<size_t>(frame.num_links) &&
                      frame.link_farther.size() == static_cast<size_t>(frame.num_links),
                  "discrepancy seq " + std::to_string(frame.seq) +
                      ": per-link arrays do not match num_links " + std::to_string(frame.num_links));
  for (int i = 0; i < frame.num_links; ++i) {
    if (i >= frame.num_robot_links) {
      environment_compared_ += frame.link_compared[i];
      environment_match_ += frame.link_match[i];
      continue;
    }
    if (frame.link_compared[i] < config.min_link_pixels) continue;
    LinkView view;
    view.name = frame.link_name[i];
    view.compared = frame.link_compared[i];
    view.mismatch =
        static_cast<double>(frame.link_compared[i] - frame.link_match[i]) / frame.link_compared[i];
    view.missing = static_cast<double>(frame.link_farther[i]) / frame.link_compared[i];
    visible_.push_back(view);
  }
}

const std::vector<LinkView>& FrameEvidence::visible_links() const {
  build_link_views();
  return visible_;
}

int64_t FrameEvidence::environment_compared() const {
  build_link_views();
  return environment_compared_;
}

int64_t FrameEvidence::environment_match() const {
  build_link_views();
  return environment_match_;
}

namespace {

FrameFinding finding(int8_t cause, std::string suspect, double score, double threshold, std::string detail) {
  return FrameFinding{cause, std::move(suspect), score, threshold, std::move(detail)};
}

// ---- Sensor and component faults (debounced with sensor_debounce_frames) ----

// The discrepancy process could not compare the frame: no rendering in time
// (the renderer is dead or slow), or labels unusable / not fitting it.
FrameFinding unusable_frame(const FrameEvidence& e) {
  const discrepancy_t& f = e.frame;
  if (f.usable) return {};
  if (f.unusable_kind == discrepancy_t::UNUSABLE_NO_RENDERING) {
    return finding(risk_t::CAUSE_COMPONENT_FAULT, "tofguard-renderer", 1, 0,
                   "frame not rendered in time: " + f.unusable_reason);
  }
  if (f.unusable_kind == discrepancy_t::UNUSABLE_OUTSIDE_PROFILE) {
    // The camera's commissioning does not cover where the arm is.
    return finding(risk_t::CAUSE_SENSOR_FAULT, e.context.depth_channel, 1, 0, f.unusable_reason);
  }
  return finding(risk_t::CAUSE_SENSOR_FAULT, e.context.labels_channel, 1, 0,
                 "frame unusable: " + f.unusable_reason);
}

// Too many pixels without a return (fraction of the image).
FrameFinding invalid_pixels(const FrameEvidence& e) {
  const discrepancy_t& f = e.frame;
  const RiskSettings& config = e.config;
  if (!(f.invalid_fraction > config.max_invalid_fraction)) return {};
  return finding(risk_t::CAUSE_SENSOR_FAULT, e.context.depth_channel, f.invalid_fraction,
                 config.max_invalid_fraction,
                 "invalid pixels (fraction): " + fixed(100.0 * f.invalid_fraction, 1) +
                     " % have no return, limit " + fixed(100.0 * config.max_invalid_fraction, 1) + " %");
}

FrameFinding uncalibrated_camera(const FrameEvidence& e) {
  if (!e.config.calibrated_required || e.frame.calibrated) return {};
  return finding(risk_t::CAUSE_SENSOR_FAULT, e.context.depth_channel, 0, 1,
                 "camera frame not calibrated (calibrated = false) but risk.sensor.calibrated_required");
}

// The same depth image again while the arm moves (at the frame's capture
// time): a real ToF camera's noise never repeats.
FrameFinding frozen_image(const FrameEvidence& e) {
  const discrepancy_t& f = e.frame;
  const RiskSettings& config = e.config;
  if (!e.context.arm_moving || f.repeat_count < config.frozen_repeat_frames) return {};
  return finding(risk_t::CAUSE_SENSOR_FAULT, e.context.depth_channel, f.repeat_count,
                 config.frozen_repeat_frames,
                 "frozen image (repeated frames): the same depth image " +
                     std::to_string(f.repeat_count + 1) + " times in a row while the arm moves");
}

// ---- What the mismatch looks like ----

// The three fraction rules below judge only frames without evidence
// (discrepancy_t.evidence_available false: labels from a renderer that
// publishes no kinematics). With evidence, the sequential tests
// (sequential_evidence.hpp) decide calibration and joint errors, in frame order
// (RiskMonitor).

// CALIBRATION_ERROR: the static environment and the arm disagree broadly.
FrameFinding calibration_error(const FrameEvidence& e) {
  const discrepancy_t& f = e.frame;
  if (f.evidence_available) return {};
  const RiskSettings& config = e.config;
  const std::vector<LinkView>& visible = e.visible_links();
  const int64_t environment_compared = e.environment_compared();
  if (environment_compared < config.min_environment_pixels) return {};
  const double environment_mismatch = static_cast<double>(environment_compared - e.environment_match()) /
                                      static_cast<double>(environment_compared);
  int mismatching_links = 0;
  for (const LinkView& link : visible)
    mismatching_links += link.mismatch >= config.link_mismatch_fraction ? 1 : 0;
  const double robot_fraction =
      visible.empty() ? 1.0 : static_cast<double>(mismatching_links) / static_cast<double>(visible.size());
  // A link fixed to the robot's root (its base) cannot be moved by any
  // joint: when it mismatches together with most of the arm, the camera
  // pose is off. (A camera moved by a few centimetres shifts the near arm
  // far more than a distant floor, which may stay within tolerance.)
  std::string fixed_link_mismatching;
  for (const LinkView& link : visible) {
    if (link.mismatch >= config.link_mismatch_fraction && e.robot.is_robot_link(link.name) &&
        e.robot.nearest_movable_joint_above(link.name).empty()) {
      fixed_link_mismatching = link.name;
    }
  }
  const bool broad_mismatch = robot_fraction >= config.calibration_robot_link_fraction &&
                              (environment_mismatch >= config.calibration_environment_mismatch_fraction ||
                               !fixed_link_mismatching.empty());
  if (!broad_mismatch) return {};
  return finding(
      risk_t::CAUSE_CALIBRATION_ERROR, "", environment_mismatch,
      config.calibration_environment_mismatch_fraction,
      "camera pose or calibration off (environment mismatch fraction): " +
          fixed(100.0 * environment_mismatch, 1) + " % of the environment and " +
          std::to_string(mismatching_links) + "/" + std::to_string(visible.size()) +
          " visible links mismatch" +
          (fixed_link_mismatching.empty() ? std::string()
                                          : ", the fixed " + fixed_link_mismatching + " among them") +
          "; median I_dis environment " + fixed(f.environment_median_dis_mm, 0) + " mm, arm " +
          fixed(f.robot_median_dis_mm, 0) + " mm");
}

// CALIBRATION_ERROR, several cameras: this camera's matched static surfaces,
// seen by the other cameras, mostly lie off their surfaces by more than
// the tolerance a match gets (discrepancy_t.registration_*): the cameras
// disagree with each other where their views overlap, so one of them
// moved or its distances drifted (each camera's own pose test names
// which, where it can). With at least kMinRegistrationPoints points: a
// point beyond the tolerance (4 sigma + the model's allowance) by chance
// has probability < 1e-4, so half of 100 never do by chance.
constexpr int32_t kMinRegistrationPoints = 100;

FrameFinding cameras_disagree(const FrameEvidence& e) {
  const discrepancy_t& f = e.frame;
  if (f.registration_points < kMinRegistrationPoints || !(f.registration_mismatch_fraction > 0.5)) return {};
  return finding(
      risk_t::CAUSE_CALIBRATION_ERROR, e.context.depth_channel, f.registration_mismatch_fraction, 0.5,
      "the cameras disagree where their views overlap (fraction of shared static points beyond the "
      "tolerance): " +
          fixed(100.0 * f.registration_mismatch_fraction, 0) + " % of " +
          std::to_string(f.registration_points) + " points, the other cameras' depths " +
          fixed(f.registration_median_mm, 0) + " mm off (median): this camera or another moved");
}

// JOINT_ERROR: the arm is missing where the model has it, on links that all
// hang below one moving joint; the proximal links match. A missing link the
// URDF does not know is UNCLASSIFIED (never judged safe).
FrameFinding joint_error_missing_links(const FrameEvidence& e) {
  if (e.frame.evidence_available) return {};
  const RiskSettings& config = e.config;
  const robot_model::KinematicTree& robot = e.robot;
  const std::vector<LinkView>& visible = e.visible_links();
  std::vector<std::string> missing_links;
  int64_t missing_pixels = 0;
  int64_t compared_pixels = 0;
  std::string unknown;
  for (const LinkView& link : visible) {
    // Only a displaced arm is missing where the model has it: an object
    // can hide a link (nearer) but never make the camera see farther.
    if (link.missing < config.joint_link_missing_fraction) continue;
    if (!robot.is_robot_link(link.name)) {
      unknown = link.name;
      continue;
    }
    missing_links.push_back(link.name);
    missing_pixels += static_cast<int64_t>(std::lround(link.mismatch * link.compared));
    compared_pixels += link.compared;
  }
  if (!missing_links.empty()) {
    std::string common = robot.lowest_common_ancestor(missing_links);
    // The joint's own link moves least (it turns about the joint), so it
    // may mismatch only slightly while its distal links are missing: blame
    // the most proximal link on the way down to `common` that is visibly
    // affected, when all above it match.
    for (const std::string& link : robot.chain_from_root(common)) {
      const auto view =
          std::find_if(visible.begin(), visible.end(), [&](const LinkView& v) { return v.name == link; });
      if (view != visible.end() && view->mismatch >= config.joint_link_affected_fraction &&
          view->mismatch * view->compared >= config.joint_link_affected_min_pixels) {
        common = link;
        break;
      }
    }
    const std::string joint = robot.nearest_movable_joint_above(common);
    if (!joint.empty()) {
      const double score = static_cast<double>(missing_pixels) / static_cast<double>(compared_pixels);
      std::string links;
      for (const std::string& l : missing_links) links += (links.empty() ? "" : ", ") + l;
      return finding(risk_t::CAUSE_JOINT_ERROR, joint, score, config.joint_link_missing_fraction,
                     "joint " + joint + " reads other than seen (mismatch fraction): the arm mismatches at " +
                         fixed(100.0 * score, 1) + " % of the modelled pixels of " + links +
                         ", all distal to " + joint);
    }
  }
  if (!unknown.empty()) {
    return finding(risk_t::CAUSE_UNCLASSIFIED, unknown, 1, 0,
                   "link '" + unknown + "' of the discrepancy is not in the robot's URDF");
  }
  return {};
}

// JOINT_ERROR, second chance: no link is missing enough, yet the arm's own
// links mismatch (a link moved towards the camera is seen nearer, and the
// surfaces beside it look like an object near the arm). When every visibly
// affected link hangs below one moving joint and the links above it match,
// that joint is the suspect. (An object that hides part of a link lands
// here too: either way the arm stops.)
FrameFinding joint_error_beside_unexplained_surfaces(const FrameEvidence& e) {
  if (e.frame.evidence_available) return {};
  const RiskSettings& config = e.config;
  const robot_model::KinematicTree& robot = e.robot;
  if (!(e.frame.near_arm_area_m2 >= config.unknown_object_min_area_m2)) return {};
  std::vector<std::string> affected;
  int64_t mismatching = 0;
  int64_t compared = 0;
  for (const LinkView& link : e.visible_links()) {
    if (!robot.is_robot_link(link.name)) continue;
    if (link.mismatch < config.joint_link_affected_fraction ||
        link.mismatch * link.compared < config.joint_link_affected_min_pixels) {
      continue;
    }
    affected.push_back(link.name);
    mismatching += static_cast<int64_t>(std::lround(link.mismatch * link.compared));
    compared += link.compared;
  }
  if (affected.empty()) return {};
  const std::string common = robot.lowest_common_ancestor(affected);
  const std::string joint = robot.nearest_movable_joint_above(common);
  // The affected links must be the common link and links below it.
  if (joint.empty() || std::find(affected.begin(), affected.end(), common) == affected.end()) return {};
  const double score = static_cast<double>(mismatching) / static_cast<double>(compared);
  std::string links;
  for (const std::string& l : affected) links += (links.empty() ? "" : ", ") + l;
  return finding(risk_t::CAUSE_JOINT_ERROR, joint, score, config.joint_link_affected_fraction,
                 "joint " + joint + " reads other than seen (mismatch fraction): " + links + " mismatch at " +
                     fixed(100.0 * score, 1) + " % and surfaces beside them are " +
                     "unexplained; the links above " + joint + " match");
}

// UNKNOWN_OBJECT: an unexplained nearer surface of at least
// unknown_object_min_area_m2 inside the protective separation S (DANGEROUS
// after the debounce), or inside the warning field (WARNING only). Beyond:
// nothing, whatever its size (protective_field.hpp).
FrameFinding unknown_object(const FrameEvidence& e) {
  const discrepancy_t& f = e.frame;
  const double min_area_m2 = e.config.unknown_object_min_area_m2;
  const FieldSize& field = e.context.field;
  const std::optional<double> distance_m = object_distance_m(f, min_area_m2);
  if (!std::isfinite(field.protective_m)) {
    // The arm's speed cannot be bounded: every object measured is inside S.
    if (!distance_m) return {};
    return finding(risk_t::CAUSE_UNKNOWN_OBJECT, "", *distance_m, field_range_m(f),
                   "unknown object " + fixed(*distance_m * 100, 0) +
                       " cm from the arm (distance m), inside the protective field: the arm's speed cannot "
                       "be bounded (" +
                       e.context.field_unbounded_reason + ")");
  }
  // An object beyond the range is not measured: a protective field reaching
  // beyond it is not monitored.
  if (field.protective_m > field_range_m(f)) {
    return finding(
        risk_t::CAUSE_UNCLASSIFIED, "discrepancy.field.range_m", field.protective_m, field_range_m(f),
        "protective field not monitored (separation m): S = " + fixed(field.protective_m, 2) +
            " m at arm speed " + fixed(field.arm_speed_m_s, 2) +
            " m/s reaches beyond discrepancy.field.range_m = " + fixed(field_range_m(f), 2) + " m");
  }
  if (!distance_m) return {};
  const std::string sizes = "S = " + fixed(field.protective_m, 2) + " m at arm speed " +
                            fixed(field.arm_speed_m_s, 2) + " m/s, warning field to " +
                            fixed(field.warning_m, 2) + " m";
  const std::string what =
      fixed(
          f.unexplained_area_within_m2[static_cast<int>(std::lround(*distance_m / f.field_bin_m)) - 1] * 1e4,
          0) +
      " cm^2 within " + fixed(*distance_m * 100, 0) + " cm of the arm";
  if (*distance_m <= field.protective_m) {
    return finding(risk_t::CAUSE_UNKNOWN_OBJECT, "", *distance_m, field.protective_m,
                   "unknown object " + fixed(*distance_m * 100, 0) +
                       " cm from the arm, inside the protective field (distance m): " + what + "; " + sizes);
  }
  if (*distance_m <= field.warning_m) {
    FrameFinding w =
        finding(risk_t::CAUSE_UNKNOWN_OBJECT, "", *distance_m, field.protective_m,
                "unknown object " + fixed(*distance_m * 100, 0) +
                    " cm from the arm, in the warning field (distance m): " + what + "; " + sizes);
    w.warning_only = true;
    return w;
  }
  return {};
}

// UNCLASSIFIED: a large mismatch none of the rules above explains (area of
// the largest blob in m^2).
FrameFinding unexplained_blob(const FrameEvidence& e) {
  const discrepancy_t& f = e.frame;
  const double min_area_m2 = e.config.unclassified_blob_area_m2;
  if (!(f.largest_blob_area_m2 >= min_area_m2)) return {};
  return finding(risk_t::CAUSE_UNCLASSIFIED, "", f.largest_blob_area_m2, min_area_m2,
                 "unexplained mismatch (largest blob area m^2): " + fixed(f.largest_blob_area_m2 * 1e4, 0) +
                     " cm^2 (" + std::to_string(f.largest_blob_pixels) + " px)");
}

}  // namespace

const std::vector<FrameRule>& frame_rules() {
  static const std::vector<FrameRule> rules = {
      {"unusable frame", unusable_frame},
      {"invalid pixels", invalid_pixels},
      {"uncalibrated camera", uncalibrated_camera},
      {"frozen image", frozen_image},
      {"calibration error", calibration_error},
      {"cameras disagree", cameras_disagree},
      {"joint error: links missing", joint_error_missing_links},
      {"joint error: links beside unexplained surfaces", joint_error_beside_unexplained_surfaces},
      {"unknown object", unknown_object},
      {"unexplained blob", unexplained_blob},
  };
  return rules;
}

FrameFinding classify_frame(const discrepancy_t& frame, const robot_model::KinematicTree& robot,
                            const RiskSettings& config, const ClassifierContext& context) {
  const FrameEvidence evidence(frame, robot, config, context);
  for (const FrameRule& rule : frame_rules()) {
    FrameFinding f = rule.apply(evidence);
    if (f.cause != risk_t::CAUSE_NONE) return f;
  }
  return {};
}

}  // namespace tofguard::risk
