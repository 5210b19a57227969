#pragma once
// The spy's refreshing status board: the permission to move and why, the
// latest risk with cause and suspect, the arm's speed limit, each camera
// (its frame rate, its last frame's age and the latest verdict that named
// it: with several cameras tofguard-risk's verdict is the worst of theirs,
// its detail starting with the camera's id), each process's heartbeat age
// and counters, each channel's rate, and the end-to-end latency from the
// camera frame's capture utime. Pure: every call gets the clocks.
//
// Latency is wall clock at arrival minus the message's camera utime, so it
// is only meaningful live (a replayed log carries old utimes); rates and
// heartbeat ages use the monotonic clock.
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <ostream>
#include <string>

#include "tofguard/heartbeat_t.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/safety_status_t.hpp"
#include "tofguard/speed_limit_t.hpp"

namespace tofguard::spy {

class StatusBoard {
 public:
  void on_message(const std::string& channel, const void* data, int size, int64_t now_us, int64_t now_utime);
  std::string render(int64_t now_us, int64_t now_utime) const;

 private:
  struct ChannelStats {
    std::deque<int64_t> arrivals_us;  // last 2 s
    std::optional<int64_t> latency_us;
  };
  // A camera, by depth_image_t.camera_id.
  struct CameraStats {
    std::deque<int64_t> frame_arrivals_us;  // last 2 s
    std::optional<risk_t> verdict;          // the latest whose detail names it
    int64_t verdict_arrival_us = 0;
  };
  void on_risk(const risk_t& risk, int64_t now_us);
  void render_cameras(std::ostream& s, int64_t now_us) const;
  std::optional<safety_status_t> status_;
  int64_t status_arrival_us_ = 0;
  std::optional<risk_t> risk_;
  int64_t risk_arrival_us_ = 0;
  std::optional<speed_limit_t> limit_;
  int64_t limit_arrival_us_ = 0;
  std::map<std::string, std::pair<heartbeat_t, int64_t>> heartbeats_;  // by process: message, arrival
  std::map<std::string, ChannelStats> channels_;
  std::map<std::string, CameraStats> cameras_;
};

}  // namespace tofguard::spy
