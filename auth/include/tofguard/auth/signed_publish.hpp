#pragma once
// Publishing a message that can allow motion (docs/security.md): with a
// signer, signed on its companion channel first (the copy receivers act
// on), then plain on its own channel (for people, logs and tools); without
// one (auth.insecure), plain only. The one place the order and the pairing
// of the two channels are decided.
#include <lcm/lcm-cpp.hpp>

#include <string>

#include "tofguard/auth/message_signer.hpp"
#include "tofguard/authenticated_message_t.hpp"

namespace tofguard::auth {

// "" when both went out, else which channel could not be published.
template <class T>
std::string publish_signed(lcm::LCM& lcm, MessageSigner* signer, const std::string& channel,
                           const std::string& auth_channel, const T& message, int64_t now_utime) {
  if (signer != nullptr) {
    const authenticated_message_t signed_message = signer->sign(channel, message, now_utime);
    if (lcm.publish(auth_channel, &signed_message) != 0) return "cannot publish " + auth_channel;
  }
  if (lcm.publish(channel, &message) != 0) return "cannot publish " + channel;
  return "";
}

}  // namespace tofguard::auth
