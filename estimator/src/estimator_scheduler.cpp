#include "tofguard/estimator/estimator_scheduler.hpp"

#include <iterator>
#include <utility>

#include "tofguard/common/depth_frame.hpp"
#include "tofguard/common/risk_names.hpp"
#include "tofguard/renderer/state_history_settings.hpp"
#include "tofguard/robot_model/kinematics.hpp"
#include "tofguard/settings/renderer_settings.hpp"

namespace tofguard::estimator {

EstimatorScheduler::EstimatorScheduler(const EstimatorProcessSettings& settings,
                                       const robot_model::SceneModel& scene)
    : settings_(settings),
      scene_(scene),
      state_(renderer::state_history_settings(settings.renderer, settings.robot.id, settings.camera)) {}

bool EstimatorScheduler::on_joint_state(const joint_state_t& state) {
  // A frame waiting for its joints may now be ready.
  return state_.add_joint_state(state);
}

void EstimatorScheduler::on_camera_pose(const camera_pose_t& message) { state_.add_camera_pose(message); }

bool EstimatorScheduler::on_depth(const depth_image_t& frame) {
  if (frame.camera_id != settings_.camera.id) return false;
  if (settings_.camera_profile) {
    // Corrected by the camera's profile as tofguard-discrepancy corrects it;
    // a frame the profile does not fit is not estimated (tofguard-discrepancy
    // reports it unusable).
    if (!profile_mismatch(*settings_.camera_profile, frame).empty()) return false;
    depth_image_t corrected = frame;
    apply_camera_profile(*settings_.camera_profile, &corrected);
    frames_[frame.seq] = std::move(corrected);
  } else {
    frames_[frame.seq] = frame;
  }
  while (static_cast<int>(frames_.size()) > settings_.estimator.max_pending_frames) {
    const int64_t oldest = frames_.begin()->first;
    if (wanted_.count(oldest) > 0) {
      wanted_.erase(oldest);
      ++missed_;
    }
    frames_.erase(frames_.begin());
  }
  while (!warning_seqs_.empty() && *warning_seqs_.begin() < frames_.begin()->first) {
    warning_seqs_.erase(warning_seqs_.begin());
  }
  // Wanted seqs older than every kept frame will never come.
  while (!wanted_.empty() && wanted_.begin()->first < frames_.begin()->first) {
    wanted_.erase(wanted_.begin());
    ++missed_;
  }
  while (estimated_.size() > 1000) estimated_.erase(estimated_.begin());
  const auto w = wanted_.find(frame.seq);
  if (w != wanted_.end()) {
    ready_.push_back(build(frame, w->second));
    estimated_.insert(frame.seq);
    wanted_.erase(w);
  }
  return true;
}

bool EstimatorScheduler::passes_warning(const discrepancy_t& d) const {
  // The estimator's own thresholds on the published summary (estimator.
  // warning); tofguard-risk's verdicts add the frames its rules judge a
  // model mismatch (on_risk).
  return d.mismatch_fraction >= settings_.estimator.warning_mismatch_fraction ||
         d.p95_abs_dis_mm >= settings_.estimator.warning_p95_abs_dis_mm;
}

void EstimatorScheduler::on_discrepancy(const discrepancy_t& d) {
  if (d.camera_id != settings_.camera.id || !d.usable) return;
  if (passes_warning(d)) on_warning(d.seq, d.utime);
}

void EstimatorScheduler::on_risk(const risk_t& r) {
  // Timeouts (seq -1) are about no frame; faults are not the model's.
  if (r.seq < 0 || r.level < risk_t::WARNING || !is_model_mismatch(r.cause)) return;
  // Another camera's verdict (several cameras): not about this camera's
  // frame of that seq.
  if (settings_.several_cameras && r.detail.rfind(settings_.camera.id + ": ", 0) != 0) return;
  // A verdict on a frame kept with another utime is not about that frame
  // (a camera restarted its seqs).
  const auto f = frames_.find(r.seq);
  if (f != frames_.end() && f->second.utime != r.utime) return;
  on_warning(r.seq, r.utime);
}

void EstimatorScheduler::on_warning(int64_t seq, int64_t utime) {
  if (frames_.empty() || seq >= frames_.begin()->first) warning_seqs_.insert(seq);
  if (estimated_.count(seq) > 0) return;
  const int64_t min_interval_us = settings_.estimator.warning_min_interval_us;
  if (last_warning_utime_ > 0 && utime >= last_warning_utime_ &&
      utime - last_warning_utime_ < min_interval_us) {
    return;  // rate limit (camera time)
  }
  last_warning_utime_ = utime;
  const auto f = frames_.find(seq);
  if (f != frames_.end()) {
    ready_.push_back(build(f->second, motion_estimate_t::TRIGGER_WARNING));
    estimated_.insert(seq);
  } else if (frames_.empty() || seq > frames_.begin()->first) {
    wanted_[seq] = motion_estimate_t::TRIGGER_WARNING;
  } else {
    ++missed_;
  }
}

void EstimatorScheduler::request_newest() {
  if (frames_.empty()) return;
  const auto newest = std::prev(frames_.end());
  if (estimated_.count(newest->first) > 0) return;
  ready_.push_back(build(newest->second, motion_estimate_t::TRIGGER_PERIODIC));
  estimated_.insert(newest->first);
}

std::vector<ScheduledWork> EstimatorScheduler::take_ready() {
  std::vector<ScheduledWork> out;
  out.swap(ready_);
  return out;
}

std::optional<EstimatorFrame> EstimatorScheduler::estimator_frame(const depth_image_t& frame,
                                                                  const std::string& frame_id,
                                                                  std::string* why) const {
  const robot_state::StateAtFrame state = state_.at(frame.camera_id, frame.utime);
  if (!state.joints.usable) {
    *why = "joint state: " + state.joints.unusable_reason;
    return std::nullopt;
  }
  const robot_state::PoseAtTime& pose = state.camera_pose;
  if (!pose.usable) {
    *why = "camera pose: " + pose.unusable_reason;
    return std::nullopt;
  }
  if (pose.pose.frame_id != frame_id) {
    *why = "camera pose frame changed from '" + frame_id + "' to '" + pose.pose.frame_id + "'";
    return std::nullopt;
  }
  const int frame_link = scene_.find_link(frame_id);
  if (frame_link < 0) {
    *why = "camera pose frame '" + frame_id + "' is not a model link";
    return std::nullopt;
  }
  // A camera on a moving link would move with the joints being estimated:
  // not modelled.
  const std::string moving = scene_.nearest_movable_joint_above(frame_id);
  if (!moving.empty()) {
    *why = "camera pose frame '" + frame_id + "' moves with joint '" + moving +
           "': a camera on the arm is not supported by the estimator";
    return std::nullopt;
  }
  const robot_model::LinkPoses poses = robot_model::forward_kinematics(scene_, state.joints.joints);
  if (!poses.usable) {
    *why = poses.unusable_reason;
    return std::nullopt;
  }
  EstimatorFrame out;
  out.intrinsics = intrinsics_of(frame);
  out.reported_joints = state.joints.joints;
  out.world_from_optical = poses.world_from_link[frame_link] * pose.pose.frame_from_optical();
  out.depth_m = depth_m_of(frame);
  return out;
}

ScheduledWork EstimatorScheduler::build(const depth_image_t& frame, int8_t trigger) const {
  ScheduledWork work;
  EstimateContext context;
  context.utime = frame.utime;
  context.seq = frame.seq;
  context.camera_id = frame.camera_id;
  context.trigger = trigger;
  context.joint_names = scene_.actuated_joint_names;
  const robot_state::StateAtFrame state = state_.at(frame.camera_id, frame.utime);
  if (state.camera_pose.usable) {
    context.frame_id = state.camera_pose.pose.frame_id;
    context.frame_from_optical = state.camera_pose.pose.frame_from_optical();
  }
  const robot_model::JointPositions& joints = state.joints.joints;
  for (const std::string& name : context.joint_names) {
    const auto found = joints.find(name);
    context.reported_positions.push_back(found != joints.end() ? found->second : 0.0);
  }
  std::string why;
  std::optional<EstimatorFrame> first = estimator_frame(frame, context.frame_id, &why);
  if (!first) {
    work.unusable = unusable_message(context, why);
    return work;
  }
  EstimateJob job;
  job.context = context;
  job.frames.push_back(std::move(*first));
  // The kept frames just before it, newest first, that can be estimated
  // with it: on the same side of a fault's onset (warning or not), joints
  // and pose known, same size and pose frame.
  const bool warning = trigger == motion_estimate_t::TRIGGER_WARNING || warning_seqs_.count(frame.seq) > 0;
  for (auto it = frames_.lower_bound(frame.seq);
       it != frames_.begin() &&
       static_cast<int>(job.frames.size()) < settings_.estimator.frames_per_estimate;) {
    --it;
    const depth_image_t& earlier = it->second;
    if ((warning_seqs_.count(it->first) > 0) != warning) continue;
    if (earlier.width != frame.width || earlier.height != frame.height) continue;
    std::optional<EstimatorFrame> f = estimator_frame(earlier, context.frame_id, &why);
    if (f) job.frames.push_back(std::move(*f));
  }
  work.job = std::move(job);
  return work;
}

}  // namespace tofguard::estimator
