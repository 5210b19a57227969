// libFuzzer target: every message type a tofguard process receives, as it
// arrives on the wire. The input is decoded as each type in turn, the way
// LcmNode does it (decode_message<T>: the fingerprint in the first 8 bytes
// picks the one type it can be), then given to the check(s) the processes
// apply to that type (wire_checks.hpp, see the subscribe calls in each
// *_process.cpp) and, when the check passes, to the conversions the
// processes make of a valid message. Bad input must come back as "not a T"
// or as a one-line problem; anything else (a crash, a sanitizer report, an
// allocation beyond libFuzzer's limit, an exception) is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_auth_key.hpp"
#include "tofguard/auth/message_verifier.hpp"
#include "tofguard/authenticated_message_t.hpp"
#include "tofguard/camera_pose_t.hpp"
#include "tofguard/common/camera_pose_message.hpp"
#include "tofguard/common/decode.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/common/wire_checks.hpp"
#include "tofguard/depth_image_t.hpp"
#include "tofguard/discrepancy_image_t.hpp"
#include "tofguard/discrepancy_t.hpp"
#include "tofguard/heartbeat_t.hpp"
#include "tofguard/joint_state_t.hpp"
#include "tofguard/link_labels_t.hpp"
#include "tofguard/motion_estimate_t.hpp"
#include "tofguard/planned_trajectory_t.hpp"
#include "tofguard/power_relay_t.hpp"
#include "tofguard/reset_reply_t.hpp"
#include "tofguard/reset_request_t.hpp"
#include "tofguard/risk_t.hpp"
#include "tofguard/safety_status_t.hpp"
#include "tofguard/sim_camera_fault_t.hpp"
#include "tofguard/sim_controller_fault_t.hpp"
#include "tofguard/sim_joint_fault_t.hpp"

namespace {

using namespace tofguard;

// The problem line a check returns is built from the message's fields:
// looking at every character makes a read past a string's end visible.
size_t consume(const std::string& problem) {
  size_t sum = 0;
  for (char c : problem) sum += static_cast<unsigned char>(c);
  return sum;
}

// Decodes `data` as T; when it is one, runs `use` on it.
template <class T, class Use>
void as(const uint8_t* data, size_t size, Use use) {
  if (const auto message = decode_message<T>(data, static_cast<int>(size))) use(*message);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // LCM messages are at most INT_MAX bytes (decode takes an int).
  if (size > (1u << 20)) return 0;
  volatile size_t sink = 0;
  // The depth image, by tofguard-renderer, -estimator (check_depth_image),
  // -discrepancy and -risk (check_depth_image_from their camera).
  as<depth_image_t>(data, size, [&](const depth_image_t& image) {
    sink += consume(check_depth_image_from(image, "tof-mast"));
    const std::string problem = check_depth_image(image);
    sink += consume(problem);
    if (!problem.empty()) return;
    sink += static_cast<size_t>(intrinsics_of(image).width);
    sink += depth_m_of(image).size();
  });
  as<joint_state_t>(data, size, [&](const joint_state_t& m) { sink += consume(check_joint_state(m)); });
  as<camera_pose_t>(data, size, [&](const camera_pose_t& m) {
    const std::string problem = check_camera_pose(m);
    sink += consume(problem);
    if (problem.empty()) sink += from_camera_pose_message(m).frame_id.size();
  });
  // tofguard-discrepancy pairs labels with frames pixel by pixel.
  as<link_labels_t>(data, size, [&](const link_labels_t& m) {
    const std::string problem = check_link_labels(m);
    sink += consume(problem);
    if (!problem.empty() || !m.usable) return;
    for (int16_t label : m.label)
      sink += static_cast<size_t>(link_of_label(label, m.num_robot_links, m.num_links) + 1);
  });
  as<discrepancy_t>(data, size, [&](const discrepancy_t& m) { sink += consume(check_discrepancy(m)); });
  as<risk_t>(data, size, [&](const risk_t& m) { sink += consume(check_risk(m)); });
  as<heartbeat_t>(data, size, [&](const heartbeat_t& m) { sink += consume(check_heartbeat(m)); });
  as<safety_status_t>(data, size, [&](const safety_status_t& m) { sink += consume(check_safety_status(m)); });
  as<motion_estimate_t>(data, size,
                        [&](const motion_estimate_t& m) { sink += consume(check_motion_estimate(m)); });
  as<planned_trajectory_t>(
      data, size, [&](const planned_trajectory_t& m) { sink += consume(check_planned_trajectory(m)); });
  as<sim_camera_fault_t>(data, size,
                         [&](const sim_camera_fault_t& m) { sink += consume(check_sim_camera_fault(m)); });
  as<sim_joint_fault_t>(data, size,
                        [&](const sim_joint_fault_t& m) { sink += consume(check_sim_joint_fault(m)); });
  as<sim_controller_fault_t>(
      data, size, [&](const sim_controller_fault_t& m) { sink += consume(check_sim_controller_fault(m)); });
  // No process checks these beyond decoding them: tofguard-intervene takes
  // a reset_request_t as it is, tofguard-reset a reset_reply_t, tofguard-spy
  // and tofguard-view everything (spy_format_fuzz formats them).
  as<reset_request_t>(data, size, [&](const reset_request_t& m) { sink += m.who.size() + m.why.size(); });
  as<reset_reply_t>(data, size, [&](const reset_reply_t& m) { sink += m.reason.size(); });
  as<power_relay_t>(data, size, [&](const power_relay_t& m) { sink += m.reason.size(); });
  as<discrepancy_image_t>(data, size, [&](const discrepancy_image_t& m) { sink += m.rgb.size(); });
  // A signed message, as tofguard-intervene opens SAFETY_RISK_AUTH and
  // SAFETY_RESET_AUTH and a controller SAFETY_STATUS_AUTH (the key is
  // make_wire_seeds' fuzz key, so its seeds pass the tag), and the
  // controller's bounded decoder on the same bytes.
  static tofguard::auth::MessageVerifier verifier(tofguard::fuzz_auth_key(), 1'000'000'000'000'000);
  auto open_all = [&](const authenticated_message_t& m) {
    std::string why;
    if (auto r = verifier.open<risk_t>(m, "SAFETY_RISK", m.utime, &why)) sink += consume(check_risk(*r));
    if (auto q = verifier.open<reset_request_t>(m, "SAFETY_RESET", m.utime, &why)) sink += q->who.size();
    if (auto s = verifier.open<safety_status_t>(m, "SAFETY_STATUS", m.utime, &why)) sink += s->reason.size();
    sink += consume(why);
  };
  as<authenticated_message_t>(data, size, open_all);
  if (const auto m = tofguard::auth::decode_authenticated_message(data, size)) sink += m->payload.size();
  return 0;
}
