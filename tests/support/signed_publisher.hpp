#pragma once
// Publishes a message the way tofguard-risk and tofguard-intervene do when
// the deployment has a key (docs/security.md): signed on <channel>_AUTH
// first, then plain on <channel>. For tests that stand in for tofguard-risk
// or tofguard-reset in front of a keyed tofguard-intervene. One per thread.
#include <lcm/lcm-cpp.hpp>

#include <string>

#include "tofguard/auth/auth_key.hpp"
#include "tofguard/auth/message_signer.hpp"
#include "tofguard/auth/signed_publish.hpp"
#include "tofguard/common/clock.hpp"
#include "tool_support.hpp"

namespace tofguard::test {

// The embedded default's key (config/sim.yaml's auth.key_file, made by
// scripts/build).
inline std::string default_key_file() { return source_dir() + "/config/auth.key"; }

class SignedPublisher {
 public:
  explicit SignedPublisher(lcm::LCM& lcm, const std::string& key_file = default_key_file())
      : lcm_(lcm), signer_(auth::read_auth_key_file(key_file), wall_utime()) {}

  template <class T>
  void publish(const std::string& channel, const T& message) {
    auth::publish_signed(lcm_, &signer_, channel, channel + "_AUTH", message, wall_utime());
  }
  // Only the signed copy (e.g. a reset, which a keyed sender never sends
  // plain). Returns what was sent, for replays.
  template <class T>
  authenticated_message_t publish_signed_only(const std::string& channel, const T& message) {
    const authenticated_message_t m = signer_.sign(channel, message, wall_utime());
    lcm_.publish(channel + "_AUTH", &m);
    return m;
  }

 private:
  lcm::LCM& lcm_;
  auth::MessageSigner signer_;
};

}  // namespace tofguard::test
