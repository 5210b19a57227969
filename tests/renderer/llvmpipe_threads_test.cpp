// llvmpipe's threads per frame size (renderer/llvmpipe_threads.hpp): the
// calling thread up to half of 320x240, llvmpipe's default above, and an
// operator's LP_NUM_THREADS never overridden.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "tofguard/renderer/llvmpipe_threads.hpp"

namespace tofguard::renderer {
namespace {

Intrinsics size(int width, int height) {
  return Intrinsics{width, height, 200.0, 200.0, width / 2.0, height / 2.0};
}

TEST(LlvmpipeThreads, TheCallingThreadUpToHalfOf320x240AndTheDefaultAbove) {
  EXPECT_EQ(llvmpipe_threads_for(size(176, 144)), "0");
  EXPECT_EQ(llvmpipe_threads_for(size(240, 160)), "0");  // 38 400 pixels
  EXPECT_EQ(llvmpipe_threads_for(size(241, 160)), "");
  EXPECT_EQ(llvmpipe_threads_for(size(320, 240)), "");
  EXPECT_EQ(llvmpipe_threads_for(size(640, 480)), "");
}

TEST(LlvmpipeThreads, SetsTheVariableOnlyWhenTheEnvironmentHasNone) {
  unsetenv("LP_NUM_THREADS");
  std::string line = choose_llvmpipe_threads(size(176, 144));
  ASSERT_NE(std::getenv("LP_NUM_THREADS"), nullptr);
  EXPECT_STREQ(std::getenv("LP_NUM_THREADS"), "0");
  EXPECT_NE(line.find("LP_NUM_THREADS=0"), std::string::npos) << line;
  EXPECT_NE(line.find("176x144"), std::string::npos) << line;

  unsetenv("LP_NUM_THREADS");
  line = choose_llvmpipe_threads(size(640, 480));
  EXPECT_EQ(std::getenv("LP_NUM_THREADS"), nullptr);
  EXPECT_NE(line.find("default"), std::string::npos) << line;

  setenv("LP_NUM_THREADS", "3", 1);
  line = choose_llvmpipe_threads(size(176, 144));
  EXPECT_STREQ(std::getenv("LP_NUM_THREADS"), "3");
  EXPECT_NE(line.find("LP_NUM_THREADS=3 from the environment"), std::string::npos) << line;
  unsetenv("LP_NUM_THREADS");
}

}  // namespace
}  // namespace tofguard::renderer
