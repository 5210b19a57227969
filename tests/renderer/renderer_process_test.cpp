// tofguard-renderer as a real process over real LCM (private network
// namespace): joint states and a depth frame in, the rendered frame and its
// labels out, with the numbers the library gives for the interpolated
// joints; unusable frames carry their reason and no TOF_RENDERED.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <iostream>
#include <map>
#include <optional>

#include "tofguard/common/camera_pose_message.hpp"
#include "tofguard/common/clock.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/heartbeat_t.hpp"
#include "tofguard/renderer/depth_renderer.hpp"
#include "tofguard/renderer/renderer_service.hpp"
#include "tool_support.hpp"

namespace tofguard::renderer {
namespace {

using tofguard::test::wait_until;

// Joint values that change linearly in time, so that interpolation between
// any two messages is exact: a_i(t) = 0.1*i + 0.5*i*(t - t0) [s].
robot_model::JointPositions arm_at(int64_t utime, int64_t t0) {
  robot_model::JointPositions q;
  for (int i = 1; i <= 7; ++i) q["a" + std::to_string(i)] = 0.1 * i + 0.5 * i * (utime - t0) * 1e-6;
  return q;
}

// config/sim.yaml without its occupant: these tests compare the process's
// frames with the library's renders of the arm and the scene
// (renderer_service_test renders the user).
const std::string& config_path() {
  static const std::string path = tofguard::test::sim_config_variant("renderer-process", {}, "occupant: ~\n");
  return path;
}

struct Bench {
  deployment::Config config = deployment::load_config(config_path(), nullptr);
  lcm::LCM safety{config.lcm.url};
  lcm::LCM images{config.lcm.image_url};
  std::map<int64_t, depth_image_t> rendered;  // by seq
  std::map<int64_t, link_labels_t> labels;
  heartbeat_t heartbeat;
  int64_t t0 = wall_utime();
  int64_t next_joint_utime = t0;
  int64_t seq = 0;

  Bench() {
    images.subscribe(config.channels.rendered, &Bench::on_rendered, this);
    images.subscribe(config.channels.labels, &Bench::on_labels, this);
    safety.subscribe(config.channels.heartbeat, &Bench::on_heartbeat, this);
  }
  void on_rendered(const lcm::ReceiveBuffer*, const std::string&, const depth_image_t* m) {
    rendered[m->seq] = *m;
  }
  void on_labels(const lcm::ReceiveBuffer*, const std::string&, const link_labels_t* m) {
    labels[m->seq] = *m;
  }
  void on_heartbeat(const lcm::ReceiveBuffer*, const std::string&, const heartbeat_t* m) {
    if (m->process == "tofguard-renderer") heartbeat = *m;
  }
  void pump() {
    images.handleTimeout(2);
    safety.handleTimeout(2);
  }
  void publish_joints(int64_t utime, const robot_model::JointPositions& q) {
    joint_state_t m;
    m.utime = utime;
    m.robot_id = config.robot.id;
    for (const auto& [name, value] : q) {
      m.name.push_back(name);
      m.position.push_back(value);
      m.velocity.push_back(0);
    }
    m.num_joints = static_cast<int32_t>(m.name.size());
    safety.publish(config.channels.joint_state, &m);
  }
  // Joint states every 10 ms of utime up to `until`: arm_at, or
  // `fixed_joints` when set.
  void publish_joints_until(int64_t until) {
    for (; next_joint_utime <= until; next_joint_utime += 10'000) {
      publish_joints(next_joint_utime, fixed_joints ? *fixed_joints : arm_at(next_joint_utime, t0));
    }
  }
  std::optional<robot_model::JointPositions> fixed_joints;
  void publish_pose(int64_t utime, const CameraPose& pose) {
    const camera_pose_t m = to_camera_pose_message(config.camera.id, utime, pose);
    safety.publish(config.channels.camera_pose, &m);
  }
  int64_t publish_frame(int64_t utime) {
    const Intrinsics& k = config.camera.intrinsics;
    const depth_image_t f = make_depth_image(config.camera.id, k, utime, ++seq, /*calibrated=*/true,
                                             std::vector<float>(k.width * k.height, 1.5f));
    images.publish(config.channels.depth, &f);
    return f.seq;
  }
};

TEST(RendererProcess, RendersFramesAtInterpolatedJointsAndMarksUnusableOnes) {
  tofguard::test::Subprocess process(
      "renderer-process", {tofguard::test::bin_dir() + "/tofguard-renderer", "--config", config_path()});
  Bench bench;

  // Until the process is up, keep sending joint states and a frame between
  // the last two of them.
  int64_t first_seq = 0;
  ASSERT_TRUE(wait_until(
      [&] { return first_seq != 0 && bench.rendered.count(first_seq) > 0; }, std::chrono::seconds(20),
      [&] {
        if (bench.rendered.empty()) {
          bench.publish_joints_until(bench.next_joint_utime + 10'000);
          first_seq = bench.publish_frame(bench.next_joint_utime - 10'000 - 3'700);  // between the last two
        }
        bench.pump();
      }))
      << process.stderr_text();
  // The renderer is up now. A frame sent while it was still joining its
  // multicast groups may have reached it without the joint state before it
  // (the safety and image sockets join one after the other), and was then
  // rendered at the nearest joint state, not interpolated: compare a frame
  // sent now. The joint states travel on the safety URL and the frame on the
  // image URL, so the frame can overtake the last of them: it lies between
  // two states that have three more behind them.
  bench.publish_joints_until(bench.next_joint_utime + 40'000);
  const int64_t compared_seq = bench.publish_frame(bench.next_joint_utime - 40'000 - 3'700);
  ASSERT_TRUE(wait_until([&] { return bench.rendered.count(compared_seq) > 0; }, std::chrono::seconds(5),
                         [&] { bench.pump(); }))
      << process.stderr_text();
  const depth_image_t& out = bench.rendered.at(compared_seq);
  ASSERT_EQ(bench.labels.count(out.seq), 1u);
  const link_labels_t& labels = bench.labels.at(out.seq);
  EXPECT_TRUE(labels.usable) << labels.unusable_reason;
  EXPECT_GT(labels.num_axes, 0) << "the kinematics as rendered";
  EXPECT_EQ(out.camera_id, bench.config.camera.id);
  EXPECT_EQ(out.width, 176);
  EXPECT_EQ(out.height, 144);
  EXPECT_EQ(out.fx, 221.0);
  EXPECT_EQ(out.num_pixels, 176 * 144);
  EXPECT_EQ(labels.utime, out.utime);
  EXPECT_EQ(labels.num_robot_links, 10);

  // The numbers: the library at the joints interpolated at the frame's utime.
  const deployment::Config& config = bench.config;
  const robot_model::SceneModel scene = robot_model::load_scene(
      config.robot.urdf_path, config.environment.urdf_paths, scene_options(config.renderer, config.robot));
  DepthRenderer renderer(scene, config.renderer.near_m, config.renderer.far_m);
  const RenderResult expected =
      renderer.render(arm_at(out.utime, bench.t0), config.camera.pose, config.camera.intrinsics);
  ASSERT_TRUE(expected.usable);
  int differing = 0, robot_pixels = 0;
  for (size_t i = 0; i < expected.depth_m.size(); ++i) {
    differing += std::abs(out.depth_mm[i] - std::lround(expected.depth_m[i] * 1000)) > 1 ||
                 labels.label[i] != expected.labels[i];
    robot_pixels += expected.labels[i] > 0 && expected.labels[i] < kLabelEnvironmentFirst;
  }
  EXPECT_GT(robot_pixels, 1000);
  EXPECT_EQ(differing, 0);

  // A frame far beyond the newest joint state: unusable, labels only.
  // (200 ms beyond: still beyond every joint state sent below, whichever
  // arrives first.)
  const int64_t late_seq = bench.publish_frame(bench.next_joint_utime - 10'000 + 200'000);
  // A frame whose joint state lacks a4. The frame can overtake that state
  // (other URL) and be extrapolated from the complete one before it: send
  // the same capture again (new seq) until one is judged after the state
  // without a4 arrived.
  robot_model::JointPositions without_a4 = arm_at(bench.next_joint_utime, bench.t0);
  without_a4.erase("a4");
  bench.publish_joints(bench.next_joint_utime, without_a4);
  int64_t missing_seq = -1;
  for (int attempt = 0; attempt < 20 && missing_seq < 0; ++attempt) {
    const int64_t seq = bench.publish_frame(bench.next_joint_utime);
    ASSERT_TRUE(wait_until([&] { return bench.labels.count(seq) > 0; }, std::chrono::seconds(10),
                           [&] { bench.pump(); }))
        << process.stderr_text();
    if (!bench.labels.at(seq).usable) missing_seq = seq;
  }
  ASSERT_GE(missing_seq, 0) << "no frame judged after the joint state without a4 arrived";
  bench.next_joint_utime += 10'000;
  // Then a good one, bracketed by complete joint states. The joint states
  // travel on the safety URL and the frame on the image URL, so under load
  // the frame can overtake them; the renderer then (rightly) extrapolates
  // from the state without a4 and marks it unusable. Send the same capture
  // again (new seq) until one is rendered after its joint states arrived.
  bench.publish_joints_until(bench.next_joint_utime + 10'000);
  const int64_t good_utime = bench.next_joint_utime - 15'000;
  int64_t good_seq = -1;
  for (int attempt = 0; attempt < 20; ++attempt) {
    const int64_t seq = bench.publish_frame(good_utime);
    ASSERT_TRUE(wait_until([&] { return bench.labels.count(seq) > 0; }, std::chrono::seconds(10),
                           [&] { bench.pump(); }))
        << process.stderr_text();
    if (bench.labels.at(seq).usable) {
      good_seq = seq;
      break;
    }
    // Overtaken: extrapolated from the state without a4, or further than
    // the extrapolation limit beyond it.
    const std::string& why = bench.labels.at(seq).unusable_reason;
    EXPECT_TRUE(why == "joint 'a4' missing from the joint state" ||
                why.find("older than the frame (limit 20.000000 ms)") != std::string::npos)
        << why;
  }
  ASSERT_GE(good_seq, 0) << "no frame rendered after its bracketing joint states arrived";
  // The frames before it may have been dropped as stale (only the newest
  // pending one is rendered); those that were rendered say why not usable.
  if (bench.labels.count(late_seq)) {
    EXPECT_FALSE(bench.labels.at(late_seq).usable);
    EXPECT_NE(bench.labels.at(late_seq).unusable_reason.find("older than the frame"), std::string::npos)
        << bench.labels.at(late_seq).unusable_reason;
    EXPECT_EQ(bench.labels.at(late_seq).num_pixels, 0);
  }
  if (bench.labels.count(missing_seq)) {
    EXPECT_FALSE(bench.labels.at(missing_seq).usable);
    EXPECT_EQ(bench.labels.at(missing_seq).unusable_reason, "joint 'a4' missing from the joint state");
  }
  std::cout << "late frame " << (bench.labels.count(late_seq) ? "labelled" : "dropped")
            << ", missing-joint frame " << (bench.labels.count(missing_seq) ? "labelled" : "dropped") << "\n";
  EXPECT_EQ(bench.rendered.count(late_seq), 0u);
  EXPECT_EQ(bench.rendered.count(missing_seq), 0u);
  EXPECT_TRUE(bench.labels.at(good_seq).usable) << bench.labels.at(good_seq).unusable_reason;
  ASSERT_TRUE(wait_until([&] { return bench.rendered.count(good_seq) > 0; }, std::chrono::seconds(5),
                         [&] { bench.pump(); }));

  // Every frame the process took in was either rendered or dropped.
  ASSERT_TRUE(wait_until([&] { return bench.heartbeat.last_frame_utime == bench.labels.at(good_seq).utime; },
                         std::chrono::seconds(5), [&] { bench.pump(); }));
  const int64_t frames_sent = bench.seq;
  EXPECT_LE(bench.heartbeat.frames_out + bench.heartbeat.frames_dropped, frames_sent);
  EXPECT_EQ(bench.heartbeat.validation_errors, 0);
  EXPECT_EQ(bench.heartbeat.decode_errors, 0);

  process.signal(SIGTERM);
  EXPECT_EQ(process.wait(std::chrono::seconds(5)), 0) << process.stderr_text();
}

// Robot pixels whose label or depth (beyond 1 mm) differ from `expected`.
int differing_pixels(const depth_image_t& out, const link_labels_t& labels, const RenderResult& expected) {
  int differing = 0;
  for (size_t i = 0; i < expected.depth_m.size(); ++i) {
    differing += std::abs(out.depth_mm[i] - std::lround(expected.depth_m[i] * 1000)) > 1 ||
                 labels.label[i] != expected.labels[i];
  }
  return differing;
}

TEST(RendererProcess, FollowsAMovingCameraAtEachFramesUtime) {
  tofguard::test::Subprocess process(
      "renderer-process-moving-camera",
      {tofguard::test::bin_dir() + "/tofguard-renderer", "--config", config_path()});
  Bench bench;
  const deployment::Config& config = bench.config;
  // The configured pose panned by `deg` about the world's vertical axis.
  auto panned = [&](double deg) {
    CameraPose p = config.camera.pose;
    p.rotation =
        Eigen::Quaterniond(Eigen::AngleAxisd(deg * M_PI / 180, Eigen::Vector3d::UnitZ())) * p.rotation;
    return p;
  };
  // The head pans 6 deg between two readings 66 ms apart (90 deg/s).
  const int64_t t0 = bench.t0;
  const int64_t t1 = t0 + 66'000;
  // Once the process listens (its heartbeat comes after it subscribed).
  ASSERT_TRUE(
      wait_until([&] { return bench.heartbeat.utime > 0; }, std::chrono::seconds(20), [&] { bench.pump(); }))
      << process.stderr_text();
  // Joint states and both readings, until the process has taken them all
  // in (11 joint states + 2 poses; the first messages after it subscribed
  // can be lost, and repeats are ignored).
  int64_t sent_us = 0;
  ASSERT_TRUE(wait_until([&] { return bench.heartbeat.frames_in >= 13; }, std::chrono::seconds(10),
                         [&] {
                           if (monotonic_us() - sent_us > 300'000) {
                             sent_us = monotonic_us();
                             bench.next_joint_utime = t0;
                             bench.publish_joints_until(t1 + 40'000);
                             bench.publish_pose(t0, panned(0));
                             bench.publish_pose(t1, panned(6));
                           }
                           bench.pump();
                         }))
      << bench.heartbeat.frames_in;

  // A frame between the readings, and one past the newest beyond the 40 ms
  // limit. Until the process is up, and while a frame may overtake its pose
  // (poses travel on the safety URL, frames on the image URL), send them
  // again with new seqs.
  const int64_t mid_utime = t0 + 22'000;  // a third of the way: pan 2 deg
  const int64_t late_utime = t1 + 41'000;
  int64_t mid_seq = -1;
  int64_t late_seq = -1;
  int64_t mid_sent_us = 0;
  ASSERT_TRUE(wait_until(
      [&] {
        return mid_seq > 0 && bench.labels.count(mid_seq) && bench.labels.at(mid_seq).usable &&
               bench.rendered.count(mid_seq) && late_seq > 0 && bench.labels.count(late_seq);
      },
      std::chrono::seconds(20),
      [&] {
        // (A frame sent while the process was still subscribing is lost.)
        const bool unanswered =
            mid_seq > 0 && !bench.labels.count(mid_seq) && monotonic_us() - mid_sent_us > 300'000;
        if (mid_seq < 0 || unanswered || (bench.labels.count(mid_seq) && !bench.labels.at(mid_seq).usable)) {
          mid_seq = bench.publish_frame(mid_utime);
          mid_sent_us = monotonic_us();
        }
        if (mid_seq > 0 && bench.labels.count(mid_seq) && bench.labels.at(mid_seq).usable && late_seq < 0) {
          late_seq = bench.publish_frame(late_utime);
        }
        bench.pump();
      }))
      << process.stderr_text() << "heartbeat in " << bench.heartbeat.frames_in << " validation "
      << bench.heartbeat.validation_errors << " decode " << bench.heartbeat.decode_errors << " status "
      << bench.heartbeat.status << "; mid seq " << mid_seq << " late seq " << late_seq
      << ", labels: " << [&] {
           std::string why;
           for (const auto& [seq, l] : bench.labels)
             why += std::to_string(seq) + ": " + (l.usable ? "usable" : l.unusable_reason) + "; ";
           return why;
         }();

  const robot_model::SceneModel scene = robot_model::load_scene(
      config.robot.urdf_path, config.environment.urdf_paths, scene_options(config.renderer, config.robot));
  DepthRenderer renderer(scene, config.renderer.near_m, config.renderer.far_m);
  const RenderResult at_mid = renderer.render(arm_at(mid_utime, t0), panned(2), config.camera.intrinsics);
  const RenderResult unpanned = renderer.render(arm_at(mid_utime, t0), panned(0), config.camera.intrinsics);
  ASSERT_TRUE(at_mid.usable);
  EXPECT_EQ(differing_pixels(bench.rendered.at(mid_seq), bench.labels.at(mid_seq), at_mid), 0);
  // (The newest or the oldest pose alone would not do.)
  EXPECT_GT(differing_pixels(bench.rendered.at(mid_seq), bench.labels.at(mid_seq), unpanned), 500);

  EXPECT_FALSE(bench.labels.at(late_seq).usable);
  EXPECT_EQ(bench.labels.at(late_seq).unusable_reason,
            "newest camera pose of moving camera 'tof-mast' is 41.0 ms older than the frame (limit 40.0 ms)");
  EXPECT_EQ(bench.rendered.count(late_seq), 0u);

  process.signal(SIGTERM);
  EXPECT_EQ(process.wait(std::chrono::seconds(5)), 0) << process.stderr_text();
}

// Hits and misses from the renderer's heartbeat status ({-1, -1}: none said).
std::pair<int, int> prediction_counts(const heartbeat_t& hb) {
  const auto stats = RendererService::prediction_stats_from_status(hb.status);
  if (!stats) return {-1, -1};
  return {static_cast<int>(stats->hits), static_cast<int>(stats->misses)};
}

TEST(RendererProcess, APlannedFrameIsRenderedAheadAndIdenticalToTheNormalRendering) {
  tofguard::test::Subprocess process(
      "renderer-process-prediction",
      {tofguard::test::bin_dir() + "/tofguard-renderer", "--config", config_path()});
  Bench bench;
  const deployment::Config& config = bench.config;
  ASSERT_TRUE(
      wait_until([&] { return bench.heartbeat.utime > 0; }, std::chrono::seconds(20), [&] { bench.pump(); }))
      << process.stderr_text();
  // The arm holds still where its plan says, for 10 s.
  const robot_model::JointPositions planned = arm_at(bench.t0 + 300'000, bench.t0);
  bench.fixed_joints = planned;
  planned_trajectory_t plan;
  plan.utime = bench.t0;
  for (const auto& [name, value] : planned) plan.joint_name.push_back(name);
  plan.num_joints = static_cast<int32_t>(plan.joint_name.size());
  plan.point_utime = {bench.t0, bench.t0 + 10'000'000};
  plan.num_points = 2;
  for (int p = 0; p < 2; ++p) {
    plan.position.emplace_back();
    for (const auto& [name, value] : planned) plan.position.back().push_back(value);
  }

  // Frames every 33 ms of utime, one at a time, each after its joint states;
  // the plan sent again until the process has it.
  std::vector<int64_t> seqs;
  // (The first messages after the process subscribed can be lost: a frame
  // without an answer is sent again with a new seq.)
  auto send_frame = [&](int64_t utime) {
    bench.publish_joints_until(utime + 20'000);
    for (int attempt = 0; attempt < 5; ++attempt) {
      const int64_t seq = bench.publish_frame(utime);
      const auto answered = [&] {
        return bench.labels.count(seq) > 0 && (!bench.labels.at(seq).usable || bench.rendered.count(seq) > 0);
      };
      if (wait_until(answered, std::chrono::seconds(1), [&] { bench.pump(); })) {
        seqs.push_back(seq);
        return seq;
      }
    }
    ADD_FAILURE() << "no labels for the frame at " << utime << "\n" << process.stderr_text();
    return int64_t{-1};
  };
  int64_t utime = bench.t0 + 33'000;
  ASSERT_TRUE(wait_until([&] { return prediction_counts(bench.heartbeat).first >= 3; },
                         std::chrono::seconds(20),
                         [&] {
                           bench.safety.publish(config.channels.planned_trajectory, &plan);
                           send_frame(utime);
                           utime += 33'000;
                           // Give the process its idle time to render ahead, as a camera does.
                           const int64_t until = monotonic_us() + 30'000;
                           while (monotonic_us() < until) bench.pump();
                         }))
      << process.stderr_text() << bench.heartbeat.status;
  // The counts once the heartbeat has caught up with the last frame.
  const int64_t last_utime = utime - 33'000;
  ASSERT_TRUE(wait_until([&] { return bench.heartbeat.last_frame_utime == last_utime; },
                         std::chrono::seconds(5), [&] { bench.pump(); }));
  const auto [hits, misses] = prediction_counts(bench.heartbeat);
  EXPECT_EQ(misses, 0) << bench.heartbeat.status;

  // Every rendered frame is the library's rendering at the planned joints:
  // those published from a prediction are identical to the others.
  const robot_model::SceneModel scene = robot_model::load_scene(
      config.robot.urdf_path, config.environment.urdf_paths, scene_options(config.renderer, config.robot));
  DepthRenderer renderer(scene, config.renderer.near_m, config.renderer.far_m);
  const RenderResult expected = renderer.render(planned, config.camera.pose, config.camera.intrinsics);
  ASSERT_TRUE(expected.usable);
  int compared = 0;
  for (const int64_t seq : seqs) {
    if (!bench.rendered.count(seq)) continue;
    ++compared;
    const depth_image_t& out = bench.rendered.at(seq);
    for (size_t i = 0; i < expected.depth_m.size(); ++i) {
      ASSERT_EQ(out.depth_mm[i], static_cast<int16_t>(std::round(expected.depth_m[i] * 1000.0)))
          << seq << " " << i;
      ASSERT_EQ(bench.labels.at(seq).label[i], expected.labels[i]) << seq << " " << i;
    }
  }
  EXPECT_GE(compared, hits);

  // The arm leaves the plan by 0.2 deg at a2: a miss, rendered at the
  // reported joints.
  robot_model::JointPositions off = planned;
  off["a2"] += 0.2 * M_PI / 180;
  bench.fixed_joints = off;
  // Its joint states first, taken in before the frame comes (else the frame
  // may overtake them and be extrapolated from the planned ones).
  const int64_t in_before = bench.heartbeat.frames_in;
  const int64_t joint_states = (utime + 20'000 - bench.next_joint_utime) / 10'000 + 1;
  bench.publish_joints_until(utime + 20'000);
  ASSERT_TRUE(wait_until([&] { return bench.heartbeat.frames_in >= in_before + joint_states; },
                         std::chrono::seconds(5), [&] { bench.pump(); }));
  const int64_t off_seq = send_frame(utime);
  ASSERT_GE(off_seq, 0);
  ASSERT_TRUE(wait_until([&] { return bench.heartbeat.last_frame_utime == utime; }, std::chrono::seconds(5),
                         [&] { bench.pump(); }))
      << bench.heartbeat.status;
  EXPECT_EQ(prediction_counts(bench.heartbeat).first, hits);
  EXPECT_EQ(prediction_counts(bench.heartbeat).second, 1) << bench.heartbeat.status;
  ASSERT_TRUE(bench.rendered.count(off_seq));
  const RenderResult at_off = renderer.render(off, config.camera.pose, config.camera.intrinsics);
  EXPECT_EQ(differing_pixels(bench.rendered.at(off_seq), bench.labels.at(off_seq), at_off), 0);
  std::cout << "prediction: " << bench.heartbeat.status << "\n";

  process.signal(SIGTERM);
  EXPECT_EQ(process.wait(std::chrono::seconds(5)), 0) << process.stderr_text();
}

}  // namespace
}  // namespace tofguard::renderer
