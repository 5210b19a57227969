// The fuzz target TOFGUARD_FUZZ_TARGET (<name>_fuzz.cpp, compiled into this
// test by the main g++ build) on its committed seeds and on every crash
// input kept in tests/fuzz/regressions/<name>/, so that a fixed crash
// cannot come back unnoticed even where clang and the sanitizers are not
// run (scripts/fuzz replays the same files under them).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace {

namespace fs = std::filesystem;

std::vector<fs::path> files_in(const fs::path& folder) {
  std::vector<fs::path> files;
  if (!fs::is_directory(folder)) return files;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.is_regular_file()) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

void replay(const std::string& kind, size_t* count) {
  const fs::path folder = fs::path(TOFGUARD_SOURCE_DIR) / "tests" / "fuzz" / kind / TOFGUARD_FUZZ_TARGET;
  for (const fs::path& file : files_in(folder)) {
    SCOPED_TRACE(file.string());
    std::ifstream in(file, std::ios::binary);
    const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(LLVMFuzzerTestOneInput(bytes.data(), bytes.size()), 0);
    ++*count;
  }
}

TEST(FuzzReplay, Seeds) {
  size_t count = 0;
  replay("corpus", &count);
  // wire_messages and spy_format have their seeds made at build time only.
  std::cout << TOFGUARD_FUZZ_TARGET << ": " << count << " seeds replayed\n";
}

TEST(FuzzReplay, Regressions) {
  size_t count = 0;
  replay("regressions", &count);
  std::cout << TOFGUARD_FUZZ_TARGET << ": " << count << " regression inputs replayed\n";
}

}  // namespace
