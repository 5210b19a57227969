#include "tofguard/risk/sequential_evidence.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "tofguard/common/demand.hpp"
#include "tofguard/risk_t.hpp"

namespace tofguard::risk {

double log_cosh(double x) {
  const double a = std::abs(x);
  return a + std::log1p(std::exp(-2 * a)) - std::log(2.0);
}

double joint_llr(double score, double information, double delta) {
  return log_cosh(delta * score) - delta * delta * information / 2;
}

double effective_delta(double delta, double information, double static_bound) {
  if (!(information > 0) || !(static_bound > 0)) return delta;
  return std::max(0.0, delta - static_bound / information);
}

double smallest_growing_offset(double delta, double information, double static_bound, double memory_decay) {
  const double tested = effective_delta(delta, information, static_bound);
  if (!(information > 0) || !(tested > 0)) return std::numeric_limits<double>::infinity();
  return std::max(0.0, static_bound) / information + tested / 2 +
         std::max(0.0, memory_decay) / (tested * information);
}

namespace {

// The diagonal of a row-major 6x6 information matrix.
std::array<double, 6> diagonal_of(const double* information) {
  return {information[0], information[7], information[14], information[21], information[28], information[35]};
}

// camera_llr on the information's diagonal.
double camera_llr_diagonal(const double* score, const double* information_diagonal,
                           const std::array<double, 6>& delta) {
  std::array<double, 6> terms{};
  double largest = -std::numeric_limits<double>::infinity();
  for (int a = 0; a < 6; ++a) {
    terms[a] = log_cosh(delta[a] * score[a]) - delta[a] * delta[a] * information_diagonal[a] / 2;
    largest = std::max(largest, terms[a]);
  }
  if (!std::isfinite(largest)) return largest;
  double sum = 0;
  for (double t : terms) sum += std::exp(t - largest);
  return largest + std::log(sum / 6);
}

}  // namespace

double camera_llr(const std::array<double, 6>& score, const std::array<double, 36>& information,
                  const std::array<double, 6>& delta) {
  return camera_llr_diagonal(score.data(), diagonal_of(information.data()).data(), delta);
}

bool camera_region_votes(const double* information_diagonal, const std::array<double, 6>& delta) {
  double divergence = 0;
  for (int a = 0; a < 6; ++a) {
    divergence = std::max(divergence, delta[a] * delta[a] * information_diagonal[a] / 2);
  }
  return divergence >= kCameraRegionVoteNats;
}

namespace {

// Each axis's delta beyond what the static error can give its score
// (effective_delta), for the scores `score`, information diagonal and bounds.
std::array<double, 6> effective_camera_delta(const std::array<double, 6>& delta,
                                             const double* information_diagonal, const double* static_bound) {
  std::array<double, 6> out = delta;
  for (int a = 0; a < 6; ++a) out[a] = effective_delta(delta[a], information_diagonal[a], static_bound[a]);
  return out;
}

std::array<double, 6> scaled(std::array<double, 6> delta, double fraction) {
  for (double& d : delta) d *= fraction;
  return delta;
}

}  // namespace

CameraRegionRatio camera_region_llr(const discrepancy_t& f, const std::array<double, 6>& delta,
                                    double alternative_fraction) {
  std::array<double, 4> ratios{};
  int voters = 0;
  for (int r = 0; r < 4; ++r) {
    const double* information = f.camera_region_information + 6 * r;
    const std::array<double, 6> region_delta =
        effective_camera_delta(delta, information, f.camera_region_static_bound + 6 * r);
    if (!camera_region_votes(information, region_delta)) continue;
    ratios[voters++] = camera_llr_diagonal(f.camera_region_score + 6 * r, information,
                                           scaled(region_delta, alternative_fraction));
  }
  CameraRegionRatio result;
  result.voters = voters;
  if (voters == 0) {
    // No region carries a nat at delta (a frame without regions, from an
    // older tofguard-discrepancy, or a scene with hardly any static
    // surface): the whole image's ratio, on its information's diagonal.
    const std::array<double, 6> diagonal = diagonal_of(f.camera_information);
    result.llr = camera_llr_diagonal(
        f.camera_score, diagonal.data(),
        scaled(effective_camera_delta(delta, diagonal.data(), f.camera_static_bound), alternative_fraction));
    return result;
  }
  // The m-th largest of the n voters' ratios, m = min(n, 3): with
  // n = 4, three must agree. exp of it is at most the mean of the m
  // largest exp(LLR_r), so E_0[exp] <= n / m: subtracting log(n / m)
  // keeps E_0[LR] <= 1 (docs/safety-chain.md).
  const int agree = std::min(voters, 3);
  // Ascending, by insertion (at most four; std::sort on a partial
  // std::array trips GCC 12's -Warray-bounds).
  for (int i = 1; i < voters; ++i) {
    for (int j = i; j > 0 && ratios[j - 1] > ratios[j]; --j) std::swap(ratios[j - 1], ratios[j]);
  }
  result.agree = agree;
  result.llr = ratios[voters - agree] - std::log(static_cast<double>(voters) / agree);
  return result;
}

double cusum_threshold(int hypotheses, double rate_hz, double false_stop_period_h) {
  TOFGUARD_DEMAND(hypotheses >= 1 && rate_hz > 0 && false_stop_period_h > 0,
                  "cusum_threshold: hypotheses " + std::to_string(hypotheses) + ", rate " +
                      std::to_string(rate_hz) + " Hz, period " + std::to_string(false_stop_period_h) + " h");
  return std::log(hypotheses * rate_hz * 3600.0 * false_stop_period_h);
}

RiskSettings several_cameras_evidence_settings(const RiskSettings& risk, size_t cameras) {
  RiskSettings each = risk;
  if (cameras > 1) each.evidence_false_stop_period_h *= static_cast<double>(cameras + 1);
  return each;
}

SequentialEvidence::SequentialEvidence(const RiskSettings& risk, const robot_model::KinematicTree& robot,
                                       double camera_rate_hz, bool camera_test)
    : camera_test_(camera_test),
      prismatic_(robot.prismatic_joint_names),
      joint_delta_rad_(risk.evidence_joint_offset_rad),
      joint_delta_m_(risk.evidence_joint_offset_m),
      joint_large_rad_(risk.evidence_large_joint_offset_rad),
      joint_large_m_(risk.evidence_large_joint_offset_m),
      camera_delta_{risk.evidence_camera_translation_m, risk.evidence_camera_translation_m,
                    risk.evidence_camera_translation_m, risk.evidence_camera_rotation_rad,
                    risk.evidence_camera_rotation_rad,  risk.evidence_camera_rotation_rad},
      warning_fraction_(risk.evidence_warning_fraction) {
  if (camera_test_) clearing_cusum_["camera"] = 0;
  for (const std::string& joint : robot.movable_joint_names) {
    joint_tests_[joint] = JointTests{};
    clearing_cusum_[joint] = 0;
  }
  h_ = cusum_threshold(hypotheses(), camera_rate_hz, risk.evidence_false_stop_period_h);
  memory_decay_ = h_ / (camera_rate_hz * kEvidenceMemoryS);
}

double SequentialEvidence::joint_cusum(const std::string& joint) const {
  const auto it = joint_tests_.find(joint);
  return it == joint_tests_.end() ? 0 : it->second.largest();
}

double SequentialEvidence::joint_large_cusum(const std::string& joint) const {
  const auto it = joint_tests_.find(joint);
  return it == joint_tests_.end() ? 0 : it->second.at_large;
}

bool SequentialEvidence::quiet() const {
  if (camera_cusum_ >= warning_level()) return false;
  for (const auto& [joint, tests] : joint_tests_) {
    if (tests.largest() >= warning_level()) return false;
  }
  return true;
}

bool SequentialEvidence::cleared(const std::string& hypothesis) const {
  return clearing_cusum_.count(hypothesis) == 0 || clearing_cusum(hypothesis) >= clearing_level();
}

double SequentialEvidence::clearing_cusum(const std::string& hypothesis) const {
  const auto it = clearing_cusum_.find(hypothesis);
  return it == clearing_cusum_.end() ? 0 : it->second;
}

void SequentialEvidence::reset() {
  camera_cusum_ = 0;
  for (auto& [joint, tests] : joint_tests_) tests = JointTests{};
  for (auto& [hypothesis, g] : clearing_cusum_) g = 0;
}

namespace {

constexpr double kDeg = 180.0 / M_PI;

// One CUSUM step, capped at h: once crossed, more evidence adds nothing,
// and a fault that went away clears as fast as one frame can show it. A
// non-finite ratio (a bug upstream) counts as crossing: fail safe.
double step(double cusum, double llr, double h) {
  if (!std::isfinite(llr)) return h;
  return std::min(h, std::max(0.0, cusum + llr));
}

// One step of a clearing test, on the stop test's ratio `llr` at the
// clearing alternative: evidence against the fault adds, capped at `level`. A
// non-finite ratio is no evidence that a fault is gone: back to 0.
double clearing_step(double clearing, double llr, double level) {
  if (!std::isfinite(llr)) return 0;
  return std::min(level, std::max(0.0, clearing - llr));
}

// Joint i's static bound on frame f (discrepancy_t.joint_static_bound;
// 0 from a tofguard-discrepancy without an allowance).
double joint_static_bound(const discrepancy_t& f, int i) {
  return static_cast<size_t>(i) < f.joint_static_bound.size() ? f.joint_static_bound[i] : 0.0;
}

}  // namespace

bool searched(const discrepancy_t& f) {
  return f.search_points > 0 && f.joint_search_gain.size() == f.joint_name.size() &&
         f.joint_search_offset.size() == f.joint_name.size();
}

double naming_chi2(const discrepancy_t& f, int i) {
  if (searched(f)) return f.joint_search_gain[i];
  if (!(f.joint_naming_information[i] > 0)) return 0;
  return f.joint_naming_score[i] * f.joint_naming_score[i] / f.joint_naming_information[i];
}

double camera_beyond_joints_chi2(const discrepancy_t& f) {
  if (!searched(f) || f.camera_search_axis < 0 || f.camera_search_axis > 5 || !(f.camera_search_gain > 0))
    return -std::numeric_limits<double>::infinity();
  double best_joint = 0;
  for (const double gain : f.joint_search_gain) best_joint = std::max(best_joint, gain);
  return f.camera_search_gain - best_joint;
}

DistanceDrift distance_drift(const discrepancy_t& f, double threshold_chi2) {
  DistanceDrift d;
  const double info_d = f.distance_offset_information;
  if (!(info_d > 0)) return d;
  using Matrix6 = Eigen::Matrix<double, 6, 6, Eigen::RowMajor>;
  const Eigen::Map<const Matrix6> info(f.camera_information);
  const Eigen::Map<const Eigen::Matrix<double, 6, 1>> correction(f.camera_correction);
  // The plain camera score (the wire's is shrunk; the correction is the
  // plain fit's: I c).
  const Eigen::Matrix<double, 6, 1> score = info * correction;
  const double pose_chi2 = correction.dot(score);
  const double offset_chi2 = f.distance_offset_score * f.distance_offset_score / info_d;
  Eigen::Matrix<double, 7, 7> joint;
  joint.topLeftCorner<6, 6>() = info;
  for (int a = 0; a < 6; ++a) joint(a, 6) = joint(6, a) = f.distance_offset_cross[a];
  joint(6, 6) = info_d;
  Eigen::Matrix<double, 7, 1> joint_score;
  joint_score << score, f.distance_offset_score;
  const Eigen::LDLT<Eigen::Matrix<double, 7, 7>> ldlt(joint);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return d;
  const double joint_chi2 = joint_score.dot(ldlt.solve(joint_score));
  if (!std::isfinite(joint_chi2)) return d;
  d.offset_mm = f.distance_offset_score / info_d;
  d.offset_sigma_mm = 1.0 / std::sqrt(info_d);
  d.offset_beyond_pose_chi2 = joint_chi2 - pose_chi2;
  d.pose_beyond_offset_chi2 = joint_chi2 - offset_chi2;
  d.drift = d.offset_beyond_pose_chi2 > threshold_chi2 && d.pose_beyond_offset_chi2 <= threshold_chi2;
  return d;
}

FrameFinding SequentialEvidence::drift_finding(const DistanceDrift& d) const {
  FrameFinding finding;
  finding.cause = risk_t::CAUSE_SENSOR_FAULT;
  finding.score = camera_cusum_;
  finding.threshold = h_;
  finding.detail =
      "camera needs recommissioning: its distances read " + fixed(d.offset_mm, 1) + " mm (± " +
      fixed(d.offset_sigma_mm, 1) + ") farther than its profile (sequential evidence: the camera test at " +
      fixed(camera_cusum_, 1) + " of h " + fixed(h_, 1) + "; a common distance offset explains chi^2 " +
      fixed(d.offset_beyond_pose_chi2, 0) + " beyond a moved camera, a moved camera " +
      fixed(d.pose_beyond_offset_chi2, 0) + " beyond the offset)";
  return finding;
}

FrameFinding SequentialEvidence::camera_finding(const discrepancy_t& f) const {
  // As for naming a joint: a difference of two hypotheses' chi-squares is
  // twice their log-likelihood ratio, so 2h is the threshold's own level.
  if (const DistanceDrift drift = distance_drift(f, 2 * h_); drift.drift) return drift_finding(drift);
  const double* c = f.camera_correction;
  FrameFinding finding;
  finding.cause = risk_t::CAUSE_CALIBRATION_ERROR;
  finding.score = camera_cusum_;
  finding.threshold = h_;
  finding.detail =
      "camera pose off (sequential evidence, CUSUM log-likelihood ratio): " + fixed(camera_cusum_, 1) +
      " of h " + fixed(h_, 1) + "; fitted correction (" + fixed(100 * c[0], 1) + ", " + fixed(100 * c[1], 1) +
      ", " + fixed(100 * c[2], 1) + ") cm, (" + fixed(kDeg * c[3], 2) + ", " + fixed(kDeg * c[4], 2) + ", " +
      fixed(kDeg * c[5], 2) + ")° about the optical x, y, z axes (seen vs configured)";
  return finding;
}

FrameFinding SequentialEvidence::search_camera_finding(const discrepancy_t& f,
                                                       const NamedCusum& crossed) const {
  static const char* const kAxes[6] = {"along optical x", "along optical y", "along the optical axis",
                                       "about optical x", "about optical y", "about the optical axis"};
  const int axis = f.camera_search_axis;
  const double amount = axis < 3 ? 100 * f.camera_search_offset : kDeg * f.camera_search_offset;
  FrameFinding finding;
  finding.cause = risk_t::CAUSE_CALIBRATION_ERROR;
  finding.score = crossed.value;
  finding.threshold = h_;
  finding.crossed_test = crossed.name;
  finding.detail = "camera pose off (named by the search: the camera moved " +
                   fixed(amount, axis < 3 ? 1 : 2) + (axis < 3 ? " cm " : "° ") + kAxes[axis] +
                   " (seen vs configured) explains chi^2 " + fixed(f.camera_search_gain, 0) + ", " +
                   fixed(camera_beyond_joints_chi2(f), 0) +
                   " more than any joint's offset; the test that crossed: " + crossed.name + "'s, " +
                   fixed(crossed.value, 1) + " of h " + fixed(h_, 1) + "; the camera's own test at " +
                   fixed(camera_cusum_, 1) + ")";
  return finding;
}

FrameFinding SequentialEvidence::joint_finding(const discrepancy_t& f, int i) const {
  const std::string& joint = f.joint_name[i];
  const bool prismatic = prismatic_.count(joint) > 0;
  const double unit = prismatic ? 1000.0 : kDeg;
  const std::string unit_name = prismatic ? " mm" : "°";
  const double information = f.joint_information[i];
  FrameFinding finding;
  finding.cause = risk_t::CAUSE_JOINT_ERROR;
  finding.suspect = joint;
  finding.score = joint_cusum(joint);
  finding.threshold = h_;
  finding.detail =
      "joint " + joint +
      " reads other than seen (sequential evidence, CUSUM log-likelihood ratio): " + fixed(finding.score, 1) +
      " of h " + fixed(h_, 1);
  const auto tests = joint_tests_.find(joint);
  if (tests != joint_tests_.end() && tests->second.at_large > tests->second.at_delta) {
    finding.detail += " (its test at the large offset " + fixed(unit * joint_alternatives(joint).large, 0) +
                      unit_name + ")";
  }
  if (information > 0) {
    finding.detail += "; fitted offset (seen - reported) " + fixed(unit * f.joint_score[i] / information, 1) +
                      unit_name + " ± " + fixed(unit / std::sqrt(information), 1) + unit_name;
  }
  if (searched(f) && f.joint_search_gain[i] > 0) {
    finding.detail += "; named by the search: " + fixed(unit * f.joint_search_offset[i], 1) + unit_name +
                      " explains chi^2 " + fixed(f.joint_search_gain[i], 0);
    return finding;
  }
  const double naming = f.joint_naming_information[i];
  if (naming > 0) {
    finding.detail +=
        ", named by the fit within the linear range: " + fixed(unit * f.joint_naming_score[i] / naming, 1) +
        unit_name + ", explains chi^2 " +
        fixed(f.joint_naming_score[i] * f.joint_naming_score[i] / naming, 0);
  }
  return finding;
}

namespace {

// The joint arrays of a frame with evidence all have num_joints entries.
void demand_joint_arrays(const discrepancy_t& f) {
  TOFGUARD_DEMAND(f.num_joints >= 0 && f.joint_name.size() == static_cast<size_t>(f.num_joints) &&
                      f.joint_score.size() == f.joint_name.size() &&
                      f.joint_information.size() == f.joint_name.size() &&
                      f.joint_naming_score.size() == f.joint_name.size() &&
                      f.joint_naming_information.size() == f.joint_name.size(),
                  "discrepancy seq " + std::to_string(f.seq) + ": joint arrays do not match num_joints");
}

}  // namespace

EvidenceStep SequentialEvidence::update(const discrepancy_t& f) {
  EvidenceStep result;
  if (f.evidence_available) demand_joint_arrays(f);
  // A repeated image (repeat_count > 0: the same depth bytes as the frame
  // before) is not new evidence: counted again it would double its weight,
  // and while the arm moves it shows the arm where it was (the frozen-image
  // rule names that fault).
  if (f.evidence_available && f.repeat_count == 0) {
    result.updated = true;
    add_frame(f);
  }
  // The largest CUSUM relative to h, for warnings and the summary.
  const NamedCusum largest = largest_cusum();
  result.quiet = quiet();
  result.summary =
      "evidence: largest CUSUM " + largest.name + " " + fixed(largest.value, 1) + " of h " + fixed(h_, 1);
  if (!f.evidence_available) return result;

  if (camera_cusum_ >= h_) {
    result.crossed = true;
    result.finding = camera_finding(f);
    return result;
  }
  const NamedCusum crossed = crossed_joint();
  if (!crossed.name.empty()) {
    result.crossed = true;
    // As for naming a joint: a difference of two hypotheses' chi-squares
    // is twice their log-likelihood ratio, so 2h is the threshold's own level.
    result.finding = camera_beyond_joints_chi2(f) >= 2 * h_ ? search_camera_finding(f, crossed)
                                                            : joint_stop_finding(f, crossed);
    return result;
  }
  if (largest.value >= warning_level()) {
    result.warning = true;
    result.finding = warning_finding(f, largest);
  }
  return result;
}

void SequentialEvidence::add_frame(const discrepancy_t& f) {
  if (camera_test_) {
    camera_cusum_ = step(camera_cusum_, camera_region_llr(f, camera_delta_).llr - memory_decay_, h_);
    double& camera_clearing = clearing_cusum_["camera"];
    camera_clearing =
        clearing_step(camera_clearing, camera_region_llr(f, camera_delta_, kClearingAlternativeFraction).llr,
                      clearing_level());
    if (camera_cusum_ >= h_) camera_clearing = 0;
  }
  for (int i = 0; i < f.num_joints; ++i) {
    const auto it = joint_tests_.find(f.joint_name[i]);
    if (it == joint_tests_.end()) continue;  // not a moving joint of the robot: not a hypothesis
    add_joint(f, i, &it->second);
  }
}

SequentialEvidence::JointAlternatives SequentialEvidence::joint_alternatives(const std::string& joint) const {
  if (prismatic_.count(joint) > 0) return {joint_delta_m_, joint_large_m_};
  return {joint_delta_rad_, joint_large_rad_};
}

double SequentialEvidence::smallest_offset(const discrepancy_t& f, int i) const {
  const JointAlternatives alternatives = joint_alternatives(f.joint_name[i]);
  const double bound = joint_static_bound(f, i);
  const double information = f.joint_information[i];
  return std::min(smallest_growing_offset(alternatives.first, information, bound, memory_decay_),
                  smallest_growing_offset(alternatives.large, information, bound, memory_decay_));
}

void SequentialEvidence::add_joint(const discrepancy_t& f, int i, JointTests* tests) {
  const JointAlternatives alternatives = joint_alternatives(f.joint_name[i]);
  const double bound = joint_static_bound(f, i);
  const double information = f.joint_information[i];
  const double tested = effective_delta(alternatives.first, information, bound);
  const double large = effective_delta(alternatives.large, information, bound);
  tests->at_delta =
      step(tests->at_delta, joint_llr(f.joint_score[i], information, tested) - memory_decay_, h_);
  tests->at_large =
      step(tests->at_large, joint_llr(f.joint_score[i], information, large) - memory_decay_, h_);
  // Each crossing restarts the clearing test, at half of the alternative
  // of the test that crossed (the first test's when both did).
  if (tests->at_delta >= h_) {
    tests->clearing_at_large = false;
  } else if (tests->at_large >= h_) {
    tests->clearing_at_large = true;
  }
  const double clearing_delta = kClearingAlternativeFraction * (tests->clearing_at_large ? large : tested);
  double& clearing = clearing_cusum_[f.joint_name[i]];
  clearing =
      clearing_step(clearing, joint_llr(f.joint_score[i], information, clearing_delta), clearing_level());
  if (tests->largest() >= h_) clearing = 0;
}

std::string SequentialEvidence::clearing_summary(const std::string& hypothesis) const {
  return "evidence " + hypothesis +
         "'s fault is gone (clearing test at delta/2): " + fixed(clearing_cusum(hypothesis), 1) + " of " +
         fixed(clearing_level(), 1);
}

SequentialEvidence::NamedCusum SequentialEvidence::largest_cusum() const {
  // (Without the camera's test, a joint's among zeros.)
  NamedCusum largest{camera_test_ ? "camera" : "", camera_test_ ? camera_cusum_ : -1.0};
  for (const auto& [joint, tests] : joint_tests_) {
    if (tests.largest() > largest.value) largest = NamedCusum{joint, tests.largest()};
  }
  return largest;
}

SequentialEvidence::NamedCusum SequentialEvidence::crossed_joint() const {
  NamedCusum crossed{"", 0};
  for (const auto& [joint, tests] : joint_tests_) {
    const double s = tests.largest();
    if (s >= h_ && s > crossed.value) crossed = NamedCusum{joint, s};
  }
  return crossed;
}

int SequentialEvidence::suspect_joint(const discrepancy_t& f) const {
  int best = -1;
  int best_crossed = -1;
  double best_explained = -1;
  double best_crossed_explained = -1;
  for (int i = 0; i < f.num_joints; ++i) {
    if (joint_tests_.count(f.joint_name[i]) == 0) continue;
    const double explained = naming_chi2(f, i);
    if (!(explained > 0)) continue;
    if (explained > best_explained) {
      best_explained = explained;
      best = i;
    }
    if (joint_cusum(f.joint_name[i]) >= h_ && explained > best_crossed_explained) {
      best_crossed_explained = explained;
      best_crossed = i;
    }
  }
  // A joint whose test has not crossed must explain this frame better
  // than the best crossed one by 2h (the difference of two hypotheses'
  // chi-squares is twice their log-likelihood ratio: this frame alone
  // prefers it at the threshold's level); with no crossed joint in the
  // fit, by 2h against nothing.
  const double crossed_explained = best_crossed >= 0 ? best_crossed_explained : 0.0;
  const bool best_is_weak =
      best >= 0 && joint_cusum(f.joint_name[best]) < h_ && best_explained - crossed_explained < 2 * h_;
  return best_is_weak ? best_crossed : best;
}

FrameFinding SequentialEvidence::joint_stop_finding(const discrepancy_t& f, const NamedCusum& crossed) const {
  const int suspect = suspect_joint(f);
  if (suspect < 0) {
    // No joint explains anything this frame (no robot point seen, or
    // every robot pixel beyond the naming fit's gate), or only a joint
    // whose test has not crossed, weakly: the joint whose test crossed.
    // Still a stop.
    FrameFinding finding;
    finding.cause = risk_t::CAUSE_JOINT_ERROR;
    finding.suspect = crossed.name;
    finding.score = crossed.value;
    finding.threshold = h_;
    finding.detail = "joint " + crossed.name +
                     " reads other than seen (sequential evidence, CUSUM log-likelihood ratio): " +
                     fixed(crossed.value, 1) + " of h " + fixed(h_, 1);
    return finding;
  }
  FrameFinding finding = joint_finding(f, suspect);
  if (joint_cusum(f.joint_name[suspect]) < h_) {
    // Named by the naming search (or fit); the evidence that crossed is another
    // joint's test.
    finding.score = crossed.value;
    finding.detail += " (the test that crossed: " + crossed.name + "'s, " + fixed(crossed.value, 1) +
                      " of h " + fixed(h_, 1) + ")";
  }
  return finding;
}

FrameFinding SequentialEvidence::warning_finding(const discrepancy_t& f, const NamedCusum& largest) const {
  const auto at = std::find(f.joint_name.begin(), f.joint_name.end(), largest.name);
  if (camera_test_ && largest.name == "camera" && largest.value == camera_cusum_) return camera_finding(f);
  if (at != f.joint_name.end()) return joint_finding(f, static_cast<int>(at - f.joint_name.begin()));
  FrameFinding finding;
  finding.cause = risk_t::CAUSE_JOINT_ERROR;
  finding.suspect = largest.name;
  finding.score = largest.value;
  finding.threshold = h_;
  finding.detail = "joint " + largest.name +
                   " evidence growing (CUSUM log-likelihood ratio): " + fixed(largest.value, 1) + " of h " +
                   fixed(h_, 1);
  return finding;
}

}  // namespace tofguard::risk
