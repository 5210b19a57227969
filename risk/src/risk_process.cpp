#include "tofguard/risk/risk_process.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "tofguard/auth/message_signer.hpp"
#include "tofguard/auth/signed_publish.hpp"
#include "tofguard/camera_pose_t.hpp"
#include "tofguard/common/clock.hpp"
#include "tofguard/common/lcm_node.hpp"
#include "tofguard/common/wire_checks.hpp"
#include "tofguard/risk/risk_monitor.hpp"

namespace tofguard::risk {

ProcessInfo process_info() {
  return {
      "tofguard-risk",
      "Classifies the risk of every frame and fires deadlines: SAFETY_DISCREPANCY, TOF_DEPTH, JOINT_STATE, "
      "CAMERA_POSE, SAFETY_HEARTBEAT, MOTION_ESTIMATE, PLANNED_TRAJECTORY -> SAFETY_RISK (risk_t) and the "
      "arm's "
      "speed limit, SAFETY_SPEED_LIMIT (speed_limit_t)."};
}

int run_risk(const RiskProcessSettings& settings) {
  RiskMonitor monitor(settings.risk, settings.channels,
                      robot_model::load_kinematic_tree(settings.robot_urdf_path), settings.camera_rate_hz,
                      monotonic_us());
  if (settings.occupant) monitor.set_occupant(*settings.occupant);
  const std::string camera_id = settings.camera_id;
  LcmNode node(settings.lcm, settings.channels, process_info().name);
  int64_t dangerous = 0;
  // With a key, each verdict goes out signed first (the copy a keyed
  // tofguard-intervene acts on), then plain (for people, logs and tools).
  std::optional<auth::MessageSigner> signer;
  if (auth::authenticated(settings.auth)) signer.emplace(settings.auth.key, wall_utime());

  auto publish = [&](const risk_t& r) {
    auth::publish_signed(node.safety(), signer ? &*signer : nullptr, settings.channels.risk,
                         settings.channels.risk_auth, r, wall_utime());
    node.counters().frames_out++;
    if (r.seq >= 0) node.heartbeat().set_last_frame_utime(r.utime);
    if (r.level == risk_t::DANGEROUS) ++dangerous;
    const RiskMonitor::EstimateStats& e = monitor.estimate_stats();
    node.heartbeat().set_status(
        "last verdict: level " + std::to_string(r.level) + " cause " + std::to_string(r.cause) + " (" +
        r.detail + "); " + std::to_string(dangerous) +
        " dangerous so far; estimates: " + std::to_string(e.received) + " received, " +
        std::to_string(e.used) + " used, " + std::to_string(e.explained_nothing) + " explained nothing, " +
        std::to_string(e.missing) + " missing, " + std::to_string(e.late) + " late");
  };

  auto publish_all = [&](const std::vector<risk_t>& verdicts) {
    for (const risk_t& r : verdicts) publish(r);
  };
  // The controller's speed limit, signed first as the verdicts are.
  auto publish_limit = [&](const speed_limit_t& limit) {
    auth::publish_signed(node.safety(), signer ? &*signer : nullptr, settings.channels.speed_limit,
                         settings.channels.speed_limit_auth, limit, wall_utime());
  };
  node.subscribe<discrepancy_t>(
      node.safety(), settings.channels.discrepancy,
      [&](const discrepancy_t& d) {
        const int64_t refused_before = monitor.refused_frames();
        publish_all(monitor.on_frame(d, monotonic_us()));
        if (monitor.refused_frames() != refused_before) {
          // A duplicate or out-of-order frame: no verdict (RiskMonitor::on_frame).
          node.counters().frames_dropped++;
          node.errors().report(settings.channels.discrepancy + " order",
                               settings.channels.discrepancy + ": refused: " + monitor.last_refusal());
        } else {
          publish_limit(monitor.speed_limit(d));
        }
      },
      check_discrepancy);
  node.subscribe<motion_estimate_t>(
      node.safety(), settings.channels.motion_estimate,
      [&](const motion_estimate_t& e) { publish_all(monitor.on_estimate(e, monotonic_us())); },
      [&](const motion_estimate_t& e) {
        std::string problem = check_motion_estimate(e);
        if (problem.empty() && e.camera_id != camera_id) {
          problem = "camera_id: expected '" + camera_id + "', got '" + e.camera_id + "'";
        }
        if (problem.empty() && e.usable) problem = monitor.check_joint_names(e.joint_name, "joint_name");
        return problem;
      });
  node.subscribe<planned_trajectory_t>(
      node.safety(), settings.channels.planned_trajectory,
      [&](const planned_trajectory_t& p) { monitor.on_plan(p); },
      [&](const planned_trajectory_t& p) {
        std::string problem = check_planned_trajectory(p);
        if (problem.empty()) problem = monitor.check_joint_names(p.joint_name, "joint_name");
        return problem;
      });
  node.subscribe<depth_image_t>(
      node.images(), settings.channels.depth, [&](const depth_image_t&) { monitor.on_depth(monotonic_us()); },
      [camera_id](const depth_image_t& image) { return check_depth_image_from(image, camera_id); });
  node.subscribe<joint_state_t>(
      node.safety(), settings.channels.joint_state,
      [&](const joint_state_t& s) {
        const std::string refused = monitor.on_joint_state(s, monotonic_us());
        if (!refused.empty()) {
          node.counters().frames_dropped++;
          node.errors().report(settings.channels.joint_state + " order",
                               settings.channels.joint_state + ": refused: " + refused);
        }
      },
      [&](const joint_state_t& s) {
        std::string problem = check_joint_state(s);
        if (problem.empty()) problem = monitor.check_joint_names(s);
        return problem;
      });
  node.subscribe<camera_pose_t>(
      node.safety(), settings.channels.camera_pose,
      [&](const camera_pose_t&) { monitor.on_camera_pose(monotonic_us()); }, check_camera_pose);
  node.subscribe<heartbeat_t>(
      node.safety(), settings.channels.heartbeat,
      [&](const heartbeat_t& hb) { monitor.on_heartbeat(hb, monotonic_us()); }, check_heartbeat);
  node.add_timer(settings.risk.check_period_us, [&] {
    publish_all(monitor.release_due(monotonic_us()));
    if (const auto timeout = monitor.check_deadlines(monotonic_us())) {
      publish(*timeout);
      publish_limit(stand_still_limit(settings.risk, timeout->utime, camera_id, timeout->detail));
    }
  });
  node.heartbeat().set_status("ok: waiting for frames");
  node.run();
  return 0;
}

}  // namespace tofguard::risk
