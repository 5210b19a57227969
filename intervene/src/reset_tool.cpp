#include "tofguard/intervene/reset_tool.hpp"

#include <algorithm>
#include <iostream>
#include <optional>
#include <random>

#include "tofguard/auth/message_signer.hpp"
#include "tofguard/common/clock.hpp"
#include "tofguard/common/config_error.hpp"
#include "tofguard/common/lcm_node.hpp"
#include "tofguard/reset_reply_t.hpp"
#include "tofguard/reset_request_t.hpp"

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
                   "refuses it. Exit code 0 accepted, 1 refused, 3 no answer.",
                   /*config_required=*/false};
  info.takes_arguments = true;
  return info;
}

int run_reset(const ResetToolSettings& settings, const std::vector<std::string>& args) {
  reset_request_t request;
  int64_t timeout_ms = 2000;
  for (size_t i = 0; i < args.size(); ++i) {
    const bool has_value = i + 1 < args.size();
    if (args[i] == "--who" && has_value) {
      request.who = args[++i];
    } else if (args[i] == "--why" && has_value) {
      request.why = args[++i];
    } else if (args[i] == "--timeout-ms" && has_value) {
      timeout_ms = std::stoll(args[++i]);
    } else {
      std::cerr << "tofguard-reset: unexpected argument '" << args[i]
                << "' (usage: tofguard-reset [--config FILE] --who NAME --why TEXT [--timeout-ms MS])\n";
      return kConfigErrorExitCode;
    }
  }
  if (request.who.empty() || request.why.empty()) {
    std::cerr << "tofguard-reset: --who NAME and --why TEXT are both required\n";
    return kConfigErrorExitCode;
  }
  lcm::LCM lcm(settings.lcm.url);
  if (!lcm.good()) {
    std::cerr << "tofguard-reset: cannot open LCM at " << settings.lcm.url << "\n";
    return kNoAnswerExitCode;
  }
  request.utime = wall_utime();
  request.request_id = static_cast<int64_t>(std::random_device{}() & 0x7fffffff) << 20 ^ request.utime;

  struct Waiter {
    int64_t request_id = 0;
    bool answered = false;
    reset_reply_t reply;
    void on_reply(const lcm::ReceiveBuffer*, const std::string&, const reset_reply_t* r) {
      if (r->request_id == request_id) {
        reply = *r;
        answered = true;
      }
    }
  } waiter;
  waiter.request_id = request.request_id;
  lcm.subscribe(settings.channels.reset_reply, &Waiter::on_reply, &waiter);
  std::optional<auth::MessageSigner> signer;
  if (!settings.auth.key.id.empty()) signer.emplace(settings.auth.key, request.utime);
  auto send = [&] {
    if (signer) {
      // Signed: the only reset a keyed tofguard-intervene accepts. Each
      // send is signed afresh (a new seq: a repeated envelope would be
      // refused as a replay); the request id stays the same.
      const authenticated_message_t signed_request =
          signer->sign(settings.channels.reset, request, wall_utime());
      lcm.publish(settings.channels.reset_auth, &signed_request);
    } else {
      // No key (insecure: true, or no config given): plain, which only an
      // insecure tofguard-intervene accepts; a keyed one answers why not.
      lcm.publish(settings.channels.reset, &request);
    }
  };

  // UDP multicast can lose a datagram (a full receive buffer at a busy
  // tofguard-intervene, a lossy bus): the request goes again every
  // kResendPeriodMs until answered. tofguard-intervene answers a repeat
  // of the same request id with its first answer.
  constexpr int64_t kResendPeriodMs = 250;
  const int64_t deadline_us = monotonic_us() + timeout_ms * 1000;
  while (!waiter.answered && monotonic_us() < deadline_us && !stop_requested()) {
    send();
    const int64_t resend_us = std::min(deadline_us, monotonic_us() + kResendPeriodMs * 1000);
    while (!waiter.answered && monotonic_us() < resend_us && !stop_requested()) {
      lcm.handleTimeout(static_cast<int>(std::max<int64_t>(1, (resend_us - monotonic_us()) / 1000)));
    }
  }
  if (!waiter.answered) {
    std::cout << "no answer on " << settings.channels.reset_reply << " within " << timeout_ms
              << " ms: is tofguard-intervene running on " << settings.lcm.url << "?" << std::endl;
    return kNoAnswerExitCode;
  }
  std::cout << (waiter.reply.accepted ? "reset accepted" : "reset " + waiter.reply.reason) << std::endl;
  return waiter.reply.accepted ? 0 : 1;
}

}  // namespace tofguard::intervene
