#include "tofguard/common/depth_frame.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace tofguard {

namespace {

// Z in mm (unrounded) -> the wire's depth_mm: rounded half away from zero,
// as std::round, without its library call (the x86-64 baseline has no
// rounding instruction, and this runs for every pixel of every rendered
// frame: 0.6 ms of a 640x480 frame's critical path, 2026-11-27), and without
// branches (a rendered image's edges would mispredict them). For
// 0 < mm < 32768 the conversion truncates exactly and mm - whole is exact, so
// the result is std::round's to the bit (depth_frame_test compares the two);
// outside, and for NaN, which fails the comparison, 0 ("no return"), and a
// value that rounds above kMaxDepthMm is no return too.
inline int16_t rounded_depth_mm(double mm) {
  const double in_range = (mm > 0 && mm < kMaxDepthMm + 1) ? mm : 0.0;
  const int whole = static_cast<int>(in_range);
  const int rounded = whole + (in_range - whole >= 0.5 ? 1 : 0);
  return static_cast<int16_t>(rounded <= kMaxDepthMm ? rounded : 0);
}

}  // namespace

int16_t depth_mm_from_m(double depth_m) { return rounded_depth_mm(depth_m * 1000.0); }

std::vector<int16_t> depth_mm_from_m(const std::vector<float>& depth_m) {
  std::vector<int16_t> depth_mm(depth_m.size());
  const float* in = depth_m.data();
  int16_t* out = depth_mm.data();
  const size_t n = depth_m.size();
  size_t i = 0;
#if defined(__SSE2__)
  // Four pixels at a time, in SSE2 (the x86-64 baseline) as rounded_depth_mm
  // does each: widened to double and scaled by 1000 (the same bits), masked
  // to 0 outside (0, 32768) and for NaN, truncated, plus 1 where the rest is
  // >= 0.5, 32768 -> 0; then packed to int16. 3x the scalar loop's speed
  // (640x480: 1.0 -> 0.33 ms; std::round's 1.6 ms); depth_frame_test compares it with std::round.
  const __m128d thousand = _mm_set1_pd(1000.0);
  const __m128d zero = _mm_setzero_pd();
  const __m128d beyond = _mm_set1_pd(kMaxDepthMm + 1.0);
  const __m128d half = _mm_set1_pd(0.5);
  const __m128i one = _mm_set1_epi32(1);
  const __m128i max_mm = _mm_set1_epi32(kMaxDepthMm);
  const auto round_two = [&](__m128d m) {
    const __m128d mm = _mm_mul_pd(m, thousand);
    const __m128d in_range = _mm_and_pd(_mm_and_pd(_mm_cmpgt_pd(mm, zero), _mm_cmplt_pd(mm, beyond)), mm);
    const __m128i whole = _mm_cvttpd_epi32(in_range);  // two int32 in the low half
    const __m128d rest = _mm_sub_pd(in_range, _mm_cvtepi32_pd(whole));
    // The comparison's all-ones lanes, as doubles, shuffled to the two low
    // int32 lanes: 1 where rest >= 0.5.
    const __m128i up = _mm_shuffle_epi32(_mm_castpd_si128(_mm_cmpge_pd(rest, half)), _MM_SHUFFLE(3, 1, 2, 0));
    return _mm_add_epi32(whole, _mm_and_si128(up, one));
  };
  for (; i + 4 <= n; i += 4) {
    const __m128 z = _mm_loadu_ps(in + i);
    const __m128i low = round_two(_mm_cvtps_pd(z));
    const __m128i high = round_two(_mm_cvtps_pd(_mm_movehl_ps(z, z)));
    __m128i rounded = _mm_unpacklo_epi64(low, high);
    // 32768 (mm just below 32768 rounded up) is no return.
    rounded = _mm_andnot_si128(_mm_cmpgt_epi32(rounded, max_mm), rounded);
    _mm_storel_epi64(reinterpret_cast<__m128i*>(out + i), _mm_packs_epi32(rounded, rounded));
  }
#endif
  for (; i < n; ++i) out[i] = rounded_depth_mm(static_cast<double>(in[i]) * 1000.0);
  return depth_mm;
}

std::vector<float> depth_m_from_mm(const std::vector<int16_t>& depth_mm) {
  std::vector<float> depth_m(depth_mm.size());
  for (size_t i = 0; i < depth_mm.size(); ++i) {
    depth_m[i] = depth_mm[i] > 0 ? static_cast<float>(metres_from_mm(depth_mm[i])) : 0.0f;
  }
  return depth_m;
}

Intrinsics intrinsics_of(const depth_image_t& image) {
  Intrinsics in;
  in.width = image.width;
  in.height = image.height;
  in.fx = image.fx;
  in.fy = image.fy;
  in.cx = image.cx;
  in.cy = image.cy;
  return in;
}

depth_image_t make_depth_image(const std::string& camera_id, const Intrinsics& intrinsics, int64_t utime,
                               int64_t seq, bool calibrated, const std::vector<float>& depth_m,
                               const std::vector<float>& amplitude) {
  const size_t n = static_cast<size_t>(std::max(intrinsics.width, 0)) *
                   static_cast<size_t>(std::max(intrinsics.height, 0));
  if (depth_m.size() != n || (!amplitude.empty() && amplitude.size() != n)) {
    throw std::invalid_argument("make_depth_image: " + std::to_string(depth_m.size()) + " depths / " +
                                std::to_string(amplitude.size()) + " amplitudes, expected " +
                                std::to_string(n) + " (" + std::to_string(intrinsics.width) + "x" +
                                std::to_string(intrinsics.height) + ")");
  }
  depth_image_t image;
  image.utime = utime;
  image.seq = seq;
  image.camera_id = camera_id;
  image.width = intrinsics.width;
  image.height = intrinsics.height;
  image.fx = intrinsics.fx;
  image.fy = intrinsics.fy;
  image.cx = intrinsics.cx;
  image.cy = intrinsics.cy;
  image.calibrated = calibrated;
  image.num_pixels = static_cast<int32_t>(n);
  image.depth_mm = depth_mm_from_m(depth_m);
  image.num_amplitude = static_cast<int32_t>(amplitude.size());
  image.amplitude.resize(amplitude.size());
  for (size_t i = 0; i < amplitude.size(); ++i) {
    const float a = std::isfinite(amplitude[i]) ? amplitude[i] : 0.0f;
    image.amplitude[i] = static_cast<int16_t>(std::lround(std::clamp(a, 0.0f, 32767.0f)));
  }
  return image;
}

std::vector<float> depth_m_of(const depth_image_t& image) { return depth_m_from_mm(image.depth_mm); }

namespace {

link_labels_t labels_header(const depth_image_t& frame, int num_robot_links,
                            std::vector<std::string> link_names) {
  if (num_robot_links < 0 || static_cast<size_t>(num_robot_links) > link_names.size()) {
    throw std::invalid_argument("make_link_labels: num_robot_links " + std::to_string(num_robot_links) +
                                ", expected 0.." + std::to_string(link_names.size()));
  }
  link_labels_t m{};
  m.utime = frame.utime;
  m.seq = frame.seq;
  m.camera_id = frame.camera_id;
  m.width = frame.width;
  m.height = frame.height;
  m.num_robot_links = num_robot_links;
  m.link_name = std::move(link_names);
  m.num_links = static_cast<int32_t>(m.link_name.size());
  m.usable = false;
  m.num_pixels = 0;
  // No kinematics (the renderer adds them: renderer/rendered_kinematics.hpp).
  m.num_joints = 0;
  m.num_axes = 0;
  m.num_link_axes = 0;
  return m;
}

}  // namespace

link_labels_t make_link_labels(const depth_image_t& frame, int num_robot_links,
                               std::vector<std::string> link_names, std::vector<int16_t> labels) {
  const size_t n =
      static_cast<size_t>(std::max(frame.width, 0)) * static_cast<size_t>(std::max(frame.height, 0));
  if (labels.size() != n) {
    throw std::invalid_argument("make_link_labels: " + std::to_string(labels.size()) + " labels, expected " +
                                std::to_string(n) + " (" + std::to_string(frame.width) + "x" +
                                std::to_string(frame.height) + ")");
  }
  link_labels_t m = labels_header(frame, num_robot_links, std::move(link_names));
  m.usable = true;
  m.num_pixels = static_cast<int32_t>(labels.size());
  m.label = std::move(labels);
  return m;
}

link_labels_t make_unusable_link_labels(const depth_image_t& frame, int num_robot_links,
                                        std::vector<std::string> link_names, const std::string& reason) {
  link_labels_t m = labels_header(frame, num_robot_links, std::move(link_names));
  m.unusable_reason = reason;
  return m;
}

}  // namespace tofguard
