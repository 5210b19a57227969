#include "tofguard/camera/uvc_payload.hpp"

#include <cstring>

namespace tofguard::camera {
namespace {

constexpr uint8_t kFid = 0x01;
constexpr uint8_t kEof = 0x02;
constexpr uint8_t kPts = 0x04;
constexpr uint8_t kScr = 0x08;
constexpr uint8_t kSti = 0x20;
constexpr uint8_t kErr = 0x40;

}  // namespace

std::optional<UvcPayloadHeader> parse_uvc_payload_header(const uint8_t* payload, size_t size,
                                                         std::string* error) {
  if (size < 2) {
    *error = "UVC payload of " + std::to_string(size) + " bytes: expected at least the 2-byte header";
    return std::nullopt;
  }
  UvcPayloadHeader h;
  h.length = payload[0];
  const uint8_t info = payload[1];
  h.frame_id = (info & kFid) != 0;
  h.end_of_frame = (info & kEof) != 0;
  h.has_pts = (info & kPts) != 0;
  h.has_scr = (info & kScr) != 0;
  h.still_image = (info & kSti) != 0;
  h.error = (info & kErr) != 0;
  const size_t needed = 2 + (h.has_pts ? 4 : 0) + (h.has_scr ? 6 : 0);
  if (h.length < needed || h.length > size) {
    *error = "UVC payload header: bHeaderLength " + std::to_string(h.length) + ", expected between " +
             std::to_string(needed) + " (for its PTS/SCR flags) and " + std::to_string(size) +
             " (the payload's size)";
    return std::nullopt;
  }
  if (h.has_pts) {
    h.pts = static_cast<uint32_t>(payload[2]) | static_cast<uint32_t>(payload[3]) << 8 |
            static_cast<uint32_t>(payload[4]) << 16 | static_cast<uint32_t>(payload[5]) << 24;
  }
  return h;
}

UvcFrameAssembler::UvcFrameAssembler(size_t frame_bytes) : frame_bytes_(frame_bytes) {
  current_.bytes.reserve(frame_bytes_);
}

void UvcFrameAssembler::start_frame(bool frame_id) {
  in_frame_ = true;
  have_frame_id_ = true;
  frame_id_ = frame_id;
  frame_error_ = false;
  frame_oversize_ = false;
  current_.bytes.clear();
  current_.has_pts = false;
  current_.pts = 0;
}

void UvcFrameAssembler::finish_frame(std::vector<AssembledFrame>* out) {
  in_frame_ = false;
  const size_t got = current_.bytes.size();
  if (frame_error_) {
    ++counters_.frames_error;
    last_error_ = "UVC frame dropped: a payload had the ERR bit or a malformed header";
  } else if (frame_oversize_) {
    ++counters_.frames_oversize;
    last_error_ = "UVC frame dropped: more than the expected " + std::to_string(frame_bytes_) + " bytes";
  } else if (got < frame_bytes_) {
    ++counters_.frames_short;
    last_error_ =
        "UVC frame dropped: " + std::to_string(got) + " bytes, expected " + std::to_string(frame_bytes_);
  } else {
    ++counters_.frames_delivered;
    out->push_back(current_);
  }
  current_.bytes.clear();
}

std::vector<AssembledFrame> UvcFrameAssembler::push(const uint8_t* payload, size_t size) {
  std::vector<AssembledFrame> out;
  ++counters_.payloads;
  std::string error;
  const auto header = parse_uvc_payload_header(payload, size, &error);
  if (!header) {
    // We cannot tell which frame the bytes belong to: the frame in progress
    // is lost.
    ++counters_.malformed_payloads;
    last_error_ = error;
    if (in_frame_) frame_error_ = true;
    return out;
  }
  // A toggled FID starts a new frame; the previous one ends here if EOF did
  // not end it already.
  if (!have_frame_id_ || header->frame_id != frame_id_) {
    if (in_frame_) finish_frame(&out);
    start_frame(header->frame_id);
  } else if (!in_frame_) {
    // Same FID after EOF: trailing payloads of an ended frame (often empty).
    const size_t data = size - header->length;
    if (data > 0) {
      ++counters_.malformed_payloads;
      last_error_ = "UVC payload with " + std::to_string(data) +
                    " bytes after its frame's EOF, same FID: bytes ignored";
    }
    return out;
  }
  if (header->error) frame_error_ = true;
  if (header->has_pts && !current_.has_pts) {
    current_.has_pts = true;
    current_.pts = header->pts;
  }
  const size_t data = size - header->length;
  if (current_.bytes.size() + data > frame_bytes_) {
    frame_oversize_ = true;
  } else if (data > 0) {
    current_.bytes.insert(current_.bytes.end(), payload + header->length, payload + size);
  }
  if (header->end_of_frame) finish_frame(&out);
  return out;
}

}  // namespace tofguard::camera
