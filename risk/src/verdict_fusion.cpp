#include "tofguard/risk/verdict_fusion.hpp"

#include <utility>

namespace tofguard::risk {

VerdictFusion::VerdictFusion(std::vector<std::string> camera_ids, std::vector<std::string> depth_channels)
    : camera_ids_(std::move(camera_ids)),
      depth_channels_(std::move(depth_channels)),
      latest_(camera_ids_.size()) {}

risk_t VerdictFusion::no_verdict_yet(size_t camera, const risk_t& verdict) const {
  risk_t r = verdict;
  r.level = risk_t::DANGEROUS;
  r.cause = risk_t::CAUSE_SENSOR_FAULT;
  r.suspect = depth_channels_[camera];
  r.score = 0;
  r.threshold = 0;
  r.detail = camera_ids_[camera] + ": no frame of this camera judged yet";
  return r;
}

risk_t VerdictFusion::fuse(size_t camera, risk_t verdict) {
  if (camera_ids_.size() == 1) return verdict;
  verdict.detail = camera_ids_[camera] + ": " + verdict.detail;
  latest_[camera] = verdict;
  risk_t worst = verdict;
  for (size_t other = 0; other < latest_.size(); ++other) {
    if (other == camera) continue;
    const risk_t candidate = latest_[other] ? *latest_[other] : no_verdict_yet(other, verdict);
    if (candidate.level > worst.level) worst = candidate;
  }
  return worst;
}

}  // namespace tofguard::risk
