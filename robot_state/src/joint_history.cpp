#include "tofguard/robot_state/joint_history.hpp"

#include <algorithm>

namespace tofguard::robot_state {

JointHistory::JointHistory(int64_t max_extrapolation_us, int64_t span_us, size_t max_messages)
    : max_extrapolation_us_(std::max<int64_t>(0, max_extrapolation_us)),
      span_us_(span_us),
      max_messages_(std::max<size_t>(2, max_messages)) {}

bool JointHistory::add(int64_t utime, const robot_model::JointPositions& positions) {
  if (!history_.empty() && utime <= history_.back().utime) return false;
  history_.push_back({utime, positions});
  while (history_.size() > max_messages_ ||
         (history_.size() > 2 && history_.front().utime < utime - span_us_)) {
    history_.pop_front();
  }
  return true;
}

robot_model::JointPositions JointHistory::blend(const Sample& a, const Sample& b, int64_t utime) {
  // Linear in time through a and b; also beyond them (extrapolation).
  const double s = static_cast<double>(utime - a.utime) / static_cast<double>(b.utime - a.utime);
  robot_model::JointPositions result;
  for (const auto& [name, value_a] : a.positions) {
    const auto value_b = b.positions.find(name);
    if (value_b != b.positions.end()) result[name] = value_a + s * (value_b->second - value_a);
  }
  return result;
}

JointsAtTime JointHistory::at(int64_t utime, int64_t max_extrapolation_us) const {
  JointsAtTime result;
  if (history_.empty()) {
    result.unusable_reason = "no joint state received yet";
    return result;
  }
  const Sample& newest = history_.back();
  const Sample& oldest = history_.front();
  if (utime > newest.utime) {
    const int64_t ahead_us = utime - newest.utime;
    if (ahead_us > max_extrapolation_us) {
      result.unusable_reason = "newest joint state is " + std::to_string(ahead_us / 1000.0) +
                               " ms older than the frame (limit " +
                               std::to_string(max_extrapolation_us / 1000.0) + " ms)";
      return result;
    }
    result.joints =
        history_.size() >= 2 ? blend(history_[history_.size() - 2], newest, utime) : newest.positions;
  } else if (utime < oldest.utime) {
    const int64_t behind_us = oldest.utime - utime;
    if (behind_us > max_extrapolation_us) {
      result.unusable_reason =
          "frame is " + std::to_string(behind_us / 1000.0) + " ms older than the oldest joint state kept";
      return result;
    }
    result.joints = oldest.positions;
  } else {
    // First sample not older than utime; its predecessor brackets from below.
    const auto after = std::lower_bound(history_.begin(), history_.end(), utime,
                                        [](const Sample& s, int64_t t) { return s.utime < t; });
    result.joints = (after->utime == utime) ? after->positions : blend(*(after - 1), *after, utime);
  }
  result.usable = true;
  return result;
}

}  // namespace tofguard::robot_state
