#include "tofguard/risk/verdict_fusion.hpp"

#include <utility>

#include "tofguard/common/risk_names.hpp"

namespace tofguard::risk {

VerdictFusion::VerdictFusion(std::vector<std::string> camera_ids, std::vector<std::string> depth_channels,
                             bool releases_allowed)
    : camera_ids_(std::move(camera_ids)),
      depth_channels_(std::move(depth_channels)),
      releases_allowed_(releases_allowed),
      latest_(camera_ids_.size()),
      dangerous_since_(camera_ids_.size(), 0),
      released_(camera_ids_.size()) {}

size_t VerdictFusion::index_of(const std::string& id) const {
  for (size_t i = 0; i < camera_ids_.size(); ++i) {
    if (camera_ids_[i] == id) return i;
  }
  return camera_ids_.size();
}

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

risk_t VerdictFusion::worst_counted(size_t camera, const risk_t& verdict) const {
  std::optional<risk_t> worst;
  size_t worst_camera = camera;
  if (!released_[camera]) worst = verdict;
  for (size_t other = 0; other < latest_.size(); ++other) {
    if (other == camera || released_[other]) continue;
    const risk_t candidate = latest_[other] ? *latest_[other] : no_verdict_yet(other, verdict);
    const bool found_first = worst && latest_[other] && candidate.level == risk_t::DANGEROUS &&
                             worst->level == risk_t::DANGEROUS &&
                             dangerous_since_[other] < dangerous_since_[worst_camera];
    if (!worst || candidate.level > worst->level || found_first) {
      worst = candidate;
      worst_camera = other;
    }
  }
  // release() never leaves every camera released.
  return *worst;
}

std::optional<risk_t> VerdictFusion::fuse(size_t camera, risk_t verdict) {
  if (camera_ids_.size() == 1) return verdict;
  verdict.detail = camera_ids_[camera] + ": " + verdict.detail;
  latest_[camera] = verdict;
  if (verdict.level != risk_t::DANGEROUS) {
    dangerous_since_[camera] = 0;
  } else if (dangerous_since_[camera] == 0) {
    dangerous_since_[camera] = ++dangerous_runs_;
  }
  // Back: a released camera that judges a frame SAFE counts again.
  if (released_[camera] && verdict.seq >= 0 && verdict.level == risk_t::SAFE) released_[camera].reset();
  if (released_[camera]) return std::nullopt;
  risk_t published = worst_counted(camera, verdict);
  // A verdict about no frame (a deadline's, seq -1) that publishes another
  // camera's worse frame verdict publishes it as about no frame: that
  // frame's verdict went out when it was judged, and a second one with its
  // seq would be taken for another frame judged.
  if (verdict.seq < 0) published.seq = -1;
  for (size_t c = 0; c < released_.size(); ++c) {
    if (!released_[c]) continue;
    published.detail += " [" + camera_ids_[c] + " left out: released by " + released_[c]->who + ": " +
                        released_[c]->why + "]";
  }
  return published;
}

std::string VerdictFusion::release(size_t camera, const std::string& who, const std::string& why) {
  if (!releases_allowed_) {
    return "refused: risk.camera_loss is stop: a lost camera stops the arm until it is back";
  }
  if (released_[camera]) return "";
  const std::string& id = camera_ids_[camera];
  if (latest_[camera]) {
    const risk_t& latest = *latest_[camera];
    if (latest.level != risk_t::DANGEROUS) {
      return "refused: " + id + " is not lost: its latest verdict is " + risk_level_name(latest.level);
    }
    const bool the_cameras_own =
        is_fault_cause(latest.cause) || latest.cause == risk_t::CAUSE_CALIBRATION_ERROR;
    if (!the_cameras_own) {
      return "refused: " + id + "'s finding is a " + risk_cause_name(latest.cause) +
             ", not a fault of the camera: it holds (" + latest.detail + ")";
    }
  }
  size_t still_judging = 0;
  for (size_t c = 0; c < released_.size(); ++c) {
    if (c != camera && !released_[c]) ++still_judging;
  }
  if (still_judging == 0) return "refused: " + id + " is the last camera judging the arm";
  released_[camera] = Release{who, why};
  return "";
}

}  // namespace tofguard::risk
