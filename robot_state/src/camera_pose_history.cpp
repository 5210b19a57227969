#include "tofguard/robot_state/camera_pose_history.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace tofguard::robot_state {
namespace {

// Poses closer than this are the same (a repeated calibration), metres and
// radians: far below anything a depth camera resolves.
constexpr double kSamePoseM = 1e-9;
constexpr double kSamePoseRad = 1e-9;

bool same_pose(const CameraPose& a, const CameraPose& b) {
  return a.frame_id == b.frame_id && (a.translation_m - b.translation_m).norm() <= kSamePoseM &&
         a.rotation.angularDistance(b.rotation) <= kSamePoseRad;
}

std::string ms(int64_t us) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(1) << us / 1000.0 << " ms";
  return s.str();
}

}  // namespace

CameraPoseHistory::CameraPoseHistory(int64_t history_us, int64_t max_extrapolation_us, int64_t max_gap_us)
    : history_us_(history_us),
      max_extrapolation_us_(std::max<int64_t>(0, max_extrapolation_us)),
      max_gap_us_(max_gap_us) {}

void CameraPoseHistory::set_static(const std::string& camera_id, const CameraPose& pose) {
  static_poses_[camera_id] = pose;
}

bool CameraPoseHistory::add(const std::string& camera_id, int64_t utime, const CameraPose& pose) {
  Camera& camera = cameras_[camera_id];
  if (!camera.poses.empty() && camera.poses.back().pose.frame_id != pose.frame_id) camera = Camera{};
  if (!camera.poses.empty() && utime <= camera.poses.back().utime) return false;
  camera.poses.push_back({utime, pose});
  while (camera.poses.size() > 2 && camera.poses.front().utime < utime - history_us_)
    camera.poses.pop_front();
  return true;
}

bool CameraPoseHistory::motion(const Sample& a, const Sample& b) const {
  return b.utime - a.utime <= max_gap_us_ && !same_pose(a.pose, b.pose);
}

bool CameraPoseHistory::moving(const std::string& camera_id) const {
  const auto it = cameras_.find(camera_id);
  if (it == cameras_.end() || it->second.poses.size() < 2) return false;
  const std::deque<Sample>& poses = it->second.poses;
  return motion(poses[poses.size() - 2], poses.back());
}

CameraPose CameraPoseHistory::blend(const Sample& a, const Sample& b, int64_t utime) {
  // Linear in time through a and b; beyond b (s > 1) the same motion goes on.
  const double s = static_cast<double>(utime - a.utime) / static_cast<double>(b.utime - a.utime);
  CameraPose pose;
  pose.frame_id = b.pose.frame_id;
  pose.translation_m = a.pose.translation_m + s * (b.pose.translation_m - a.pose.translation_m);
  // The rotation from a to b (in frame_id), scaled by s: exact slerp for
  // 0 <= s <= 1, and the same angular velocity beyond.
  const Eigen::AngleAxisd step(b.pose.rotation * a.pose.rotation.inverse());
  pose.rotation =
      (Eigen::Quaterniond(Eigen::AngleAxisd(step.angle() * s, step.axis())) * a.pose.rotation).normalized();
  return pose;
}

PoseAtTime CameraPoseHistory::at(const std::string& camera_id, int64_t utime) const {
  PoseAtTime result;
  const auto camera = cameras_.find(camera_id);
  if (camera == cameras_.end() || camera->second.poses.empty()) {
    const auto fixed = static_poses_.find(camera_id);
    if (fixed == static_poses_.end()) {
      result.unusable_reason = "no camera pose for camera '" + camera_id + "'";
      return result;
    }
    result.pose = fixed->second;
    result.usable = true;
    return result;
  }
  const std::deque<Sample>& poses = camera->second.poses;
  result.usable = true;
  const Sample& newest = poses.back();
  const Sample& oldest = poses.front();
  if (utime >= newest.utime) {
    const int64_t ahead_us = utime - newest.utime;
    if (poses.size() < 2 || !motion(poses[poses.size() - 2], newest)) {
      result.pose = newest.pose;  // at rest, or a calibration: holds
    } else if (ahead_us > max_extrapolation_us_) {
      result.usable = false;
      result.unusable_reason = "newest camera pose of moving camera '" + camera_id + "' is " + ms(ahead_us) +
                               " older than the frame (limit " + ms(max_extrapolation_us_) + ")";
    } else {
      result.pose = blend(poses[poses.size() - 2], newest, utime);
    }
  } else if (utime < oldest.utime) {
    const int64_t behind_us = oldest.utime - utime;
    if (poses.size() >= 2 && motion(oldest, poses[1]) && behind_us > max_extrapolation_us_) {
      result.usable = false;
      result.unusable_reason = "frame is " + ms(behind_us) +
                               " older than the oldest camera pose kept of moving camera '" + camera_id +
                               "' (limit " + ms(max_extrapolation_us_) + ")";
    } else {
      result.pose = oldest.pose;
    }
  } else {
    const auto after = std::lower_bound(poses.begin(), poses.end(), utime,
                                        [](const Sample& s, int64_t t) { return s.utime < t; });
    const Sample& before = *(after - 1);
    if (after->utime == utime) {
      result.pose = after->pose;
    } else if (motion(before, *after)) {
      result.pose = blend(before, *after, utime);
    } else {
      result.pose = before.pose;  // a step: the earlier pose holds until the next
    }
  }
  return result;
}

}  // namespace tofguard::robot_state
