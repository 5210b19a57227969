#include "tofguard/risk/risk_process.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "tofguard/auth/message_signer.hpp"
#include "tofguard/auth/message_verifier.hpp"
#include "tofguard/auth/signed_publish.hpp"
#include "tofguard/camera_pose_t.hpp"
#include "tofguard/camera_release_t.hpp"
#include "tofguard/common/clock.hpp"
#include "tofguard/common/decode.hpp"
#include "tofguard/common/lcm_node.hpp"
#include "tofguard/common/wire_checks.hpp"
#include "tofguard/reset_reply_t.hpp"
#include "tofguard/risk/cameras_judgement.hpp"

namespace tofguard::risk {

ProcessInfo process_info() {
  return {
      "tofguard-risk",
      "Classifies the risk of every frame and fires deadlines: SAFETY_DISCREPANCY, TOF_DEPTH, JOINT_STATE, "
      "CAMERA_POSE, SAFETY_HEARTBEAT, MOTION_ESTIMATE, PLANNED_TRAJECTORY -> SAFETY_RISK (risk_t) and the "
      "arm's "
      "speed limit, SAFETY_SPEED_LIMIT (speed_limit_t)."};
}

namespace {

// Each robot link's surface area, read from the URDF's meshes, with
// several cameras (the unseen arm's share); none with one.
std::vector<LinkArea> arm_link_areas(const RiskProcessSettings& settings) {
  if (settings.cameras.size() < 2) return {};
  return read_robot_link_areas(settings.robot_urdf_path, settings.robot_package_paths,
                               settings.rendered_geometry);
}

// One camera's judgement: its monitor, fed from its own channels.
// The wiring of one process: every camera's inputs to its monitor, the
// shared inputs to all, the fused verdicts and the speed limits out.
class RiskProcess {
 public:
  explicit RiskProcess(const RiskProcessSettings& settings)
      : settings_(settings),
        robot_(robot_model::load_kinematic_tree(settings.robot_urdf_path)),
        judgement_(settings.risk, settings.cameras, robot_, arm_link_areas(settings), settings.occupant,
                   monotonic_us()),
        node_(settings.lcm, settings.channels, process_info().name) {
    // With a key, each verdict goes out signed first (the copy a keyed
    // tofguard-intervene acts on), then plain (for people, logs and tools).
    if (auth::authenticated(settings.auth)) {
      signer_.emplace(settings.auth.key, wall_utime());
      verifier_.emplace(settings.auth.key, settings.auth.max_age_us);
    }
    for (size_t camera = 0; camera < judgement_.cameras(); ++camera) subscribe_camera(camera);
    subscribe_shared();
    subscribe_camera_release();
    node_.add_timer(settings.risk.check_period_us, [this] { check_due_and_deadlines(); });
    node_.heartbeat().set_status("ok: waiting for frames");
  }

  void run() { node_.run(); }

 private:
  // A verdict of camera `camera`'s monitor, as the judgement publishes it.
  void publish(size_t camera, const risk_t& verdict) {
    if (const std::optional<risk_t> r = judgement_.published(camera, verdict)) send(camera, *r);
  }

  void send(size_t camera, const risk_t& r) {
    auth::publish_signed(node_.safety(), signer_ ? &*signer_ : nullptr, settings_.channels.risk,
                         settings_.channels.risk_auth, r, wall_utime());
    node_.counters().frames_out++;
    if (r.seq >= 0) node_.heartbeat().set_last_frame_utime(r.utime);
    if (r.level == risk_t::DANGEROUS) ++dangerous_;
    const RiskMonitor::EstimateStats& e = judgement_.monitor(camera).estimate_stats();
    node_.heartbeat().set_status(
        "last verdict: level " + std::to_string(r.level) + " cause " + std::to_string(r.cause) + " (" +
        r.detail + "); " + std::to_string(dangerous_) + " dangerous so far; estimates of " +
        judgement_.camera(camera).id + ": " + std::to_string(e.received) + " received, " +
        std::to_string(e.used) + " used, " + std::to_string(e.explained_nothing) + " explained nothing, " +
        std::to_string(e.missing) + " missing, " + std::to_string(e.late) + " late");
  }

  void publish_all(size_t camera, const std::vector<risk_t>& verdicts) {
    for (const risk_t& r : verdicts) publish(camera, r);
  }

  // The controller's speed limit, signed first as the verdicts are.
  void publish_limit(const speed_limit_t& limit) {
    auth::publish_signed(node_.safety(), signer_ ? &*signer_ : nullptr, settings_.channels.speed_limit,
                         settings_.channels.speed_limit_auth, limit, wall_utime());
  }

  void on_frame(size_t camera, const discrepancy_t& d) {
    RiskMonitor& monitor = judgement_.monitor(camera);
    const std::string& channel = judgement_.camera(camera).channels.discrepancy;
    const int64_t refused_before = monitor.refused_frames();
    for (const risk_t& r : judgement_.on_frame(camera, d, monotonic_us())) send(camera, r);
    if (monitor.refused_frames() != refused_before) {
      // A duplicate or out-of-order frame: no verdict (RiskMonitor::on_frame).
      node_.counters().frames_dropped++;
      node_.errors().report(channel + " order", channel + ": refused: " + monitor.last_refusal());
    } else {
      publish_limit(monitor.speed_limit(d));
    }
  }

  void subscribe_camera(size_t camera) {
    RiskMonitor& monitor = judgement_.monitor(camera);
    const RiskCamera& c = judgement_.camera(camera);
    node_.subscribe<discrepancy_t>(
        node_.safety(), c.channels.discrepancy,
        [this, camera](const discrepancy_t& d) { on_frame(camera, d); },
        [id = c.id](const discrepancy_t& d) {
          std::string problem = check_discrepancy(d);
          if (problem.empty() && d.camera_id != id) {
            problem = "camera_id: expected '" + id + "', got '" + d.camera_id + "'";
          }
          return problem;
        });
    node_.subscribe<motion_estimate_t>(
        node_.safety(), c.channels.motion_estimate,
        [this, camera, &monitor](const motion_estimate_t& e) {
          publish_all(camera, monitor.on_estimate(e, monotonic_us()));
        },
        [&monitor, id = c.id](const motion_estimate_t& e) {
          std::string problem = check_motion_estimate(e);
          if (problem.empty() && e.camera_id != id) {
            problem = "camera_id: expected '" + id + "', got '" + e.camera_id + "'";
          }
          if (problem.empty() && e.usable) problem = monitor.check_joint_names(e.joint_name, "joint_name");
          return problem;
        });
    node_.subscribe<depth_image_t>(
        node_.images(), c.channels.depth,
        [&monitor](const depth_image_t&) { monitor.on_depth(monotonic_us()); },
        [id = c.id](const depth_image_t& image) { return check_depth_image_from(image, id); });
    node_.subscribe<camera_pose_t>(
        node_.safety(), c.channels.camera_pose,
        [&monitor](const camera_pose_t&) { monitor.on_camera_pose(monotonic_us()); }, check_camera_pose);
  }

  void subscribe_shared() {
    RiskMonitor& first = judgement_.monitor(0);
    node_.subscribe<planned_trajectory_t>(
        node_.safety(), settings_.channels.planned_trajectory,
        [this](const planned_trajectory_t& p) {
          for (size_t c = 0; c < judgement_.cameras(); ++c) judgement_.monitor(c).on_plan(p);
        },
        [&first](const planned_trajectory_t& p) {
          std::string problem = check_planned_trajectory(p);
          if (problem.empty()) problem = first.check_joint_names(p.joint_name, "joint_name");
          return problem;
        });
    node_.subscribe<joint_state_t>(
        node_.safety(), settings_.channels.joint_state, [this](const joint_state_t& s) { on_joint_state(s); },
        [&first](const joint_state_t& s) {
          std::string problem = check_joint_state(s);
          if (problem.empty()) problem = first.check_joint_names(s);
          return problem;
        });
    node_.subscribe<heartbeat_t>(
        node_.safety(), settings_.channels.heartbeat,
        [this](const heartbeat_t& hb) {
          for (size_t c = 0; c < judgement_.cameras(); ++c)
            judgement_.monitor(c).on_heartbeat(hb, monotonic_us());
        },
        check_heartbeat);
  }

  // Every camera's monitor takes the state; it is refused (and counted
  // once) when the first refuses it, as all have seen the same stream.
  void on_joint_state(const joint_state_t& s) {
    std::string refused;
    for (size_t c = 0; c < judgement_.cameras(); ++c) {
      const std::string why = judgement_.monitor(c).on_joint_state(s, monotonic_us());
      if (refused.empty()) refused = why;
    }
    if (!refused.empty()) {
      node_.counters().frames_dropped++;
      node_.errors().report(settings_.channels.joint_state + " order",
                            settings_.channels.joint_state + ": refused: " + refused);
    }
  }

  void check_due_and_deadlines() {
    for (size_t camera = 0; camera < judgement_.cameras(); ++camera) {
      RiskMonitor& monitor = judgement_.monitor(camera);
      publish_all(camera, monitor.release_due(monotonic_us()));
      if (const auto timeout = monitor.check_deadlines(monotonic_us())) {
        publish(camera, *timeout);
        // A released camera's silence is known and said in every verdict:
        // the others' limits stand.
        if (judgement_.fusion().released(camera)) continue;
        publish_limit(
            stand_still_limit(settings_.risk, timeout->utime, judgement_.camera(camera).id, timeout->detail));
      }
    }
  }

  // An operator's release of a lost camera (verdict_fusion.hpp), answered
  // on channels.camera_release_reply.
  void on_camera_release(const camera_release_t& request) {
    reset_reply_t reply;
    reply.utime = wall_utime();
    reply.request_id = request.request_id;
    VerdictFusion& fusion = judgement_.fusion();
    const size_t camera = fusion.index_of(request.camera_id);
    if (request.who.empty() || request.why.empty()) {
      reply.reason = "refused: a release needs who and why";
    } else if (camera == fusion.cameras()) {
      reply.reason = "refused: no camera '" + request.camera_id + "' in this deployment";
    } else {
      reply.reason = fusion.release(camera, request.who, request.why);
    }
    reply.accepted = reply.reason.empty();
    if (reply.accepted) reply.reason = "released: " + request.camera_id + " is left out until it is back";
    std::cerr << "tofguard-risk: camera release of '" << request.camera_id << "' from '" << request.who
              << "' (" << request.why << "): " << reply.reason << std::endl;
    node_.safety().publish(settings_.channels.camera_release_reply, &reply);
  }

  void subscribe_camera_release() {
    const ChannelNames& channels = settings_.channels;
    if (!verifier_) {
      node_.subscribe<camera_release_t>(node_.safety(), channels.camera_release,
                                        [this](const camera_release_t& r) { on_camera_release(r); });
      return;
    }
    // With a key only a signed release counts; a plain one is answered.
    node_.subscribe<camera_release_t>(
        node_.safety(), channels.camera_release, [this](const camera_release_t& r) {
          refuse_release(r.request_id, "not authenticated (no tag): send it signed on " +
                                           settings_.channels.camera_release_auth);
        });
    node_.subscribe<authenticated_message_t>(
        node_.safety(), channels.camera_release_auth, [this](const authenticated_message_t& m) {
          std::string why;
          const std::optional<camera_release_t> request =
              verifier_->open<camera_release_t>(m, settings_.channels.camera_release, wall_utime(), &why);
          if (request) {
            on_camera_release(*request);
          } else if (const auto claimed =
                         decode_message<camera_release_t>(m.payload.data(), m.payload_size)) {
            refuse_release(claimed->request_id, "not authenticated: " + why);
          }
        });
  }

  void refuse_release(int64_t request_id, const std::string& why) {
    node_.counters().validation_errors++;
    node_.errors().report(settings_.channels.camera_release_auth,
                          settings_.channels.camera_release + ": " + why);
    reset_reply_t reply;
    reply.utime = wall_utime();
    reply.request_id = request_id;
    reply.accepted = false;
    reply.reason = "refused: " + why;
    node_.safety().publish(settings_.channels.camera_release_reply, &reply);
  }

  const RiskProcessSettings& settings_;
  const robot_model::KinematicTree robot_;
  CamerasJudgement judgement_;
  LcmNode node_;
  std::optional<auth::MessageSigner> signer_;
  std::optional<auth::MessageVerifier> verifier_;
  int64_t dangerous_ = 0;
};

}  // namespace

int run_risk(const RiskProcessSettings& settings) {
  if (settings.cameras.empty()) throw std::runtime_error("tofguard-risk: no camera to judge");
  RiskProcess process(settings);
  process.run();
  return 0;
}

}  // namespace tofguard::risk
