#pragma once
// Signs a message that can allow motion into an authenticated_message_t for
// its companion channel (docs/security.md). Used by tofguard-risk
// (SAFETY_RISK), tofguard-intervene (SAFETY_STATUS, SAFETY_POWER) and
// tofguard-reset (SAFETY_RESET); message_verifier.hpp checks the result.
#include <cstdint>
#include <string>
#include <vector>

#include "tofguard/auth/message_tag.hpp"
#include "tofguard/authenticated_message_t.hpp"

namespace tofguard::auth {

class MessageSigner {
 public:
  // now_utime: the sender's wall clock at start (microseconds since the Unix
  // epoch); the replay counter starts there, so it keeps rising across
  // restarts as long as the wall clock does.
  MessageSigner(AuthKey key, int64_t now_utime);

  // `message` (an LCM type) encoded as the payload of a message for
  // `channel`, sent at `now_utime`.
  template <class T>
  authenticated_message_t sign(const std::string& channel, const T& message, int64_t now_utime) {
    std::vector<uint8_t> payload(static_cast<size_t>(message.getEncodedSize()));
    message.encode(payload.data(), 0, static_cast<int>(payload.size()));
    return sign_payload(channel, std::move(payload), now_utime);
  }

  // An already encoded payload (for tests and tools).
  authenticated_message_t sign_payload(const std::string& channel, std::vector<uint8_t> payload,
                                       int64_t now_utime);

  const std::string& key_id() const { return key_.id; }

 private:
  AuthKey key_;
  // The next seq: one above the last one sent, or the wall clock when that
  // is higher (the counter never falls behind real time, so a restarted
  // sender is not taken for a replay).
  int64_t next_seq_;
};

}  // namespace tofguard::auth
