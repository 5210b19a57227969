#include "tofguard/common/resident_heap.hpp"

#include <malloc.h>

namespace tofguard {

bool keep_heap_resident() {
  constexpr int kLargestBlockFromHeap = 32 * 1024 * 1024;  // glibc's HEAP_MAX mmap threshold (64-bit)
  constexpr int kNeverTrim = -1;                           // M_TRIM_THRESHOLD: -1 turns trimming off
  const bool mmap_ok = mallopt(M_MMAP_THRESHOLD, kLargestBlockFromHeap) == 1;
  const bool trim_ok = mallopt(M_TRIM_THRESHOLD, kNeverTrim) == 1;
  return mmap_ok && trim_ok;
}

}  // namespace tofguard
