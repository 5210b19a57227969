#include "tofguard/risk/risk_monitor.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tofguard/risk/user_presence.hpp"

namespace tofguard::risk {
namespace {

ClassifierContext classifier_context(const ChannelNames& channels) {
  ClassifierContext context;
  context.depth_channel = channels.depth;
  context.labels_channel = channels.labels;
  return context;
}

}  // namespace

RiskMonitor::RiskMonitor(const RiskSettings& settings, const ChannelNames& channels,
                         robot_model::KinematicTree robot, double camera_rate_hz, int64_t start_us)
    : settings_(settings),
      classifier_context_(classifier_context(channels)),
      robot_(std::move(robot)),
      deadlines_(settings, channels, start_us),
      plan_(settings, robot_.prismatic_joint_names),
      gate_(settings, robot_.prismatic_joint_names),
      evidence_(settings, robot_, camera_rate_hz),
      decision_(settings),
      response_time_s_(chain_response_time_s(settings, camera_rate_hz)) {}

std::string RiskMonitor::on_joint_state(const joint_state_t& state, int64_t now_us) {
  // After the stream went stale it may start afresh (a driver restarted,
  // its clock set back), but never with a copy of the newest state: a
  // driver stuck resending it must stay stale.
  if (deadlines_.joint_state_expired(now_us) && state.utime != joint_states_.newest_utime()) {
    joint_states_.clear();
  }
  if (!joint_states_.add(state)) {
    return "joint state utime " + std::to_string(state.utime) +
           " is not newer than the newest taken (a duplicate, out of order, or the driver's clock set back)";
  }
  deadlines_.on_joint_state(now_us);
  return "";
}

std::string RiskMonitor::check_joint_names(const std::vector<std::string>& names,
                                           const std::string& field) const {
  for (size_t i = 0; i < names.size(); ++i) {
    if (!robot_.is_movable_joint(names[i])) {
      return field + "[" + std::to_string(i) + "]: expected a moving joint of the robot's URDF, got '" +
             names[i] + "'";
    }
  }
  return "";
}

speed_limit_t RiskMonitor::speed_limit(const discrepancy_t& frame) const {
  return frame_speed_limit(settings_, response_time_s_, frame,
                           arm_speed_bound_m_s(frame, joint_states_.at(frame.utime)), body_region_rules_);
}

void RiskMonitor::set_occupant(const OccupantSettings& occupant) {
  body_region_rules_ = body_region_rules(occupant, robot_model::moving_mass_kg(robot_));
  occupant_ = occupant;
}

namespace {

// The arm faster than a body region's limit, or of a speed that cannot be
// bounded (arm_speed_m_s -1: no joint state at the capture, a joint
// without its speed) where a region sets the limit: the finding, as the
// protective field's, UNKNOWN_OBJECT.
std::optional<FrameFinding> faster_than_the_user_allows(const speed_limit_t& limit) {
  const bool unbounded = limit.arm_speed_m_s < 0;
  if (limit.set_by != speed_limit_t::SET_BY_BODY_REGION ||
      !(unbounded || limit.arm_speed_m_s > limit.max_arm_speed_m_s)) {
    return std::nullopt;
  }
  FrameFinding f;
  f.cause = risk_t::CAUSE_UNKNOWN_OBJECT;
  f.score = unbounded ? std::numeric_limits<double>::infinity() : limit.arm_speed_m_s;
  f.threshold = limit.max_arm_speed_m_s;
  const std::string where = fixed(limit.separation_m * 100, 0) + " cm from the user's " + limit.body_region +
                            ", limit " + fixed(limit.max_arm_speed_m_s, 2) + " m/s";
  f.detail = unbounded ? "arm speed not bounded, " + where
                       : "arm at " + fixed(limit.arm_speed_m_s, 2) + " m/s, " + where;
  return f;
}

}  // namespace

ClassifiedFrame RiskMonitor::classify(const discrepancy_t& frame) const {
  const joint_state_t* at_capture = joint_states_.at(frame.utime);
  ClassifierContext context = classifier_context_;
  if (at_capture != nullptr) {
    double fastest = 0;  // rad/s (m/s for prismatic joints)
    for (double v : at_capture->velocity) fastest = std::max(fastest, std::abs(v));
    context.arm_moving = fastest >= settings_.moving_joint_speed_rad_s;
  }
  context.field = field_size(settings_, response_time_s_,
                             arm_speed_bound_m_s(frame, at_capture, &context.field_unbounded_reason));
  ClassifiedFrame c;
  c.frame = frame;
  c.finding = classify_frame(frame, robot_, settings_, context);
  c.model_mismatch = is_model_mismatch(c.finding.cause);
  // The user not where the model seats them (an empty chair): only when
  // the camera shows nothing else wrong.
  if (c.finding.cause == risk_t::CAUSE_NONE && occupant_) {
    if (std::optional<FrameFinding> absent = user_not_where_modelled(frame, *occupant_)) {
      c.finding = std::move(*absent);
    }
  }
  // The arm faster than the user's body regions allow: only when the
  // camera shows nothing wrong (the protective field's own finding comes
  // from the rules above).
  if (c.finding.cause == risk_t::CAUSE_NONE && !body_region_rules_.empty()) {
    if (std::optional<FrameFinding> faster = faster_than_the_user_allows(speed_limit(frame))) {
      c.finding = std::move(*faster);
    }
  }
  // The arm left its plan: only when the camera shows nothing wrong (a
  // camera finding says more).
  if (c.finding.cause == risk_t::CAUSE_NONE && at_capture != nullptr) {
    if (std::optional<FrameFinding> deviation = plan_.deviation(*at_capture))
      c.finding = std::move(*deviation);
  }
  return c;
}

namespace {

// The hypothesis of the sequential evidence an open diagnosis names when
// a sequential test crossed for it (FrameFinding::at_once): the test that
// crossed where the cause names another (FrameFinding::crossed_test), else
// its suspect joint for a joint error, the camera for a calibration error;
// empty for a rule's finding or none open.
std::string diagnosed_hypothesis(const FrameFinding* diagnosis) {
  if (diagnosis == nullptr || !diagnosis->at_once) return "";
  if (!diagnosis->crossed_test.empty()) return diagnosis->crossed_test;
  if (diagnosis->cause == risk_t::CAUSE_CALIBRATION_ERROR) return "camera";
  if (diagnosis->cause == risk_t::CAUSE_JOINT_ERROR) return diagnosis->suspect;
  return "";
}

}  // namespace

std::vector<risk_t> RiskMonitor::judge(std::vector<ClassifiedFrame> released, int64_t now_us) {
  std::vector<risk_t> verdicts;
  verdicts.reserve(released.size());
  for (ClassifiedFrame& c : released) {
    last_frame_utime_ = c.frame.utime;
    FrameFinding finding = std::move(c.finding);
    EvidenceStep evidence;
    // The sensor rules come first: a frame with a sensor or component fault
    // carries no evidence to trust (a frozen image would count twice).
    if (!is_fault_cause(finding.cause)) evidence = weigh_evidence(c.frame, &finding);
    const bool was_open = decision_.diagnosis_open();
    // Clean for the diagnosis: every CUSUM below its warning level, and the
    // diagnosis's own hypothesis shows evidence that its fault is gone.
    const std::string latched = diagnosed_hypothesis(decision_.open_finding());
    if (!latched.empty()) evidence.summary += "; " + evidence_.clearing_summary(latched);
    verdicts.push_back(decision_.decide(c.frame, std::move(finding), deadlines_.first_expired(now_us),
                                        evidence_clean(latched), evidence.summary));
    // A closed diagnosis starts the tests afresh.
    if (was_open && !decision_.diagnosis_open()) evidence_.reset();
  }
  return verdicts;
}

EvidenceStep RiskMonitor::weigh_evidence(const discrepancy_t& frame, FrameFinding* finding) {
  EvidenceStep evidence = evidence_.update(frame);
  EvidenceStep pooled = pooled_ != nullptr ? pooled_->update(frame) : EvidenceStep{};
  if (pooled_ != nullptr) evidence.summary += "; pooled over the cameras: " + pooled.summary;
  if (evidence.crossed) {
    *finding = std::move(evidence.finding);
    finding->at_once = true;
  } else if (pooled.crossed) {
    *finding = std::move(pooled.finding);
    finding->detail = "pooled over the cameras: " + finding->detail;
    finding->at_once = true;
  } else if (finding->cause == risk_t::CAUSE_NONE && (evidence.warning || pooled.warning)) {
    *finding = std::move(evidence.warning ? evidence.finding : pooled.finding);
    finding->warning_only = true;
  }
  return evidence;
}

bool RiskMonitor::evidence_clean(const std::string& latched) const {
  const bool own = evidence_.quiet() && evidence_.cleared(latched);
  return own && (pooled_ == nullptr || (pooled_->quiet() && pooled_->cleared(latched)));
}

std::vector<risk_t> RiskMonitor::on_frame(const discrepancy_t& frame, int64_t now_us) {
  const bool in_order = !any_frame_ || (frame.seq > newest_seq_ && frame.utime > newest_utime_);
  const bool judged_before =
      std::find(judged_seqs_.begin(), judged_seqs_.end(), frame.seq) != judged_seqs_.end();
  if (in_order || (deadlines_.discrepancy_expired(now_us) && !judged_before)) {
    // In order, or the stream starts afresh after it went stale.
    any_frame_ = true;
    newest_seq_ = frame.seq;
    newest_utime_ = frame.utime;
    deadlines_.on_discrepancy(now_us);
  } else if (frame.usable || judged_before) {
    // A duplicate or an older frame must never count as a fresh SAFE
    // frame (nor keep the deadline fed): refused.
    ++refused_frames_;
    last_refusal_ = "frame seq " + std::to_string(frame.seq) + " utime " + std::to_string(frame.utime) +
                    (judged_before ? " was judged already (a duplicate)"
                                   : " is not newer than frame seq " + std::to_string(newest_seq_) +
                                         " utime " + std::to_string(newest_utime_) +
                                         " (out of order, or the camera's clock set back)");
    return {};
  }
  // (An unusable frame never judged, late: judged below, without feeding
  // the deadline; it can only stop the arm.)
  judged_seqs_.push_back(frame.seq);
  if (judged_seqs_.size() > 64) judged_seqs_.pop_front();
  return judge(gate_.admit(classify(frame), now_us), now_us);
}

std::vector<risk_t> RiskMonitor::on_estimate(const motion_estimate_t& estimate, int64_t now_us) {
  return judge(gate_.add_estimate(estimate, now_us), now_us);
}

std::vector<risk_t> RiskMonitor::release_due(int64_t now_us) {
  return judge(gate_.release_due(now_us), now_us);
}

std::optional<risk_t> RiskMonitor::check_deadlines(int64_t now_us) const {
  const std::optional<FrameFinding> expired = deadlines_.first_expired(now_us);
  if (!expired) return std::nullopt;
  return timeout_verdict(last_frame_utime_, *expired);
}

}  // namespace tofguard::risk
