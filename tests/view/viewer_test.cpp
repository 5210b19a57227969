// tofguard-view --log --out: one PNG per camera frame, with the colour
// convention checked on pixels whose discrepancy is known.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <filesystem>

#include <opencv2/imgcodecs.hpp>

#include "log_events.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/link_labels_t.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/view/view_compose.hpp"
#include "tool_support.hpp"

namespace tofguard::test {
namespace {

constexpr int kW = 176;
constexpr int kH = 144;

// The arm at `arm_mm`, 1 m unless said.
depth_image_t frame(int64_t seq, bool camera, int16_t arm_mm = 1000) {
  depth_image_t m;
  m.utime = 1700000000000000 + seq * 33333;
  m.seq = seq;
  m.camera_id = "tof-mast";
  m.width = kW;
  m.height = kH;
  m.fx = 221.0;
  m.fy = 220.5;
  m.cx = 87.3;
  m.cy = 71.8;
  m.calibrated = true;
  m.num_pixels = kW * kH;
  m.depth_mm.assign(m.num_pixels, 2000);  // the floor
  for (int v = 40; v < 100; ++v) {
    for (int u = 40; u < 70; ++u) m.depth_mm[v * kW + u] = arm_mm;  // the arm
  }
  if (camera) {
    // Something nearer than the modelled floor: I_dis = 2000 - 1200 > 0.
    for (int v = 50; v < 90; ++v) {
      for (int u = 110; u < 140; ++u) m.depth_mm[v * kW + u] = 1200;
    }
    // The arm's top missing, the camera sees the floor: I_dis = arm_mm - 2000 < 0.
    for (int v = 40; v < 60; ++v) {
      for (int u = 40; u < 70; ++u) m.depth_mm[v * kW + u] = 2000;
    }
  }
  m.num_amplitude = 0;
  return m;
}

link_labels_t labels(int64_t seq) {
  link_labels_t m{};
  m.utime = 1700000000000000 + seq * 33333;
  m.seq = seq;
  m.camera_id = "tof-mast";
  m.usable = true;
  m.width = kW;
  m.height = kH;
  m.num_robot_links = 1;
  m.num_links = 2;
  m.link_name = {"link1", "floor"};
  m.num_pixels = kW * kH;
  m.label.assign(m.num_pixels, link_labels_t::ENVIRONMENT_FIRST);
  for (int v = 40; v < 100; ++v) {
    for (int u = 40; u < 70; ++u) m.label[v * kW + u] = link_labels_t::ROBOT_FIRST;
  }
  m.num_joints = 0;
  m.num_axes = 0;
  m.num_link_axes = 0;
  return m;
}

TEST(Viewer, ExportsOnePngPerCameraFrameWithNearerRedAndFartherBlue) {
  const std::string log_path = output_dir() + "/viewer.lcmlog";
  const std::string out = output_dir() + "/viewer-frames";
  std::filesystem::remove(log_path);
  std::filesystem::remove_all(out);
  {
    lcm::LogFile log(log_path, "w");
    for (int64_t seq = 10; seq < 13; ++seq) {
      const int64_t t = 1700000000000000 + seq * 33333;
      // The arm 1.5 m away: within the distances config/sim.yaml's camera
      // profile was measured over (nearer, the frame is unusable).
      write_log_event(&log, t, "TOF_DEPTH", frame(seq, true, 1500));
      if (seq == 12) continue;  // the last frame never got its rendering
      write_log_event(&log, t + 5000, "TOF_RENDERED", frame(seq, false, 1500));
      write_log_event(&log, t + 5000, "TOF_LABELS", labels(seq));
      risk_t risk;
      risk.utime = t;
      risk.seq = seq;
      risk.level = risk_t::DANGEROUS;
      risk.cause = risk_t::CAUSE_UNKNOWN_OBJECT;
      risk.score = 1;
      risk.threshold = 0.5;
      risk.detail = "test";
      write_log_event(&log, t + 9000, "SAFETY_RISK", risk);
    }
  }
  std::string stdout_text, stderr_text;
  ASSERT_EQ(run_command("viewer-export",
                        {bin_dir() + "/tofguard-view", "--config", source_dir() + "/config/sim.yaml", "--log",
                         log_path, "--out", out},
                        &stdout_text, &stderr_text),
            0)
      << stderr_text;
  EXPECT_NE(stdout_text.find("3 camera frames"), std::string::npos) << stdout_text;
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(out))
    files.push_back(e.path().filename().string());
  std::sort(files.begin(), files.end());
  ASSERT_EQ(files,
            (std::vector<std::string>{"frame_00000010.png", "frame_00000011.png", "frame_00000012.png"}));

  const cv::Mat3b view = cv::imread(out + "/frame_00000010.png", cv::IMREAD_COLOR);
  const int scale = view::panel_scale(kW);
  ASSERT_EQ(view.cols, 3 * kW * scale);
  const int banner = view.rows - kH * scale;
  auto discrepancy_pixel = [&](int u, int v) {
    return view(banner + v * scale + scale / 2, 2 * kW * scale + u * scale + scale / 2);  // BGR
  };
  const cv::Vec3b nearer = discrepancy_pixel(125, 70);
  EXPECT_GT(nearer[2], 100) << "camera nearer than the model must be red";
  EXPECT_EQ(nearer[0], 0);
  const cv::Vec3b farther = discrepancy_pixel(55, 50);
  EXPECT_GT(farther[0], 100) << "camera farther than the model must be blue";
  EXPECT_EQ(farther[2], 0);
  const cv::Vec3b match = discrepancy_pixel(10, 10);
  EXPECT_EQ(match, cv::Vec3b(0, 0, 0));
  EXPECT_EQ(discrepancy_pixel(55, 80), cv::Vec3b(0, 0, 0)) << "the arm's matching part";
}

// The fields on the camera panel: a cover of one sphere (5 cm) at the
// arm's middle (pixel 55, 70 at 1 m): the arm (1 m from the camera, within
// 0.15 m of the sphere) lies inside a 0.3 m protective field, the floor
// (2 m) beyond a 0.5 m warning field; the arm's outline is drawn red.
TEST(Viewer, DrawsTheProtectiveFieldsOutlineOnTheCameraPanel) {
  const depth_image_t camera = frame(10, false);
  link_labels_t l = labels(10);
  l.num_arm_spheres = 1;
  l.arm_cover_max_radius_m = 0.05;
  l.arm_sphere_link = {0};
  l.arm_sphere_center_m = {
      {static_cast<float>((55 - 87.3) / 221.0), static_cast<float>((70 - 71.8) / 220.5), 1.0f}};
  l.arm_sphere_radius_m = {0.05f};
  const cv::Mat1b classes = view::field_classes(camera, l, 0.3, 0.5);
  EXPECT_EQ(classes(70, 55), 2);
  EXPECT_EQ(classes(41, 41), 2) << "the arm's corner: 0.1 m from the sphere";
  EXPECT_EQ(classes(70, 100), 0) << "the floor, a metre behind";
  EXPECT_EQ(cv::countNonZero(classes), 30 * 60) << "exactly the arm";
  // Moved 0.6 m nearer to the floor, the sphere puts part of the floor in
  // the warning field.
  l.arm_sphere_center_m[0][2] = 1.6f;
  EXPECT_GT(cv::countNonZero(view::field_classes(camera, l, 0.3, 0.5) == 1), 0);
  l.arm_sphere_center_m[0][2] = 1.0f;

  view::FrameSet set;
  set.camera = camera;
  set.rendered = frame(10, false);
  set.labels = l;
  const int scale = view::panel_scale(kW);
  const cv::Mat3b with_fields =
      view::compose_view(set, discrepancy::DiscrepancyOptions{}, 8000, 200, view::FieldSizes{0.3, 0.2});
  const cv::Mat3b without = view::compose_view(set, discrepancy::DiscrepancyOptions{}, 8000, 200);
  const int banner = with_fields.rows - kH * scale;
  auto camera_pixel = [&](const cv::Mat3b& view, int u, int v) {
    return view(banner + v * scale + scale / 2, u * scale + scale / 2);
  };
  EXPECT_EQ(camera_pixel(with_fields, 40, 70), cv::Vec3b(0, 0, 255)) << "the arm's outline, red";
  EXPECT_EQ(camera_pixel(with_fields, 55, 70), camera_pixel(without, 55, 70)) << "inside: the depth colour";
  EXPECT_NE(camera_pixel(without, 40, 70), cv::Vec3b(0, 0, 255));
}

TEST(Viewer, VerdictText) {
  view::FrameSet set;
  set.camera = frame(42, true);
  EXPECT_EQ(view::verdict_text(set), "seq 42  no verdict");
  risk_t risk;
  risk.seq = 42;
  risk.level = risk_t::DANGEROUS;
  risk.cause = risk_t::CAUSE_JOINT_ERROR;
  risk.suspect = "a4";
  risk.detail = "a4 off";
  set.risk = risk;
  EXPECT_EQ(view::verdict_text(set), "seq 42  DANGEROUS joint error, suspect a4 | a4 off");
}

// The user's line: the region nearest the arm (the labels') and the frame's
// limit; none without body regions.
TEST(Viewer, UserText) {
  view::FrameSet set;
  set.camera = frame(42, true);
  EXPECT_EQ(view::user_text(set), "");
  link_labels_t labels{};
  labels.num_body_regions = 3;
  labels.body_region = {"face", "chest", "hand"};
  labels.body_region_separation_m = {0.19f, 0.17f, 0.021f};
  set.labels = labels;
  EXPECT_EQ(view::user_text(set), "user: hand nearest, 0.02 m");
  speed_limit_t limit{};
  limit.seq = 42;
  limit.max_arm_speed_m_s = 0.38;
  limit.set_by = speed_limit_t::SET_BY_BODY_REGION;
  limit.body_region = "face";
  limit.separation_m = 0.14;
  set.limit = limit;
  EXPECT_EQ(view::user_text(set), "user: hand nearest, 0.02 m | limit 0.38 m/s, set by face at 0.14 m");
}

}  // namespace
}  // namespace tofguard::test
