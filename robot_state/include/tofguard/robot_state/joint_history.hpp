#pragma once
// A bounded history of reported joint states, to know the joints at a
// camera frame's capture time: linear interpolation between the two
// messages that bracket it; beyond the newest message, linear extrapolation
// from the last two, but only up to a limit (further than that, the frame is
// unusable: the arm may have moved anywhere).
//
// Times are utime (microseconds since the Unix epoch, as on the wire):
// joint_state_t.utime is when the encoders were read, depth_image_t.utime
// the camera frame's mid-exposure.
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "tofguard/robot_model/kinematics.hpp"

namespace tofguard::robot_state {

struct JointsAtTime {
  // False when no joint values may be used; then `unusable_reason` says why.
  bool usable = false;
  std::string unusable_reason;
  // Joints reported in both bracketing messages (a joint missing from one
  // of them is left out, and forward kinematics then names it).
  robot_model::JointPositions joints;
};

class JointHistory {
 public:
  // Keeps messages no older than `span_us` behind the newest one, and at
  // most `max_messages`. `max_extrapolation_us` (>= 0) is how far beyond
  // the newest message (or before the oldest) a time may be.
  JointHistory(int64_t max_extrapolation_us, int64_t span_us = 2'000'000, size_t max_messages = 1000);

  // Adds one message; a message not newer than the newest one so far is
  // ignored and false returned (LCM does not reorder one publisher's
  // messages, so this is a duplicate or a second publisher, worth counting).
  bool add(int64_t utime, const robot_model::JointPositions& positions);

  JointsAtTime at(int64_t utime) const { return at(utime, max_extrapolation_us_); }
  // The same with another limit beyond the newest message (or before the
  // oldest), us (>= 0): for a guess that is checked later, e.g. the
  // renderer's prediction of the next frame's joints.
  JointsAtTime at(int64_t utime, int64_t max_extrapolation_us) const;

  // The newest message's utime (nullopt before the first).
  std::optional<int64_t> newest_utime() const {
    if (history_.empty()) return std::nullopt;
    return history_.back().utime;
  }

  size_t size() const { return history_.size(); }

 private:
  struct Sample {
    int64_t utime;
    robot_model::JointPositions positions;
  };
  static robot_model::JointPositions blend(const Sample& a, const Sample& b, int64_t utime);

  int64_t max_extrapolation_us_;
  int64_t span_us_;
  size_t max_messages_;
  std::deque<Sample> history_;
};

}  // namespace tofguard::robot_state
