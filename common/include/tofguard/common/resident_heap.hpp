#pragma once
// Keeps the memory a frame frees in the process, for the next frame
// (docs/benchmarks.md, "The hot paths"). glibc's malloc hands large blocks
// (>= 128 kB: a 640x480 image or mask) back to the kernel with munmap as
// soon as they are freed, and trims the heap's top when more than 128 kB is
// free: the next frame then takes page faults and the kernel zeroes every
// page again. A process that allocates the same sizes every frame (the
// renderer's and the discrepancy's images) keeps them instead: blocks up to
// 32 MB (glibc's largest mmap threshold) come from the heap, and the heap is
// never trimmed. Its size stays that of its largest frame.
namespace tofguard {

// Call once, at the start of main (before the first frame). Returns false
// when malloc refused a setting (the process then runs as before).
bool keep_heap_resident();

}  // namespace tofguard
