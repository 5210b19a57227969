#pragma once
// One judgement from every camera of a deployment (docs/safety-chain.md,
// "Several cameras"): a RiskMonitor per camera (its deadlines, frame
// rules, sequential tests and open diagnosis), the joints' tests pooled
// over every camera's frames, and the published verdict the worst of every
// camera's latest (VerdictFusion), the links no camera sees said and
// limited (arm_coverage.hpp). With one camera it is that camera's monitor.
//
// tofguard-risk's logic without its transport: no LCM, no clocks (the
// caller's monotonic microseconds, `now_us`), so that the judgement
// campaign judges several cameras as the process does.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tofguard/discrepancy_t.hpp"
#include "tofguard/risk/arm_coverage.hpp"
#include "tofguard/risk/risk_monitor.hpp"
#include "tofguard/risk/sequential_evidence.hpp"
#include "tofguard/risk/verdict_fusion.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/robot_model/kinematic_tree.hpp"
#include "tofguard/settings/occupant_settings.hpp"
#include "tofguard/settings/risk_settings.hpp"

namespace tofguard::risk {

class CamerasJudgement {
 public:
  // `robot` must outlive the judgement. Each camera's monitor holds the
  // evidence thresholds for N cameras (several_cameras_evidence_settings).
  // `robot_link_areas` (arm_coverage.hpp) weigh the links no camera sees;
  // with several cameras they must give the arm a surface
  // (std::invalid_argument otherwise), with one they are not used.
  CamerasJudgement(const RiskSettings& risk, const std::vector<RiskCamera>& cameras,
                   const robot_model::KinematicTree& robot, const std::vector<LinkArea>& robot_link_areas,
                   const std::optional<OccupantSettings>& occupant, int64_t now_us);

  size_t cameras() const { return cameras_.size(); }
  const RiskCamera& camera(size_t c) const { return cameras_[c]; }
  RiskMonitor& monitor(size_t c) { return *monitors_[c]; }
  VerdictFusion& fusion() { return fusion_; }
  const VerdictFusion& fusion() const { return fusion_; }

  // Camera `c`'s frame: its monitor's verdicts, published (below).
  std::vector<risk_t> on_frame(size_t c, const discrepancy_t& d, int64_t now_us);
  // A verdict of camera `c`'s monitor as it is published: the worst of
  // every camera's latest, with the unseen arm said and, over
  // risk.unseen_arm_max_fraction, DANGEROUS (several cameras); none while
  // camera `c` is released (VerdictFusion::fuse).
  std::optional<risk_t> published(size_t c, const risk_t& verdict);
  std::vector<risk_t> published(size_t c, const std::vector<risk_t>& verdicts);

 private:
  // The robot links no camera still judging sees.
  std::vector<std::string> unseen_links() const;

  const double unseen_arm_max_fraction_;
  std::vector<RiskCamera> cameras_;
  // Declared before the monitors that point at it.
  std::unique_ptr<SequentialEvidence> pooled_;
  std::vector<std::unique_ptr<RiskMonitor>> monitors_;
  VerdictFusion fusion_;
  ArmCoverage coverage_;
};

}  // namespace tofguard::risk
