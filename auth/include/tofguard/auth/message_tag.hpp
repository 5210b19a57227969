#pragma once
// HMAC-SHA256 tags of authenticated_message_t (docs/security.md), computed
// with libsodium. Header-only, like message_verifier.hpp and auth_key.hpp:
// a robot controller verifies SAFETY_STATUS with these three headers, the
// generated tofguard/authenticated_message_t.hpp and -lsodium, nothing else
// of tofguard.
#include <sodium.h>

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "tofguard/authenticated_message_t.hpp"

namespace tofguard::auth {

constexpr size_t kKeyBytes = crypto_auth_hmacsha256_KEYBYTES;  // 32
constexpr size_t kTagBytes = crypto_auth_hmacsha256_BYTES;     // 32
static_assert(kKeyBytes == 32 && kTagBytes == 32, "authenticated_message_t.tag is 32 bytes");

using Tag = std::array<uint8_t, kTagBytes>;

// The deployment's key (tofguard-keygen) and its public id (key_id_of).
struct AuthKey {
  std::array<uint8_t, kKeyBytes> bytes{};
  std::string id;
};

// libsodium must be initialised once per process before any use; safe to
// call again. Throws when the library cannot start (no entropy source).
inline void ensure_sodium() {
  if (sodium_init() < 0) throw std::runtime_error("libsodium cannot start (sodium_init failed)");
}

// The key's public id: the first 8 bytes of SHA-256("tofguard key id" ||
// key), 16 hex digits. It names the key without revealing it.
inline std::string key_id_of(const std::array<uint8_t, kKeyBytes>& key) {
  ensure_sodium();
  static const char kLabel[] = "tofguard key id";
  std::vector<uint8_t> input(kLabel, kLabel + sizeof kLabel - 1);
  input.insert(input.end(), key.begin(), key.end());
  std::array<uint8_t, crypto_hash_sha256_BYTES> digest{};
  crypto_hash_sha256(digest.data(), input.data(), input.size());
  char hex[2 * 8 + 1];
  sodium_bin2hex(hex, sizeof hex, digest.data(), 8);
  return hex;
}

namespace detail {
inline void append_be(std::vector<uint8_t>& out, uint64_t value, int bytes) {
  for (int i = bytes - 1; i >= 0; --i) out.push_back(static_cast<uint8_t>(value >> (8 * i)));
}
inline void append_field(std::vector<uint8_t>& out, const uint8_t* data, size_t size) {
  append_be(out, size, 4);
  out.insert(out.end(), data, data + size);
}
}  // namespace detail

// The bytes the tag covers, in this order (version 1): the 16 ASCII bytes
// "tofguard-auth-v1"; utime and seq as big-endian 64-bit two's complement;
// then channel, key_id and payload, each as a big-endian 32-bit length and
// its bytes. Lengths make the split unambiguous: no two different messages
// have the same tagged bytes. (auth/python/tofguard_auth.py writes the same.)
inline std::vector<uint8_t> tagged_bytes(const authenticated_message_t& m) {
  static const char kVersion[] = "tofguard-auth-v1";
  std::vector<uint8_t> out(kVersion, kVersion + sizeof kVersion - 1);
  detail::append_be(out, static_cast<uint64_t>(m.utime), 8);
  detail::append_be(out, static_cast<uint64_t>(m.seq), 8);
  detail::append_field(out, reinterpret_cast<const uint8_t*>(m.channel.data()), m.channel.size());
  detail::append_field(out, reinterpret_cast<const uint8_t*>(m.key_id.data()), m.key_id.size());
  detail::append_field(out, m.payload.data(), m.payload.size());
  return out;
}

// HMAC-SHA256(key, tagged_bytes(m)).
inline Tag compute_tag(const AuthKey& key, const authenticated_message_t& m) {
  ensure_sodium();
  const std::vector<uint8_t> bytes = tagged_bytes(m);
  Tag tag{};
  crypto_auth_hmacsha256(tag.data(), bytes.data(), bytes.size(), key.bytes.data());
  return tag;
}

}  // namespace tofguard::auth
