// tofguard-bench's logic, short (tests/support/chain_bench.hpp): the
// default arm at 176x144 and 10 Hz for 3 s through the real observer chain.
// Asserts that every frame went through every stage, none was dropped, and
// the report has its rows; never a wall-clock latency (the machine may be
// loaded).
#include <gtest/gtest.h>

#include <filesystem>
#include <iostream>

#include "chain_bench.hpp"
#include "test_support.hpp"

namespace tofguard::test {
namespace {

TEST(BenchSmoke, FramesGoThroughEveryStageAtTenHertz) {
  BenchOptions options;
  options.arms = {"default"};
  options.resolutions = {{176, 144}};
  options.rate_hz = 10;
  options.seconds = 3;
  options.shared_dir = shared_dir();
  const BenchReport report = run_bench(options, std::cerr);
  ASSERT_EQ(report.steps.size(), 1u);
  const BenchStep& step = report.steps.front();
  EXPECT_EQ(step.frames_sent, 30);
  EXPECT_EQ(step.frames_rendered, step.frames_sent);
  EXPECT_EQ(step.frames_judged, step.frames_sent);
  EXPECT_EQ(step.frames_verdict, step.frames_sent);
  EXPECT_EQ(step.frames_dropped, 0);
  EXPECT_EQ(step.end_to_end.count, step.frames_sent);
  EXPECT_GT(step.triangles, 0u);
  for (const char* p : {"tofguard-renderer", "tofguard-discrepancy", "tofguard-risk", "tofguard-intervene"})
    EXPECT_EQ(step.cpu_percent.count(p), 1u) << p;

  const std::string markdown = bench_markdown(report);
  std::cout << markdown;
  for (const char* column : {"TOF_DEPTH → TOF_RENDERED", "TOF_RENDERED → SAFETY_DISCREPANCY",
                             "SAFETY_DISCREPANCY → SAFETY_RISK", "TOF_DEPTH → SAFETY_RISK", "CPU %"})
    EXPECT_NE(markdown.find(column), std::string::npos) << column;
  EXPECT_NE(markdown.find("| default | "), std::string::npos);
  EXPECT_NE(markdown.find("| 176x144 | 10 | 30 | 0 | "), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("nproc"), std::string::npos);

  const std::string plot = output_dir() + "/bench_smoke/bench.png";
  plot_bench(report, plot);
  EXPECT_GT(std::filesystem::file_size(plot), 1000u);
}

}  // namespace
}  // namespace tofguard::test
