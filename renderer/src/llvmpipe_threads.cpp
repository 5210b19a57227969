#include "tofguard/renderer/llvmpipe_threads.hpp"

#include <cstdlib>

namespace tofguard::renderer {

std::string llvmpipe_threads_for(const Intrinsics& intrinsics) {
  const int64_t pixels = int64_t{intrinsics.width} * intrinsics.height;
  return pixels <= kLlvmpipeCallingThreadMaxPixels ? "0" : "";
}

std::string choose_llvmpipe_threads(const Intrinsics& intrinsics) {
  const std::string size = std::to_string(intrinsics.width) + "x" + std::to_string(intrinsics.height);
  if (const char* set = std::getenv("LP_NUM_THREADS"); set != nullptr) {
    return std::string("LP_NUM_THREADS=") + set + " from the environment (" + size + " frames)";
  }
  const std::string threads = llvmpipe_threads_for(intrinsics);
  if (threads.empty()) {
    return "LP_NUM_THREADS unset: llvmpipe's default, a thread per core (" + size + " frames, more than " +
           std::to_string(kLlvmpipeCallingThreadMaxPixels) + " pixels)";
  }
  setenv("LP_NUM_THREADS", threads.c_str(), /*overwrite=*/0);
  return "LP_NUM_THREADS=" + threads + ": llvmpipe rasterises in the renderer's thread (" + size +
         " frames, at most " + std::to_string(kLlvmpipeCallingThreadMaxPixels) + " pixels)";
}

}  // namespace tofguard::renderer
