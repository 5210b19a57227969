#pragma once
#include <cstdint>
#include <string>

#include "tofguard/common/lcm_node.hpp"

namespace tofguard::intervene {

// Messages refused by the authentication: counted as validation errors in
// the heartbeat, reported in one line each (rate-limited per channel), and
// summed up in the heartbeat's status.
struct AuthRefusals {
  int64_t count = 0;
  std::string last;

  void refuse(LcmNode& node, const std::string& channel, const std::string& why) {
    ++count;
    last = channel + ": " + why;
    node.counters().validation_errors++;
    node.errors().report(channel, channel + ": refused: " + why);
  }
  std::string summary() const {
    if (count == 0) return "";
    return "; " + std::to_string(count) + " messages refused by authentication (last: " + last + ")";
  }
};

}  // namespace tofguard::intervene
