#include "tofguard/camera/uvc_payload.hpp"

#include <algorithm>

#include <gtest/gtest.h>

namespace tofguard::camera {
namespace {

constexpr uint8_t kFid = 0x01, kEof = 0x02, kPts = 0x04, kScr = 0x08, kErr = 0x40, kEoh = 0x80;

// A payload: 2-byte header with `info`, then `data`.
std::vector<uint8_t> payload(uint8_t info, std::vector<uint8_t> data) {
  // Built in one piece (GCC 12 warns falsely about vector::insert here).
  std::vector<uint8_t> p(2 + data.size());
  p[0] = 2;
  p[1] = static_cast<uint8_t>(info | kEoh);
  std::copy(data.begin(), data.end(), p.begin() + 2);
  return p;
}

std::vector<AssembledFrame> push(UvcFrameAssembler* a, const std::vector<uint8_t>& p) {
  return a->push(p.data(), p.size());
}

TEST(UvcPayloadHeader, ParsesFlagsAndPts) {
  // 12-byte header: PTS 0x12345678 and a 6-byte SCR.
  const std::vector<uint8_t> p = {
      12, kFid | kEof | kPts | kScr | kEoh, 0x78, 0x56, 0x34, 0x12, 1, 2, 3, 4, 5, 6, 0xAA, 0xBB};
  std::string error;
  const auto h = parse_uvc_payload_header(p.data(), p.size(), &error);
  ASSERT_TRUE(h) << error;
  EXPECT_EQ(h->length, 12u);
  EXPECT_TRUE(h->frame_id);
  EXPECT_TRUE(h->end_of_frame);
  EXPECT_TRUE(h->has_pts);
  EXPECT_TRUE(h->has_scr);
  EXPECT_FALSE(h->error);
  EXPECT_EQ(h->pts, 0x12345678u);
}

TEST(UvcPayloadHeader, RejectsMalformedHeaders) {
  std::string error;
  const std::vector<uint8_t> one_byte = {2};
  EXPECT_FALSE(parse_uvc_payload_header(one_byte.data(), one_byte.size(), &error));
  EXPECT_NE(error.find("at least the 2-byte header"), std::string::npos) << error;

  const std::vector<uint8_t> too_long = {8, 0, 1, 2};  // says 8 bytes, has 4
  EXPECT_FALSE(parse_uvc_payload_header(too_long.data(), too_long.size(), &error));
  EXPECT_NE(error.find("bHeaderLength 8"), std::string::npos) << error;

  // PTS announced but the header has no room for it.
  const std::vector<uint8_t> no_room = {2, kPts, 0, 0, 0, 0};
  EXPECT_FALSE(parse_uvc_payload_header(no_room.data(), no_room.size(), &error));
  EXPECT_NE(error.find("between 6"), std::string::npos) << error;
}

TEST(UvcFrameAssembler, AssemblesFramesEndedByEof) {
  UvcFrameAssembler a(8);
  EXPECT_TRUE(push(&a, payload(0, {1, 2, 3, 4})).empty());
  const auto frames = push(&a, payload(kEof, {5, 6, 7, 8}));
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].bytes, (std::vector<uint8_t>{1, 2, 3, 4, 5, 6, 7, 8}));
  // Empty trailing payload with the same FID after EOF: ignored.
  EXPECT_TRUE(push(&a, payload(kEof, {})).empty());
  // Next frame, FID toggled.
  EXPECT_TRUE(push(&a, payload(kFid, {9, 9, 9, 9})).empty());
  ASSERT_EQ(push(&a, payload(kFid | kEof, {8, 8, 8, 8})).size(), 1u);
  EXPECT_EQ(a.counters().frames_delivered, 2);
  EXPECT_EQ(a.counters().frames_dropped(), 0);
}

TEST(UvcFrameAssembler, CompletesFramesOnFidToggleWithoutEof) {
  UvcFrameAssembler a(4);
  EXPECT_TRUE(push(&a, payload(0, {1, 2})).empty());
  EXPECT_TRUE(push(&a, payload(0, {3, 4})).empty());
  auto frames = push(&a, payload(kFid, {5, 6}));  // toggle ends frame 1
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].bytes, (std::vector<uint8_t>{1, 2, 3, 4}));
  EXPECT_TRUE(push(&a, payload(kFid, {7, 8})).empty());
  frames = push(&a, payload(0, {}));  // toggle back ends frame 2
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].bytes, (std::vector<uint8_t>{5, 6, 7, 8}));
}

TEST(UvcFrameAssembler, OnePayloadCanEndOneFrameAndCarryTheNext) {
  UvcFrameAssembler a(2);
  push(&a, payload(0, {1, 2}));
  const auto frames = push(&a, payload(kFid | kEof, {3, 4}));
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].bytes, (std::vector<uint8_t>{1, 2}));
  EXPECT_EQ(frames[1].bytes, (std::vector<uint8_t>{3, 4}));
}

TEST(UvcFrameAssembler, DropsAndCountsShortOversizeAndErrorFrames) {
  UvcFrameAssembler a(4);
  // Short: EOF after 2 bytes.
  EXPECT_TRUE(push(&a, payload(kEof, {1, 2})).empty());
  EXPECT_EQ(a.counters().frames_short, 1);
  EXPECT_NE(a.last_error().find("2 bytes, expected 4"), std::string::npos) << a.last_error();
  // Oversize: 6 bytes before EOF.
  push(&a, payload(kFid, {1, 2, 3, 4}));
  EXPECT_TRUE(push(&a, payload(kFid | kEof, {5, 6})).empty());
  EXPECT_EQ(a.counters().frames_oversize, 1);
  // Error bit on one payload: the whole frame goes, even at the right size.
  push(&a, payload(kErr, {1, 2}));
  EXPECT_TRUE(push(&a, payload(kEof, {3, 4})).empty());
  EXPECT_EQ(a.counters().frames_error, 1);
  // A malformed payload in the middle of a frame loses that frame.
  push(&a, payload(kFid, {1, 2}));
  const std::vector<uint8_t> malformed = {40, kFid, 0};
  push(&a, malformed);
  EXPECT_TRUE(push(&a, payload(kFid | kEof, {3, 4})).empty());
  EXPECT_EQ(a.counters().malformed_payloads, 1);
  EXPECT_EQ(a.counters().frames_error, 2);
  // A good frame still gets through afterwards.
  push(&a, payload(0, {1, 2}));
  EXPECT_EQ(push(&a, payload(kEof, {3, 4})).size(), 1u);
  EXPECT_EQ(a.counters().frames_delivered, 1);
  EXPECT_EQ(a.counters().frames_dropped(), 4);
}

TEST(UvcFrameAssembler, DataOffsetSkipsPtsAndScrAndKeepsFirstPts) {
  UvcFrameAssembler a(4);
  const std::vector<uint8_t> first = {12, kPts | kScr, 0x10, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 2};
  const std::vector<uint8_t> second = {6, kPts | kEof, 0x20, 0, 0, 0, 3, 4};
  push(&a, first);
  const auto frames = push(&a, second);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].bytes, (std::vector<uint8_t>{1, 2, 3, 4}));
  EXPECT_TRUE(frames[0].has_pts);
  EXPECT_EQ(frames[0].pts, 0x10u);
}

}  // namespace
}  // namespace tofguard::camera
