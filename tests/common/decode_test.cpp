// decode_message's bounds walk (decode.hpp): valid messages decode; a
// count that the bytes received cannot hold is "not a T" before the
// generated decoder allocates anything (the fuzzer's finds, kept in
// tests/fuzz/regressions/wire_messages/).
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "tofguard/common/decode.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/planned_trajectory_t.hpp"

namespace tofguard {
namespace {

template <class T>
std::vector<uint8_t> encode(const T& message) {
  std::vector<uint8_t> bytes(static_cast<size_t>(message.getEncodedSize()));
  EXPECT_EQ(message.encode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  return bytes;
}

void put_int32(std::vector<uint8_t>& bytes, size_t at, int32_t value) {
  for (int i = 0; i < 4; ++i)
    bytes[at + i] = static_cast<uint8_t>(static_cast<uint32_t>(value) >> (24 - 8 * i));
}

depth_image_t small_image() {
  depth_image_t m{};
  m.utime = 1;
  m.camera_id = "cam";
  m.width = 2;
  m.height = 2;
  m.num_pixels = 4;
  m.depth_mm = {1, 2, 3, 4};
  return m;
}

// Offset of depth_image_t's num_pixels: fingerprint, utime, seq,
// camera_id (4 + "cam\0"), width, height, fx..cy, calibrated.
constexpr size_t kNumPixelsAt = 8 + 8 + 8 + (4 + 4) + 4 + 4 + 4 * 8 + 1;

TEST(DecodeMessage, ValidMessagesDecode) {
  const auto image = decode_message<depth_image_t>(encode(small_image()).data(),
                                                   static_cast<int>(encode(small_image()).size()));
  ASSERT_TRUE(image);
  EXPECT_EQ(image->depth_mm, (std::vector<int16_t>{1, 2, 3, 4}));

  planned_trajectory_t plan{};
  plan.num_joints = 2;
  plan.joint_name = {"a", "b"};
  plan.num_points = 3;
  plan.point_utime = {1, 2, 3};
  plan.position = {{0, 1}, {2, 3}, {4, 5}};
  const std::vector<uint8_t> bytes = encode(plan);
  const auto decoded = decode_message<planned_trajectory_t>(bytes.data(), static_cast<int>(bytes.size()));
  ASSERT_TRUE(decoded);
  EXPECT_EQ(decoded->position[2][1], 5);

  joint_state_t none{};
  const std::vector<uint8_t> empty = encode(none);
  EXPECT_TRUE(decode_message<joint_state_t>(empty.data(), static_cast<int>(empty.size())));
}

TEST(DecodeMessage, CountsBeyondTheBytesAreRejectedBeforeDecoding) {
  std::vector<uint8_t> bytes = encode(small_image());
  ASSERT_EQ(bytes[kNumPixelsAt + 3], 4);
  for (int32_t count : {5, 1000, 0x7fffffff, -1}) {
    put_int32(bytes, kNumPixelsAt, count);
    EXPECT_FALSE(decode_message<depth_image_t>(bytes.data(), static_cast<int>(bytes.size()))) << count;
  }
  // A plan of 2^31 points of no joints: 2^31 empty rows, no bytes on the
  // wire for them, but point_utime's 8 bytes each are missing.
  planned_trajectory_t plan{};
  std::vector<uint8_t> plan_bytes = encode(plan);
  put_int32(plan_bytes, 8 + 8 + 4, 0x7fffffff);  // num_points
  EXPECT_FALSE(decode_message<planned_trajectory_t>(plan_bytes.data(), static_cast<int>(plan_bytes.size())));
}

TEST(DecodeMessage, MalformedStringsAndBuffersAreRejected) {
  std::vector<uint8_t> bytes = encode(small_image());
  put_int32(bytes, 8 + 8 + 8, 0);  // camera_id's length (LCM counts the NUL: at least 1)
  EXPECT_FALSE(decode_message<depth_image_t>(bytes.data(), static_cast<int>(bytes.size())));
  put_int32(bytes, 8 + 8 + 8, 1 << 30);
  EXPECT_FALSE(decode_message<depth_image_t>(bytes.data(), static_cast<int>(bytes.size())));
  const std::vector<uint8_t> good = encode(small_image());
  EXPECT_FALSE(decode_message<depth_image_t>(good.data(), static_cast<int>(good.size()) - 1));
  EXPECT_FALSE(decode_message<depth_image_t>(good.data(), 4));
  EXPECT_FALSE(decode_message<depth_image_t>(nullptr, 0));
}

}  // namespace
}  // namespace tofguard
