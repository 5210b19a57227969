#include "tofguard/intervene/reset_tool.hpp"

#include <algorithm>
#include <iostream>
#include <optional>
#include <random>

#include "tofguard/auth/message_signer.hpp"
#include "tofguard/camera_release_t.hpp"
#include "tofguard/common/clock.hpp"
#include "tofguard/common/config_error.hpp"
#include "tofguard/common/lcm_node.hpp"
#include "tofguard/reset_reply_t.hpp"
#include "tofguard/reset_request_t.hpp"
#include "tofguard/risk_t.hpp"

namespace tofguard::intervene {
namespace {

constexpr int kNoAnswerExitCode = 3;

}  // namespace

ProcessInfo reset_info() {
  ProcessInfo info{"tofguard-reset",
                   "Sends a reset request (who and why) to tofguard-intervene and prints\n"
                   "whether it was accepted and why not. Options: --who NAME --why TEXT\n"
                   "[--timeout-ms MS]. With a config that names auth.key_file the request is signed\n"
                   "(SAFETY_RESET_AUTH); without one it is plain, and a keyed tofguard-intervene\n"
                   "refuses it. --release-camera ID (several cameras, risk.camera_loss\n"
                   "continue_after_named_reset): first asks tofguard-risk to leave lost camera ID out\n"
                   "(SAFETY_CAMERA_RELEASE_AUTH), waits for a SAFE verdict, then resets.\n"
                   "Exit code 0 accepted, 1 refused, 3 no answer.",
                   /*config_required=*/false};
  info.takes_arguments = true;
  return info;
}

namespace {

struct ResetArguments {
  reset_request_t request;
  int64_t timeout_ms = 2000;
  // --release-camera ID: first ask tofguard-risk to leave lost camera ID out.
  std::string release_camera;
};

// The arguments, or nullopt after a usage line on stderr.
std::optional<ResetArguments> parse_reset_arguments(const std::vector<std::string>& args) {
  ResetArguments parsed;
  for (size_t i = 0; i < args.size(); ++i) {
    const bool has_value = i + 1 < args.size();
    if (args[i] == "--who" && has_value) {
      parsed.request.who = args[++i];
    } else if (args[i] == "--why" && has_value) {
      parsed.request.why = args[++i];
    } else if (args[i] == "--timeout-ms" && has_value) {
      parsed.timeout_ms = std::stoll(args[++i]);
    } else if (args[i] == "--release-camera" && has_value) {
      parsed.release_camera = args[++i];
    } else {
      std::cerr << "tofguard-reset: unexpected argument '" << args[i]
                << "' (usage: tofguard-reset [--config FILE] --who NAME --why TEXT [--release-camera ID] "
                   "[--timeout-ms MS])\n";
      return std::nullopt;
    }
  }
  if (parsed.request.who.empty() || parsed.request.why.empty()) {
    std::cerr << "tofguard-reset: --who NAME and --why TEXT are both required\n";
    return std::nullopt;
  }
  return parsed;
}

// Sends `request` until a reset_reply_t with its request_id arrives on
// `reply_channel` or `timeout_ms` passes: signed on `auth_channel` with a
// key (each send signed afresh: a new seq, since a repeated envelope would
// be refused as a replay; the request id stays), else plain on `channel`.
// UDP multicast can lose a datagram (a full receive buffer at a busy
// receiver, a lossy bus), so the request goes again every 250 ms; the
// receivers answer a repeat with the same answer.
template <class Request>
std::optional<reset_reply_t> ask(lcm::LCM& lcm, auth::MessageSigner* signer, const Request& request,
                                 const std::string& channel, const std::string& auth_channel,
                                 const std::string& reply_channel, int64_t timeout_ms) {
  struct Waiter {
    int64_t request_id = 0;
    std::optional<reset_reply_t> reply;
    void on_reply(const lcm::ReceiveBuffer*, const std::string&, const reset_reply_t* r) {
      if (r->request_id == request_id) reply = *r;
    }
  } waiter;
  waiter.request_id = request.request_id;
  lcm::Subscription* subscription = lcm.subscribe(reply_channel, &Waiter::on_reply, &waiter);
  constexpr int64_t kResendPeriodMs = 250;
  const int64_t deadline_us = monotonic_us() + timeout_ms * 1000;
  while (!waiter.reply && monotonic_us() < deadline_us && !stop_requested()) {
    if (signer) {
      const authenticated_message_t signed_request = signer->sign(channel, request, wall_utime());
      lcm.publish(auth_channel, &signed_request);
    } else {
      lcm.publish(channel, &request);
    }
    const int64_t resend_us = std::min(deadline_us, monotonic_us() + kResendPeriodMs * 1000);
    while (!waiter.reply && monotonic_us() < resend_us && !stop_requested()) {
      lcm.handleTimeout(static_cast<int>(std::max<int64_t>(1, (resend_us - monotonic_us()) / 1000)));
    }
  }
  lcm.unsubscribe(subscription);
  return waiter.reply;
}

// Waits up to `timeout_ms` for a SAFE verdict on `risk_channel`: after a
// release the next frame's verdict leaves the camera out.
bool wait_for_safe_verdict(lcm::LCM& lcm, const std::string& risk_channel, int64_t timeout_ms) {
  struct Watcher {
    bool safe = false;
    void on_risk(const lcm::ReceiveBuffer*, const std::string&, const risk_t* r) {
      if (r->seq >= 0 && r->level == risk_t::SAFE) safe = true;
    }
  } watcher;
  lcm::Subscription* subscription = lcm.subscribe(risk_channel, &Watcher::on_risk, &watcher);
  const int64_t deadline_us = monotonic_us() + timeout_ms * 1000;
  while (!watcher.safe && monotonic_us() < deadline_us && !stop_requested()) {
    lcm.handleTimeout(static_cast<int>(std::max<int64_t>(1, (deadline_us - monotonic_us()) / 1000)));
  }
  lcm.unsubscribe(subscription);
  return watcher.safe;
}

// tofguard-risk's answer to the release of `arguments.release_camera`:
// 0 released, else the exit code after a line on stdout.
int release_camera(lcm::LCM& lcm, auth::MessageSigner* signer, const ResetToolSettings& settings,
                   const ResetArguments& arguments) {
  camera_release_t release;
  release.utime = arguments.request.utime;
  release.request_id = arguments.request.request_id + 1;
  release.camera_id = arguments.release_camera;
  release.who = arguments.request.who;
  release.why = arguments.request.why;
  const std::optional<reset_reply_t> reply =
      ask(lcm, signer, release, settings.channels.camera_release, settings.channels.camera_release_auth,
          settings.channels.camera_release_reply, arguments.timeout_ms);
  if (!reply) {
    std::cout << "no answer on " << settings.channels.camera_release_reply << " within "
              << arguments.timeout_ms << " ms: is tofguard-risk running on " << settings.lcm.url << "?"
              << std::endl;
    return kNoAnswerExitCode;
  }
  std::cout << "camera " << arguments.release_camera << ": " << reply->reason << std::endl;
  if (!reply->accepted) return 1;
  if (!wait_for_safe_verdict(lcm, settings.channels.risk, arguments.timeout_ms)) {
    std::cout << "no SAFE verdict on " << settings.channels.risk << " within " << arguments.timeout_ms
              << " ms of the release: the remaining cameras do not allow motion" << std::endl;
    return 1;
  }
  return 0;
}

}  // namespace

int run_reset(const ResetToolSettings& settings, const std::vector<std::string>& args) {
  std::optional<ResetArguments> arguments = parse_reset_arguments(args);
  if (!arguments) return kConfigErrorExitCode;
  lcm::LCM lcm(settings.lcm.url);
  if (!lcm.good()) {
    std::cerr << "tofguard-reset: cannot open LCM at " << settings.lcm.url << "\n";
    return kNoAnswerExitCode;
  }
  reset_request_t& request = arguments->request;
  request.utime = wall_utime();
  request.request_id = static_cast<int64_t>(std::random_device{}() & 0x7fffffff) << 20 ^ request.utime;
  // With a key the requests go signed: the only ones a keyed
  // tofguard-intervene and tofguard-risk accept. Without one (insecure:
  // true, or no config given) they go plain, and a keyed receiver answers
  // why not.
  std::optional<auth::MessageSigner> signer;
  if (!settings.auth.key.id.empty()) signer.emplace(settings.auth.key, request.utime);
  if (!arguments->release_camera.empty()) {
    if (const int code = release_camera(lcm, signer ? &*signer : nullptr, settings, *arguments); code != 0) {
      return code;
    }
  }
  const std::optional<reset_reply_t> reply =
      ask(lcm, signer ? &*signer : nullptr, request, settings.channels.reset, settings.channels.reset_auth,
          settings.channels.reset_reply, arguments->timeout_ms);
  if (!reply) {
    std::cout << "no answer on " << settings.channels.reset_reply << " within " << arguments->timeout_ms
              << " ms: is tofguard-intervene running on " << settings.lcm.url << "?" << std::endl;
    return kNoAnswerExitCode;
  }
  std::cout << (reply->accepted ? "reset accepted" : "reset " + reply->reason) << std::endl;
  return reply->accepted ? 0 : 1;
}

}  // namespace tofguard::intervene
