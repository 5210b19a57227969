#pragma once
// Process-level tests of the safety chain: the test publishes synthetic
// inputs on the config's two LCM URLs (inside the test's private network
// namespace) and collects what the processes under test publish.
#include <lcm/lcm-cpp.hpp>

#include <chrono>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "tofguard/common/clock.hpp"
#include "tofguard/discrepancy_t.hpp"
#include "tofguard/heartbeat_t.hpp"
#include "tofguard/risk_t.hpp"
#include "tool_support.hpp"

namespace tofguard::test {

// The URLs of config/sim.yaml.
constexpr const char* kSafetyUrl = "udpm://239.255.76.67:7667?ttl=0";
constexpr const char* kImageUrl = "udpm://239.255.76.67:7668?ttl=0&recv_buf_size=4194304";

// config/sim.yaml with its paths made absolute and each (from, to)
// replacement applied (`from` must occur), written to the test outputs as
// chain-<name>.yaml.
inline std::string chain_config(const std::string& name,
                                const std::vector<std::pair<std::string, std::string>>& replacements = {}) {
  return sim_config_variant("chain-" + name, replacements);
}

template <class T>
struct Inbox {
  std::vector<T> messages;
  std::vector<int64_t> arrival_us;  // monotonic
  void on_message(const lcm::ReceiveBuffer*, const std::string&, const T* m) {
    messages.push_back(*m);
    arrival_us.push_back(monotonic_us());
  }
};

class ChainBus {
 public:
  ChainBus() : safety(kSafetyUrl), images(kImageUrl) {
    safety.subscribe("SAFETY_DISCREPANCY", &Inbox<discrepancy_t>::on_message, &discrepancies);
    safety.subscribe("SAFETY_RISK", &Inbox<risk_t>::on_message, &risks);
    safety.subscribe("SAFETY_HEARTBEAT", &Inbox<heartbeat_t>::on_message, &heartbeats);
  }

  // Handles what has arrived, waiting at most 1 ms.
  void poll() { safety.handleTimeout(1); }

  // The newest heartbeat of `process` (process empty when none yet).
  heartbeat_t last_heartbeat(const std::string& process) const {
    for (auto it = heartbeats.messages.rbegin(); it != heartbeats.messages.rend(); ++it) {
      if (it->process == process) return *it;
    }
    return heartbeat_t{};
  }

  // Publishes a heartbeat as `process` would.
  void beat(const std::string& process) {
    heartbeat_t hb{};
    hb.utime = wall_utime();
    hb.process = process;
    hb.pid = 1;
    hb.status = "test";
    safety.publish("SAFETY_HEARTBEAT", &hb);
  }

  lcm::LCM safety;
  lcm::LCM images;
  Inbox<discrepancy_t> discrepancies;
  Inbox<risk_t> risks;
  Inbox<heartbeat_t> heartbeats;
};

// Runs `step` every `period_ms` (monotonic) while waiting for `condition`,
// polling the bus in between; returns whether the condition came true.
inline bool run_until(ChainBus& bus, const std::function<bool()>& condition,
                      std::chrono::milliseconds deadline, int period_ms, const std::function<void()>& step) {
  int64_t next_us = monotonic_us();
  return wait_until(condition, deadline, [&] {
    if (monotonic_us() >= next_us) {
      step();
      next_us += int64_t{period_ms} * 1000;
    }
    bus.poll();
  });
}

}  // namespace tofguard::test
