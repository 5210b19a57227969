#pragma once
// The spy's refreshing status board: the permission to move and why, the
// latest risk with cause and suspect, the arm's speed limit, each process's heartbeat age and
// counters, each channel's rate, and the end-to-end latency from the camera
// frame's capture utime. Pure: every call gets the clocks.
//
// Latency is wall clock at arrival minus the message's camera utime, so it
// is only meaningful live (a replayed log carries old utimes); rates and
// heartbeat ages use the monotonic clock.
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
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
  std::optional<safety_status_t> status_;
  int64_t status_arrival_us_ = 0;
  std::optional<risk_t> risk_;
  int64_t risk_arrival_us_ = 0;
  std::optional<speed_limit_t> limit_;
  int64_t limit_arrival_us_ = 0;
  std::map<std::string, std::pair<heartbeat_t, int64_t>> heartbeats_;  // by process: message, arrival
  std::map<std::string, ChannelStats> channels_;
};

}  // namespace tofguard::spy
