#pragma once
// One verdict stream from several cameras (docs/safety-chain.md, "Several
// cameras"). tofguard-risk judges each camera's frames and inputs with a
// RiskMonitor of its own; what goes out on SAFETY_RISK is, at every
// verdict of any camera, the worst of every camera's latest verdict. So a
// camera's open diagnosis, stale input or stop holds in every verdict
// published until that camera itself says otherwise, whatever the other
// cameras see, and a camera that has not yet had a frame judged keeps the
// verdict DANGEROUS: a camera never leaves the judgement silently.
//
// Pure logic, no LCM or clocks: a camera's silence is its own monitor's
// deadline (its timeout verdicts come through here as any other).
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "tofguard/risk_t.hpp"

namespace tofguard::risk {

class VerdictFusion {
 public:
  // The cameras' ids, in config order, and each one's depth channel (the
  // suspect while it has had no verdict). With one camera every verdict is
  // published as it is.
  VerdictFusion(std::vector<std::string> camera_ids, std::vector<std::string> depth_channels);

  // Camera `camera`'s verdict `verdict`: the verdict to publish. With
  // several cameras its detail begins with the camera's id ("tof-side: ").
  // The worst level wins; among equals, the newest.
  risk_t fuse(size_t camera, risk_t verdict);

  size_t cameras() const { return camera_ids_.size(); }

 private:
  // The stand-in for a camera without a verdict yet, at `verdict`'s frame.
  risk_t no_verdict_yet(size_t camera, const risk_t& verdict) const;

  std::vector<std::string> camera_ids_;
  std::vector<std::string> depth_channels_;
  std::vector<std::optional<risk_t>> latest_;
};

}  // namespace tofguard::risk
