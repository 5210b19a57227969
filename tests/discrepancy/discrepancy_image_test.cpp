// The discrepancy image on synthetic frames whose every count is known.
#include <gtest/gtest.h>

#include <cstdlib>
#include <memory>
#include <random>
#include <vector>

#include <opencv2/core.hpp>

#include "sample_messages.hpp"
#include "synthetic_frames.hpp"
#include "tofguard/common/worker_pool.hpp"
#include "tofguard/discrepancy/discrepancy_image.hpp"

namespace tofguard::test {
namespace {

using discrepancy::compute_discrepancy;
using discrepancy::DiscrepancyFrame;
using discrepancy::DiscrepancyOptions;

// OpenCV's own parallel loops (the blob stage's morphology and connected
// components) run on the calling thread in this test: OpenCV otherwise
// starts TBB threads, whose synchronisation TSan cannot see (TBB is not
// instrumented), and reports its scratch buffers, allocated on a TBB thread
// and freed on the caller's, as races. Under TSan (scripts/sanitize) every
// thread is then tofguard's own (the WorkerPool's).
const bool kOpenCvOnTheCallersThread = [] {
  cv::setNumThreads(0);
  return true;
}();

// The simulated camera's noise, 4 sigma + 15 mm, 3x3 opening, 0.2 m.
DiscrepancyOptions sim_options() { return DiscrepancyOptions{}; }

DiscrepancyFrame compare(const SyntheticImage& model, const std::vector<int16_t>& camera_depth,
                         const DiscrepancyOptions& options = sim_options()) {
  link_labels_t labels = labels_frame(model.label, 7);
  add_pixel_cover(&labels, model.depth_mm);
  return compute_discrepancy(depth_frame(camera_depth, 7), depth_frame(model.depth_mm, 7), labels, options);
}

constexpr int kPixels = kWidth * kHeight;

TEST(Tolerance, GrowsWithTheSquareOfTheDepth) {
  const discrepancy::Tolerance t;
  // 4 * (4 + 1.2 * d^2) + 15
  EXPECT_DOUBLE_EQ(t.at(500), 4 * (4 + 1.2 * 0.25) + 15);
  EXPECT_DOUBLE_EQ(t.at(5000), 4 * (4 + 1.2 * 25) + 15);
}

TEST(Discrepancy, IdenticalFramesMatchEverywhere) {
  const SyntheticImage model = draw(default_arm());
  const DiscrepancyFrame f = compare(model, model.depth_mm);
  const discrepancy_t& s = f.summary;
  ASSERT_TRUE(s.usable) << s.unusable_reason;
  EXPECT_EQ(s.seq, 7);
  EXPECT_EQ(s.num_pixels, kPixels);
  EXPECT_EQ(s.num_compared, kPixels);
  EXPECT_EQ(s.num_match, kPixels);
  EXPECT_EQ(s.sum_abs_dis_mm, 0);
  EXPECT_EQ(s.largest_blob_pixels, 0);
  EXPECT_EQ(s.near_arm_pixels, 0);
  EXPECT_FLOAT_EQ(s.near_arm_min_distance_m, -1);
  ASSERT_EQ(s.num_links, 4);
  EXPECT_EQ(s.link_name[2], "link2");
  // base_link 20x40, link1 20x40, link2 40x20 pixels; the floor the rest.
  EXPECT_EQ(s.link_compared[0], 800);
  EXPECT_EQ(s.link_compared[1], 800);
  EXPECT_EQ(s.link_compared[2], 800);
  EXPECT_EQ(s.link_compared[3], kPixels - 2400);
  EXPECT_EQ(s.link_match[2], 800);
}

TEST(Discrepancy, NoiseOnlyFramesMatchAndScoreAsNoise) {
  const SyntheticImage model = draw(default_arm());
  for (uint32_t seed = 1; seed <= 5; ++seed) {
    const discrepancy_t s = compare(model, with_noise(model.depth_mm, seed)).summary;
    ASSERT_TRUE(s.usable);
    EXPECT_EQ(s.num_match, kPixels) << "seed " << seed;
    EXPECT_EQ(s.largest_blob_pixels, 0);
    EXPECT_EQ(s.near_arm_pixels, 0);
    // Most pixels see the floor at 2 m: sigma = 8.8 mm, median |noise| =
    // 0.674 sigma = 5.9 mm.
    EXPECT_NEAR(s.median_abs_dis_mm, 5.9, 1.0);
    EXPECT_NEAR(s.p95_abs_dis_mm, 1.96 * 8.8, 2.0);
    EXPECT_NEAR(s.environment_median_dis_mm, 0, 1.0);
  }
}

TEST(Discrepancy, ShiftedLinkIsMissingWhereModelledAndUnexpectedBesideIt) {
  const SyntheticImage model = draw(default_arm());
  const SyntheticImage seen = draw(default_arm(/*link2_shift_px=*/10));
  const DiscrepancyFrame f = compare(model, seen.depth_mm);
  const discrepancy_t& s = f.summary;
  ASSERT_TRUE(s.usable);
  // u 60..69 x v 60..79: the model's link2, the camera sees the floor.
  EXPECT_EQ(s.num_robot_missing, 200);
  // u 100..109 x v 60..79: the camera sees the arm where the model has floor.
  EXPECT_EQ(s.num_unexpected_surface, 200);
  EXPECT_EQ(s.num_occluded, 0);
  EXPECT_EQ(s.num_match, kPixels - 400);
  EXPECT_EQ(s.link_farther[2], 200);
  EXPECT_EQ(s.link_match[2], 600);
  EXPECT_EQ(s.link_farther[0] + s.link_farther[1], 0);
  EXPECT_EQ(s.link_nearer[3], 200);
  EXPECT_FLOAT_EQ(s.link_median_dis_mm[2], 0);
  // The seed's score: 400 pixels 500 mm off.
  EXPECT_DOUBLE_EQ(s.sum_abs_dis_mm, 400 * 500.0);
  EXPECT_DOUBLE_EQ(s.normalized_sum_abs_dis, 400 * 500.0 / (kPixels * 8000.0));
  EXPECT_NEAR(s.mismatch_fraction, 400.0 / kPixels, 1e-6);
  // Blobs are of farther mismatches only: the 10x20 where link2 is missing.
  EXPECT_EQ(s.largest_blob_pixels, 200);
  // The unexpected surface lies beside the arm: all of it near the arm; the
  // closest pixel's centre is one column (1.5 m / 200 px = 7.5 mm) from the
  // nearest sphere's centre, whose radius is half a pixel's diagonal.
  EXPECT_TRUE(s.field_available);
  EXPECT_EQ(s.near_arm_pixels, 200);
  EXPECT_NEAR(s.near_arm_area_m2, 200 * (1.5 / 200) * (1.5 / 200), 1e-7);
  EXPECT_NEAR(s.near_arm_min_distance_m, 0.0075 * (1 - std::sqrt(0.5)), 1e-5);
  EXPECT_EQ(f.pixel_class(70, 65), discrepancy_t::PIXEL_ROBOT_MISSING);
  EXPECT_EQ(f.pixel_class(70, 105), discrepancy_t::PIXEL_UNEXPECTED_SURFACE);
  EXPECT_EQ(f.dis_mm(70, 65), -500);
  EXPECT_EQ(f.dis_mm(70, 105), 500);
}

// compute_discrepancy shares its work among a WorkerPool's threads (the
// naming search's trials, the evidence's bands, and the pixel stages beside
// the trials): whatever the threads, the same summary and images. Also run
// under TSan (scripts/sanitize): the pixel stages and the search write the
// same summary from two threads.
TEST(Discrepancy, TheSummaryAndImagesDoNotDependOnTheWorkerThreads) {
  const SyntheticImage model = draw(default_arm());
  link_labels_t labels = labels_frame(model.label, 7);
  add_pixel_cover(&labels, model.depth_mm);
  add_default_arm_kinematics(&labels);
  // link2 seen 4 px to the right of where it is modelled, and a box in
  // front of the arm: every stage has something to find.
  std::vector<Box> scene = default_arm(4);
  scene.push_back({30, 110, 50, 130, 1400, 0});
  const depth_image_t camera = depth_frame(with_noise(draw(scene).depth_mm, 5), 7);
  const depth_image_t rendered = depth_frame(model.depth_mm, 7);
  const DiscrepancyFrame alone = compute_discrepancy(camera, rendered, labels, sim_options());
  const discrepancy_t& a = alone.summary;
  ASSERT_TRUE(a.usable && a.evidence_available);
  ASSERT_GT(a.search_points, 500);
  ASSERT_EQ(a.num_robot_missing, 4 * 20);  // link2 (20 rows) uncovered where modelled
  ASSERT_EQ(a.num_occluded, 200);
  for (int threads : {2, 4}) {
    WorkerPool pool(threads);
    for (int call = 0; call < 5; ++call) {
      const DiscrepancyFrame shared = compute_discrepancy(camera, rendered, labels, sim_options(), &pool);
      EXPECT_TRUE(encoded(shared.summary) == encoded(a)) << threads << " threads, call " << call;
      EXPECT_EQ(cv::countNonZero(shared.pixel_class != alone.pixel_class), 0) << threads << " threads";
      EXPECT_EQ(cv::countNonZero(shared.dis_mm != alone.dis_mm), 0) << threads << " threads";
    }
  }
}

TEST(Discrepancy, ObjectInFrontOfTheArmIsOccludedAndNearTheArm) {
  const SyntheticImage model = draw(default_arm());
  std::vector<Box> scene = default_arm();
  // 20x20 box 0.1 m in front of base_link, half over it, half over floor.
  scene.push_back({30, 110, 50, 130, 1400, 0});
  const discrepancy_t s = compare(model, with_noise(draw(scene).depth_mm, 3)).summary;
  EXPECT_EQ(s.num_occluded, 200);
  EXPECT_EQ(s.num_unexpected_surface, 200);
  EXPECT_EQ(s.num_robot_missing, 0);
  EXPECT_EQ(s.link_nearer[0], 200);
  // Nearer surfaces make no blob: they are judged by their distance.
  EXPECT_EQ(s.largest_blob_pixels, 0);
  // The half that hides base_link is at the arm (what cannot be seen is
  // occupied); the other half is 0.1 m in front of the arm's plane and at
  // most 10 px (7 cm) beside it.
  EXPECT_EQ(s.near_arm_pixels, 400);
  EXPECT_FLOAT_EQ(s.near_arm_min_distance_m, 0);
  const double pixel_m2 = (1.4 / 200) * (1.4 / 200);
  ASSERT_EQ(s.num_field_bins, 150);  // DiscrepancyOptions' default: 1.5 m in 1 cm bins
  EXPECT_NEAR(s.unexplained_area_within_m2[0], 200 * pixel_m2, 1e-6);
  // The other half: 9.5-10.6 cm from the arm's cover (noise: sigma 6.4 mm
  // at 1.4 m), none within 6 cm, all within 13 cm.
  EXPECT_NEAR(s.unexplained_area_within_m2[5], 200 * pixel_m2, 1e-5);
  EXPECT_NEAR(s.unexplained_area_within_m2[12], 400 * pixel_m2, 1e-5);
}

TEST(Discrepancy, ObjectFarFromTheArmIsNotNearTheArm) {
  const SyntheticImage model = draw(default_arm());
  std::vector<Box> scene = default_arm();
  scene.push_back({140, 10, 160, 30, 1900, 0});  // 0.5 m from the arm
  const discrepancy_t s = compare(model, draw(scene).depth_mm).summary;
  EXPECT_EQ(s.num_unexpected_surface, 400);
  EXPECT_EQ(s.largest_blob_pixels, 0);
  EXPECT_EQ(s.near_arm_pixels, 0);
  EXPECT_FLOAT_EQ(s.near_arm_min_distance_m, -1);
  // In 3-D: its nearest corner (u 140, v 29 at 1.9 m) is 0.65 m from
  // link2's corner (u 99, v 60 at 1.5 m), its farthest (u 159, v 10) 0.87 m.
  const double pixel_m2 = (1.9 / 200) * (1.9 / 200);
  EXPECT_FLOAT_EQ(s.unexplained_area_within_m2[62], 0);  // within 0.63 m
  EXPECT_GT(s.unexplained_area_within_m2[65], 0);        // within 0.66 m
  EXPECT_LT(s.unexplained_area_within_m2[85], 400 * pixel_m2 - 1e-6);
  EXPECT_NEAR(s.unexplained_area_within_m2[87], 400 * pixel_m2, 1e-6);  // within 0.88 m
  EXPECT_NEAR(s.unexplained_area_within_m2[149], 400 * pixel_m2, 1e-6);
}

// A box 0.5 m in front of the arm's plane, beside it in the image, with
// its left edge mixed with the floor behind it (a ToF camera's flying
// pixels: 1500 mm, half way between the box at 1000 and the floor at 2000).
// Back-projected at their own depth they would float in the arm's plane
// 0.23 m from link2; they are placed at the box's depth instead, so that
// nothing is nearer the arm than the box itself (0.52 m).
TEST(Discrepancy, MixedPixelsAtAnObjectsEdgeStandAtTheObject) {
  const SyntheticImage model = draw(default_arm());
  std::vector<Box> scene = default_arm();
  scene.push_back({130, 60, 150, 80, 1000, 0});
  SyntheticImage seen = draw(scene);
  for (int v = 60; v < 80; ++v) seen.depth_mm[v * kWidth + 129] = 1500;
  const discrepancy_t s = compare(model, seen.depth_mm).summary;
  EXPECT_EQ(s.num_unexpected_surface, 420);
  EXPECT_EQ(s.near_arm_pixels, 0);
  // The box's nearest point (u 130, v 79 at 1.0 m) is 0.52 m from link2's
  // nearest (u 99, v 60..79 at 1.5 m): nothing within 0.45 m.
  EXPECT_FLOAT_EQ(s.unexplained_area_within_m2[44], 0);
  EXPECT_GT(s.unexplained_area_within_m2[60], 0);
  // Without the neighbours' evidence (the same pixels, nothing beside
  // them nearer): they stay where they are, in the arm's plane 0.23 m away.
  SyntheticImage alone = draw(default_arm());
  for (int v = 60; v < 80; ++v) {
    for (int u = 127; u < 130; ++u) alone.depth_mm[v * kWidth + u] = 1500;
  }
  const discrepancy_t t = compare(model, alone.depth_mm).summary;
  EXPECT_EQ(t.num_unexpected_surface, 60);
  EXPECT_GT(t.unexplained_area_within_m2[25], 0);  // within 0.26 m
}

// A person 0.3 m behind link2, beside it in the image, with the link's edge
// mixed with the person (1650 mm, between the link at 1500 and the person at
// 1800). The mixed pixels' unexplained part is the person, not the link:
// they are placed at the person's depth, 0.3 m from the arm, not on it.
TEST(Discrepancy, MixedPixelsBetweenTheArmAndSomethingBehindItStandBehind) {
  const SyntheticImage model = draw(default_arm());
  std::vector<Box> scene = default_arm();
  scene.push_back({100, 55, 130, 85, 1800, 0});
  SyntheticImage seen = draw(scene);
  for (int v = 60; v < 80; ++v) seen.depth_mm[v * kWidth + 100] = 1650;
  const discrepancy_t s = compare(model, seen.depth_mm).summary;
  EXPECT_EQ(s.num_unexpected_surface, 900);
  EXPECT_EQ(s.near_arm_pixels, 0);
  EXPECT_FLOAT_EQ(s.unexplained_area_within_m2[25], 0);  // nothing within 0.26 m
  EXPECT_GT(s.unexplained_area_within_m2[40], 0);        // the person, 0.3 m behind
}

// The arm's own edge seen two pixels wider than modelled (u 100-101 at
// link2's depth, where the model has the floor), with a cart passing 0.3 m
// behind the arm right beside it (1800 mm). Alone, the 2-pixel sliver goes
// with the opening; touching the cart it would survive a plain opening and
// stand 1 cm from the arm. The opening on surfaces (silhouette_jump_mm 50,
// as config/sim.yaml) keeps only the cart: nothing near the arm.
TEST(Discrepancy, TheArmsOwnEdgeBesideAPasserBehindItIsNotAnObject) {
  const SyntheticImage model = draw(default_arm());
  std::vector<Box> scene = default_arm();
  scene.push_back({100, 60, 102, 80, kArmMm, 0});
  scene.push_back({102, 50, 130, 90, 1800, 0});
  const std::vector<int16_t> seen = draw(scene).depth_mm;
  DiscrepancyOptions options = sim_options();
  options.silhouette_jump_mm = 50;
  const discrepancy_t s = compare(model, seen, options).summary;
  EXPECT_EQ(s.near_arm_pixels, 0);
  EXPECT_FLOAT_EQ(s.unexplained_area_within_m2[25], 0);  // nothing within 0.26 m
  EXPECT_GT(s.unexplained_area_within_m2[40], 0);        // the cart, 0.3 m behind
  // Without the depth condition (silhouette_jump_mm 0: the plain opening)
  // the sliver stays beside the arm.
  options.silhouette_jump_mm = 0;
  EXPECT_GT(compare(model, seen, options).summary.near_arm_pixels, 0);
}

TEST(Discrepancy, ThinSilhouetteSliversAreNotBlobs) {
  const SyntheticImage model = draw(default_arm());
  // The camera's link2 one pixel wider: a one-pixel column of nearer
  // surface beside the model.
  std::vector<Box> scene = default_arm();
  scene.push_back({100, 60, 101, 80, kArmMm, 3});
  const discrepancy_t s = compare(model, draw(scene).depth_mm).summary;
  EXPECT_EQ(s.num_unexpected_surface, 20);
  EXPECT_EQ(s.near_arm_pixels, 0);
  EXPECT_FLOAT_EQ(s.unexplained_area_within_m2.back(), 0);
  // The model's link2 one pixel wider than the camera's: a one-pixel column
  // where the camera sees farther.
  std::vector<Box> wider = default_arm();
  wider.push_back({100, 60, 101, 80, kArmMm, 3});
  const SyntheticImage wide_model = draw(wider);
  const discrepancy_t narrower = compare(wide_model, model.depth_mm).summary;
  EXPECT_EQ(narrower.num_robot_missing, 20);
  EXPECT_EQ(narrower.largest_blob_pixels, 0);
  // Without the opening the slivers count.
  DiscrepancyOptions raw = sim_options();
  raw.opening_radius_px = 0;
  EXPECT_EQ(compare(wide_model, model.depth_mm, raw).summary.largest_blob_pixels, 20);
  EXPECT_EQ(compare(model, draw(scene).depth_mm, raw).summary.near_arm_pixels, 20);
}

TEST(Discrepancy, ConstantOffsetScoresAsTheSeedDefines) {
  const SyntheticImage model = draw(default_arm());
  std::vector<int16_t> camera = model.depth_mm;
  for (int16_t& d : camera) d = static_cast<int16_t>(d - 100);  // 100 mm nearer
  const discrepancy_t s = compare(model, camera).summary;
  EXPECT_DOUBLE_EQ(s.sum_abs_dis_mm, 100.0 * kPixels);
  EXPECT_DOUBLE_EQ(s.normalized_sum_abs_dis, 100.0 / 8000.0);
  EXPECT_FLOAT_EQ(s.median_abs_dis_mm, 100);
  EXPECT_FLOAT_EQ(s.robot_median_dis_mm, 100);
  EXPECT_FLOAT_EQ(s.environment_median_dis_mm, 100);
  EXPECT_EQ(s.num_occluded, 2400);
  EXPECT_EQ(s.num_unexpected_surface, kPixels - 2400);
  // Everything seen nearer: no blob of farther mismatches; every pixel is
  // an unexplained nearer surface, the arm's own (2400 px) at the arm.
  EXPECT_EQ(s.largest_blob_pixels, 0);
  EXPECT_EQ(s.near_arm_min_distance_m, 0);
  // 100 mm nearer everywhere, the same the other way round: a blob of them all.
  std::vector<int16_t> farther = model.depth_mm;
  for (int16_t& d : farther) d = static_cast<int16_t>(d + 100);
  EXPECT_EQ(compare(model, farther).summary.largest_blob_pixels, kPixels);
}

TEST(Discrepancy, InvalidPixelsAreCountedAndNotCompared) {
  const SyntheticImage model = draw(default_arm());
  std::vector<int16_t> camera = model.depth_mm;
  for (int v = 100; v < 110; ++v) {
    for (int u = 40; u < 50; ++u) camera[v * kWidth + u] = 0;  // on base_link
  }
  camera[0] = -1;
  const discrepancy_t s = compare(model, camera).summary;
  EXPECT_EQ(s.num_invalid, 101);
  EXPECT_NEAR(s.invalid_fraction, 101.0 / kPixels, 1e-7);
  EXPECT_EQ(s.num_compared, kPixels - 101);
  EXPECT_EQ(s.link_invalid[0], 100);
  EXPECT_EQ(s.link_compared[0], 700);
  EXPECT_EQ(s.num_match + s.num_invalid, kPixels);
}

TEST(Discrepancy, NothingModelledButSomethingSeenIsUnexpectedNotCompared) {
  SyntheticImage model = draw(default_arm());
  for (int i = 0; i < kWidth * 10; ++i) {
    model.depth_mm[i] = 0;
    model.label[i] = link_labels_t::NOTHING;
  }
  const discrepancy_t s = compare(model, draw(default_arm()).depth_mm).summary;
  EXPECT_EQ(s.num_unexpected_surface, kWidth * 10);
  EXPECT_EQ(s.num_compared, kPixels - kWidth * 10);
  // Far from the arm, and not modelled: neither near the arm nor a blob.
  EXPECT_EQ(s.near_arm_pixels, 0);
  EXPECT_EQ(s.largest_blob_pixels, 0);
}

TEST(Discrepancy, UnusableLabelsMakeAnUnusableFrame) {
  const SyntheticImage model = draw(default_arm());
  const depth_image_t camera = depth_frame(model.depth_mm, 9);
  const discrepancy_t s =
      compute_discrepancy(camera, depth_image_t{}, unusable_labels(9, "joint 'a3' missing"), sim_options())
          .summary;
  EXPECT_FALSE(s.usable);
  EXPECT_EQ(s.unusable_kind, discrepancy_t::UNUSABLE_RENDERER);
  EXPECT_EQ(s.unusable_reason, "renderer: joint 'a3' missing");
  EXPECT_EQ(s.seq, 9);
  EXPECT_EQ(s.utime, camera.utime);
  EXPECT_TRUE(s.calibrated);
}

TEST(Discrepancy, FramesThatDoNotFitAreUnusableAndSayWhy) {
  const SyntheticImage model = draw(default_arm());
  const depth_image_t camera = depth_frame(model.depth_mm, 4);
  const link_labels_t labels = labels_frame(model.label, 4);

  const SyntheticImage small = draw({}, 88, 72);
  auto s = compute_discrepancy(camera, depth_frame(small.depth_mm, 4, 88, 72), labels, sim_options()).summary;
  EXPECT_FALSE(s.usable);
  EXPECT_EQ(s.unusable_kind, discrepancy_t::UNUSABLE_MISMATCHED);
  EXPECT_EQ(s.unusable_reason, "rendered frame is 88x72, camera frame 176x144");

  depth_image_t other_focal = depth_frame(model.depth_mm, 4);
  other_focal.fx = 210;
  s = compute_discrepancy(camera, other_focal, labels, sim_options()).summary;
  EXPECT_FALSE(s.usable);
  EXPECT_NE(s.unusable_reason.find("intrinsics"), std::string::npos) << s.unusable_reason;

  link_labels_t bad_label = labels;
  bad_label.label[kWidth + 3] = 500;
  s = compute_discrepancy(camera, depth_frame(model.depth_mm, 4), bad_label, sim_options()).summary;
  EXPECT_FALSE(s.usable);
  EXPECT_EQ(s.unusable_reason, "label[179]: expected 0, 1..3 or 1000..1000, got 500");

  // An arm cover that does not fit its own counts or links (an in-process
  // caller that skipped the wire checks): unusable, not read out of range.
  link_labels_t bad_cover = labels;
  bad_cover.arm_cover_max_radius_m = 0.1;
  bad_cover.num_arm_spheres = 2;
  bad_cover.arm_sphere_link = {0, 7};
  bad_cover.arm_sphere_center_m = {{0.f, 0.f, 1.f}, {0.f, 0.f, 1.f}};
  bad_cover.arm_sphere_radius_m = {0.05f, 0.05f};
  s = compute_discrepancy(camera, depth_frame(model.depth_mm, 4), bad_cover, sim_options()).summary;
  EXPECT_FALSE(s.usable);
  EXPECT_EQ(s.unusable_kind, discrepancy_t::UNUSABLE_MISMATCHED);
  EXPECT_NE(s.unusable_reason.find("arm_sphere_link[1]"), std::string::npos) << s.unusable_reason;
  bad_cover.num_arm_spheres = 3;
  s = compute_discrepancy(camera, depth_frame(model.depth_mm, 4), bad_cover, sim_options()).summary;
  EXPECT_FALSE(s.usable);
  EXPECT_NE(s.unusable_reason.find("num_arm_spheres"), std::string::npos) << s.unusable_reason;
}

// A zero profile of the synthetic camera whose smooth correction was
// measured over `first_m`..`first_m` + 0.2 m (radial).
std::shared_ptr<const CameraProfile> zero_profile_from(double first_m) {
  CameraProfile p;
  p.file = "tof-mast-profile.yaml";
  p.camera_id = "tof-mast";
  p.width = kWidth;
  p.height = kHeight;
  p.fx = p.fy = kFocalPx;
  p.cx = kWidth / 2.0;
  p.cy = kHeight / 2.0;
  p.distance_first_m = first_m;
  p.distance_bin_m = 0.1;
  p.distance_correction_mm = {0, 0, 0};
  p.pixel_correction_mm.assign(static_cast<size_t>(kPixels), 0.0f);
  derive_fixed_pattern(&p);
  return std::make_shared<const CameraProfile>(p);
}

// The arm (1.5 m) where the camera's profile was not measured (1.8-2.0 m,
// a bin of margin): the frame is refused, the camera needs
// recommissioning. An object before the arm is no such thing: the range is
// the model's.
TEST(Discrepancy, TheArmBeyondTheProfilesRangeMakesTheFrameUnusable) {
  const SyntheticImage model = draw(default_arm());
  DiscrepancyOptions options = sim_options();
  options.camera_profile = zero_profile_from(1.8);
  discrepancy_t s = compare(model, model.depth_mm, options).summary;
  EXPECT_FALSE(s.usable);
  EXPECT_EQ(s.unusable_kind, discrepancy_t::UNUSABLE_OUTSIDE_PROFILE);
  EXPECT_EQ(s.unusable_reason.rfind("camera needs recommissioning: the arm is 1.50-", 0), 0u)
      << s.unusable_reason;
  EXPECT_NE(
      s.unusable_reason.find("beyond the 1.80-2.00 m its profile tof-mast-profile.yaml was measured over"),
      std::string::npos)
      << s.unusable_reason;

  options.camera_profile = zero_profile_from(1.4);
  EXPECT_TRUE(compare(model, model.depth_mm, options).summary.usable);
  std::vector<int16_t> object_before_arm = model.depth_mm;
  for (size_t i = 0; i < object_before_arm.size(); ++i) {
    if (model.label[i] == 3) object_before_arm[i] = 1000;
  }
  s = compare(model, object_before_arm, options).summary;
  EXPECT_TRUE(s.usable) << s.unusable_reason;
  EXPECT_GT(s.num_occluded + s.num_unexpected_surface, 500);
}

TEST(Discrepancy, ColourImageIsRedForNearerBlueForFartherBlackForMatch) {
  const SyntheticImage model = draw(default_arm());
  const DiscrepancyFrame f = compare(model, draw(default_arm(10)).depth_mm);
  const discrepancy_image_t image = discrepancy::colour_image(f, /*full_scale_mm=*/1000);
  ASSERT_EQ(image.num_bytes, 3 * kPixels);
  auto rgb = [&](int v, int u, int c) { return image.rgb[3 * (v * kWidth + u) + c]; };
  // Robot missing (the camera sees farther): I_dis = -500 -> blue at half
  // brightness.
  EXPECT_EQ(rgb(70, 65, 2), 127);
  EXPECT_EQ(rgb(70, 65, 0), 0);
  // Unexpected surface (the camera sees nearer): I_dis = +500 -> red.
  EXPECT_EQ(rgb(70, 105, 0), 127);
  EXPECT_EQ(rgb(70, 105, 2), 0);
  // Match -> black.
  EXPECT_EQ(rgb(10, 10, 0) + rgb(10, 10, 1) + rgb(10, 10, 2), 0);
}

TEST(DepthHash, RepeatsAreCountedInARow) {
  const std::vector<int16_t> a = {1, 2, 3};
  const std::vector<int16_t> b = {1, 2, 4};
  EXPECT_NE(discrepancy::depth_hash(a), discrepancy::depth_hash(b));
  discrepancy::RepeatCounter repeats;
  EXPECT_EQ(repeats.update(discrepancy::depth_hash(a)), 0);
  EXPECT_EQ(repeats.update(discrepancy::depth_hash(a)), 1);
  EXPECT_EQ(repeats.update(discrepancy::depth_hash(a)), 2);
  EXPECT_EQ(repeats.update(discrepancy::depth_hash(b)), 0);
}

}  // namespace
}  // namespace tofguard::test

namespace tofguard::test {
namespace {

TEST(Discrepancy, MixedPixelsOnAThinLinksSilhouetteDoNotCountAgainstIt) {
  // A finger 3 px wide at 1.5 m in front of the floor at 2 m; the camera
  // mixes both surfaces on its two edge columns (1750 mm: 250 mm off).
  const std::vector<Box> finger = {{80, 40, 83, 100, kArmMm, 1}};
  const SyntheticImage model = draw(finger);
  std::vector<int16_t> camera = model.depth_mm;
  for (int v = 40; v < 100; ++v) {
    camera[v * kWidth + 80] = 1750;
    camera[v * kWidth + 82] = 1750;
  }
  discrepancy::DiscrepancyOptions with_silhouettes;
  with_silhouettes.silhouette_jump_mm = 50;
  const auto raw = compute_discrepancy(depth_frame(camera, 1), depth_frame(model.depth_mm, 1),
                                       labels_frame(model.label, 1), discrepancy::DiscrepancyOptions{})
                       .summary;
  const auto seen = compute_discrepancy(depth_frame(camera, 1), depth_frame(model.depth_mm, 1),
                                        labels_frame(model.label, 1), with_silhouettes)
                        .summary;
  // Without silhouettes two thirds of the finger look missing.
  EXPECT_EQ(raw.link_farther[0], 2 * 60);
  EXPECT_EQ(raw.link_compared[0], 3 * 60);
  // With them, only its middle column's inner rows count, and they match.
  EXPECT_EQ(seen.link_farther[0], 0);
  EXPECT_EQ(seen.link_compared[0], 58);
  EXPECT_EQ(seen.link_match[0], 58);
  // The pixel classes themselves are unchanged (the colour image shows them).
  EXPECT_EQ(seen.num_robot_missing, raw.num_robot_missing);
  EXPECT_EQ(seen.largest_blob_pixels, 0);
}

TEST(Discrepancy, AStepJustOverTheJumpIsASilhouetteInWholeMillimetres) {
  // A link 10 px wide at 1.5 m, 50.4 mm in front of the surface behind it:
  // the camera mixes its edge pixels (a scene step over silhouette_jump_mm),
  // but the rendered depths, rounded to the millimetre, differ by 50. The
  // mixed pixels must stay out of the link's counts (and the evidence) all
  // the same: on a still arm the same pixel is mixed in every frame.
  SyntheticImage model = draw({{80, 40, 90, 100, kArmMm, 1}});
  for (size_t i = 0; i < model.depth_mm.size(); ++i) {
    if (model.label[i] != 1) model.depth_mm[i] = kArmMm + 50;
  }
  std::vector<int16_t> camera = model.depth_mm;
  for (int v = 40; v < 100; ++v) {
    camera[v * kWidth + 80] = kArmMm + 25;
    camera[v * kWidth + 89] = kArmMm + 25;
  }
  discrepancy::DiscrepancyOptions options;
  options.silhouette_jump_mm = 50;
  const auto seen = compute_discrepancy(depth_frame(camera, 1), depth_frame(model.depth_mm, 1),
                                        labels_frame(model.label, 1), options)
                        .summary;
  // The link's inner 8 x 58 pixels count; its outline does not.
  EXPECT_EQ(seen.link_compared[0], 8 * 58);
  EXPECT_EQ(seen.link_match[0], 8 * 58);
}

// silhouette_mask against its rule written out pixel by pixel: a pixel is
// beside a silhouette when it or one of its 4-neighbours has depth and the
// other not, or both have depth and differ by more than the jump in whole
// millimetres. Random depths near a few levels (steps just under and over
// the jump), invalid pixels among them, on sizes with one row or column,
// and the jumps at the edges (none, 1 mm, fractional, huge).
TEST(SilhouetteMask, FollowsItsRuleOnEveryPairOfNeighbours) {
  std::mt19937 random(17);
  const auto reference = [](const std::vector<int16_t>& depth, int width, int height, double jump_mm) {
    std::vector<uint8_t> mask(depth.size(), 0);
    if (!(jump_mm > 0)) return mask;
    const int limit = discrepancy::silhouette_step_limit_mm(jump_mm);
    const auto steps = [&](int i, int j) {
      const int a = depth[static_cast<size_t>(i)];
      const int b = depth[static_cast<size_t>(j)];
      if ((a > 0) != (b > 0)) return true;
      return a > 0 && std::abs(a - b) > limit;
    };
    for (int v = 0; v < height; ++v) {
      for (int u = 0; u < width; ++u) {
        const int i = v * width + u;
        const bool beside = (u > 0 && steps(i, i - 1)) || (u + 1 < width && steps(i, i + 1)) ||
                            (v > 0 && steps(i, i - width)) || (v + 1 < height && steps(i, i + width));
        mask[static_cast<size_t>(i)] = beside ? 1 : 0;
      }
    }
    return mask;
  };
  int silhouettes = 0;
  for (const auto& [width, height] :
       std::vector<std::pair<int, int>>{{1, 1}, {1, 9}, {9, 1}, {2, 2}, {17, 13}, {176, 144}}) {
    for (const double jump_mm : {0.0, -5.0, 0.5, 1.0, 1.5, 50.0, 50.4, 1e12}) {
      for (int scene = 0; scene < 4; ++scene) {
        std::vector<int16_t> depth(static_cast<size_t>(width) * height);
        std::uniform_int_distribution<int> level(0, 4), jitter(-60, 60);
        for (int16_t& d : depth) {
          const int l = level(random);
          d = static_cast<int16_t>(l == 0 ? (jitter(random) > 0 ? 0 : -1) : 1000 * l + jitter(random));
        }
        depth_image_t rendered = depth_frame(std::vector<int16_t>(kWidth * kHeight, 0), 1);
        rendered.width = width;
        rendered.height = height;
        rendered.num_pixels = width * height;
        rendered.depth_mm = depth;
        const std::vector<uint8_t> mask = discrepancy::silhouette_mask(rendered, jump_mm);
        ASSERT_EQ(mask, reference(depth, width, height, jump_mm))
            << width << "x" << height << ", jump " << jump_mm << " mm, scene " << scene;
        for (uint8_t m : mask) silhouettes += m;
      }
    }
  }
  EXPECT_GT(silhouettes, 1000);  // the scenes have silhouettes to find
}

// ---- The wheelchair's user (docs/safety-chain.md, "The user") ----

namespace user {

// The user's chest as the model has it: a box whose front face is at
// 1.6 m, seen over columns 110..149 and rows 60..119 (fx = fy = 200, the
// principal point at the image centre), 10 columns (8 cm) beside link2.
constexpr int kU0 = 110, kU1 = 150, kV0 = 60, kV1 = 120;
constexpr int16_t kFrontMm = 1600;
constexpr double kEnvelopeM = 0.03;

Box chest(int shift_px = 0, int16_t depth_mm = kFrontMm) {
  return {kU0 + shift_px, kV0, kU1 + shift_px, kV1, depth_mm, link_labels_t::OCCUPANT_FIRST};
}

// Adds to the labels a body region `name` (envelope `envelope_m`) with one
// box in the optical frame: its face at `front_mm` over exactly columns
// u0..u1-1 and rows v0..v1-1 (pixel edges at u - 0.5), 0.2 m deep.
void add_user_box(link_labels_t* labels, const std::string& name, double envelope_m, int u0, int u1, int v0,
                  int v1, int16_t front_mm) {
  const double z = front_mm * 1e-3;
  const double cx = kWidth / 2.0, cy = kHeight / 2.0;
  const double x0 = (u0 - 0.5 - cx) * z / kFocalPx, x1 = (u1 - 0.5 - cx) * z / kFocalPx;
  const double y0 = (v0 - 0.5 - cy) * z / kFocalPx, y1 = (v1 - 0.5 - cy) * z / kFocalPx;
  labels->num_body_regions++;
  labels->body_region.push_back(name);
  labels->body_region_separation_m.push_back(0.08f);
  labels->body_region_envelope_m.push_back(static_cast<float>(envelope_m));
  labels->num_occupant_shapes++;
  labels->occupant_shape_kind.push_back(link_labels_t::SHAPE_BOX);
  labels->occupant_shape_region.push_back(static_cast<int16_t>(labels->num_body_regions - 1));
  labels->occupant_shape_center_m.push_back(
      {static_cast<float>((x0 + x1) / 2), static_cast<float>((y0 + y1) / 2), static_cast<float>(z + 0.1)});
  labels->occupant_shape_rotation.push_back({1, 0, 0, 0, 1, 0, 0, 0, 1});
  labels->occupant_shape_size_m.push_back(
      {static_cast<float>((x1 - x0) / 2), static_cast<float>((y1 - y0) / 2), 0.1f});
}

// The labels' region "chest" (envelope 3 cm) and its one box.
void add_chest(link_labels_t* labels) {
  add_user_box(labels, "chest", kEnvelopeM, kU0, kU1, kV0, kV1, kFrontMm);
}

// The default arm with the user's chest beside it, the model's image, and
// the camera's image of `seen` (with noise).
discrepancy_t compare_with_user(const std::vector<Box>& seen) {
  std::vector<Box> modelled = default_arm();
  modelled.push_back(chest());
  const SyntheticImage model = draw(modelled);
  link_labels_t labels = labels_frame(model.label, 7);
  add_pixel_cover(&labels, model.depth_mm);
  add_chest(&labels);
  const DiscrepancyFrame f = compute_discrepancy(depth_frame(with_noise(draw(seen).depth_mm, 5), 7),
                                                 depth_frame(model.depth_mm, 7), labels, sim_options());
  EXPECT_TRUE(f.summary.usable) << f.summary.unusable_reason;
  return f.summary;
}

std::vector<Box> arm_and(const std::vector<Box>& more) {
  std::vector<Box> scene = default_arm();
  scene.insert(scene.end(), more.begin(), more.end());
  return scene;
}

// The model's chest pixels (the silhouette lies on the floor's side of
// the rendered step, none on the chest's).
constexpr int kChestCounted = 40 * 60;

}  // namespace user

TEST(DiscrepancyUser, TheUserAsModelledIsSeenAndNoObject) {
  const discrepancy_t s = user::compare_with_user(user::arm_and({user::chest()}));
  ASSERT_EQ(s.num_body_regions, 1);
  EXPECT_EQ(s.body_region_modelled_pixels[0], user::kChestCounted);
  EXPECT_EQ(s.body_region_seen_pixels[0], user::kChestCounted);
  EXPECT_EQ(s.body_region_missing_pixels[0], 0);
  EXPECT_EQ(s.num_unexpected_surface, 0);
  EXPECT_EQ(s.near_arm_pixels, 0);
  EXPECT_FLOAT_EQ(s.unexplained_area_within_m2.back(), 0);
  // The user's pixels are no link's, and not in the frame's scores.
  EXPECT_EQ(s.link_compared[3], kPixels - 2400 - 40 * 60);
  // Nothing of the user is seen off the model.
  EXPECT_FLOAT_EQ(s.body_region_seen_separation_m[0], -1);
}

// The user 3 px (2.4 cm at 1.6 m) towards the arm: the newly covered band
// is an unexplained surface 1.6 m away before the floor, but within the
// chest's 3 cm envelope, so it is the user, seen off the model; the band
// the user left shows the floor, farther than the envelope: missing.
// Neither is an object or a blob.
TEST(DiscrepancyUser, AUserMovedWithinTheEnvelopeIsStillTheUser) {
  const discrepancy_t s = user::compare_with_user(user::arm_and({user::chest(-3)}));
  EXPECT_EQ(s.near_arm_pixels, 0);
  EXPECT_FLOAT_EQ(s.unexplained_area_within_m2.back(), 0);
  EXPECT_EQ(s.largest_blob_pixels, 0);
  EXPECT_EQ(s.body_region_missing_pixels[0], 3 * 60);
  // Seen: the model's pixels less the missing band, plus the band before
  // the floor (3 x 60, less the floor's silhouette column beside the
  // rendered step and what the opening takes off).
  EXPECT_GE(s.body_region_seen_pixels[0], user::kChestCounted - 3 * 60 + 2 * 56);
  EXPECT_LE(s.body_region_seen_pixels[0], user::kChestCounted - 3 * 60 + 3 * 60);
  // The band off the model nearest the arm: column 107 at 1.6 m, 7 cm
  // beside link2's last column (1.5 m) and 10 cm behind it, less the
  // cover sphere's 5 mm: 11.7 cm; the camera's noise (7 mm at 1.6 m, the
  // least of 180 pixels about -2.8 sigma) brings it nearer by up to 2 cm.
  EXPECT_GT(s.body_region_seen_separation_m[0], 0.09);
  EXPECT_LT(s.body_region_seen_separation_m[0], 0.118);
}

// A hand lifted out of every envelope, 1.5 m away in columns 102..105
// (7-11 cm before and beside the chest's model): an unknown object beside
// the arm, as without a user.
TEST(DiscrepancyUser, AHandOutsideEveryEnvelopeIsAnUnknownObject) {
  const discrepancy_t s =
      user::compare_with_user(user::arm_and({user::chest(), {102, 62, 106, 72, 1500, 0}}));
  EXPECT_GE(s.near_arm_pixels, 2 * 8);  // the opening keeps the 4 x 10 block's inside
  EXPECT_LE(s.near_arm_pixels, 4 * 10);
  EXPECT_GT(s.unexplained_area_within_m2.back(), 0);
  EXPECT_EQ(s.body_region_missing_pixels[0], 0);
}

// The user's hand before a link: its model (region "hand", envelope 10 cm,
// 1.4 m away) just past link2's end (columns 102..109, rows 62..69), the
// real hand 6 columns (4 cm) nearer the arm, before link2's last 4
// columns. Those 32 pixels say nothing about link2: they are the user's,
// not an object near the arm, and link2 counts them as without a return,
// not as nearer; the same surface with no user modelled is an object
// before the link.
TEST(DiscrepancyUser, TheUsersHandBeforeALinkHidesItAndIsNoObject) {
  std::vector<Box> modelled = default_arm();
  modelled.push_back({102, 62, 110, 70, 1400, link_labels_t::OCCUPANT_FIRST});
  const SyntheticImage model = draw(modelled);
  std::vector<Box> seen = default_arm();
  seen.push_back({96, 62, 104, 70, 1400, 0});
  const depth_image_t camera = depth_frame(draw(seen).depth_mm, 7);
  link_labels_t labels = labels_frame(model.label, 7);
  add_pixel_cover(&labels, model.depth_mm);
  link_labels_t without_user = labels;
  for (int16_t& l : without_user.label)
    l = l == link_labels_t::OCCUPANT_FIRST ? link_labels_t::ENVIRONMENT_FIRST : l;
  user::add_user_box(&labels, "hand", 0.10, 102, 110, 62, 70, 1400);
  const discrepancy_t with =
      compute_discrepancy(camera, depth_frame(model.depth_mm, 7), labels, sim_options()).summary;
  ASSERT_TRUE(with.usable) << with.unusable_reason;
  EXPECT_EQ(with.num_occluded, 32);
  EXPECT_EQ(with.link_nearer[2], 0);
  EXPECT_EQ(with.link_invalid[2], 32);
  EXPECT_EQ(with.num_robot_hidden_by_user, 32);
  EXPECT_EQ(with.near_arm_pixels, 0);
  EXPECT_GT(with.body_region_seen_pixels[0], 32);
  const discrepancy_t without =
      compute_discrepancy(camera, depth_frame(model.depth_mm, 7), without_user, sim_options()).summary;
  ASSERT_TRUE(without.usable) << without.unusable_reason;
  EXPECT_EQ(without.link_nearer[2], 32);
  EXPECT_EQ(without.num_robot_hidden_by_user, 0);
  EXPECT_GT(without.near_arm_pixels, 0);
}

// Nobody in the chair: every modelled pixel of the user sees the floor
// 0.4 m behind, farther than the envelope.
TEST(DiscrepancyUser, AnEmptyChairLeavesEveryModelledPixelMissing) {
  const discrepancy_t s = user::compare_with_user(default_arm());
  EXPECT_EQ(s.body_region_modelled_pixels[0], user::kChestCounted);
  EXPECT_EQ(s.body_region_missing_pixels[0], user::kChestCounted);
  EXPECT_EQ(s.body_region_seen_pixels[0], 0);
  EXPECT_FLOAT_EQ(s.body_region_seen_separation_m[0], -1);
  EXPECT_EQ(s.largest_blob_pixels, 0);
}

// Something before the user by more than the envelope (a caregiver's hand
// over the chest, 1.45 m away, 15 cm before it) is not the user.
TEST(DiscrepancyUser, SomethingBeforeTheUserBeyondTheEnvelopeIsNotTheUser) {
  const discrepancy_t s =
      user::compare_with_user(user::arm_and({user::chest(), {112, 62, 120, 72, 1450, 0}}));
  EXPECT_GT(s.near_arm_pixels, 0);
  EXPECT_GT(s.unexplained_area_within_m2.back(), 0);
  EXPECT_EQ(s.body_region_missing_pixels[0], 0);
}

}  // namespace
}  // namespace tofguard::test
