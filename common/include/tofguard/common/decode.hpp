#pragma once
// Decoding an LCM message that may be malformed. The generated decoders
// return -1 for a wrong fingerprint or a short buffer, but throw
// (std::length_error, std::bad_alloc) for absurd array sizes such as a
// negative num_pixels: both mean "not a valid T".
#include <exception>
#include <optional>

namespace tofguard {

template <class T>
std::optional<T> decode_message(const void* data, int size) {
  T message;
  try {
    if (message.decode(data, 0, size) < 0) return std::nullopt;
  } catch (const std::exception&) {
    return std::nullopt;
  }
  return message;
}

}  // namespace tofguard
