#pragma once
// Turning the payloads of a USB Video Class stream into whole frames.
//
// A UVC camera sends each video frame as a series of payloads (one per
// isochronous packet or bulk transfer). Every payload starts with a header
// (UVC 1.5, section 2.4.3.3):
//   byte 0  bHeaderLength: header size in bytes, including this byte
//   byte 1  bmHeaderInfo:  bit 0 FID (frame id, toggles at each new frame),
//           bit 1 EOF (last payload of a frame), bit 2 PTS present, bit 3
//           SCR present, bit 4 reserved, bit 5 STI (still image), bit 6 ERR
//           (the camera reports a streaming error), bit 7 EOH (end of header)
//   then    PTS (4 bytes, little-endian) when bit 2, SCR (6 bytes) when bit 3.
// The frame's bytes follow the header. A frame ends at EOF or, for cameras
// that never set EOF, when FID toggles.
//
// A frame is delivered only when it has exactly the expected size and no
// payload of it carried ERR; any other frame is dropped and counted, never
// patched up: a frame with missing rows would put nonsense depths where the
// arm might be. The stream is joined mid-frame, so the first frame is usually
// short and dropped.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace tofguard::camera {

struct UvcPayloadHeader {
  size_t length = 0;  // bHeaderLength
  bool frame_id = false;
  bool end_of_frame = false;
  bool has_pts = false;
  bool has_scr = false;
  bool still_image = false;
  bool error = false;
  // Presentation time stamp in the camera's clock (dwClockFrequency units),
  // valid when has_pts.
  uint32_t pts = 0;
};

// Parses the header at the start of `payload`. Returns nullopt and sets
// `*error` (one line) when the header is malformed: fewer than 2 bytes,
// bHeaderLength < 2 or larger than the payload, or too short for the PTS/SCR
// fields its flags announce.
std::optional<UvcPayloadHeader> parse_uvc_payload_header(const uint8_t* payload, size_t size,
                                                         std::string* error);

// One complete frame's bytes as the camera sent them.
struct AssembledFrame {
  std::vector<uint8_t> bytes;
  bool has_pts = false;
  uint32_t pts = 0;  // PTS of the frame's first payload that carried one
};

// Why frames were lost; all counters only grow.
struct UvcAssemblerCounters {
  int64_t payloads = 0;
  // Header unparseable, or data after EOF with the same FID: skipped.
  int64_t malformed_payloads = 0;
  int64_t frames_delivered = 0;
  int64_t frames_short = 0;     // ended with fewer bytes than expected
  int64_t frames_oversize = 0;  // more bytes than expected
  int64_t frames_error = 0;     // a payload had the ERR bit, or was malformed
  int64_t frames_dropped() const { return frames_short + frames_oversize + frames_error; }
};

class UvcFrameAssembler {
 public:
  // `frame_bytes`: the exact size of one frame (width * height * 2 for the
  // 16-bit depth formats).
  explicit UvcFrameAssembler(size_t frame_bytes);

  // Feeds the next payload of the stream. Returns the frames it completed,
  // in order (usually none or one; two when a single payload both toggles
  // FID and carries EOF with a whole frame).
  std::vector<AssembledFrame> push(const uint8_t* payload, size_t size);

  // The last one-line reason a payload or frame was rejected ("" if none).
  const std::string& last_error() const { return last_error_; }
  const UvcAssemblerCounters& counters() const { return counters_; }

 private:
  void finish_frame(std::vector<AssembledFrame>* out);
  void start_frame(bool frame_id);

  size_t frame_bytes_;
  bool in_frame_ = false;  // a frame has started and has not ended yet
  bool have_frame_id_ = false;
  bool frame_id_ = false;  // FID of the current (or last ended) frame
  bool frame_error_ = false;
  bool frame_oversize_ = false;
  AssembledFrame current_;
  UvcAssemblerCounters counters_;
  std::string last_error_;
};

}  // namespace tofguard::camera
