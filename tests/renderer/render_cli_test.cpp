// `tofguard-renderer render ...` as a real process: the PNGs it writes
// carry the right millimetres and labels; usage errors exit with 2.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "renderer_test_util.hpp"

namespace tofguard::renderer::test {
namespace {

TEST(RenderCli, WritesDepthInMillimetresAndLabels) {
  // A 0.2 m cube whose front face is 1.0 m ahead of a camera at the world
  // origin looking along world z; an environment floor further back.
  const std::string robot = write_test_file(
      "cli/robot.urdf",
      "<robot name=\"r\"><link name=\"world\"/><joint name=\"slide\" type=\"prismatic\"><parent "
      "link=\"world\"/>"
      "<child link=\"cube\"/><axis xyz=\"0 0 1\"/><limit lower=\"0\" upper=\"2\" effort=\"1\" "
      "velocity=\"1\"/></joint>"
      "<link name=\"cube\"><visual><geometry><box size=\"0.2 0.2 0.2\"/></geometry></visual></link></robot>");
  const std::string environment = write_test_file(
      "cli/env.urdf",
      "<robot name=\"e\"><link name=\"world\"/><joint name=\"w\" type=\"fixed\"><parent link=\"world\"/>"
      "<child link=\"wall\"/><origin xyz=\"0 0 3\"/></joint><link name=\"wall\"><visual><geometry>"
      "<box size=\"10 10 0.1\"/></geometry></visual></link></robot>");
  const std::string depth_png = write_test_file("cli/depth.png", "");
  const std::string labels_png = write_test_file("cli/labels.png", "");
  std::string out, err;
  const int rc = tofguard::test::run_command(
      "render_cli",
      {tofguard::test::bin_dir() + "/tofguard-renderer", "render", "--urdf", robot, "--env", environment,
       "--joint", "slide=1.1", "--camera-pose", "0,0,0,1,0,0,0", "--intrinsics", "64,48,60,58,30.5,22.5",
       "--out", depth_png, "--labels", labels_png},
      &out, &err);
  ASSERT_EQ(rc, 0) << err;
  EXPECT_NE(out.find("wrote"), std::string::npos) << out;
  const cv::Mat depth = cv::imread(depth_png, cv::IMREAD_UNCHANGED);
  const cv::Mat labels = cv::imread(labels_png, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(depth.type(), CV_16UC1);
  ASSERT_EQ(labels.type(), CV_16UC1);
  ASSERT_EQ(depth.cols, 64);
  ASSERT_EQ(depth.rows, 48);
  // The pixel at the principal point sees the cube's front face at 1.0 m...
  EXPECT_EQ(depth.at<uint16_t>(22, 30), 1000);
  EXPECT_EQ(labels.at<uint16_t>(22, 30), kLabelRobotFirst + 1);
  // ...and a corner pixel the wall's front at 2.95 m (links: world, cube |
  // world, wall, so the wall is environment link 1).
  EXPECT_EQ(depth.at<uint16_t>(0, 0), 2950);
  EXPECT_EQ(labels.at<uint16_t>(0, 0), kLabelEnvironmentFirst + 1);
}

TEST(RenderCli, UsageAndModelErrors) {
  std::string out, err;
  const std::string bin = tofguard::test::bin_dir() + "/tofguard-renderer";
  EXPECT_EQ(tofguard::test::run_command("render_cli_usage", {bin, "render", "--urdf", "x.urdf"}, &out, &err),
            2);
  EXPECT_NE(err.find("--camera-pose is required"), std::string::npos) << err;
  EXPECT_EQ(
      tofguard::test::run_command("render_cli_missing",
                                  {bin, "render", "--urdf", "/nonexistent.urdf", "--camera-pose",
                                   "0,0,0,1,0,0,0", "--intrinsics", "8,8,8,8,4,4", "--out", "/tmp/x.png"},
                                  &out, &err),
      1);
  EXPECT_NE(err.find("/nonexistent.urdf: cannot read the URDF file"), std::string::npos) << err;
  const std::string robot = write_test_file(
      "cli/sphere.urdf",
      "<robot name=\"r\"><link name=\"world\"><visual><geometry><sphere radius=\"0.1\"/></geometry></visual>"
      "</link></robot>");
  EXPECT_EQ(tofguard::test::run_command("render_cli_simplify",
                                        {bin, "render", "--urdf", robot, "--simplify-error-mm", "-1",
                                         "--camera-pose", "0,0,0,1,0,0,0", "--intrinsics", "8,8,8,8,4,4",
                                         "--out", write_test_file("cli/simplify.png", "")},
                                        &out, &err),
            1);
  EXPECT_NE(err.find("simplify_error_mm must be a finite value >= 0, got -1.0"), std::string::npos) << err;
}

}  // namespace
}  // namespace tofguard::renderer::test
