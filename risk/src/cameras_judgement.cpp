#include "tofguard/risk/cameras_judgement.hpp"

#include <stdexcept>

namespace tofguard::risk {
namespace {

// Several cameras: the joints' tests pooled over every camera's frames, at
// the cameras' summed frame rate (none with one camera).
std::unique_ptr<SequentialEvidence> pooled_evidence(const RiskSettings& risk,
                                                    const std::vector<RiskCamera>& cameras,
                                                    const robot_model::KinematicTree& robot) {
  if (cameras.size() < 2) return nullptr;
  double rate_hz = 0;
  for (const RiskCamera& camera : cameras) rate_hz += camera.rate_hz;
  return std::make_unique<SequentialEvidence>(several_cameras_evidence_settings(risk, cameras.size()), robot,
                                              rate_hz, /*camera_test=*/false);
}

VerdictFusion verdict_fusion(const std::vector<RiskCamera>& cameras, const RiskSettings& risk) {
  std::vector<std::string> ids;
  std::vector<std::string> depth_channels;
  for (const RiskCamera& camera : cameras) {
    ids.push_back(camera.id);
    depth_channels.push_back(camera.channels.depth);
  }
  return VerdictFusion(ids, depth_channels, risk.continue_after_named_camera_release);
}

}  // namespace

CamerasJudgement::CamerasJudgement(const RiskSettings& risk, const std::vector<RiskCamera>& cameras,
                                   const robot_model::KinematicTree& robot,
                                   const std::vector<LinkArea>& robot_link_areas,
                                   const std::optional<OccupantSettings>& occupant, int64_t now_us)
    : unseen_arm_max_fraction_(risk.unseen_arm_max_fraction),
      cameras_(cameras),
      pooled_(pooled_evidence(risk, cameras, robot)),
      fusion_(verdict_fusion(cameras, risk)),
      coverage_(cameras.size(), risk.min_link_pixels, robot_link_areas) {
  if (cameras.empty()) throw std::invalid_argument("CamerasJudgement: no camera to judge");
  if (cameras.size() > 1 && !(coverage_.total_area_m2() > 0)) {
    throw std::invalid_argument(
        "CamerasJudgement: no robot link with a surface area, so the arm no camera sees cannot be measured "
        "(risk.unseen_arm_max_fraction)");
  }
  for (const RiskCamera& camera : cameras_) {
    RiskSettings settings = several_cameras_evidence_settings(risk, cameras_.size());
    settings.required_heartbeats = camera.required_heartbeats;
    monitors_.push_back(
        std::make_unique<RiskMonitor>(settings, camera.channels, robot, camera.rate_hz, now_us));
    if (occupant) monitors_.back()->set_occupant(*occupant);
    monitors_.back()->set_pooled_evidence(pooled_.get());
  }
}

std::vector<risk_t> CamerasJudgement::on_frame(size_t c, const discrepancy_t& d, int64_t now_us) {
  coverage_.on_frame(c, d);
  return published(c, monitors_[c]->on_frame(d, now_us));
}

std::optional<risk_t> CamerasJudgement::published(size_t c, const risk_t& verdict) {
  std::optional<risk_t> fused = fusion_.fuse(c, verdict);
  if (!fused || cameras_.size() < 2 || fused->seq < 0) return fused;
  const std::vector<std::string> unseen = unseen_links();
  const double unseen_fraction = coverage_.area_fraction(unseen);
  limit_unseen_arm(unseen, unseen_fraction, unseen_arm_max_fraction_, &*fused);
  fused->detail += unseen_links_text(unseen, unseen_fraction);
  return fused;
}

std::vector<risk_t> CamerasJudgement::published(size_t c, const std::vector<risk_t>& verdicts) {
  std::vector<risk_t> out;
  for (const risk_t& verdict : verdicts) {
    if (std::optional<risk_t> r = published(c, verdict)) out.push_back(std::move(*r));
  }
  return out;
}

std::vector<std::string> CamerasJudgement::unseen_links() const {
  std::vector<bool> counted(cameras_.size());
  for (size_t c = 0; c < cameras_.size(); ++c) counted[c] = !fusion_.released(c);
  return coverage_.unseen_links(counted);
}

}  // namespace tofguard::risk
