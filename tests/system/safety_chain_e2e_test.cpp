// The whole safety chain as its users run it: the simulated arm and the
// simulated ToF camera (with its noise), tofguard-renderer,
// tofguard-discrepancy, tofguard-risk and tofguard-intervene as real
// processes over real LCM in a private network namespace.
//
// Every fault must withdraw the permission to move within 200 ms of the
// first camera frame it affects (for stalls: of the deadline), with the
// right cause. Times are taken on this test's monotonic clock when the
// messages arrive here.
#include <gtest/gtest.h>
#include <signal.h>
#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <deque>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <thread>

#include "quiet_subscriptions.hpp"
#include "recovery_deadline.hpp"
#include "tofguard/authenticated_message_t.hpp"
#include "tofguard/camera_pose_t.hpp"
#include "tofguard/common/clock.hpp"
#include "tofguard/common/risk_names.hpp"
#include "tofguard/deployment/config.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/discrepancy_t.hpp"
#include "tofguard/heartbeat_t.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/motion_estimate_t.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/robot_model/kinematics.hpp"
#include "tofguard/robot_model/occupant_model.hpp"
#include "tofguard/robot_model/scene_model.hpp"
#include "tofguard/safety_status_t.hpp"
#include "tofguard/sim_camera_fault_t.hpp"
#include "tofguard/sim_joint_fault_t.hpp"
#include "tool_support.hpp"

namespace tofguard::test {
namespace {

constexpr int64_t kStopBudgetUs = 200'000;

class Chain {
 public:
  Chain()
      : config_path_(sim_config_variant("e2e-chain")),
        config_(deployment::load_config(config_path_, nullptr)),
        safety_(config_.lcm.url),
        images_(config_.lcm.image_url) {
    // Quiet: the nominal part sends malformed messages on these channels.
    listening_.add<safety_status_t>(safety_, config_.channels.status, [this](auto& m) { on_status(m); });
    listening_.add<risk_t>(safety_, config_.channels.risk, [this](auto& m) { on_risk(m); });
    listening_.add<depth_image_t>(images_, config_.channels.depth, [this](auto& m) { on_depth(m); });
    listening_.add<joint_state_t>(safety_, config_.channels.joint_state, [this](auto& m) { on_joints(m); });
    listening_.add<heartbeat_t>(safety_, config_.channels.heartbeat, [this](auto& m) { on_heartbeat(m); });
    listening_.add<motion_estimate_t>(safety_, config_.channels.motion_estimate,
                                      [this](auto& m) { on_estimate(m); });
    listening_.add<discrepancy_t>(safety_, config_.channels.discrepancy, [this](auto& m) {
      ++frames_compared;
      most_arm_hidden_by_user = std::max(most_arm_hidden_by_user, m.num_robot_hidden_by_user);
    });
    safety_.getFileno();
    images_.getFileno();
    for (const char* name :
         {"tofguard-intervene", "tofguard-risk", "tofguard-discrepancy", "tofguard-renderer",
          "tofguard-joints-sim", "tofguard-camera", "tofguard-estimator"}) {
      start(name);
    }
  }

  void start(const std::string& name) {
    processes_[name] = std::make_unique<Subprocess>(
        "e2e-" + name + "-" + std::to_string(++starts_),
        std::vector<std::string>{bin_dir() + "/" + name, "--config", config_path_});
  }
  Subprocess& process(const std::string& name) { return *processes_.at(name); }
  std::string stderr_of_all() {
    std::string text;
    for (auto& [name, p] : processes_) text += "--- " + name + ":\n" + p->stderr_text();
    return text;
  }

  // While on, sends malformed messages on every channel the chain
  // subscribes to, a few times a second: wrong fingerprints, truncated
  // bytes, sizes that do not fit, NaN, a non-unit quaternion.
  bool send_malformed = false;
  int malformed_rounds = 0;

  void send_malformed_round() {
    const uint8_t junk[7] = {9, 8, 7, 6, 5, 4, 3};
    joint_state_t nan_joints;
    nan_joints.utime = wall_utime();
    nan_joints.robot_id = config_.robot.id;
    nan_joints.num_joints = 1;
    nan_joints.name = {"a1"};
    nan_joints.position = {std::nan("")};
    nan_joints.velocity = {0};
    depth_image_t bad_size;
    bad_size.utime = wall_utime();
    bad_size.seq = 1;
    bad_size.camera_id = config_.camera.id;
    bad_size.width = 176;
    bad_size.height = 144;
    bad_size.fx = bad_size.fy = 200;
    bad_size.cx = bad_size.cy = 80;
    bad_size.num_pixels = 10;
    bad_size.depth_mm.assign(10, 1000);
    bad_size.num_amplitude = 0;
    camera_pose_t bad_pose;
    bad_pose.utime = wall_utime();
    bad_pose.camera_id = config_.camera.id;
    bad_pose.frame_id = "world";
    for (int i = 0; i < 3; ++i) bad_pose.translation[i] = 0;
    for (int i = 0; i < 4; ++i) bad_pose.rotation[i] = 0.9;
    images_.publish(config_.channels.depth, &bad_size);
    images_.publish(config_.channels.depth, junk, sizeof junk);
    images_.publish(config_.channels.rendered, &nan_joints);
    images_.publish(config_.channels.labels, junk, sizeof junk);
    safety_.publish(config_.channels.joint_state, &nan_joints);
    safety_.publish(config_.channels.joint_state, junk, sizeof junk);
    safety_.publish(config_.channels.sim_true_joint_state, &nan_joints);
    safety_.publish(config_.channels.camera_pose, &bad_pose);
    safety_.publish(config_.channels.discrepancy, junk, sizeof junk);
    safety_.publish(config_.channels.risk, &nan_joints);
    safety_.publish(config_.channels.status, junk, sizeof junk);
    safety_.publish(config_.channels.heartbeat, junk, sizeof junk);
    safety_.publish(config_.channels.reset, junk, sizeof junk);
    safety_.publish(config_.channels.sim_joint_fault, junk, sizeof junk);
    safety_.publish(config_.channels.sim_camera_fault, junk, sizeof junk);
    safety_.publish(config_.channels.motion_estimate, junk, sizeof junk);
    safety_.publish(config_.channels.motion_estimate, &nan_joints);
    safety_.publish(config_.channels.planned_trajectory, junk, sizeof junk);
    // The signed channels (docs/security.md): garbage, and a valid envelope
    // signed with no key anyone holds.
    safety_.publish(config_.channels.risk_auth, junk, sizeof junk);
    safety_.publish(config_.channels.status_auth, junk, sizeof junk);
    safety_.publish(config_.channels.reset_auth, &nan_joints);
    authenticated_message_t forged{};
    forged.utime = wall_utime();
    forged.seq = forged.utime + 1'000'000'000;
    forged.channel = config_.channels.status;
    forged.key_id = "0000000000000000";
    forged.payload_size = 3;
    forged.payload = {1, 2, 3};
    safety_.publish(config_.channels.status_auth, &forged);
    safety_.publish(config_.channels.risk_auth, &forged);
    ++malformed_rounds;
  }

  // Handles what arrives (and keeps a published camera pose going).
  void pump() {
    if (send_malformed && monotonic_us() - last_malformed_us_ > 250'000) {
      last_malformed_us_ = monotonic_us();
      send_malformed_round();
    }
    if (camera_pose_ && monotonic_us() - last_pose_us_ > 100'000) {
      last_pose_us_ = monotonic_us();
      camera_pose_->utime = wall_utime();
      safety_.publish(config_.channels.camera_pose, &*camera_pose_);
    }
    images_.handleTimeout(2);
    while (safety_.handleTimeout(0) > 0) {
    }
  }
  bool wait(const std::function<bool()>& condition, std::chrono::milliseconds deadline) {
    return wait_until(condition, deadline, [this] { pump(); });
  }

  // Waits for `frames` SAFE verdicts in a row, then resets until accepted.
  void bring_to_motion(const std::string& why) {
    safe_streak_ = 0;
    const int64_t waiting_since_us = monotonic_us();
    ASSERT_TRUE(wait([&] { return safe_streak_ >= 15; }, kRecoveryDeadline))
        << "never SAFE: last risk " << describe_last_risk() << "\n"
        << stderr_of_all();
    std::cout << "15 SAFE verdicts in a row " << (monotonic_us() - waiting_since_us) / 1000
              << " ms after the wait began (" << why << ")" << std::endl;
    std::string out;
    int code = -1;
    for (int attempt = 0; attempt < 5 && code != 0; ++attempt) {
      // tofguard-reset blocks; the chain keeps running on its own.
      code = run_command(
          "e2e-reset",
          {bin_dir() + "/tofguard-reset", "--config", config_path_, "--who", "e2e", "--why", why}, &out);
      pump();
    }
    ASSERT_EQ(code, 0) << out << " last risk " << describe_last_risk();
    ASSERT_TRUE(wait([&] { return motion_allowed_; }, std::chrono::seconds(2)));
  }

  // Runs `inject` and returns how long after the first affected camera
  // frame (the first captured after it) the permission was withdrawn;
  // fills the stop's status. 0 when the stop came before that frame
  // arrived: a fault that reaches the chain beside the camera (a camera pose
  // on CAMERA_POSE) already affects the frames in flight.
  int64_t stop_latency_after_frame(const std::function<void()>& inject, safety_status_t* stop) {
    const int64_t injected_utime = wall_utime();
    risk_log_.clear();
    risk_details_.clear();
    inject();
    first_affected_arrival_us_ = -1;
    affected_after_utime_ = injected_utime;
    stopped_at_us_ = -1;
    EXPECT_TRUE(wait([&] { return stopped_at_us_ > 0; }, std::chrono::seconds(3)))
        << "no stop; last risk " << describe_last_risk();
    *stop = stop_status_;
    std::cout << "risk verdicts after the fault:\n" << risk_log_ << std::flush;
    if (stopped_at_us_ < 0) return std::numeric_limits<int64_t>::max();  // no stop (failed above)
    if (first_affected_arrival_us_ < 0 || first_affected_arrival_us_ > stopped_at_us_) {
      std::cout << "the stop came on a frame captured before the fault" << std::endl;
      return 0;
    }
    return stopped_at_us_ - first_affected_arrival_us_;
  }

  // For stalls: returns how long after `since_us` (monotonic) the
  // permission was withdrawn.
  int64_t stop_latency_since(int64_t since_us, safety_status_t* stop) {
    stopped_at_us_ = -1;
    risk_log_.clear();
    EXPECT_TRUE(wait([&] { return stopped_at_us_ > 0; }, std::chrono::seconds(3)))
        << "no stop; last risk " << describe_last_risk();
    *stop = stop_status_;
    return stopped_at_us_ - since_us;
  }

  void camera_fault(int32_t kind, double duration_s = 1000) {
    if (kind == sim_camera_fault_t::INTRUDING_OBJECT) {
      // A 10 cm box (a hand) standing still 15 cm beside the forearm's
      // joint (link5's origin), to the image's left (the arm stands in the
      // image's right half): within 0.2 m of the arm, not in front of it.
      intrude(object_beside_forearm_m(-0.15), Eigen::Vector3d::Constant(0.10), duration_s);
      return;
    }
    sim_camera_fault_t f{};
    f.utime = wall_utime();
    f.camera_id = config_.camera.id;
    f.kind = kind;
    f.duration_s = duration_s;
    safety_.publish(config_.channels.sim_camera_fault, &f);
  }
  // A box of `size_m` standing still at `at_m` (world frame) from now on.
  void intrude(const Eigen::Vector3d& at_m, const Eigen::Vector3d& size_m, double duration_s = 1000) {
    sim_camera_fault_t f{};
    f.utime = wall_utime();
    f.camera_id = config_.camera.id;
    f.kind = sim_camera_fault_t::INTRUDING_OBJECT;
    f.duration_s = duration_s;
    for (int i = 0; i < 3; ++i) {
      f.object_size_m[i] = size_m[i];
      f.object_position_m[i] = at_m[i];
    }
    safety_.publish(config_.channels.sim_camera_fault, &f);
  }
  // Where the seated user's `link` (its first shape's centre) is in the
  // world, as the config's occupant model seats it.
  Eigen::Vector3d user_part_m(const std::string& link) {
    const robot_model::SceneModel scene = robot_model::load_scene(
        config_.robot.urdf_path, config_.environment.urdf_paths, robot_model::SceneOptions{});
    EXPECT_TRUE(config_.occupant.has_value());
    const robot_model::OccupantModel user = robot_model::load_occupant(
        config_.occupant->urdf_path, robot_model::fixed_link_pose(scene, config_.occupant->seated_on));
    for (const robot_model::OccupantPart& part : user.parts) {
      if (part.link_name == link) return part.shapes.front().frame_from_shape.translation();
    }
    ADD_FAILURE() << "no user link " << link;
    return Eigen::Vector3d::Zero();
  }
  void joint_fault(const std::string& joint, double offset_rad) {
    sim_joint_fault_t f;
    f.utime = wall_utime();
    f.joint = joint;
    f.offset = offset_rad;
    safety_.publish(config_.channels.sim_joint_fault, &f);
  }
  void publish_camera_pose(const Eigen::Vector3d& offset_m) {
    camera_pose_t pose;
    pose.camera_id = config_.camera.id;
    pose.frame_id = config_.camera.pose.frame_id;
    const Eigen::Vector3d t = config_.camera.pose.translation_m + offset_m;
    const Eigen::Quaterniond& q = config_.camera.pose.rotation;
    for (int i = 0; i < 3; ++i) pose.translation[i] = t[i];
    pose.rotation[0] = q.w();
    pose.rotation[1] = q.x();
    pose.rotation[2] = q.y();
    pose.rotation[3] = q.z();
    camera_pose_ = pose;
    last_pose_us_ = 0;
  }

  // SAFETY_DISCREPANCY frames since these were last zeroed, and the most
  // robot pixels the user's body hid in one of them.
  int frames_compared = 0;
  int32_t most_arm_hidden_by_user = 0;

  int64_t last_depth_arrival_us() const { return last_depth_arrival_us_; }
  bool motion_allowed() const { return motion_allowed_; }
  int stops_seen() const { return stops_seen_; }
  std::string describe_last_risk() const {
    return risk_level_name(last_risk_.level) + " " + risk_cause_name(last_risk_.cause) + " suspect '" +
           last_risk_.suspect + "' seq " + std::to_string(last_risk_.seq) + " | " + last_risk_.detail;
  }
  const deployment::Config& config() const { return config_; }
  // A point `distance_m` from link5's origin along the camera's x axis
  // (image right), at the latest joint state (world frame, metres).
  Eigen::Vector3d object_beside_forearm_m(double distance_m) {
    const robot_model::KinematicTree tree = robot_model::load_kinematic_tree(config_.robot.urdf_path);
    const robot_model::LinkPoses poses = robot_model::forward_kinematics(tree, latest_joints_);
    EXPECT_TRUE(poses.usable) << poses.unusable_reason;
    const auto names = tree.link_names();
    const size_t link5 = std::find(names.begin(), names.end(), "link5") - names.begin();
    EXPECT_LT(link5, names.size());
    const Eigen::Vector3d forearm = poses.world_from_link.at(link5).translation();
    const Eigen::Vector3d image_right = config_.camera.pose.rotation * Eigen::Vector3d::UnitX();
    return forearm + distance_m * image_right;
  }

 private:
  void on_status(const safety_status_t& s) {
    if (motion_allowed_ && !s.motion_allowed) {
      ++stops_seen_;
      if (stopped_at_us_ < 0) {
        stopped_at_us_ = monotonic_us();
        stop_status_ = s;
      }
    }
    motion_allowed_ = s.motion_allowed;
  }
  void on_risk(const risk_t& r) {
    last_risk_ = r;
    if (r.seq >= 0) risk_details_.push_back(r.detail);
    if (r.seq >= 0 && std::count(risk_log_.begin(), risk_log_.end(), '\n') < 12) {
      risk_log_ += "  seq " + std::to_string(r.seq) + " " + risk_level_name(r.level) + " " +
                   risk_cause_name(r.cause) + " '" + r.suspect + "': " + r.detail + "\n";
    }
    if (r.seq < 0) return;
    safe_streak_ = r.level == risk_t::SAFE ? safe_streak_ + 1 : 0;
  }
  void on_estimate(const motion_estimate_t& e) {
    std::string line = "  estimate seq " + std::to_string(e.seq) + " trigger " + std::to_string(e.trigger) +
                       (e.usable ? "" : " unusable: " + e.unusable_reason) +
                       (e.converged ? " converged" : " not converged") + " it " +
                       std::to_string(e.iterations) + " res " + std::to_string(e.residual_before_mm) + "->" +
                       std::to_string(e.residual_after_mm) + " mm, offsets deg:";
    for (int i = 0; i < e.num_joints; ++i) {
      line += " " + e.joint_name[i] + "=" +
              std::to_string((e.estimated_position[i] - e.reported_position[i]) * 180 / M_PI) + "+-" +
              std::to_string(e.position_sigma[i] * 180 / M_PI);
    }
    line += " cam " + std::to_string(e.correction_translation[0]) + "," +
            std::to_string(e.correction_translation[1]) + "," + std::to_string(e.correction_translation[2]) +
            " us " + std::to_string(e.compute_us);
    estimate_log_.push_back(line);
  }
  void on_joints(const joint_state_t& j) {
    for (int i = 0; i < j.num_joints; ++i) latest_joints_[j.name[i]] = j.position[i];
  }
  void on_depth(const depth_image_t& d) {
    last_depth_arrival_us_ = monotonic_us();
    if (first_affected_arrival_us_ < 0 && affected_after_utime_ > 0 && d.utime >= affected_after_utime_) {
      first_affected_arrival_us_ = last_depth_arrival_us_;
    }
  }

  std::string config_path_;
  deployment::Config config_;
  lcm::LCM safety_;
  lcm::LCM images_;
  QuietSubscriptions listening_;
  std::map<std::string, std::unique_ptr<Subprocess>> processes_;
  int starts_ = 0;
  bool motion_allowed_ = false;
  int stops_seen_ = 0;
  int safe_streak_ = 0;
  risk_t last_risk_{};
  int64_t stopped_at_us_ = -1;
  safety_status_t stop_status_{};
  int64_t affected_after_utime_ = 0;
  int64_t first_affected_arrival_us_ = -1;
  int64_t last_depth_arrival_us_ = 0;
  std::optional<camera_pose_t> camera_pose_;
  int64_t last_malformed_us_ = 0;
  std::map<std::string, heartbeat_t> heartbeats_;

 public:
  const std::map<std::string, heartbeat_t>& heartbeats() const { return heartbeats_; }
  void on_heartbeat(const heartbeat_t& hb) { heartbeats_[hb.process] = hb; }

 private:
  int64_t last_pose_us_ = 0;
  robot_model::JointPositions latest_joints_;
  std::string risk_log_;
  std::vector<std::string> risk_details_;  // of frame verdicts since the last fault
  std::vector<std::string> estimate_log_;  // one line per MOTION_ESTIMATE

 public:
  const std::vector<std::string>& estimate_log() const { return estimate_log_; }

 public:
  // The frame verdicts since the last fault whose detail contains both.
  std::vector<std::string> details_with(const std::string& text, const std::string& and_text) const {
    std::vector<std::string> out;
    for (const std::string& d : risk_details_) {
      if (d.find(text) != std::string::npos && d.find(and_text) != std::string::npos) out.push_back(d);
    }
    return out;
  }

  // Waits for a frame verdict since the last fault whose detail contains
  // `text`; returns that detail, or "" when none came within `deadline`.
  std::string wait_for_detail(const std::string& text, std::chrono::milliseconds deadline,
                              const std::string& and_text = "") {
    std::string found;
    wait(
        [&] {
          for (const std::string& d : risk_details_) {
            if (d.find(text) != std::string::npos && d.find(and_text) != std::string::npos) {
              found = d;
              return true;
            }
          }
          return false;
        },
        deadline);
    return found;
  }
};

#define EXPECT_STOP(latency_us, status, expected_cause)                                             \
  do {                                                                                              \
    std::cout << "stop " << (latency_us) / 1000.0 << " ms after the first affected frame, cause "   \
              << risk_cause_name((status).cause) << ": " << (status).reason << std::endl;           \
    EXPECT_LE(latency_us, kStopBudgetUs) << "stop took " << (latency_us) / 1000 << " ms";           \
    EXPECT_EQ(risk_cause_name((status).cause), risk_cause_name(expected_cause)) << (status).reason; \
    EXPECT_FALSE((status).motion_allowed);                                                          \
    EXPECT_TRUE((status).latched);                                                                  \
  } while (0)

TEST(SafetyChainE2E, NominalMotionThenEveryFaultStopsTheArmWithItsCause) {
  Chain chain;
  chain.bring_to_motion("start of the test");
  if (HasFatalFailure()) return;

  {
    SCOPED_TRACE("nominal: 20 s of motion without a stop, with malformed input on every channel");
    std::map<std::string, heartbeat_t> before = chain.heartbeats();
    chain.send_malformed = true;
    const int64_t start_us = monotonic_us();
    const int stops_before = chain.stops_seen();
    chain.wait([&] { return monotonic_us() - start_us > 20'000'000 || chain.stops_seen() > stops_before; },
               std::chrono::seconds(25));
    chain.send_malformed = false;
    EXPECT_EQ(chain.stops_seen(), stops_before) << chain.describe_last_risk();
    EXPECT_TRUE(chain.motion_allowed());
    EXPECT_GE(chain.malformed_rounds, 50);
    // Every process dropped and counted what it could not use, and lives.
    for (const char* name :
         {"tofguard-intervene", "tofguard-risk", "tofguard-discrepancy", "tofguard-renderer",
          "tofguard-joints-sim", "tofguard-camera", "tofguard-estimator"}) {
      ASSERT_TRUE(chain.heartbeats().count(name)) << name;
      const heartbeat_t& hb = chain.heartbeats().at(name);
      const int64_t errors =
          hb.decode_errors + hb.validation_errors -
          (before.count(name) ? before[name].decode_errors + before[name].validation_errors : 0);
      EXPECT_GE(errors, 50) << name << ": decode " << hb.decode_errors << ", validation "
                            << hb.validation_errors;
      EXPECT_TRUE(chain.process(name).running()) << name;
    }
  }

  safety_status_t stop;
  {
    SCOPED_TRACE("a 10 degree encoder offset on a4");
    const int64_t latency =
        chain.stop_latency_after_frame([&] { chain.joint_fault("a4", 10 * M_PI / 180); }, &stop);
    EXPECT_STOP(latency, stop, risk_t::CAUSE_JOINT_ERROR);
    EXPECT_NE(stop.reason.find("suspect a4"), std::string::npos) << stop.reason;
    // The motion estimate names the joint and its offset in the verdicts
    // that follow (the first frames are judged before it comes).
    // Verdicts that follow may name a4 and its offset from the motion
    // estimate (printed; not asserted here: on this 2-core machine the
    // estimator is rate limited and many single-frame estimates of this arm
    // pose do not converge, docs/estimator.md; estimator_process_test checks
    // the offset on real frames). Any verdict the estimate names blames a4.
    chain.wait_for_detail("joint a4 reads", std::chrono::seconds(2), " than seen (estimate");
    for (const std::string& d : chain.details_with(" reads ", " than seen (estimate")) {
      std::cout << "estimate-named verdict: " << d << std::endl;
      EXPECT_EQ(d.rfind("joint a4 reads ", 0), 0u) << d;
    }
    chain.joint_fault("a4", 0);
    chain.bring_to_motion("encoder fixed");
    if (HasFatalFailure()) return;
  }
  {
    SCOPED_TRACE("the camera pose off by 5 cm");
    const int64_t latency = chain.stop_latency_after_frame(
        [&] { chain.publish_camera_pose(Eigen::Vector3d(0.05, 0, 0)); }, &stop);
    EXPECT_STOP(latency, stop, risk_t::CAUSE_CALIBRATION_ERROR);
    // The stop itself names the camera correction the evidence fitted
    // (docs/safety-chain.md, "Evidence"); the estimator, slower, no longer
    // renames a stop the sequential evidence has made.
    EXPECT_NE(stop.reason.find("fitted correction"), std::string::npos) << stop.reason;
    chain.publish_camera_pose(Eigen::Vector3d::Zero());
    chain.bring_to_motion("calibration fixed");
    if (HasFatalFailure()) return;
  }
  {
    SCOPED_TRACE("an object within 0.2 m of the arm");
    const int64_t latency = chain.stop_latency_after_frame(
        [&] { chain.camera_fault(sim_camera_fault_t::INTRUDING_OBJECT); }, &stop);
    EXPECT_STOP(latency, stop, risk_t::CAUSE_UNKNOWN_OBJECT);
    chain.camera_fault(sim_camera_fault_t::CLEAR);
    chain.bring_to_motion("object gone");
    if (HasFatalFailure()) return;
  }
  {
    SCOPED_TRACE("a frozen camera");
    const int64_t latency =
        chain.stop_latency_after_frame([&] { chain.camera_fault(sim_camera_fault_t::FROZEN_IMAGE); }, &stop);
    EXPECT_STOP(latency, stop, risk_t::CAUSE_SENSOR_FAULT);
    chain.camera_fault(sim_camera_fault_t::CLEAR);
    chain.bring_to_motion("camera unfrozen");
    if (HasFatalFailure()) return;
  }
  const int64_t depth_deadline_us = chain.config().risk.depth_deadline_us;
  {
    SCOPED_TRACE("a camera stall");
    chain.camera_fault(sim_camera_fault_t::STALL);
    // The deadline runs from the last frame that arrived.
    chain.wait([&] { return monotonic_us() - chain.last_depth_arrival_us() > 50'000; },
               std::chrono::seconds(2));
    const int64_t latency = chain.stop_latency_since(chain.last_depth_arrival_us(), &stop);
    std::cout << "camera stall: stop " << latency / 1000.0 << " ms after the last frame" << std::endl;
    EXPECT_LE(latency, depth_deadline_us + kStopBudgetUs);
    EXPECT_EQ(risk_cause_name(stop.cause), risk_cause_name(risk_t::CAUSE_SENSOR_FAULT)) << stop.reason;
    chain.camera_fault(sim_camera_fault_t::CLEAR);
    chain.bring_to_motion("camera back");
    if (HasFatalFailure()) return;
  }
  {
    SCOPED_TRACE("a joint-state stall");
    const int64_t stalled_us = monotonic_us();
    chain.process("tofguard-joints-sim").signal(SIGSTOP);
    const int64_t latency = chain.stop_latency_since(stalled_us, &stop);
    std::cout << "joint-state stall: stop " << latency / 1000.0 << " ms after the stall" << std::endl;
    EXPECT_LE(latency, chain.config().risk.joint_state_deadline_us + kStopBudgetUs);
    EXPECT_EQ(risk_cause_name(stop.cause), risk_cause_name(risk_t::CAUSE_SENSOR_FAULT)) << stop.reason;
    chain.process("tofguard-joints-sim").signal(SIGCONT);
    chain.bring_to_motion("arm driver back");
    if (HasFatalFailure()) return;
  }
  {
    SCOPED_TRACE("the renderer killed");
    const int64_t killed_us = monotonic_us();
    chain.process("tofguard-renderer").signal(SIGKILL);
    const int64_t latency = chain.stop_latency_since(killed_us, &stop);
    std::cout << "renderer killed: stop " << latency / 1000.0 << " ms after the kill, cause "
              << risk_cause_name(stop.cause) << std::endl;
    // Frames without a rendering go out unusable after pair_timeout_ms.
    EXPECT_LE(latency, chain.config().discrepancy.pair_timeout_us + depth_deadline_us + kStopBudgetUs);
    EXPECT_TRUE(stop.cause == risk_t::CAUSE_COMPONENT_FAULT || stop.cause == risk_t::CAUSE_SENSOR_FAULT)
        << risk_cause_name(stop.cause) << ": " << stop.reason;
    chain.start("tofguard-renderer");
    chain.bring_to_motion("renderer restarted");
  }
}

// The user in the chair (config/sim.yaml's occupant and simulated user):
// their own moving body never stops the arm (the nominal part above runs
// with them), but a hand lifted out of its envelope into the arm's reach
// and a caregiver's hand reaching in are unknown objects, stopped as
// docs/detection.md's objects are; a hand raised within its envelope
// before the arm hides it from the camera, and is no stop.
TEST(SafetyChainE2E, AHandOutsideTheUsersEnvelopesIsAnUnknownObject) {
  Chain chain;
  chain.bring_to_motion("start of the test");
  if (HasFatalFailure()) return;
  safety_status_t stop;
  // The world's z is up (the wheelchair stands on the floor).
  const Eigen::Vector3d hand = chain.user_part_m("hand_right");
  {
    SCOPED_TRACE("the user's right hand lifted 25 cm (its envelope: 10 cm)");
    const int64_t latency = chain.stop_latency_after_frame(
        [&] { chain.intrude(hand + Eigen::Vector3d(0, 0, 0.25), Eigen::Vector3d(0.10, 0.08, 0.03)); }, &stop);
    EXPECT_STOP(latency, stop, risk_t::CAUSE_UNKNOWN_OBJECT);
    chain.camera_fault(sim_camera_fault_t::CLEAR);
    chain.bring_to_motion("hand lowered");
    if (HasFatalFailure()) return;
  }
  {
    // (Before the chest the user hides it from the camera behind them.)
    SCOPED_TRACE("a caregiver's hand reaching in 25 cm before the user's right hand, 15 cm above the lap");
    const int64_t latency = chain.stop_latency_after_frame(
        [&] { chain.intrude(hand + Eigen::Vector3d(0.25, 0, 0.15), Eigen::Vector3d(0.10, 0.08, 0.03)); },
        &stop);
    EXPECT_STOP(latency, stop, risk_t::CAUSE_UNKNOWN_OBJECT);
    chain.camera_fault(sim_camera_fault_t::CLEAR);
    chain.bring_to_motion("caregiver gone");
    if (HasFatalFailure()) return;
  }
  {
    // A 4 cm box 8 cm above the hand's model and 9 cm towards the arm's
    // base (y falls to the right), within its 10 cm envelope: from the
    // camera behind the user it stands before the arm's base.
    SCOPED_TRACE("the user's right hand raised within its envelope before the arm");
    const int stops_before = chain.stops_seen();
    chain.intrude(hand + Eigen::Vector3d(-0.02, -0.09, 0.08), Eigen::Vector3d::Constant(0.04));
    chain.frames_compared = 0;
    chain.most_arm_hidden_by_user = 0;
    ASSERT_TRUE(chain.wait([&] { return chain.frames_compared >= 60; }, std::chrono::seconds(5)));
    std::cout << "the raised hand hid at most " << chain.most_arm_hidden_by_user << " of the arm's pixels in "
              << chain.frames_compared << " frames" << std::endl;
    // Without it the user's own right hand, moving 4 cm beside the arm's
    // base, hides 2-6 of its pixels in the nominal motion.
    EXPECT_GE(chain.most_arm_hidden_by_user, 10);
    EXPECT_EQ(chain.stops_seen(), stops_before) << chain.describe_last_risk();
    EXPECT_TRUE(chain.motion_allowed());
    chain.camera_fault(sim_camera_fault_t::CLEAR);
  }
}

}  // namespace
}  // namespace tofguard::test
