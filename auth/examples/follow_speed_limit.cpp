// What a robot controller that scales its speed does with
// SAFETY_SPEED_LIMIT_AUTH beside SAFETY_STATUS_AUTH (docs/security.md, "The
// speed limit"): it takes both only as verified messages (tag, channel,
// age, seq with the deployment's key), and caps the arm's fastest surface
// point at
//   0                                  without a fresh verified status that
//                                      allows motion (its own deadline),
//   0                                  without a verified limit newer than
//                                      its valid_for_ms (on this clock),
//   min(desired, max_arm_speed_m_s)    otherwise.
// The limit only lowers what the status allows; it never allows motion.
//
// Built from the header-only verifier, the generated LCM types, LCM and
// libsodium alone. Prints one line per message on the limit's channel:
//   limit seq=<frame seq> max=<m/s> set_by=<n> -> cap <m/s> (<why>)
//   refused: <why>
// and exits after --count verified limits (0: run until killed), or with 3
// when none was verified for --timeout-ms.
#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <optional>
#include <string>
#include <utility>

#include "tofguard/auth/auth_key.hpp"
#include "tofguard/auth/message_verifier.hpp"
#include "tofguard/authenticated_message_t.hpp"
#include "tofguard/safety_status_t.hpp"
#include "tofguard/speed_limit_t.hpp"

namespace {

using Clock = std::chrono::steady_clock;

int64_t wall_utime() {
  using namespace std::chrono;
  return duration_cast<microseconds>(system_clock::now().time_since_epoch()).count();
}

struct Controller {
  explicit Controller(tofguard::auth::MessageVerifier v) : verifier(std::move(v)) {}

  tofguard::auth::MessageVerifier verifier;
  double desired_m_s = 0;
  std::chrono::milliseconds status_deadline{300};
  std::optional<tofguard::safety_status_t> status;
  Clock::time_point status_arrival;
  std::optional<tofguard::speed_limit_t> limit;
  Clock::time_point limit_arrival;
  int limits = 0;

  template <class T>
  std::optional<T> open(const lcm::ReceiveBuffer* buffer, const std::string& channel) {
    const auto m = tofguard::auth::decode_authenticated_message(buffer->data, buffer->data_size);
    std::string refusal = "not an authenticated_message_t";
    std::optional<T> message;
    if (m) message = verifier.open<T>(*m, channel, wall_utime(), &refusal);
    if (!message) std::cout << "refused: " << refusal << std::endl;  // counted; deadlines keep running
    return message;
  }

  void on_status(const lcm::ReceiveBuffer* buffer, const std::string&) {
    if (auto s = open<tofguard::safety_status_t>(buffer, "SAFETY_STATUS")) {
      status = s;
      status_arrival = Clock::now();
    }
  }

  void on_limit(const lcm::ReceiveBuffer* buffer, const std::string&) {
    auto l = open<tofguard::speed_limit_t>(buffer, "SAFETY_SPEED_LIMIT");
    if (!l) return;
    limit = l;
    limit_arrival = Clock::now();
    ++limits;
    std::string why;
    const double cap = speed_cap_m_s(&why);
    std::printf("limit seq=%lld max=%.2f set_by=%d -> cap %.2f (%s)\n", static_cast<long long>(l->seq),
                l->max_arm_speed_m_s, l->set_by, cap, why.c_str());
    std::fflush(stdout);
  }

  // The highest speed the controller commands now, and why.
  double speed_cap_m_s(std::string* why) const {
    const Clock::time_point now = Clock::now();
    if (!status || now - status_arrival > status_deadline || !status->motion_allowed) {
      *why = "no fresh status allowing motion";
      return 0;
    }
    if (!limit || now - limit_arrival > std::chrono::milliseconds(limit->valid_for_ms)) {
      *why = "no limit within its validity";
      return 0;
    }
    *why = limit->max_arm_speed_m_s < desired_m_s ? "the limit" : "the task's speed";
    return std::min(desired_m_s, limit->max_arm_speed_m_s);
  }
};

}  // namespace

int main(int argc, char** argv) {
  std::string key_file, url = "udpm://239.255.76.67:7667?ttl=0";
  int64_t max_age_ms = 250, count = 0, timeout_ms = 5000;
  double desired_m_s = 0.5;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string arg = argv[i], value = argv[i + 1];
    if (arg == "--key") {
      key_file = value;
    } else if (arg == "--url") {
      url = value;
    } else if (arg == "--max-age-ms") {
      max_age_ms = std::stoll(value);
    } else if (arg == "--count") {
      count = std::stoll(value);
    } else if (arg == "--timeout-ms") {
      timeout_ms = std::stoll(value);
    } else if (arg == "--desired-m-s") {
      desired_m_s = std::stod(value);
    }
  }
  if (key_file.empty() || argc % 2 == 0) {
    std::cerr << "usage: tofguard-follow-speed-limit-example --key FILE [--url URL] [--desired-m-s 0.5]\n"
                 "       [--max-age-ms 250] [--count N] [--timeout-ms 5000]\n";
    return 2;
  }
  try {
    Controller controller(
        tofguard::auth::MessageVerifier(tofguard::auth::read_auth_key_file(key_file), max_age_ms * 1000));
    controller.desired_m_s = desired_m_s;
    lcm::LCM lcm(url);
    if (!lcm.good()) {
      std::cerr << "cannot open LCM at " << url << "\n";
      return 2;
    }
    lcm.subscribe("SAFETY_STATUS_AUTH", &Controller::on_status, &controller);
    lcm.subscribe("SAFETY_SPEED_LIMIT_AUTH", &Controller::on_limit, &controller);
    auto last_limit = Clock::now();
    int seen = 0;
    while (count == 0 || controller.limits < count) {
      lcm.handleTimeout(100);
      if (controller.limits != seen) {
        seen = controller.limits;
        last_limit = Clock::now();
      } else if (Clock::now() - last_limit > std::chrono::milliseconds(timeout_ms)) {
        std::cout << "no verified limit for " << timeout_ms << " ms: stand" << std::endl;
        return 3;
      }
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
}
