#pragma once
// Decoding an LCM message that may be malformed. The generated decoders
// return -1 for a wrong fingerprint or a short buffer, but throw
// (std::length_error, std::bad_alloc) for absurd array sizes such as a
// negative num_pixels: both mean "not a valid T".
//
// They also size every variable-length array from the count on the wire
// before they read its elements: a 50-byte message claiming 2^31 pixels
// would make them allocate (and zero) 4 GB, which may well succeed, slowly,
// or get the process killed. So the message is first walked with its wire
// layout (wire_schema.hpp, generated from the .lcm files): every string and
// array must fit in the bytes received, and no array may have more elements
// than the message has bytes; only then is it decoded. The memory a decode
// takes is thereby bounded by a small multiple of the message's size.
#include <exception>
#include <optional>

#include "tofguard/wire_schema.hpp"

namespace tofguard {

// True when the message's strings and arrays (as `fields` lay them out,
// after the 8-byte fingerprint) fit in `size` bytes, and no array has more
// elements than `size`. Does not look at the fingerprint.
bool wire_counts_fit(const wire_schema::Field* fields, int num_fields, const void* data, int size);

template <class T>
std::optional<T> decode_message(const void* data, int size) {
  using Schema = wire_schema::Schema<T>;
  if (data == nullptr || size < 0 || !wire_counts_fit(Schema::fields, Schema::num_fields, data, size)) {
    return std::nullopt;
  }
  T message;
  try {
    if (message.decode(data, 0, size) < 0) return std::nullopt;
  } catch (const std::exception&) {
    return std::nullopt;
  }
  return message;
}

}  // namespace tofguard
