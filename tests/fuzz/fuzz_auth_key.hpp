#pragma once
// The key the fuzzing signs its seed envelopes with (make_wire_seeds) and
// verifies them with (wire_messages_fuzz): fixed, so that the seeds pass
// the tag and the fuzzer explores what comes after it. Not a secret: it is
// never a deployment's key.
#include "tofguard/auth/message_tag.hpp"

namespace tofguard {

inline auth::AuthKey fuzz_auth_key() {
  auth::AuthKey key;
  for (size_t i = 0; i < key.bytes.size(); ++i) key.bytes[i] = static_cast<uint8_t>(i);
  key.id = auth::key_id_of(key.bytes);
  return key;
}

}  // namespace tofguard
