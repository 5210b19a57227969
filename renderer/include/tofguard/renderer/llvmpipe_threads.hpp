#pragma once
// How many threads llvmpipe (Mesa's software rasteriser, what EGL gives on
// a machine without a GPU driver) rasterises with: its LP_NUM_THREADS,
// read once when the EGL display starts, default one per core. Only the
// rasterisation is shared (vertices are transformed in the calling
// thread), and every frame is handed to the threads and collected back.
// On a small frame the hand-over costs more than the threads save, and the
// threads compete with tofguard-discrepancy's for the same cores; on a
// large one they shorten the render (docs/benchmarks.md, "Sampling the evidence, and
// llvmpipe's threads"). A GPU driver ignores the variable.
#include <cstdint>
#include <string>

#include "tofguard/common/camera_geometry.hpp"

namespace tofguard::renderer {

// Frames of at most this many pixels (half of 320x240) are rasterised in
// the calling thread. Measured with tofguard-bench on the 2-core VM
// (docs/benchmarks.md, "Sampling the evidence, and llvmpipe's threads"):
// at 176x144 (25 344 pixels)
// the calling thread takes the chain's end-to-end p99 from 15.4 to 8.9 ms
// with the same render floor; at 320x240 the chain is the same either way
// and the threads shorten the Kinova Gen3's render floor (10.7 against
// 13.2 ms), at 640x480 more (10.6 against 18.6 ms).
constexpr int64_t kLlvmpipeCallingThreadMaxPixels = 320 * 240 / 2;

// The LP_NUM_THREADS for frames of `intrinsics`: "0" (the calling thread)
// up to kLlvmpipeCallingThreadMaxPixels, "" above it (llvmpipe's default).
std::string llvmpipe_threads_for(const Intrinsics& intrinsics);

// Sets LP_NUM_THREADS to llvmpipe_threads_for(intrinsics) unless the
// environment already has it (an operator's choice stands), before any
// EGL display is opened. Returns a line for the log: the value and why.
std::string choose_llvmpipe_threads(const Intrinsics& intrinsics);

}  // namespace tofguard::renderer
