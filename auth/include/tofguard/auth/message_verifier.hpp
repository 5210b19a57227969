#pragma once
// Checks authenticated_message_t before its payload may act as a permission
// (docs/security.md). Header-only: this is the verifier tofguard-intervene
// uses for SAFETY_RISK_AUTH and SAFETY_RESET_AUTH, and the one a robot
// controller includes to verify SAFETY_STATUS_AUTH (see
// auth/examples/verify_status.cpp). Link with -lsodium.
//
// A message is accepted only when, in this order:
//  1. it is for the channel the receiver expects (a status is no risk);
//  2. it names the receiver's key (key_id);
//  3. its tag is HMAC-SHA256(key, tagged_bytes) (compared in constant time);
//  4. its utime is within max_age of the receiver's wall clock (a replay of
//     an old message, or a sender whose clock is off, is refused);
//  5. its seq is above the last seq accepted on that channel (a replay
//     within the time window is refused).
// A refused message changes nothing: the last accepted seq stays.
#include <cstdint>
#include <cstdlib>
#include <map>
#include <optional>
#include <string>
#include <utility>

#include "tofguard/auth/message_tag.hpp"

namespace tofguard::auth {

// An authenticated_message_t decoded from the bytes of an LCM message, or
// nullopt when they are not one. LCM's generated decoder allocates
// payload_size bytes before it reads them: this checks first that the
// strings and the payload fit in the bytes received, so that a 40-byte
// forgery cannot make a controller allocate 2 GB.
inline std::optional<authenticated_message_t> decode_authenticated_message(const void* data, size_t size) {
  const auto* bytes = static_cast<const uint8_t*>(data);
  auto be = [bytes](size_t at, int n) {
    uint64_t v = 0;
    for (int i = 0; i < n; ++i) v = (v << 8) | bytes[at + static_cast<size_t>(i)];
    return v;
  };
  size_t at = 8 + 8 + 8;                  // fingerprint, utime, seq
  for (int text = 0; text < 2; ++text) {  // channel, key_id: length (with NUL) and bytes
    if (size < at + 4) return std::nullopt;
    const auto length = static_cast<int32_t>(be(at, 4));
    if (length < 1 || static_cast<size_t>(length) > size - at - 4) return std::nullopt;
    at += 4 + static_cast<size_t>(length);
  }
  if (size < at + 4) return std::nullopt;
  const auto payload_size = static_cast<int32_t>(be(at, 4));
  if (payload_size < 0 || static_cast<size_t>(payload_size) + kTagBytes != size - at - 4) return std::nullopt;
  authenticated_message_t m;
  try {
    if (m.decode(data, 0, static_cast<int>(size)) != static_cast<int>(size)) return std::nullopt;
  } catch (const std::exception&) {
    return std::nullopt;
  }
  return m;
}

class MessageVerifier {
 public:
  // max_age_us: the largest |receiver's wall clock - utime| accepted,
  // microseconds (auth.max_age_ms).
  MessageVerifier(AuthKey key, int64_t max_age_us) : key_(std::move(key)), max_age_us_(max_age_us) {
    ensure_sodium();
  }

  // "" when `m` is accepted as a message for `channel` at `now_utime` (the
  // receiver's wall clock, microseconds since the Unix epoch), else one line
  // saying why not. Acceptance remembers m.seq.
  std::string check(const authenticated_message_t& m, const std::string& channel, int64_t now_utime) {
    std::string refusal = refusal_of(m, channel, now_utime);
    if (refusal.empty()) last_seq_[channel] = m.seq;
    return refusal;
  }

  // The payload decoded as T, when check() accepts `m` and the payload is
  // exactly one valid T; otherwise nullopt and *refusal says why.
  template <class T>
  std::optional<T> open(const authenticated_message_t& m, const std::string& channel, int64_t now_utime,
                        std::string* refusal) {
    std::string why = refusal_of(m, channel, now_utime);
    std::optional<T> message;
    if (why.empty()) {
      message.emplace();
      try {
        const int used = message->decode(m.payload.data(), 0, static_cast<int>(m.payload.size()));
        if (used < 0) {
          why = "payload is not a " + std::string(T::getTypeName()) + " (wrong fingerprint, or truncated)";
        } else if (used != static_cast<int>(m.payload.size())) {
          why = "payload is not one " + std::string(T::getTypeName()) + " (" + std::to_string(used) + " of " +
                std::to_string(m.payload.size()) + " bytes decoded)";
        }
      } catch (const std::exception&) {
        why = "payload cannot be decoded as " + std::string(T::getTypeName());
      }
    }
    if (!why.empty()) {
      if (refusal) *refusal = why;
      return std::nullopt;
    }
    last_seq_[channel] = m.seq;
    if (refusal) refusal->clear();
    return message;
  }

  const std::string& key_id() const { return key_.id; }

 private:
  std::string refusal_of(const authenticated_message_t& m, const std::string& channel,
                         int64_t now_utime) const {
    if (m.channel != channel) return "signed for channel '" + m.channel + "', not '" + channel + "'";
    if (m.key_id != key_.id) {
      return "signed with key " + m.key_id + ", not this deployment's key " + key_.id + " (wrong key file?)";
    }
    if (static_cast<size_t>(m.payload_size) != m.payload.size())
      return "payload_size does not match the payload";
    const Tag expected = compute_tag(key_, m);
    if (crypto_verify_32(expected.data(), m.tag) != 0) return "tag does not match (forged or altered)";
    const int64_t age_us = now_utime - m.utime;
    if (age_us > max_age_us_ || age_us < -max_age_us_) {
      return "stale: sent " + std::to_string(age_us / 1000) +
             " ms ago by this receiver's clock, beyond the +-" + std::to_string(max_age_us_ / 1000) +
             " ms accepted (a replay, or the clocks disagree)";
    }
    const auto last = last_seq_.find(channel);
    if (last != last_seq_.end() && m.seq <= last->second) {
      return "replayed: seq " + std::to_string(m.seq) + " is not above the last accepted " +
             std::to_string(last->second);
    }
    return "";
  }

  AuthKey key_;
  int64_t max_age_us_;
  std::map<std::string, int64_t> last_seq_;
};

}  // namespace tofguard::auth
