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
// A lost camera (risk.camera_loss continue_after_named_reset): an
// operator's release naming it (release()) leaves it out of the worst-of
// until it judges the arm SAFE again; every verdict published meanwhile
// says which camera is left out, by whom and why. Only a camera whose own
// latest verdict is a fault of the camera (a sensor or component fault: a
// stall, a frozen image, silence, unusable frames; or a calibration error:
// it moved) can be released, and never the last camera still judging: a
// joint error, an object or an unclassified finding that one camera sees
// holds, whatever the operator says.
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
  // published as it is. `releases_allowed`: risk.camera_loss is
  // continue_after_named_reset.
  VerdictFusion(std::vector<std::string> camera_ids, std::vector<std::string> depth_channels,
                bool releases_allowed = false);

  // Camera `camera`'s verdict `verdict`: the verdict to publish. With
  // several cameras its detail begins with the camera's id ("tof-side: ").
  // The worst level of the cameras not released wins; among cameras equally
  // DANGEROUS, the one that has been so longest (the first finding stands
  // while it holds: a camera knocked, then the joint tests that its
  // frames push over, are published as the knock); among other equals,
  // the newest. The verdict published carries the seq of the verdict that
  // won, except that a verdict about no frame (seq -1, a deadline's)
  // publishes with seq -1 whichever wins: each frame verdict goes out once.
  // A released camera's SAFE frame verdict brings it back; its other
  // verdicts publish nothing (nullopt): the cameras that judge say what
  // there is to say.
  std::optional<risk_t> fuse(size_t camera, risk_t verdict);

  // An operator's release of lost camera `camera`: "" when accepted (or
  // already released), else why not ("refused: ...").
  std::string release(size_t camera, const std::string& who, const std::string& why);
  bool released(size_t camera) const { return released_[camera].has_value(); }

  size_t cameras() const { return camera_ids_.size(); }
  // The index of camera `id`, or cameras() when there is none.
  size_t index_of(const std::string& id) const;

 private:
  struct Release {
    std::string who;
    std::string why;
  };
  // The stand-in for a camera without a verdict yet, at `verdict`'s frame.
  risk_t no_verdict_yet(size_t camera, const risk_t& verdict) const;
  // The worst latest verdict of the cameras not released, at `verdict`'s
  // frame (`verdict` itself among equals when its camera counts).
  risk_t worst_counted(size_t camera, const risk_t& verdict) const;

  std::vector<std::string> camera_ids_;
  std::vector<std::string> depth_channels_;
  bool releases_allowed_;
  std::vector<std::optional<risk_t>> latest_;
  // Per camera, the order in which its latest run of DANGEROUS verdicts
  // began (1, 2, ...; 0 while its latest verdict is not DANGEROUS).
  std::vector<uint64_t> dangerous_since_;
  uint64_t dangerous_runs_ = 0;
  std::vector<std::optional<Release>> released_;
};

}  // namespace tofguard::risk
