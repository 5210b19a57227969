// scripts/record-calibration end to end (private network namespace): the
// simulated camera records a wall at three distances through the real
// renderer, and tofguard-calibrate-depth removes the systematic error.
#include <gtest/gtest.h>

#include <cstdlib>
#include <sstream>

#include "tool_support.hpp"

namespace tofguard::test {
namespace {

TEST(RecordCalibration, RecordsSimulatedPlanesAndCalibrates) {
  const std::string out = output_dir() + "/record-calibration";
  setenv("TOFGUARD_BIN", bin_dir().c_str(), 1);
  std::string stdout_text, stderr_text;
  ASSERT_EQ(run_command("record_calibration",
                        {source_dir() + "/scripts/record-calibration", "--out", out, "--distances",
                         "1.0 2.0 3.0", "--frames", "4", "--degree", "2", "--lcm-port", "7787"},
                        &stdout_text, &stderr_text),
            0)
      << stdout_text << stderr_text;
  EXPECT_EQ(read_file(out + "/captures.csv"),
            "capture,true_distance_mm\nplane_1000.lcmlog,1000\nplane_2000.lcmlog,2000\n"
            "plane_3000.lcmlog,3000\n");
  EXPECT_NE(read_file(out + "/captures_calibration.yaml").find("degree: 2"), std::string::npos);
  // Table rows: true, samples, measured, error, std, error after, std after.
  std::istringstream table(stdout_text.substr(stdout_text.find("true_mm")));
  std::string header;
  std::getline(table, header);
  for (int row = 0; row < 3; ++row) {
    double true_mm, samples, measured, error, std_mm, after, std_after;
    table >> true_mm >> samples >> measured >> error >> std_mm >> after >> std_after;
    ASSERT_TRUE(table) << stdout_text;
    EXPECT_GT(error, 50.0) << "the simulator's systematic error at " << true_mm;
    EXPECT_LT(std::abs(after), 5.0) << true_mm;
  }
}

}  // namespace
}  // namespace tofguard::test
