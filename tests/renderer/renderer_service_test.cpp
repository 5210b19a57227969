// tofguard-renderer's logic without LCM: the published numbers, unusable
// frames, frame dropping, camera poses by camera id.
#include <gtest/gtest.h>

#include <cmath>

#include "occupant_test_config.hpp"
#include "tofguard/common/wire_checks.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/renderer/prediction_schedule.hpp"
#include "tofguard/renderer/rendered_occupant.hpp"
#include "tofguard/renderer/renderer_service.hpp"
#include "tofguard/robot_model/arm_spheres.hpp"
#include "tool_support.hpp"

namespace tofguard::renderer {
namespace {

deployment::Config sim_config() {
  return deployment::load_config(tofguard::test::source_dir() + "/config/sim.yaml", nullptr);
}

joint_state_t joint_state(int64_t utime, const robot_model::JointPositions& positions,
                          const std::string& robot = "friend-sim") {
  joint_state_t m;
  m.utime = utime;
  m.robot_id = robot;
  for (const auto& [name, value] : positions) {
    m.name.push_back(name);
    m.position.push_back(value);
    m.velocity.push_back(0);
  }
  m.num_joints = static_cast<int32_t>(m.name.size());
  return m;
}

depth_image_t frame(int64_t utime, int64_t seq, const Intrinsics& k) {
  depth_image_t f;
  f.utime = utime;
  f.seq = seq;
  f.camera_id = "tof-mast";
  f.width = k.width;
  f.height = k.height;
  f.fx = k.fx;
  f.fy = k.fy;
  f.cx = k.cx;
  f.cy = k.cy;
  f.num_pixels = k.width * k.height;
  f.depth_mm.assign(f.num_pixels, 1234);
  f.calibrated = true;
  f.num_amplitude = 0;
  return f;
}

// The config's occupant as the service renders it.
std::vector<ExtraObject> seated_user(const deployment::Config& config, const robot_model::SceneModel& scene) {
  if (!config.occupant) return {};
  return occupant_render_objects(robot_model::load_occupant(
      config.occupant->urdf_path, robot_model::fixed_link_pose(scene, config.occupant->seated_on)));
}

robot_model::JointPositions arm(double s) {
  robot_model::JointPositions q;
  for (int i = 1; i <= 7; ++i) q["a" + std::to_string(i)] = 0.1 * i * s;
  return q;
}

TEST(RendererService, PublishesTheModelAtTheInterpolatedJointsInMillimetres) {
  const deployment::Config config = sim_config();
  RendererService service(deployment::renderer_process_settings(config));
  ASSERT_TRUE(service.on_joint_state(joint_state(1'000'000, arm(1.0))));
  ASSERT_TRUE(service.on_joint_state(joint_state(1'010'000, arm(2.0))));
  const Intrinsics k = config.camera.intrinsics;
  const RenderedFrame out = service.render(frame(1'002'500, 42, k));
  ASSERT_TRUE(out.labels.usable) << out.labels.unusable_reason;
  ASSERT_TRUE(out.depth.has_value());
  // The kinematics as rendered travel with the labels.
  EXPECT_GT(out.labels.num_axes, 0);
  EXPECT_EQ(out.labels.num_link_axes, out.labels.num_robot_links);
  EXPECT_EQ(check_link_labels(out.labels), "");
  EXPECT_EQ(out.depth->utime, 1'002'500);
  EXPECT_EQ(out.depth->seq, 42);
  EXPECT_EQ(out.depth->camera_id, "tof-mast");
  EXPECT_EQ(out.labels.seq, 42);
  EXPECT_EQ(out.depth->num_pixels, k.width * k.height);
  EXPECT_EQ(out.depth->fx, k.fx);
  EXPECT_EQ(out.depth->cy, k.cy);
  EXPECT_EQ(out.labels.num_robot_links, 10);
  EXPECT_EQ(out.labels.num_links, static_cast<int>(out.labels.link_name.size()));

  // The same as the library at arm(1.25) with the seated user's shapes,
  // rounded to millimetres.
  const robot_model::SceneModel scene = robot_model::load_scene(
      config.robot.urdf_path, config.environment.urdf_paths, scene_options(config.renderer, config.robot));
  DepthRenderer renderer(scene, config.renderer.near_m, config.renderer.far_m);
  const std::vector<ExtraObject> user = seated_user(config, scene);
  const RenderResult expected = renderer.render(arm(1.25), config.camera.pose, k, user);
  ASSERT_TRUE(expected.usable);
  // The user is seen, labelled by shape, and the labels carry every shape.
  EXPECT_EQ(out.labels.num_occupant_shapes, static_cast<int>(user.size()));
  int user_pixels = 0;
  for (int16_t l : out.labels.label) user_pixels += l >= kLabelOccupantFirst ? 1 : 0;
  EXPECT_GT(user_pixels, 1000);
  int robot_pixels = 0;
  for (size_t i = 0; i < expected.depth_m.size(); ++i) {
    // Rounded to the nearest millimetre; the service interpolates the
    // joints (arm(1.25) up to the last bit), so a depth that lies on a half
    // millimetre may round either way.
    ASSERT_LE(std::abs(out.depth->depth_mm[i] - expected.depth_m[i] * 1000), 0.5 + 1e-3) << "pixel " << i;
    ASSERT_EQ(out.labels.label[i], expected.labels[i]);
    robot_pixels += expected.labels[i] > 0 && expected.labels[i] < kLabelEnvironmentFirst;
  }
  EXPECT_GT(robot_pixels, 1000);
  // And different from the arm at either bracketing message.
  EXPECT_NE(renderer.render(arm(1.0), config.camera.pose, k, user).depth_m, expected.depth_m);
}

// With an occupant the labels carry each body region's separation from the
// arm's cover at the frame's joints: robot_model's, rounded down to a
// float; without one, none.
TEST(RendererService, TheLabelsCarryTheUsersBodyRegionsSeparations) {
  const deployment::Config nobody = deployment::load_config(
      tofguard::test::sim_config_variant("renderer-no-occupant", {}, "occupant: ~\n"), nullptr);
  RendererService without(deployment::renderer_process_settings(nobody));
  ASSERT_TRUE(without.on_joint_state(joint_state(1'000'000, arm(1.0))));
  ASSERT_TRUE(without.on_joint_state(joint_state(1'010'000, arm(1.0))));
  const RenderedFrame plain = without.render(frame(1'002'500, 42, nobody.camera.intrinsics));
  ASSERT_TRUE(plain.labels.usable) << plain.labels.unusable_reason;
  EXPECT_EQ(plain.labels.num_body_regions, 0);
  const deployment::Config config = deployment::load_config(
      tofguard::test::sim_config_variant("renderer-occupant", {}, tofguard::test::occupant_section()),
      nullptr);
  RendererService service(deployment::renderer_process_settings(config));
  ASSERT_TRUE(service.on_joint_state(joint_state(1'000'000, arm(1.0))));
  ASSERT_TRUE(service.on_joint_state(joint_state(1'010'000, arm(1.0))));
  const RenderedFrame out = service.render(frame(1'002'500, 42, config.camera.intrinsics));
  ASSERT_TRUE(out.labels.usable) << out.labels.unusable_reason;
  EXPECT_EQ(check_link_labels(out.labels), "");
  ASSERT_EQ(out.labels.num_body_regions, kNumBodyRegions);

  const robot_model::SceneModel scene = robot_model::load_scene(
      config.robot.urdf_path, config.environment.urdf_paths, scene_options(config.renderer, config.robot));
  const robot_model::OccupantModel occupant = robot_model::load_occupant(
      config.occupant->urdf_path, robot_model::fixed_link_pose(scene, config.occupant->seated_on));
  const auto expected = robot_model::body_region_separations_m(
      robot_model::place_arm_spheres(
          robot_model::cover_arm_with_spheres(scene, config.renderer.arm_cover_cell_m),
          robot_model::forward_kinematics(scene, arm(1.0))),
      occupant);
  ASSERT_EQ(expected.size(), static_cast<size_t>(kNumBodyRegions));
  for (int k = 0; k < kNumBodyRegions; ++k) {
    EXPECT_EQ(out.labels.body_region[k], body_region_name(expected[k].first));
    EXPECT_LE(out.labels.body_region_separation_m[k], expected[k].second) << out.labels.body_region[k];
    EXPECT_NEAR(out.labels.body_region_separation_m[k], expected[k].second, 1e-6)
        << out.labels.body_region[k];
    EXPECT_GT(out.labels.body_region_separation_m[k], 0) << out.labels.body_region[k];
  }
}

TEST(RendererService, UnusableFramesPublishOnlyLabelsWithTheReason) {
  const deployment::Config config = sim_config();
  RendererService service(deployment::renderer_process_settings(config));
  const Intrinsics k = config.camera.intrinsics;
  RenderedFrame out = service.render(frame(1'000'000, 1, k));
  EXPECT_FALSE(out.labels.usable);
  EXPECT_EQ(out.labels.unusable_reason, "no joint state received yet");
  EXPECT_FALSE(out.depth.has_value());
  EXPECT_EQ(out.labels.num_pixels, 0);

  robot_model::JointPositions without_a4 = arm(1.0);
  without_a4.erase("a4");
  service.on_joint_state(joint_state(1'000'000, without_a4));
  out = service.render(frame(1'000'000, 2, k));
  EXPECT_FALSE(out.labels.usable);
  EXPECT_EQ(out.labels.unusable_reason, "joint 'a4' missing from the joint state");

  service.on_joint_state(joint_state(1'010'000, arm(1.0)));
  service.on_joint_state(joint_state(1'020'000, arm(1.0)));
  out = service.render(frame(1'050'000, 3, k));  // 30 ms beyond the newest, limit 20 ms
  EXPECT_FALSE(out.labels.usable);
  EXPECT_EQ(out.labels.unusable_reason.rfind("newest joint state is 30.000000 ms older than the frame", 0),
            0u)
      << out.labels.unusable_reason;

  depth_image_t other_camera = frame(1'015'000, 4, k);
  other_camera.camera_id = "tof-elsewhere";
  out = service.render(other_camera);
  EXPECT_EQ(out.labels.unusable_reason, "no camera pose for camera 'tof-elsewhere'");
  EXPECT_TRUE(service.render(frame(1'015'000, 5, k)).labels.usable);
}

TEST(RendererService, CameraPoseMessagesReplaceTheStaticPoseOfThatCamera) {
  const deployment::Config config = sim_config();
  RendererService service(deployment::renderer_process_settings(config));
  service.on_joint_state(joint_state(1'000'000, arm(1.0)));
  const Intrinsics k = config.camera.intrinsics;
  const RenderedFrame before = service.render(frame(1'000'000, 1, k));
  camera_pose_t pose;
  pose.utime = 1'000'000;
  pose.camera_id = "tof-mast";
  pose.frame_id = "world";
  // 10 cm further back along the optical axis (rotation as in sim.yaml).
  const Eigen::Vector3d back =
      config.camera.pose.translation_m - 0.1 * (config.camera.pose.rotation * Eigen::Vector3d::UnitZ());
  for (int i = 0; i < 3; ++i) pose.translation[i] = back[i];
  pose.rotation[0] = config.camera.pose.rotation.w();
  pose.rotation[1] = config.camera.pose.rotation.x();
  pose.rotation[2] = config.camera.pose.rotation.y();
  pose.rotation[3] = config.camera.pose.rotation.z();
  service.on_camera_pose(pose);
  const RenderedFrame after = service.render(frame(1'000'000, 2, k));
  ASSERT_TRUE(before.depth && after.depth);
  // Moving back along the optical axis adds 100 mm to every Z; the pixel
  // nearest the principal point sees (almost) the same point as before.
  const size_t centre =
      static_cast<size_t>(std::lround(k.cy)) * k.width + static_cast<size_t>(std::lround(k.cx));
  ASSERT_NE(before.labels.label[centre], 0);
  EXPECT_EQ(before.labels.label[centre], after.labels.label[centre]);
  EXPECT_NEAR(after.depth->depth_mm[centre] - before.depth->depth_mm[centre], 100, 5);
  EXPECT_NE(before.depth->depth_mm, after.depth->depth_mm);
}

TEST(RendererService, KeepsOnlyTheNewestPendingFrameAndCountsDrops) {
  const deployment::Config config = sim_config();
  RendererService service(deployment::renderer_process_settings(config));
  service.on_joint_state(joint_state(1'000'000, arm(1.0)));
  const Intrinsics k = config.camera.intrinsics;
  EXPECT_FALSE(service.has_pending());
  EXPECT_FALSE(service.on_depth(frame(1'000'000, 1, k)));
  EXPECT_TRUE(service.on_depth(frame(1'000'000, 2, k)));
  EXPECT_TRUE(service.on_depth(frame(1'000'000, 3, k)));
  const std::optional<RenderedFrame> out = service.render_pending();
  ASSERT_TRUE(out.has_value());
  EXPECT_EQ(out->labels.seq, 3);
  EXPECT_FALSE(service.has_pending());
  EXPECT_FALSE(service.render_pending().has_value());
}

TEST(RendererService, IgnoresOtherRobotsAndRefusesFarBeyondInt16) {
  deployment::Config config = sim_config();
  RendererService service(deployment::renderer_process_settings(config));
  EXPECT_FALSE(service.on_joint_state(joint_state(1'000'000, arm(1.0), "another-robot")));
  EXPECT_EQ(service.render(frame(1'000'000, 1, config.camera.intrinsics)).labels.unusable_reason,
            "no joint state received yet");
  config.renderer.far_m = 40;
  EXPECT_THROW(RendererService{deployment::renderer_process_settings(config)}, std::invalid_argument);
}

// The heartbeat's prediction text and back: the process writes it, the
// tools and tests read it (renderer_process_test, tofguard-bench).
TEST(RendererService, PredictionCountsGoThroughTheHeartbeatStatus) {
  RendererService::PredictionStats stats;
  stats.hits = 291;
  stats.misses = 3;
  stats.without = 7;
  stats.rendered = 296;
  const std::string status = "rendering; " + RendererService::prediction_status(stats);
  EXPECT_EQ(status, "rendering; prediction: 291 hits, 3 misses, 7 frames without one, 296 rendered ahead");
  const auto back = RendererService::prediction_stats_from_status(status);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->hits, 291);
  EXPECT_EQ(back->misses, 3);
  EXPECT_EQ(back->without, 7);
  EXPECT_EQ(back->rendered, 296);
  EXPECT_FALSE(RendererService::prediction_stats_from_status("waiting for frames").has_value());
  EXPECT_FALSE(RendererService::prediction_stats_from_status("prediction: 3 hits").has_value());
}

// Without a plan (renderer.prediction.from_joint_states, on in
// config/sim.yaml), the next frame's joints are guessed from the joint
// states when the render ahead starts: linear through the two newest, at
// most one camera period beyond the newest. A frame within the tolerances
// of the guess is published from it (a hit); one that is not (an encoder
// that jumped) is rendered at its own joints (a miss). Joint states too old
// for the guess make it wait for a newer one.
TEST(RendererService, WithoutAPlanTheNextFrameIsGuessedFromTheJointStates) {
  const deployment::Config config = sim_config();
  ASSERT_TRUE(config.renderer.prediction_enabled);
  ASSERT_TRUE(config.renderer.prediction_from_joint_states);
  RendererService service(deployment::renderer_process_settings(config));
  const Intrinsics k = config.camera.intrinsics;
  // Every joint at a constant rate (joint i: 0.1 i rad/s), so that a linear
  // guess is the interpolation's value up to rounding.
  const auto moving_arm = [](int64_t utime) { return arm((utime - 1'000'000) * 1e-6); };
  int64_t next_joint_utime = 1'000'000;
  const auto joint_states_until = [&](int64_t utime, double a2_offset_rad = 0) {
    for (; next_joint_utime <= utime; next_joint_utime += 10'000) {
      robot_model::JointPositions q = moving_arm(next_joint_utime);
      q["a2"] += a2_offset_rad;
      ASSERT_TRUE(service.on_joint_state(joint_state(next_joint_utime, q)));
    }
  };
  const robot_model::SceneModel scene = robot_model::load_scene(
      config.robot.urdf_path, config.environment.urdf_paths, scene_options(config.renderer, config.robot));
  DepthRenderer renderer(scene, config.renderer.near_m, config.renderer.far_m);
  // The frame is the library's rendering at `joints` (to the millimetre's
  // rounding, as above).
  const auto expect_rendered_at = [&](const RenderedFrame& out, const robot_model::JointPositions& joints) {
    ASSERT_TRUE(out.depth.has_value()) << out.labels.unusable_reason;
    const RenderResult expected = renderer.render(joints, config.camera.pose, k, seated_user(config, scene));
    ASSERT_TRUE(expected.usable);
    for (size_t i = 0; i < expected.depth_m.size(); ++i) {
      ASSERT_LE(std::abs(out.depth->depth_mm[i] - expected.depth_m[i] * 1000), 0.5 + 1e-3) << "pixel " << i;
      ASSERT_EQ(out.labels.label[i], expected.labels[i]) << "pixel " << i;
    }
  };

  // Two frames 33 ms apart teach the period; after the second, the newest
  // joint state (1.030 s) is 41 ms before the next frame's expected utime
  // (1.071 s): more than a period, so nothing is rendered ahead yet, and
  // the guess waits for a newer joint state.
  joint_states_until(1'010'000);
  ASSERT_TRUE(service.render(frame(1'005'000, 1, k)).depth.has_value());
  joint_states_until(1'030'000);
  ASSERT_TRUE(service.render(frame(1'038'000, 2, k)).depth.has_value());
  EXPECT_EQ(service.frame_period_us(), 33'000);
  ASSERT_TRUE(service.has_prediction_to_render());
  EXPECT_FALSE(service.render_prediction());
  EXPECT_FALSE(service.has_prediction_to_render());
  EXPECT_EQ(service.prediction_stats().rendered, 0);
  // A newer joint state (31 ms before it): rendered ahead.
  joint_states_until(1'040'000);
  ASSERT_TRUE(service.has_prediction_to_render());
  EXPECT_TRUE(service.render_prediction());
  EXPECT_EQ(service.prediction_stats().rendered, 1);
  EXPECT_FALSE(service.has_prediction_to_render());

  // The frame comes with the joints the guess had: a hit, the model at the
  // frame's joints.
  joint_states_until(1'080'000);
  const RenderedFrame hit = service.render(frame(1'071'000, 3, k));
  EXPECT_EQ(service.prediction_stats().hits, 1);
  EXPECT_EQ(service.prediction_stats().misses, 0);
  expect_rendered_at(hit, moving_arm(1'071'000));

  // The next guess (from the states up to 1.090 s), then a2's encoder reads
  // 0.2 deg more from 1.100 s on: the frame at 1.104 s is a miss, rendered
  // at the joints reported for it.
  joint_states_until(1'090'000);
  ASSERT_TRUE(service.has_prediction_to_render());
  EXPECT_TRUE(service.render_prediction());
  const double jump_rad = 0.2 * M_PI / 180;
  joint_states_until(1'110'000, jump_rad);
  const RenderedFrame miss = service.render(frame(1'104'000, 4, k));
  EXPECT_EQ(service.prediction_stats().hits, 1);
  EXPECT_EQ(service.prediction_stats().misses, 1);
  robot_model::JointPositions reported = moving_arm(1'104'000);
  reported["a2"] += jump_rad;
  expect_rendered_at(miss, reported);
  EXPECT_EQ(service.prediction_stats().rendered, 2);
}

// With from_joint_states off (the default of a config without the key),
// no frame is predicted without a plan.
TEST(RendererService, WithoutAPlanOrTheJointStatesGuessNothingIsRenderedAhead) {
  deployment::Config config = sim_config();
  config.renderer.prediction_from_joint_states = false;
  RendererService service(deployment::renderer_process_settings(config));
  const Intrinsics k = config.camera.intrinsics;
  for (int64_t t = 1'000'000; t <= 1'100'000; t += 10'000)
    ASSERT_TRUE(service.on_joint_state(joint_state(t, arm(1.0))));
  ASSERT_TRUE(service.render(frame(1'005'000, 1, k)).depth.has_value());
  ASSERT_TRUE(service.render(frame(1'038'000, 2, k)).depth.has_value());
  EXPECT_EQ(service.frame_period_us(), 33'000);
  EXPECT_FALSE(service.has_prediction_to_render());
  ASSERT_TRUE(service.render(frame(1'071'000, 3, k)).depth.has_value());
  EXPECT_EQ(service.prediction_stats().rendered, 0);
  EXPECT_EQ(service.prediction_stats().without, 3);
}

// The render ahead starts as late as lets it finish before its frame is
// due: the last frame's arrival + the period - (the longest of the last 8
// renders x 1.25 + 2 ms); at once before there is a period or a render.
TEST(PredictionSchedule, StartsAsLateAsTheLongestRecentRenderAllows) {
  PredictionSchedule schedule;
  EXPECT_EQ(schedule.start_us(33'333), 0);  // no frame, no render yet
  schedule.frame_arrived(1'000'000);
  EXPECT_EQ(schedule.start_us(33'333), 0);  // no render yet
  schedule.rendered(900);
  EXPECT_EQ(schedule.start_us(0), 0);  // no period learned
  // 1 000 000 + 33 333 - (900 + 225 + 2 000)
  EXPECT_EQ(schedule.start_us(33'333), 1'030'208);
  // The longest of the kept renders counts: a 20 ms render leaves 8.3 ms.
  schedule.rendered(20'000);
  EXPECT_EQ(schedule.start_us(33'333), 1'000'000 + 33'333 - 27'000);
  // A render longer than the period: start at once (a time already past).
  schedule.rendered(40'000);
  EXPECT_LT(schedule.start_us(33'333), 1'000'000);
  // Only the last 8 renders are kept: after 8 short ones the long ones are
  // forgotten.
  for (int i = 0; i < 8; ++i) schedule.rendered(1'000);
  EXPECT_EQ(schedule.start_us(33'333), 1'000'000 + 33'333 - (1'000 + 250 + 2'000));
  // The next frame moves the schedule with it.
  schedule.frame_arrived(1'033'333);
  EXPECT_EQ(schedule.start_us(33'333), 1'033'333 + 33'333 - 3'250);
}

}  // namespace
}  // namespace tofguard::renderer
