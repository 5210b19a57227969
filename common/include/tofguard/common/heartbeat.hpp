#pragma once
// The heartbeat every process sends on SAFETY_HEARTBEAT (heartbeat_t) at
// 10 Hz or more: the risk classifier declares a component fault when one
// stops, and the spy shows the counters.
#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <string>

namespace tofguard {

// Counts since the process started; never reset, never go down.
struct MessageCounters {
  int64_t frames_in = 0;
  int64_t frames_out = 0;
  int64_t frames_dropped = 0;
  int64_t decode_errors = 0;
  int64_t validation_errors = 0;
};

class HeartbeatPublisher {
 public:
  HeartbeatPublisher(lcm::LCM* lcm, std::string channel, std::string process_name, double rate_hz);

  MessageCounters& counters() { return counters_; }
  void set_status(const std::string& status) { status_ = status; }
  void set_last_frame_utime(int64_t utime) { last_frame_utime_ = utime; }

  // Publishes when a heartbeat is due on the monotonic clock.
  void publish_if_due();
  // Microseconds until the next heartbeat is due (0 if overdue).
  int64_t us_until_due() const;

 private:
  void publish();

  lcm::LCM* lcm_;
  std::string channel_;
  std::string process_name_;
  int64_t period_us_;
  int64_t next_due_us_;
  int64_t seq_ = 0;
  MessageCounters counters_;
  std::string status_ = "starting";
  int64_t last_frame_utime_ = 0;
};

}  // namespace tofguard
