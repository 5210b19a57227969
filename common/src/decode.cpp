#include "tofguard/common/decode.hpp"

#include <cstdint>
#include <vector>

namespace tofguard {
namespace {

using wire_schema::Field;
using wire_schema::Kind;

// Bytes one element takes on the wire (strings: their 4-byte length; the
// characters are added as they are read).
int64_t element_bytes(Kind kind) {
  switch (kind) {
    case Kind::kInt8:
    case Kind::kBoolean:
    case Kind::kByte:
      return 1;
    case Kind::kInt16:
      return 2;
    case Kind::kInt32:
    case Kind::kFloat:
    case Kind::kString:
      return 4;
    case Kind::kInt64:
    case Kind::kDouble:
      return 8;
  }
  return 1;
}

// Big-endian, as LCM writes integers.
int64_t read_integer(const uint8_t* p, int64_t bytes) {
  uint64_t value = 0;
  for (int64_t i = 0; i < bytes; ++i) value = (value << 8) | p[i];
  const int bits = static_cast<int>(bytes * 8);
  if (bits < 64 && (value >> (bits - 1)) != 0) value |= ~uint64_t{0} << bits;  // sign-extend
  return static_cast<int64_t>(value);
}

bool is_integer(Kind kind) {
  return kind == Kind::kInt8 || kind == Kind::kInt16 || kind == Kind::kInt32 || kind == Kind::kInt64;
}

}  // namespace

bool wire_counts_fit(const Field* fields, int num_fields, const void* data, int size) {
  if (data == nullptr || size < 8) return false;
  const auto* bytes = static_cast<const uint8_t*>(data);
  const int64_t end = size;
  int64_t pos = 8;  // after the fingerprint
  // The value of each scalar integer field read so far (array counts).
  std::vector<int64_t> values(static_cast<size_t>(num_fields), 0);
  for (int f = 0; f < num_fields; ++f) {
    const Field& field = fields[f];
    // Elements: the product of the dimensions, each at most `size` (an
    // element takes at least one byte, except in an array of empty arrays,
    // which this bound keeps small too), so the product cannot overflow.
    int64_t count = 1;
    for (int d = 0; d < field.num_dims; ++d) {
      const int64_t n =
          field.dims[d].count_field >= 0 ? values[field.dims[d].count_field] : field.dims[d].size;
      if (n < 0 || n > end) return false;
      count *= n;
    }
    if (count > end) return false;
    const int64_t element = element_bytes(field.kind);
    if (field.kind == Kind::kString) {
      for (int64_t i = 0; i < count; ++i) {
        if (end - pos < 4) return false;
        const int64_t length = read_integer(bytes + pos, 4);  // including the terminating NUL
        pos += 4;
        if (length < 1 || length > end - pos) return false;
        pos += length;
      }
      continue;
    }
    if (count * element > end - pos) return false;
    if (field.num_dims == 0 && is_integer(field.kind)) values[f] = read_integer(bytes + pos, element);
    pos += count * element;
  }
  return true;
}

}  // namespace tofguard
