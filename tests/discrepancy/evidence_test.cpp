// The evidence stage (discrepancy/evidence.hpp, docs/safety-chain.md
// "Evidence") with the real renderer: its Jacobians against finite
// differences of renders on three arms, and its fits on simulated camera
// frames with an encoder offset, a moved camera and nothing wrong.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "estimator_test_support.hpp"
#include "simulated_frames.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/common/wire_checks.hpp"
#include "tofguard/discrepancy/discrepancy_image.hpp"
#include "tofguard/discrepancy/evidence.hpp"
#include "tofguard/renderer/depth_renderer.hpp"
#include "tofguard/renderer/rendered_kinematics.hpp"
#include "tofguard/robot_model/scene_model.hpp"
#include "tool_support.hpp"

namespace tofguard::discrepancy {
namespace {

namespace fs = std::filesystem;
using robot_model::JointPositions;

constexpr double kDeg = M_PI / 180.0;

struct Frame {
  renderer::RenderResult result;
  depth_image_t depth;
  link_labels_t labels;
};

Frame render_frame(renderer::DepthRenderer* r, const robot_model::KinematicTree& tree,
                   const JointPositions& q, const Eigen::Isometry3d& world_from_optical,
                   const Intrinsics& in) {
  Frame f;
  const robot_model::LinkPoses poses = robot_model::forward_kinematics(tree, q);
  f.result = r->render_at(poses, world_from_optical, in);
  EXPECT_TRUE(f.result.usable) << f.result.unusable_reason;
  f.depth = make_depth_image("cam", in, 1, 1, true, f.result.depth_m);
  f.labels = renderer::make_rendered_link_labels(f.depth, f.result, tree, robot_model::ArmSpheres{});
  return f;
}

// Pixels whose 3x3 neighbourhood shows one link in both renders.
bool interior(const Frame& a, const Frame& b, int i) {
  const int w = a.depth.width;
  const int u = i % w;
  const int v = i / w;
  if (u < 1 || v < 1 || u + 1 >= w || v + 1 >= a.depth.height) return false;
  const int16_t l = a.result.labels[i];
  if (l == 0) return false;
  for (int dv = -1; dv <= 1; ++dv) {
    for (int du = -1; du <= 1; ++du) {
      const int n = i + dv * w + du;
      if (a.result.labels[n] != l || b.result.labels[n] != l || a.result.depth_m[n] <= 0) return false;
    }
  }
  return true;
}

struct Agreement {
  int pixels = 0;
  double correlation = 0;
  double slope = 0;  // least squares actual = slope * predicted
  double rms_actual_mm = 0;
};

Agreement agree(const std::vector<double>& predicted, const std::vector<double>& actual) {
  Agreement a;
  a.pixels = static_cast<int>(predicted.size());
  if (a.pixels < 2) return a;
  double sp = 0, sa = 0, spp = 0, saa = 0, spa = 0;
  for (size_t k = 0; k < predicted.size(); ++k) {
    sp += predicted[k];
    sa += actual[k];
    spp += predicted[k] * predicted[k];
    saa += actual[k] * actual[k];
    spa += predicted[k] * actual[k];
  }
  const double n = a.pixels;
  const double cov = spa / n - sp * sa / (n * n);
  const double vp = spp / n - sp * sp / (n * n);
  const double va = saa / n - sa * sa / (n * n);
  a.correlation = cov / std::sqrt(vp * va);
  a.slope = spa / spp;
  a.rms_actual_mm = std::sqrt(saa / n);
  return a;
}

// Predicted (J * delta) and actual depth change (mm) on interior pixels of
// `base` for the render `moved`; `column` picks the parameter: 0..5 camera,
// 6 + j joint j.
Agreement compare(const Frame& base, const Frame& moved, int column, double delta) {
  const EvidenceJacobian jacobian(base.depth, base.labels, 50);
  EXPECT_TRUE(jacobian.available());
  std::vector<double> joints(jacobian.num_joints());
  double camera[6];
  std::vector<double> predicted;
  std::vector<double> actual;
  const int n = base.depth.width * base.depth.height;
  for (int i = 0; i < n; ++i) {
    if (!interior(base, moved, i)) continue;
    bool is_moved = false;
    int link = -1;
    if (!jacobian.at(i, camera, joints.data(), &is_moved, &link)) continue;
    const double j = column < 6 ? camera[column] : joints[column - 6];
    if (column < 6 && is_moved) continue;
    if (column >= 6 && !is_moved) continue;
    const double change_mm = 1000.0 * (moved.result.depth_m[i] - base.result.depth_m[i]);
    if (std::abs(change_mm) > 30) continue;  // an edge swept past
    predicted.push_back(j * delta);
    actual.push_back(change_mm);
  }
  return agree(predicted, actual);
}

// Every joint of `tree` moved by 0.3 degrees (1 mm for a prismatic one):
// the analytic prediction matches the rendered change.
void expect_joint_jacobians_match(const robot_model::SceneModel& scene, const JointPositions& q,
                                  const Eigen::Isometry3d& world_from_optical, const Intrinsics& in,
                                  const std::string& arm) {
  renderer::DepthRenderer r(scene, 0.1, 8.0);
  const Frame base = render_frame(&r, scene, q, world_from_optical, in);
  ASSERT_GT(base.labels.num_axes, 0);
  int checked = 0;
  for (size_t j = 0; j < scene.actuated_joint_names.size(); ++j) {
    const std::string& name = scene.actuated_joint_names[j];
    const double delta = scene.is_prismatic_joint(name) ? 0.001 : 0.3 * kDeg;
    JointPositions moved_q = q;
    moved_q[name] += delta;
    const Frame moved = render_frame(&r, scene, moved_q, world_from_optical, in);
    const Agreement a = compare(base, moved, 6 + static_cast<int>(j), delta);
    std::cout << arm << " " << name << ": " << a.pixels << " px, correlation " << a.correlation << ", slope "
              << a.slope << ", rms change " << a.rms_actual_mm << " mm\n";
    // The slope comes from whole-millimetre rendered depths: changes under
    // 0.5 mm rms are mostly quantisation. Measured (176x144): slopes
    // 0.84..1.2, correlations 0.65..0.99 (lowest where the change is ~1 mm).
    if (a.pixels < 100 || a.rms_actual_mm < 0.5) continue;
    EXPECT_GT(a.correlation, 0.6) << arm << " " << name;
    EXPECT_NEAR(a.slope, 1.0, 0.25) << arm << " " << name;
    ++checked;
  }
  EXPECT_GE(checked, 3) << arm;
}

// The joint whose naming search gained most, and `joint`'s own index (-1
// when the summary has no such joint).
std::pair<int, int> searched_best_and_own(const discrepancy_t& s, const std::string& joint) {
  int best = 0;
  int own = -1;
  for (int j = 0; j < s.num_joints; ++j) {
    if (s.joint_search_gain[j] > s.joint_search_gain[best]) best = j;
    if (s.joint_name[j] == joint) own = j;
  }
  return {best, own};
}

class EvidenceTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    config_ = new deployment::Config(estimator::test::sim_config());
    frames_ = new test::SimulatedFrames(*config_);
  }
  static void TearDownTestSuite() {
    delete frames_;
    delete config_;
  }
  static Eigen::Isometry3d camera() { return estimator::test::pose_of(config_->camera.pose); }
  static deployment::Config* config_;
  static test::SimulatedFrames* frames_;
};
deployment::Config* EvidenceTest::config_ = nullptr;
test::SimulatedFrames* EvidenceTest::frames_ = nullptr;

TEST_F(EvidenceTest, JointJacobiansMatchRenderedChangesOnTheDefaultArm) {
  expect_joint_jacobians_match(frames_->scene(), estimator::test::side_reach_pose(), camera(),
                               config_->camera.intrinsics, "default arm");
}

TEST_F(EvidenceTest, CameraJacobiansMatchRenderedChanges) {
  renderer::DepthRenderer& r = frames_->renderer();
  const Intrinsics& in = config_->camera.intrinsics;
  const JointPositions q = estimator::test::reach_pose();
  const Frame base = render_frame(&r, frames_->scene(), q, camera(), in);
  struct Case {
    const char* name;
    int column;
    double delta;
  };
  // The seen optical frame in the reported one: 5 mm along each axis,
  // 0.2 degrees about each.
  for (const Case c : {Case{"t_x", 0, 0.005}, Case{"t_y", 1, 0.005}, Case{"t_z", 2, 0.005},
                       Case{"w_x", 3, 0.2 * kDeg}, Case{"w_y", 4, 0.2 * kDeg}, Case{"w_z", 5, 0.2 * kDeg}}) {
    Eigen::Isometry3d seen = Eigen::Isometry3d::Identity();
    if (c.column < 3) {
      seen.translation()[c.column] = c.delta;
    } else {
      seen.linear() = Eigen::AngleAxisd(c.delta, Eigen::Vector3d::Unit(c.column - 3)).toRotationMatrix();
    }
    const Frame moved = render_frame(&r, frames_->scene(), q, camera() * seen, in);
    const Agreement a = compare(base, moved, c.column, c.delta);
    std::cout << "camera " << c.name << ": " << a.pixels << " px, correlation " << a.correlation << ", slope "
              << a.slope << ", rms change " << a.rms_actual_mm << " mm\n";
    EXPECT_GT(a.pixels, 1000) << c.name;
    if (a.rms_actual_mm < 0.5) continue;  // e.g. t_x on a floor seen from above
    EXPECT_GT(a.correlation, 0.85) << c.name;
    EXPECT_NEAR(a.slope, 1.0, 0.15) << c.name;
  }
}

// A camera 2 m in front of an arm standing at the origin (+x), looking
// back along -x, optical y down.
Eigen::Isometry3d front_view(double height_m) {
  Eigen::Isometry3d world_from_optical = Eigen::Isometry3d::Identity();
  world_from_optical.translation() = Eigen::Vector3d(1.8, 0.4, height_m);
  Eigen::Matrix3d r;
  r.col(2) = Eigen::Vector3d(-1.8, -0.4, 0).normalized();
  r.col(0) = Eigen::Vector3d(0, 0, 1).cross(r.col(2)).normalized();
  r.col(1) = r.col(2).cross(r.col(0));
  world_from_optical.linear() = r;
  return world_from_optical;
}

JointPositions bent(const robot_model::KinematicTree& tree) {
  const double values[7] = {0.3, 0.5, -0.4, -1.0, 0.6, 0.8, 0.3};
  JointPositions q;
  for (size_t j = 0; j < tree.actuated_joint_names.size(); ++j)
    q[tree.actuated_joint_names[j]] = values[j % 7];
  return q;
}

TEST(EvidenceOtherArms, JointJacobiansMatchRenderedChangesOnTheIiwa14AndTheKinovaGen3) {
  if (test::shared_dir().empty())
    GTEST_SKIP() << "../shared is absent: the iiwa14 and Kinova Gen3 models are not available";
  const fs::path robots = fs::path(test::shared_dir()) / "robots";
  const Intrinsics in{176, 144, 150, 150, 87.5, 71.5};
  {
    const fs::path urdf = robots / "iiwa14" / "urdf" / "iiwa14_no_collision_relative.urdf";
    if (!fs::exists(urdf)) GTEST_SKIP() << urdf << " is absent";
    const robot_model::SceneModel scene = robot_model::load_scene(urdf.string(), {}, {});
    expect_joint_jacobians_match(scene, bent(scene), front_view(0.7), in, "iiwa14");
  }
  {
    const fs::path urdf = robots / "kinova_gen3" / "kortex_description" / "arms" / "gen3" / "7dof" / "urdf" /
                          "GEN3-7DOF-NOVISION_FOR_URDF_ARM_V12.urdf";
    if (!fs::exists(urdf)) GTEST_SKIP() << urdf << " is absent";
    robot_model::SceneOptions options;
    options.package_paths = {(robots / "kinova_gen3").string()};
    const robot_model::SceneModel scene = robot_model::load_scene(urdf.string(), {}, options);
    expect_joint_jacobians_match(scene, bent(scene), front_view(0.6), in, "Kinova Gen3");
  }
}

// ---- The fits on simulated camera frames ----

// The config's options with no static-error allowance: these tests check
// the plain fit (its scores, sums and offsets); the allowance, which
// shrinks the scores, has its own test (AStaticErrorWithinItsBound...).
DiscrepancyOptions options_of(const deployment::Config& config) {
  DiscrepancyOptions options = discrepancy_options(config.discrepancy);
  options.evidence.static_bias_mm = 0;
  options.evidence.fixed_pattern_sigma_mm = 0;
  return options;
}

discrepancy_t evidence_of(test::SimulatedFrames* frames, const deployment::Config& config,
                          const JointPositions& true_q, const Eigen::Isometry3d& true_camera,
                          const JointPositions& reported_q, const Eigen::Isometry3d& reported_camera,
                          uint64_t index) {
  const Intrinsics& in = config.camera.intrinsics;
  const std::vector<float> seen = frames->capture(true_q, true_camera, in, index);
  const depth_image_t camera = make_depth_image("cam", in, 1, 1, true, seen);
  const Frame model = render_frame(&frames->renderer(), frames->scene(), reported_q, reported_camera, in);
  const DiscrepancyFrame f = compute_discrepancy(camera, model.depth, model.labels, options_of(config));
  EXPECT_TRUE(f.summary.usable) << f.summary.unusable_reason;
  EXPECT_EQ(check_discrepancy(f.summary), "");
  return f.summary;
}

// As evidence_of with the camera's frame `bias_m` farther at every pixel (a
// common-mode distance error the calibration left) and the evidence's
// static-error bound set to `static_bias_mm`.
discrepancy_t evidence_with_static_error(test::SimulatedFrames* frames, const deployment::Config& config,
                                         const JointPositions& q, const Eigen::Isometry3d& true_camera,
                                         const Eigen::Isometry3d& reported_camera, uint64_t index,
                                         double bias_m, double static_bias_mm) {
  const Intrinsics& in = config.camera.intrinsics;
  std::vector<float> seen = frames->capture(q, true_camera, in, index);
  for (float& z : seen) {
    if (z > 0) z += static_cast<float>(bias_m);
  }
  const depth_image_t camera = make_depth_image("cam", in, 1, 1, true, seen);
  const Frame model = render_frame(&frames->renderer(), frames->scene(), q, reported_camera, in);
  DiscrepancyOptions options = options_of(config);
  options.evidence.static_bias_mm = static_bias_mm;
  const DiscrepancyFrame f = compute_discrepancy(camera, model.depth, model.labels, options);
  EXPECT_TRUE(f.summary.usable) << f.summary.unusable_reason;
  EXPECT_EQ(check_discrepancy(f.summary), "");
  return f.summary;
}

// The largest |s| / sqrt(I) of the camera's parameters (whole image and
// each region) and of the joints: how far the tests' scores are from
// noise.
double largest_camera_z(const discrepancy_t& s) {
  double largest = 0;
  for (int a = 0; a < 6; ++a) {
    if (s.camera_information[7 * a] > 0)
      largest = std::max(largest, std::abs(s.camera_score[a]) / std::sqrt(s.camera_information[7 * a]));
    for (int r = 0; r < 4; ++r) {
      const double info = s.camera_region_information[6 * r + a];
      if (info > 0) largest = std::max(largest, std::abs(s.camera_region_score[6 * r + a]) / std::sqrt(info));
    }
  }
  return largest;
}

double largest_joint_z(const discrepancy_t& s) {
  double largest = 0;
  for (int j = 0; j < s.num_joints; ++j) {
    if (s.joint_information[j] > 0)
      largest = std::max(largest, std::abs(s.joint_score[j]) / std::sqrt(s.joint_information[j]));
  }
  return largest;
}

// The encoded summary, utime and compute_us aside.
// `labels` without their kinematics (num_axes 0, as from a renderer that
// sends none): the evidence is off.
void strip_kinematics(link_labels_t* labels) {
  labels->num_axes = 0;
  labels->axis_joint.clear();
  labels->axis_multiplier.clear();
  labels->axis_prismatic.clear();
  labels->axis_origin_m.clear();
  labels->axis_direction.clear();
  labels->axis_parent.clear();
}

std::vector<uint8_t> encoded(discrepancy_t s) {
  s.utime = 0;
  s.compute_us = 0;
  std::vector<uint8_t> bytes(static_cast<size_t>(s.getEncodedSize()));
  s.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

// compute_discrepancy shares the naming search's joints and the evidence
// sums' bands among a WorkerPool's threads (discrepancy.worker_threads): the
// summary must be the same to the last bit on 1, 2 or 4 threads, with and
// without a pool, for a nominal frame, an encoder offset the search finds
// and a moved camera.
TEST_F(EvidenceTest, TheSummaryDoesNotDependOnTheWorkerThreads) {
  const JointPositions truth = estimator::test::side_reach_pose();
  const Intrinsics& in = config_->camera.intrinsics;
  const std::string joint = frames_->scene().actuated_joint_names[1];
  JointPositions offset = truth;
  offset[joint] += 10 * kDeg;
  const Eigen::Isometry3d moved_camera = camera() * Eigen::Translation3d(0.03, 0, 0);
  struct Case {
    const char* what;
    JointPositions reported;
    Eigen::Isometry3d seen_from;
  };
  // The last case's labels carry no kinematics: the search stops at once,
  // and the pixel stages (compute_discrepancy's side task) run after it.
  const Case cases[] = {{"nominal", truth, camera()},
                        {"encoder 10 deg off", offset, camera()},
                        {"camera 3 cm off", truth, moved_camera},
                        {"no kinematics", offset, camera()}};
  WorkerPool two(2);
  WorkerPool four(4);
  uint64_t index = 70;
  for (const Case& c : cases) {
    const std::vector<float> seen = frames_->capture(truth, c.seen_from, in, ++index);
    const depth_image_t cam = make_depth_image("cam", in, 1, 1, true, seen);
    Frame model = render_frame(&frames_->renderer(), frames_->scene(), c.reported, camera(), in);
    const bool without_kinematics = std::string(c.what) == "no kinematics";
    if (without_kinematics) strip_kinematics(&model.labels);
    const DiscrepancyFrame alone = compute_discrepancy(cam, model.depth, model.labels, options_of(*config_));
    ASSERT_TRUE(alone.summary.usable) << c.what;
    ASSERT_EQ(alone.summary.evidence_available, !without_kinematics) << c.what;
    // The pixel stages ran: the offset leaves pixels that do not match.
    ASSERT_GT(alone.summary.num_compared, 1000) << c.what;
    if (c.what != std::string("nominal")) {
      EXPECT_GT(alone.summary.num_compared - alone.summary.num_match, 50) << c.what;
    }
    const std::vector<uint8_t> expected = encoded(alone.summary);
    for (WorkerPool* pool : {&two, &four}) {
      const DiscrepancyFrame shared =
          compute_discrepancy(cam, model.depth, model.labels, options_of(*config_), pool);
      EXPECT_TRUE(encoded(shared.summary) == expected) << c.what << ", " << pool->num_threads() << " threads";
      // The images too (the pixel stages write them).
      EXPECT_EQ(cv::countNonZero(shared.pixel_class != alone.pixel_class), 0) << c.what;
      EXPECT_EQ(cv::countNonZero(shared.dis_mm != alone.dis_mm), 0) << c.what;
    }
    if (std::string(c.what) == "encoder 10 deg off") {
      // The search found the offset: the test compares a search that ran.
      double best_gain = 0;
      for (double g : alone.summary.joint_search_gain) best_gain = std::max(best_gain, g);
      EXPECT_GT(best_gain, 20.0);
    }
    if (std::string(c.what) == "camera 3 cm off") {
      EXPECT_GT(alone.summary.camera_fit_pixels, 1000);
      // The search's camera candidate ran (its trials on the workers too).
      EXPECT_EQ(alone.summary.camera_search_axis, 0);
    }
  }
}

// The sampling stride (EvidenceOptions::max_pixels) and the weight the
// sampled pixels keep.
TEST(EvidenceSampling, TheStrideIsTheSmallestThatKeepsToMaxPixels) {
  EXPECT_EQ(evidence_stride(176, 144, 0), 1);
  EXPECT_EQ(evidence_stride(176, 144, 80000), 1);
  EXPECT_EQ(evidence_stride(320, 240, 80000), 1);  // 76 800 pixels
  EXPECT_EQ(evidence_stride(640, 480, 80000), 2);  // 320 x 240 sampled
  EXPECT_EQ(evidence_stride(528, 432, 80000), 2);
  EXPECT_EQ(evidence_stride(1280, 960, 80000), 4);
  EXPECT_EQ(evidence_stride(641, 481, 76800), 3);  // ceil(641/2) * ceil(481/2) = 321 * 241 > 76 800
  // Independent noise: sampling leaves the weight as it was. A 3x3
  // filter's footprint (9 pixels): samples 2 apart share 9/4 of it, 3 apart
  // none.
  EXPECT_DOUBLE_EQ(sampled_pixels_per_sample(1, 2), 1.0);
  EXPECT_DOUBLE_EQ(sampled_pixels_per_sample(9, 1), 9.0);
  EXPECT_DOUBLE_EQ(sampled_pixels_per_sample(9, 2), 2.25);
  EXPECT_DOUBLE_EQ(sampled_pixels_per_sample(9, 3), 1.0);
}

// A frame three times the sim camera's size (528x432, 228 096 pixels),
// sampled with max_pixels 80 000 (every second pixel in u and v), against
// the same frames summed over every pixel:
// - a quarter of the pixels and of the information;
// - under no fault the joints' scores in units of their own standard
//   deviation (z = score / sqrt(information)) vary from frame to frame as
//   the full frame's do, about 1 (measured 0.99 every pixel, 1.03 every
//   2nd): the sampled pixels keep their weights, so the risk's thresholds
//   keep their false-stop rate (weighting them by k^2 = 4 would make it
//   about 4 and fail this); the mean z^2, with the scene's fixed part, is
//   no larger (2.6 every pixel, 1.4 every 2nd);
// - an encoder offset of 10 degrees is still named and sized by the search,
//   and its score stands far above the noise.
TEST_F(EvidenceTest, ASampledLargeFrameKeepsTheFalseStopRateAndFindsAnOffset) {
  const Intrinsics small = config_->camera.intrinsics;
  const Intrinsics in{3 * small.width, 3 * small.height, 3 * small.fx,
                      3 * small.fy,    3 * small.cx + 1, 3 * small.cy + 1};
  DiscrepancyOptions full = options_of(*config_);
  full.evidence.max_pixels = 0;
  DiscrepancyOptions sampled = full;
  sampled.evidence.max_pixels = 80000;
  ASSERT_EQ(evidence_stride(in.width, in.height, sampled.evidence.max_pixels), 2);
  ASSERT_GT(frames_->scene().actuated_joint_names.size(), 3u);
  const JointPositions truth = estimator::test::side_reach_pose();
  const Frame model = render_frame(&frames_->renderer(), frames_->scene(), truth, camera(), in);
  // Per joint, its z over the frames (every pixel, every 2nd pixel).
  std::vector<std::vector<double>> z_full(model.labels.num_joints);
  std::vector<std::vector<double>> z_sampled(model.labels.num_joints);
  for (uint64_t index = 200; index < 212; ++index) {
    const depth_image_t cam =
        make_depth_image("cam", in, 1, 1, true, frames_->capture(truth, camera(), in, index));
    const discrepancy_t f = compute_discrepancy(cam, model.depth, model.labels, full).summary;
    const discrepancy_t s = compute_discrepancy(cam, model.depth, model.labels, sampled).summary;
    ASSERT_TRUE(f.evidence_available && s.evidence_available);
    const double pixel_ratio = static_cast<double>(f.camera_fit_pixels) / s.camera_fit_pixels;
    EXPECT_NEAR(pixel_ratio, 4.0, 0.4) << index;
    for (int j = 0; j < f.num_joints; ++j) {
      if (!(f.joint_information[j] > 0) || !(s.joint_information[j] > 0)) continue;
      EXPECT_NEAR(f.joint_information[j] / s.joint_information[j], 4.0, 0.8) << f.joint_name[j];
      z_full[j].push_back(f.joint_score[j] / std::sqrt(f.joint_information[j]));
      z_sampled[j].push_back(s.joint_score[j] / std::sqrt(s.joint_information[j]));
    }
  }
  // Pooled over the joints: the frame-to-frame variance of z (the noise:
  // what the risk's thresholds are derived from, docs/safety-chain.md
  // "Sequential evidence") and the mean of z^2 (noise and the scene's
  // fixed part).
  const auto spread = [](const std::vector<std::vector<double>>& z, double* mean_z2) {
    double sum_var = 0;
    double sum_z2 = 0;
    int n = 0;
    int joints = 0;
    for (const std::vector<double>& zj : z) {
      if (zj.size() < 2) continue;
      double mean = 0;
      for (double v : zj) mean += v / zj.size();
      double var = 0;
      for (double v : zj) {
        var += (v - mean) * (v - mean) / (zj.size() - 1);
        sum_z2 += v * v;
        ++n;
      }
      sum_var += var;
      ++joints;
    }
    *mean_z2 = n > 0 ? sum_z2 / n : 0;
    return joints > 0 ? sum_var / joints : 0;
  };
  double z2_full = 0;
  double z2_sampled = 0;
  const double var_full = spread(z_full, &z2_full);
  const double var_sampled = spread(z_sampled, &z2_sampled);
  std::cout << "528x432, no fault, joint z over 12 frames: frame-to-frame variance every pixel " << var_full
            << ", every 2nd pixel " << var_sampled << "; mean z^2 " << z2_full << ", " << z2_sampled << "\n";
  EXPECT_GT(var_sampled, 0.3);
  EXPECT_LT(var_sampled, 2.0);
  EXPECT_LT(var_sampled, 1.5 * var_full + 0.1);
  EXPECT_LT(z2_sampled, 1.5 * z2_full + 0.1);

  const std::string joint = frames_->scene().actuated_joint_names[1];
  JointPositions reported = truth;
  reported[joint] += 10 * kDeg;
  const Frame offset_model = render_frame(&frames_->renderer(), frames_->scene(), reported, camera(), in);
  const depth_image_t cam =
      make_depth_image("cam", in, 1, 1, true, frames_->capture(truth, camera(), in, 300));
  const discrepancy_t s = compute_discrepancy(cam, offset_model.depth, offset_model.labels, sampled).summary;
  ASSERT_TRUE(s.evidence_available);
  const auto [best, own] = searched_best_and_own(s, joint);
  ASSERT_GE(own, 0);
  EXPECT_EQ(s.joint_name[best], joint);
  EXPECT_NEAR(s.joint_search_offset[own] / kDeg, -10.0, 1.0);
  const double z_own = std::abs(s.joint_score[own]) / std::sqrt(s.joint_information[own]);
  std::cout << "528x432, " << joint << " 10 deg off, every 2nd pixel: |z| " << z_own << ", search gain "
            << s.joint_search_gain[own] << "\n";
  EXPECT_GT(z_own, 10.0);
}

TEST_F(EvidenceTest, AnEncoderOffsetIsBestExplainedByItsOwnJoint) {
  const JointPositions truth = estimator::test::side_reach_pose();
  uint64_t index = 10;
  for (const std::string& joint : frames_->scene().actuated_joint_names) {
    JointPositions reported = truth;
    reported[joint] += 3 * kDeg;  // the encoder reads 3 degrees more than the arm is
    const discrepancy_t s = evidence_of(frames_, *config_, truth, camera(), reported, camera(), ++index);
    ASSERT_TRUE(s.evidence_available);
    int best = -1;
    double best_chi2 = -1;
    int own = -1;
    for (int j = 0; j < s.num_joints; ++j) {
      const double chi2 =
          s.joint_information[j] > 0 ? s.joint_score[j] * s.joint_score[j] / s.joint_information[j] : 0;
      if (chi2 > best_chi2) {
        best_chi2 = chi2;
        best = j;
      }
      if (s.joint_name[j] == joint) own = j;
    }
    ASSERT_GE(own, 0);
    const double fit_deg = s.joint_score[own] / s.joint_information[own] / kDeg;
    const double sigma_deg = 1 / std::sqrt(s.joint_information[own]) / kDeg;
    std::cout << joint << " +3 deg: best " << s.joint_name[best] << " (chi2 " << best_chi2 << "), own fit "
              << fit_deg << " +- " << sigma_deg << " deg over " << s.joint_fit_pixels[own] << " px\n";
    // The linear fit's limit: a5 turns a cylinder about its own axis; its
    // 3 degrees are best explained by a3 (chi2 37 vs its own). The naming
    // search (next test) names it.
    if (joint != "a5") {
      EXPECT_EQ(s.joint_name[best], joint);
    }
    // Seen minus reported: -3 degrees, roughly (a one-step linear fit).
    EXPECT_LT(fit_deg, -1.0) << joint;
    EXPECT_GT(fit_deg, -6.0) << joint;
  }
}

// The naming search (joint_search.hpp): beyond the linear fit's range too
// (10 degrees), the joint with the largest gain is the one whose encoder is
// off, and its offset is found to within a degree.
TEST_F(EvidenceTest, TheNamingSearchNamesAndSizesAnEncoderOffset) {
  const JointPositions truth = estimator::test::side_reach_pose();
  uint64_t index = 30;
  int named = 0;
  int tried = 0;
  for (const double offset_deg : {3.0, -10.0}) {
    for (const std::string& joint : frames_->scene().actuated_joint_names) {
      JointPositions reported = truth;
      reported[joint] += offset_deg * kDeg;
      const discrepancy_t s = evidence_of(frames_, *config_, truth, camera(), reported, camera(), ++index);
      ASSERT_TRUE(s.evidence_available);
      ASSERT_EQ(s.joint_search_gain.size(), static_cast<size_t>(s.num_joints));
      EXPECT_GT(s.search_points, 100);
      EXPECT_LE(s.search_points, options_of(*config_).evidence.search_max_points);
      const auto [best, own] = searched_best_and_own(s, joint);
      ASSERT_GE(own, 0);
      const double found_deg = s.joint_search_offset[own] / kDeg;
      std::cout << joint << " " << offset_deg << " deg: best " << s.joint_name[best] << " (gain "
                << s.joint_search_gain[best] << "), own " << found_deg << " deg, gain "
                << s.joint_search_gain[own] << "\n";
      // a7 turns the last link, nearly a cylinder about its own axis: a few
      // pixels change, too few to name it.
      if (joint == "a7") continue;
      ++tried;
      named += s.joint_name[best] == joint ? 1 : 0;
      // Seen minus reported.
      EXPECT_NEAR(found_deg, -offset_deg, 1.0) << joint;
      EXPECT_GT(s.joint_search_gain[own], 20.0) << joint;
    }
  }
  EXPECT_EQ(named, tried);
}

// A base or shoulder joint 10 degrees off swings the arm across the
// environment: the static pixels the real arm now hides are explained by
// the joint's searched offset and stay out of the camera fit, so the camera
// is not taken to have moved (before: the camera's test crossed first and
// the stop was called a calibration error).
TEST_F(EvidenceTest, AnArmSwungAcrossTheSceneIsNotTakenForAMovedCamera) {
  const JointPositions truth = estimator::test::side_reach_pose();
  for (const std::string joint : {"a1", "a2"}) {
    JointPositions reported = truth;
    reported[joint] -= 10 * kDeg;
    const discrepancy_t s = evidence_of(frames_, *config_, truth, camera(), reported, camera(), 60);
    ASSERT_TRUE(s.evidence_available);
    const Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> info(s.camera_information);
    const Eigen::Map<const Eigen::Matrix<double, 6, 1>> score(s.camera_score);
    const double camera_chi2 = score.dot(info.ldlt().solve(score));
    int best = 0;
    for (int j = 0; j < s.num_joints; ++j) {
      if (s.joint_search_gain[j] > s.joint_search_gain[best]) best = j;
    }
    std::cout << joint << " -10 deg: camera chi2 (6 dof) " << camera_chi2 << " over " << s.camera_fit_pixels
              << " px, correction " << 100 * s.camera_correction[0] << ", " << 100 * s.camera_correction[1]
              << ", " << 100 * s.camera_correction[2] << " cm; best search " << s.joint_name[best] << " gain "
              << s.joint_search_gain[best] << "\n";
    EXPECT_EQ(s.joint_name[best], joint);
    EXPECT_LT(camera_chi2, 0.05 * s.joint_search_gain[best]) << joint;
    for (int k = 0; k < 3; ++k) EXPECT_LT(std::abs(s.camera_correction[k]), 0.005) << joint << " t" << k;
  }
}

// The camera as a candidate of the naming search (joint_search.hpp): a
// camera moved 2 cm sideways or 1 deg is found on its axis, sized, and
// explains the frame better than any joint, whose offsets only turn the arm
// (a base joint's much as the camera shifts it); an encoder offset is
// explained better by its joint than by any camera move, which would move
// the scene too.
TEST_F(EvidenceTest, TheNamingSearchTellsAMovedCameraFromAJointOffset) {
  const JointPositions q = estimator::test::side_reach_pose();
  const struct {
    int axis;
    double amount;
  } moves[] = {{0, 0.02}, {0, -0.02}, {1, 0.02}, {2, 0.02}, {3, 1 * kDeg}, {4, -1 * kDeg}, {5, 1 * kDeg}};
  uint64_t index = 70;
  for (const auto& move : moves) {
    Eigen::Isometry3d moved = Eigen::Isometry3d::Identity();
    if (move.axis < 3) {
      moved.translation()[move.axis] = move.amount;
    } else {
      moved.linear() =
          Eigen::AngleAxisd(move.amount, Eigen::Vector3d::Unit(move.axis - 3)).toRotationMatrix();
    }
    const discrepancy_t s = evidence_of(frames_, *config_, q, camera() * moved, q, camera(), ++index);
    ASSERT_TRUE(s.evidence_available);
    const auto [best, own] = searched_best_and_own(s, "a1");
    std::cout << "camera axis " << move.axis << " moved " << move.amount << ": search axis "
              << int{s.camera_search_axis} << " " << s.camera_search_offset << " gain "
              << s.camera_search_gain << " over " << s.camera_search_static_points
              << " static points; best joint " << s.joint_name[best] << " gain " << s.joint_search_gain[best]
              << "\n";
    // Measured: gains 13 000-185 000 against the best joint's 340-6 500;
    // sizes within a coarse step (5 mm, 0.5 deg).
    EXPECT_EQ(s.camera_search_axis, move.axis);
    EXPECT_NEAR(s.camera_search_offset, move.amount, move.axis < 3 ? 0.0075 : 0.5 * kDeg) << move.axis;
    EXPECT_GT(s.camera_search_gain, 2 * s.joint_search_gain[best]) << move.axis;
  }
  for (const std::string joint : {"a1", "a2", "a3", "a4"}) {
    for (const double offset_deg : {5.0, -10.0}) {
      JointPositions reported = q;
      reported[joint] += offset_deg * kDeg;
      const discrepancy_t s = evidence_of(frames_, *config_, q, camera(), reported, camera(), ++index);
      ASSERT_TRUE(s.evidence_available);
      const auto [best, own] = searched_best_and_own(s, joint);
      std::cout << joint << " " << offset_deg << " deg: own gain " << s.joint_search_gain[own]
                << ", camera axis " << int{s.camera_search_axis} << " " << s.camera_search_offset << " gain "
                << s.camera_search_gain << "\n";
      // Measured: a1 +5 deg's best camera move (t_x) gains a fifth of a1's,
      // the others none.
      EXPECT_EQ(s.joint_name[best], joint);
      EXPECT_LT(s.camera_search_gain, 0.5 * s.joint_search_gain[own]) << joint << " " << offset_deg;
    }
  }
}

TEST_F(EvidenceTest, ACameraMovedAlongItsOpticalAxisIsFitted) {
  const JointPositions q = estimator::test::reach_pose();
  for (const double dz : {0.02, -0.02}) {
    Eigen::Isometry3d moved = Eigen::Isometry3d::Identity();
    moved.translation().z() = dz;
    // The camera is really 2 cm further forward (back) than reported.
    const discrepancy_t s = evidence_of(frames_, *config_, q, camera() * moved, q, camera(), 50);
    ASSERT_TRUE(s.evidence_available);
    std::cout << "camera moved " << dz << " m: correction";
    for (double c : s.camera_correction) std::cout << " " << c;
    std::cout << " over " << s.camera_fit_pixels << " px, static chi2 " << s.static_chi2 << "\n";
    EXPECT_NEAR(s.camera_correction[2], dz, 0.006);
    EXPECT_GT(s.camera_fit_pixels, 5000);
  }
}

TEST_F(EvidenceTest, NominalFramesFitNothing) {
  const JointPositions q = estimator::test::side_reach_pose();
  const discrepancy_t s = evidence_of(frames_, *config_, q, camera(), q, camera(), 77);
  ASSERT_TRUE(s.evidence_available);
  const Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> info(s.camera_information);
  const Eigen::Map<const Eigen::Matrix<double, 6, 1>> score(s.camera_score);
  const double camera_chi2 = score.dot(info.ldlt().solve(score));
  std::cout << "nominal: camera chi2 (6 dof) " << camera_chi2 << ", correction t_z " << s.camera_correction[2]
            << " m; static chi2 " << s.static_chi2 << " over " << s.camera_fit_pixels << " px; robot chi2 "
            << s.robot_chi2 << " over " << s.robot_fit_pixels << " px\n";
  for (int j = 0; j < s.num_joints; ++j) {
    const double z = s.joint_score[j] / std::sqrt(s.joint_information[j]);
    std::cout << "  " << s.joint_name[j] << ": fit " << s.joint_score[j] / s.joint_information[j] / kDeg
              << " deg, " << z << " sigma\n";
    EXPECT_LT(std::abs(z), 5.0) << s.joint_name[j];
  }
  EXPECT_LT(std::abs(s.camera_correction[2]), 0.005);
  // No joint's offset explains noise: the search's gains stay small.
  for (int j = 0; j < s.num_joints; ++j) {
    std::cout << "  " << s.joint_name[j] << ": search " << s.joint_search_offset[j] / kDeg << " deg, gain "
              << s.joint_search_gain[j] << "\n";
    EXPECT_LT(s.joint_search_gain[j], 20.0) << s.joint_name[j];
  }
  // Per-pixel residuals as noisy as the noise model says: chi2 per pixel near 1.
  EXPECT_LT(s.static_chi2 / s.camera_fit_pixels, 2.0);
  EXPECT_GT(s.static_chi2 / s.camera_fit_pixels, 0.3);
}

// The camera fit by image quadrant (discrepancy_t.camera_region_*): the
// four partition the fit pixels, and their scores and information sum to
// the whole image's; each quadrant of this scene sees static surfaces.
TEST_F(EvidenceTest, TheCameraRegionsPartitionTheCameraFit) {
  const JointPositions q = estimator::test::side_reach_pose();
  const discrepancy_t s = evidence_of(frames_, *config_, q, camera(), q, camera(), 78);
  ASSERT_TRUE(s.evidence_available);
  int pixels = 0;
  for (int r = 0; r < 4; ++r) {
    std::cout << "region " << r << ": " << s.camera_region_fit_pixels[r] << " fit pixels\n";
    EXPECT_GT(s.camera_region_fit_pixels[r], 0) << r;
    pixels += s.camera_region_fit_pixels[r];
  }
  EXPECT_EQ(pixels, s.camera_fit_pixels);
  for (int a = 0; a < 6; ++a) {
    double score = 0;
    double information = 0;
    for (int r = 0; r < 4; ++r) {
      score += s.camera_region_score[6 * r + a];
      information += s.camera_region_information[6 * r + a];
    }
    const double scale = std::sqrt(s.camera_information[7 * a]);
    EXPECT_NEAR(score, s.camera_score[a], 1e-9 * scale + 1e-9) << a;
    EXPECT_NEAR(information, s.camera_information[7 * a], 1e-9 * s.camera_information[7 * a]) << a;
  }
}

// compute_evidence sums the camera fit a row at a time, two parameters at
// a time (Double2): its score and information must be the plain sums over
// the fit's pixels of w J r and w J J^T, J the Jacobian at() gives. With
// no search range (the search then explains no static pixel) the fit's
// pixels are the static ones with both depths, off the silhouettes, whose
// residual is within the naming gate.
TEST_F(EvidenceTest, TheCameraFitIsTheSumOverItsPixels) {
  const JointPositions q = estimator::test::side_reach_pose();
  const Intrinsics& in = config_->camera.intrinsics;
  const depth_image_t cam = make_depth_image("cam", in, 1, 1, true, frames_->capture(q, camera(), in, 79));
  const Frame model = render_frame(&frames_->renderer(), frames_->scene(), q, camera(), in);
  DiscrepancyOptions p = options_of(*config_);
  p.evidence.search_range_rad = 0;
  p.evidence.search_range_m = 0;
  const std::vector<uint8_t> silhouette = silhouette_mask(model.depth, p.silhouette_jump_mm);
  discrepancy_t s{};
  compute_evidence(cam, model.depth, model.labels, silhouette, p.silhouette_jump_mm, p.tolerance.noise,
                   p.evidence, &s);
  ASSERT_TRUE(s.evidence_available);
  for (int j = 0; j < s.num_joints; ++j) ASSERT_EQ(s.joint_search_gain[j], 0.0) << s.joint_name[j];
  const EvidenceJacobian jacobian(model.depth, model.labels, p.silhouette_jump_mm);
  std::vector<double> joints(jacobian.num_joints());
  Eigen::Matrix<double, 6, 1> score = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
  int pixels = 0;
  const double model_var = p.evidence.model_sigma_mm * p.evidence.model_sigma_mm;
  for (int i = 0; i < cam.width * cam.height; ++i) {
    const int t = cam.depth_mm[i];
    const int g = model.depth.depth_mm[i];
    double jc[6];
    bool moved = false;
    int link = -1;
    if (t <= 0 || g <= 0 || silhouette[i] || !jacobian.at(i, jc, joints.data(), &moved, &link) || moved)
      continue;
    const double sigma = p.tolerance.noise.sigma_mm(t);
    const double var = sigma * sigma + model_var;
    if (std::abs(g - t) > p.evidence.naming_gate_sigmas * std::sqrt(var)) continue;
    const double limit = p.evidence.clip_sigmas * std::sqrt(var);
    const double r = std::clamp(static_cast<double>(g - t), -limit, limit);
    const Eigen::Map<const Eigen::Matrix<double, 6, 1>> j(jc);
    score -= j * (r / var);
    information += j * j.transpose() / var;
    ++pixels;
  }
  EXPECT_EQ(s.camera_fit_pixels, pixels);
  ASSERT_GT(pixels, 1000);
  const Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> info(s.camera_information);
  for (int a = 0; a < 6; ++a) {
    EXPECT_NEAR(s.camera_score[a], score[a], 1e-9 * std::sqrt(information(a, a))) << a;
    for (int c = 0; c < 6; ++c) {
      EXPECT_NEAR(info(a, c), information(a, c), 1e-9 * std::sqrt(information(a, a) * information(c, c)))
          << a << ", " << c;
    }
  }
}

// silhouette_step_limit_mm is silhouette_step in whole millimetres, for
// every step of two depths and jumps whole, fractional, tiny, huge and NaN.
TEST(SilhouetteStep, TheIntegerLimitGivesTheSameSteps) {
  for (double jump : {50.0, 50.4, 49.99, 1.0, 0.5, 0.0, -3.0, 1e9, 3e10, std::nan("")}) {
    const int limit = silhouette_step_limit_mm(jump);
    for (int step = 0; step <= 70000; step += (step < 200 ? 1 : 997)) {
      EXPECT_EQ(step > limit, silhouette_step(0, step, jump)) << "jump " << jump << ", step " << step;
    }
  }
}

// A rendered step: columns 0..9 at 1000 mm, 10..19 at 2000 mm (a link
// before a wall), 4 rows; pixel (0, 0) without a surface.
TEST(StepDistance, CountsPixelsToTheNearestFartherSurface) {
  depth_image_t rendered{};
  rendered.width = 20;
  rendered.height = 4;
  rendered.depth_mm.assign(80, 1000);
  for (int v = 0; v < 4; ++v) {
    for (int u = 10; u < 20; ++u) rendered.depth_mm[static_cast<size_t>(v * 20 + u)] = 2000;
  }
  rendered.depth_mm[0] = 0;
  const std::vector<uint8_t> distance = step_distance_px(rendered, 4, 50);
  for (int v = 0; v < 4; ++v) {
    EXPECT_EQ(distance[static_cast<size_t>(v * 20 + 9)], 1);
    EXPECT_EQ(distance[static_cast<size_t>(v * 20 + 7)], 3);
    EXPECT_EQ(distance[static_cast<size_t>(v * 20 + 6)], 4);
    EXPECT_EQ(distance[static_cast<size_t>(v * 20 + 5)], 0) << "beyond max_px";
    EXPECT_EQ(distance[static_cast<size_t>(v * 20 + 10)], 0) << "the far side is no near side";
  }
  EXPECT_EQ(distance[0], 0);
  // A step within the jump is no step.
  EXPECT_EQ(step_distance_px(rendered, 4, 1500)[9], 0);
  const std::vector<uint8_t> band = near_side_of_steps(rendered, 2, 50);
  EXPECT_EQ(band[9], 1);
  EXPECT_EQ(band[8], 1);
  EXPECT_EQ(band[7], 0);
  EXPECT_EQ(std::count(band.begin(), band.end(), 1), 8);
  const std::vector<uint8_t> no_band = near_side_of_steps(rendered, 0, 50);
  EXPECT_EQ(std::count(no_band.begin(), no_band.end(), 1), 0);
}

// near_side_of_steps' one large dilation is step_distance_px's band, on
// random depths with holes, for every band width.
TEST(StepDistance, TheBandIsTheDistanceWithinIt) {
  depth_image_t rendered{};
  rendered.width = 31;
  rendered.height = 23;
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> depth(0, 3000);
  for (int i = 0; i < 31 * 23; ++i) {
    const int d = depth(rng);
    rendered.depth_mm.push_back(static_cast<int16_t>(d < 300 ? 0 : d));
  }
  for (int band = 1; band <= 12; ++band) {
    const std::vector<uint8_t> distance = step_distance_px(rendered, band, 500);
    const std::vector<uint8_t> near = near_side_of_steps(rendered, band, 500);
    ASSERT_EQ(near.size(), distance.size());
    for (size_t i = 0; i < near.size(); ++i)
      ASSERT_EQ(near[i], distance[i] > 0 ? 1 : 0) << band << " px, pixel " << i;
  }
}

TEST(StepDistance, TheAllowanceBandOpensAtItsOwnStep) {
  // A link (label 1) 2 cm before another (label 2): a concave corner under
  // the 50 mm silhouette jump.
  depth_image_t rendered{};
  rendered.width = 20;
  rendered.height = 4;
  rendered.depth_mm.assign(80, 1000);
  link_labels_t labels{};
  labels.num_robot_links = 2;
  labels.num_links = 2;
  labels.link_name = {"near", "far"};
  labels.label.assign(80, 1);
  for (int v = 0; v < 4; ++v) {
    for (int u = 10; u < 20; ++u) {
      rendered.depth_mm[static_cast<size_t>(v * 20 + u)] = 1020;
      labels.label[static_cast<size_t>(v * 20 + u)] = 2;
    }
  }
  EvidenceOptions options;
  options.silhouette_band_px = 2;
  options.silhouette_bias_mm = 3.0;
  const std::vector<float> from_jump = near_step_allowance_mm(rendered, labels, options, 50);
  EXPECT_EQ(std::count(from_jump.begin(), from_jump.end(), 0.0f), 80) << "no step over 50 mm";
  options.silhouette_band_step_mm = 10;
  const std::vector<float> from_step = near_step_allowance_mm(rendered, labels, options, 50);
  for (int v = 0; v < 4; ++v) {
    EXPECT_EQ(from_step[static_cast<size_t>(v * 20 + 9)], 3.0f);
    EXPECT_EQ(from_step[static_cast<size_t>(v * 20 + 8)], 3.0f);
    EXPECT_EQ(from_step[static_cast<size_t>(v * 20 + 7)], 0.0f) << "beyond band_px";
    EXPECT_EQ(from_step[static_cast<size_t>(v * 20 + 10)], 0.0f) << "the far side";
  }
  options.silhouette_band_step_mm = 30;
  const std::vector<float> above = near_step_allowance_mm(rendered, labels, options, 50);
  EXPECT_EQ(std::count(above.begin(), above.end(), 0.0f), 80) << "a 20 mm step under a 30 mm band step";
}

// One row of four surfaces, 10 columns each: the scene at 1000 mm, the
// scene at 1100 mm, an arm link at 1200 mm, the scene at 2000 mm. The
// scene before the farther scene takes no allowance (the profile's
// per-pixel map holds that multipath), the scene before the arm takes
// silhouette_bias_mm, the arm before the scene its link's own.
TEST(StepDistance, TheSceneTakesTheAllowanceOnlyBeforeTheArm) {
  depth_image_t rendered{};
  rendered.width = 40;
  rendered.height = 3;
  link_labels_t labels{};
  labels.num_robot_links = 1;
  labels.num_links = 2;
  labels.link_name = {"link7", "wall"};
  const int16_t scene = link_labels_t::ENVIRONMENT_FIRST;
  const int16_t arm = link_labels_t::ROBOT_FIRST;
  for (int v = 0; v < 3; ++v) {
    for (int u = 0; u < 40; ++u) {
      const int surface = u / 10;
      rendered.depth_mm.push_back(std::array<int, 4>{1000, 1100, 1200, 2000}[static_cast<size_t>(surface)]);
      labels.label.push_back(surface == 2 ? arm : scene);
    }
  }
  EvidenceOptions options;
  options.silhouette_band_px = 2;
  options.silhouette_band_step_mm = 10;
  options.silhouette_bias_mm = 3.0;
  options.silhouette_bias_by_link_mm["link7"] = 1.5;
  const std::vector<float> allowance = near_step_allowance_mm(rendered, labels, options, 50);
  for (int v = 0; v < 3; ++v) {
    const auto at = [&](int u) { return allowance[static_cast<size_t>(v * 40 + u)]; };
    EXPECT_EQ(at(8), 0.0f) << "the scene before the farther scene";
    EXPECT_EQ(at(9), 0.0f) << "the scene before the farther scene";
    EXPECT_EQ(at(18), 3.0f) << "the scene before the arm";
    EXPECT_EQ(at(19), 3.0f) << "the scene before the arm";
    EXPECT_EQ(at(17), 0.0f) << "beyond band_px";
    EXPECT_EQ(at(28), 1.5f) << "the arm before the scene: its own";
    EXPECT_EQ(at(29), 1.5f) << "the arm before the scene: its own";
    EXPECT_EQ(at(30), 0.0f) << "the far side";
  }
  // Without labels every pixel of the band takes silhouette_bias_mm.
  const std::vector<float> unlabelled = near_step_allowance_mm(rendered, link_labels_t{}, options, 50);
  EXPECT_EQ(unlabelled[9], 3.0f);
  EXPECT_EQ(unlabelled[29], 3.0f);
}

TEST_F(EvidenceTest, AStillArmShowsNoJointOffsetFromOneMixedPixel) {
  // The default arm halted where safety_chain_e2e_test's arm once stopped
  // (JOINT_STATE of the run): a pixel of link7 lies beside a scene step of
  // just over 50 mm that reads 50 in whole millimetres. It was left in the
  // evidence, mixed by the camera in most frames (23 mm nearer on average)
  // and with a slope taken across the step; with the arm still, the same
  // pixel in every frame gave a7 a fitted offset of +2.0 deg on average
  // (1.5 sigma of one frame), more than half the 3 deg alternative, so its
  // sequential test crossed and never cleared: a false stop. Without that
  // pixel the mean offset over frames of fresh noise is a fraction of it.
  const JointPositions q = {{"a1", 0.04857777392309953},  {"a2", 0.7856848015609976},
                            {"a3", -0.23973305377483156}, {"a4", 0.8560761415519088},
                            {"a5", -0.11736808132312533}, {"a6", 0.8071334516189423},
                            {"a7", 0.28050489318915417}};
  const int frames = 30;
  double sum_offset_rad = 0;
  double information = 0;
  for (int k = 0; k < frames; ++k) {
    const discrepancy_t s = evidence_of(frames_, *config_, q, camera(), q, camera(), 500 + k);
    ASSERT_TRUE(s.evidence_available);
    const auto at = std::find(s.joint_name.begin(), s.joint_name.end(), "a7");
    ASSERT_NE(at, s.joint_name.end());
    const size_t j = static_cast<size_t>(at - s.joint_name.begin());
    ASSERT_GT(s.joint_information[j], 0);
    sum_offset_rad += s.joint_score[j] / s.joint_information[j];
    information = s.joint_information[j];
  }
  const double mean_deg = sum_offset_rad / frames / kDeg;
  std::cout << "still arm: a7 mean fitted offset " << mean_deg << " deg, one frame's sigma "
            << 1 / std::sqrt(information) / kDeg << " deg\n";
  // Below half the sequential test's alternative (risk.evidence.
  // joint_offset_deg 3): a bias that size never accumulates
  // (docs/safety-chain.md, "A systematic model bias below delta/2 never
  // alarms"); the mean's own noise is sigma / sqrt(30), about 0.25 deg.
  EXPECT_LT(std::abs(mean_deg), 0.5 * config_->risk.evidence_joint_offset_rad / kDeg);
}

TEST(Evidence, LabelsWithoutKinematicsGiveNoEvidence) {
  depth_image_t d =
      make_depth_image("cam", Intrinsics{4, 3, 10, 10, 2, 1}, 1, 1, true, std::vector<float>(12, 1.0f));
  link_labels_t labels = make_link_labels(d, 1, {"a", "floor"}, std::vector<int16_t>(12, kLabelRobotFirst));
  const DiscrepancyFrame f = compute_discrepancy(d, d, labels, DiscrepancyOptions{});
  EXPECT_TRUE(f.summary.usable);
  EXPECT_FALSE(f.summary.evidence_available);
  EXPECT_EQ(f.summary.num_joints, 0);
  EXPECT_EQ(f.summary.num_link_bias, 0);
  EXPECT_EQ(check_discrepancy(f.summary), "");
}

}  // namespace
}  // namespace tofguard::discrepancy

namespace tofguard::discrepancy {
namespace {

// The composite null (EvidenceOptions::static_bias_mm): a common-mode
// distance error of 12 mm reads as a camera pose error far beyond noise with
// the plain scores; with a bound of 13 mm every score the tests read is
// within noise (shrunk scores are never larger than the noise part), and a
// camera 4 cm off along its axis still scores far beyond it.
TEST_F(EvidenceTest, AStaticErrorWithinItsBoundScoresAsNoise) {
  const JointPositions q = estimator::test::reach_pose();
  const discrepancy_t plain =
      evidence_with_static_error(frames_, *config_, q, camera(), camera(), 91, 0.012, 0);
  const discrepancy_t bounded =
      evidence_with_static_error(frames_, *config_, q, camera(), camera(), 91, 0.012, 13.0);
  std::cout << "12 mm static error: largest camera z " << largest_camera_z(plain) << " plain, "
            << largest_camera_z(bounded) << " bounded by 13 mm; joints " << largest_joint_z(plain) << ", "
            << largest_joint_z(bounded) << "\n";
  EXPECT_GT(largest_camera_z(plain), 30.0);
  EXPECT_LT(largest_camera_z(bounded), 5.0);
  EXPECT_LT(largest_joint_z(bounded), 5.0);
  // The fitted correction stays the plain fit's: what the pose looks like.
  EXPECT_EQ(plain.camera_correction[2], bounded.camera_correction[2]);
  // The common distance offset (discrepancy_t.distance_offset_*): 12 mm in
  // Z is 12 / f along the rays (f 0.89..1 over this image), and the
  // allowance does not touch it.
  const double offset_mm = bounded.distance_offset_score / bounded.distance_offset_information;
  std::cout << "12 mm in Z: common distance offset " << offset_mm << " mm\n";
  EXPECT_GT(offset_mm, 12.0);
  EXPECT_LT(offset_mm, 13.5);
  EXPECT_EQ(plain.distance_offset_score, bounded.distance_offset_score);

  Eigen::Isometry3d moved = Eigen::Isometry3d::Identity();
  moved.translation().z() = 0.04;
  const discrepancy_t fault =
      evidence_with_static_error(frames_, *config_, q, camera() * moved, camera(), 91, 0.012, 13.0);
  const double z = fault.camera_score[2] / std::sqrt(fault.camera_information[14]);
  std::cout << "camera 4 cm off with the 13 mm bound: t_z z " << z << "\n";
  EXPECT_GT(std::abs(z), 30.0);
}

// The silhouette allowance (EvidenceOptions::silhouette_bias_mm) reaches a
// score only through the pixels on the near side of a step: with the same
// bias it bounds each joint's score by no more than an allowance of every
// pixel does (less for a large link that reaches beyond the band), and by
// more the wider its band.
TEST_F(EvidenceTest, TheSilhouetteAllowanceBoundsOnlyThePixelsNearSteps) {
  const JointPositions q = estimator::test::reach_pose();
  const Intrinsics& in = config_->camera.intrinsics;
  const depth_image_t seen = make_depth_image("cam", in, 1, 1, true, frames_->capture(q, camera(), in, 93));
  const Frame model = render_frame(&frames_->renderer(), frames_->scene(), q, camera(), in);
  auto bounds_with = [&](double static_bias_mm, int band_px, double silhouette_bias_mm) {
    DiscrepancyOptions options = options_of(*config_);
    options.evidence.static_bias_mm = static_bias_mm;
    options.evidence.silhouette_band_px = band_px;
    options.evidence.silhouette_bias_mm = silhouette_bias_mm;
    return compute_discrepancy(seen, model.depth, model.labels, options).summary;
  };
  const discrepancy_t everywhere = bounds_with(2.0, 0, 0);
  const discrepancy_t narrow = bounds_with(0, 2, 2.0);
  const discrepancy_t wide = bounds_with(0, 8, 2.0);
  const discrepancy_t none = bounds_with(0, 0, 2.0);
  int joints_seen = 0;
  int joints_partly_near = 0;
  for (size_t j = 0; j < everywhere.joint_static_bound.size(); ++j) {
    if (!(everywhere.joint_information[j] > 0)) continue;
    ++joints_seen;
    EXPECT_GT(narrow.joint_static_bound[j], 0) << everywhere.joint_name[j];
    EXPECT_LT(narrow.joint_static_bound[j], wide.joint_static_bound[j]) << everywhere.joint_name[j];
    // At 176x144 a link lies mostly within 8 px of its silhouette.
    EXPECT_LE(wide.joint_static_bound[j], everywhere.joint_static_bound[j] * (1 + 1e-12))
        << everywhere.joint_name[j];
    std::cout << everywhere.joint_name[j] << ": the band's share of the bound, 2 px "
              << narrow.joint_static_bound[j] / everywhere.joint_static_bound[j] << ", 8 px "
              << wide.joint_static_bound[j] / everywhere.joint_static_bound[j] << "\n";
    if (narrow.joint_static_bound[j] < 0.9 * everywhere.joint_static_bound[j]) ++joints_partly_near;
    EXPECT_EQ(none.joint_static_bound[j], 0) << everywhere.joint_name[j];
  }
  EXPECT_GE(joints_seen, 5);
  EXPECT_GE(joints_partly_near, 2) << "links reach beyond a 2 px band";
  for (int a = 0; a < 6; ++a) {
    EXPECT_GT(wide.camera_static_bound[a], 0);
    EXPECT_LT(wide.camera_static_bound[a], everywhere.camera_static_bound[a]);
  }

  // A link's own allowance (silhouette_bias_by_link_mm) serves its pixels:
  // every link but the last at 0, the last's at 2 mm, bounds only the
  // joints that move the last link, and those by its share of the 2 mm
  // allowance of every link.
  DiscrepancyOptions own = options_of(*config_);
  own.evidence.silhouette_band_px = 8;
  own.evidence.silhouette_bias_mm = 2.0;
  for (size_t k = 0; k + 1 < static_cast<size_t>(model.labels.num_robot_links); ++k)
    own.evidence.silhouette_bias_by_link_mm[model.labels.link_name[k]] = 0.0;
  const std::string last = model.labels.link_name[static_cast<size_t>(model.labels.num_robot_links - 1)];
  own.evidence.silhouette_bias_by_link_mm[last] = 2.0;
  const discrepancy_t by_link = compute_discrepancy(seen, model.depth, model.labels, own).summary;
  int joints_bounded = 0;
  for (size_t j = 0; j < wide.joint_static_bound.size(); ++j) {
    EXPECT_LE(by_link.joint_static_bound[j], wide.joint_static_bound[j] * (1 + 1e-12)) << wide.joint_name[j];
    if (by_link.joint_static_bound[j] > 0) ++joints_bounded;
  }
  EXPECT_GE(joints_bounded, 1) << last << " is seen";
  EXPECT_LT(by_link.joint_static_bound[0], wide.joint_static_bound[0]) << "the first joint moves more links";
  const std::vector<float> allowance = near_step_allowance_mm(model.depth, model.labels, own.evidence,
                                                              config_->discrepancy.silhouette_jump_mm);
  for (size_t i = 0; i < allowance.size(); ++i) {
    const int link =
        link_of_label(model.labels.label[i], model.labels.num_robot_links, model.labels.num_links);
    if (allowance[i] == 0.0f) continue;
    ASSERT_TRUE(link < 0 || link >= model.labels.num_robot_links - 1) << "pixel " << i << " of link " << link;
    ASSERT_EQ(allowance[i], 2.0f);
  }
}

}  // namespace
}  // namespace tofguard::discrepancy
