#pragma once
// One process's LCM plumbing: the safety URL and the image URL (see
// LcmSettings), checked subscriptions that decode, validate and count every
// message, periodic timers on the monotonic clock, a heartbeat on
// SAFETY_HEARTBEAT, and a clean stop on SIGINT / SIGTERM.
//
// A malformed message never reaches a handler and never stops the process:
// it is counted (decode_errors for a wrong fingerprint or a truncated
// message, validation_errors for one that decodes but fails its check) and
// reported in one line naming the process, the channel, the field and what
// was expected.
#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "tofguard/common/decode.hpp"
#include "tofguard/common/error_log.hpp"
#include "tofguard/common/heartbeat.hpp"
#include "tofguard/common/lcm_settings.hpp"

namespace tofguard {

// Installs SIGINT/SIGTERM handlers that make stop_requested() true.
void install_stop_signal_handlers();
bool stop_requested();

class LcmNode {
 public:
  // Opens both URLs (one LCM instance when they are equal); throws
  // std::runtime_error naming the URL when LCM cannot start. Heartbeats go
  // out on channels.heartbeat at `heartbeat_rate_hz`, as `process_name` with
  // the camera's channels.camera_suffix appended (the processes of a second
  // camera are "tofguard-renderer/<id>", ...). Each URL is joined on the
  // first subscription on it (below).
  LcmNode(const LcmSettings& lcm, const ChannelNames& channels, const std::string& process_name,
          double heartbeat_rate_hz = 20);
  ~LcmNode();
  LcmNode(const LcmNode&) = delete;
  LcmNode& operator=(const LcmNode&) = delete;

  lcm::LCM& safety() { return *safety_; }
  lcm::LCM& images() { return images_ ? *images_ : *safety_; }
  MessageCounters& counters() { return heartbeat_.counters(); }
  HeartbeatPublisher& heartbeat() { return heartbeat_; }
  ErrorLog& errors() { return errors_; }
  const std::string& process_name() const { return process_name_; }

  // Subscribes `on_message` to `channel` on `lcm` (safety() or images()).
  // The first subscription on a URL joins it: a process that only
  // publishes images, or never reads them, is not woken by each of the
  // three image messages of every frame (TOF_DEPTH, TOF_LABELS,
  // TOF_RENDERED, 25-300 KB each) on a core the chain needs, and one that
  // reads nothing on the safety URL (tofguard-discrepancy) not by each
  // joint state, heartbeat and verdict there (the kernel copies every
  // message of a multicast group to each socket joined to it, inside the
  // sender's send).
  // `check` returns "" for a valid message, else "field: expected ..., got
  // ..." (see wire_checks.hpp). Every valid message counts as frames_in.
  template <class T>
  void subscribe(lcm::LCM& lcm, const std::string& channel, std::function<void(const T&)> on_message,
                 std::function<std::string(const T&)> check = nullptr);

  // Calls `tick` every `period_us` microseconds of the monotonic clock
  // (first call one period from now).
  void add_timer(int64_t period_us, std::function<void()> tick);
  // The same, the first call at `first_due_us` (monotonic), so that the
  // calls keep that phase.
  void add_timer(int64_t period_us, int64_t first_due_us, std::function<void()> tick);

  // Handles every message and due timer within `max_wait_ms`; returns false
  // once a stop was requested.
  bool spin_once(int max_wait_ms);
  // spin_once until a stop is requested.
  void run();

 private:
  // Joins `lcm`'s multicast group now (LCM 1.3 joins lazily, on the first
  // getFileno()/handle()), so that nothing sent after a subscription is
  // missed; for images_, also marks it to be polled.
  void join(lcm::LCM& lcm);

  struct SubscriptionBase {
    virtual ~SubscriptionBase() = default;
  };
  template <class T>
  struct CheckedSubscription;
  struct Timer {
    int64_t period_us;
    int64_t next_us;
    std::function<void()> tick;
  };

  std::string process_name_;
  std::unique_ptr<lcm::LCM> safety_;
  std::unique_ptr<lcm::LCM> images_;  // null when the image URL is the safety URL
  bool safety_joined_ = false;        // safety_ has its receive socket (subscribed on it)
  bool images_joined_ = false;        // images_ has its receive socket (subscribed on it)
  ErrorLog errors_;
  HeartbeatPublisher heartbeat_;
  std::vector<std::unique_ptr<SubscriptionBase>> subscriptions_;
  std::vector<Timer> timers_;
};

template <class T>
struct LcmNode::CheckedSubscription : LcmNode::SubscriptionBase {
  LcmNode* node;
  std::function<void(const T&)> on_message;
  std::function<std::string(const T&)> check;

  void handle(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    const std::optional<T> decoded = decode_message<T>(rbuf->data, static_cast<int>(rbuf->data_size));
    if (!decoded) {
      node->counters().decode_errors++;
      node->errors().report(channel, channel + ": cannot decode as " + T::getTypeName() +
                                         " (wrong fingerprint, or truncated / malformed)");
      return;
    }
    const T& message = *decoded;
    if (check) {
      const std::string problem = check(message);
      if (!problem.empty()) {
        node->counters().validation_errors++;
        node->errors().report(channel, channel + ": " + problem);
        return;
      }
    }
    node->counters().frames_in++;
    on_message(message);
  }
};

template <class T>
void LcmNode::subscribe(lcm::LCM& lcm, const std::string& channel, std::function<void(const T&)> on_message,
                        std::function<std::string(const T&)> check) {
  auto subscription = std::make_unique<CheckedSubscription<T>>();
  subscription->node = this;
  subscription->on_message = std::move(on_message);
  subscription->check = std::move(check);
  lcm.subscribe(channel, &CheckedSubscription<T>::handle, subscription.get());
  subscriptions_.push_back(std::move(subscription));
  join(lcm);
}

}  // namespace tofguard
