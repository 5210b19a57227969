#include "tofguard/auth/message_signer.hpp"

#include <algorithm>
#include <cstring>

namespace tofguard::auth {

MessageSigner::MessageSigner(AuthKey key, int64_t now_utime) : key_(std::move(key)), next_seq_(now_utime) {
  ensure_sodium();
}

authenticated_message_t MessageSigner::sign_payload(const std::string& channel, std::vector<uint8_t> payload,
                                                    int64_t now_utime) {
  authenticated_message_t m;
  m.utime = now_utime;
  m.seq = std::max(next_seq_, now_utime);
  next_seq_ = m.seq + 1;
  m.channel = channel;
  m.key_id = key_.id;
  m.payload_size = static_cast<int32_t>(payload.size());
  m.payload = std::move(payload);
  const Tag tag = compute_tag(key_, m);
  std::memcpy(m.tag, tag.data(), tag.size());
  return m;
}

}  // namespace tofguard::auth
