#pragma once
// Two doubles side by side, for the discrepancy's per-pixel and per-point
// loops (GCC's and Clang's vector extension: SSE2 on x86-64, NEON on
// arm64). Each lane's +, -, * and / are the scalar ones (IEEE), so a sum
// or a point computed two lanes at a time is the same to the last bit as
// one at a time where the compiler fuses no multiply-add (x86-64 without
// -march: the bench digests, docs/benchmarks.md). Where it may fuse
// (arm64) the lanes and the scalar code can differ in the last bit; each
// pixel and point still takes one fixed path, so the results never depend
// on the worker threads.
#include <cstring>

namespace tofguard::discrepancy {

using Double2 = double __attribute__((vector_size(16)));

// Two doubles from memory, no alignment needed.
inline Double2 load2(const double* p) {
  Double2 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

inline void store2(double* p, Double2 v) { std::memcpy(p, &v, sizeof v); }

}  // namespace tofguard::discrepancy
