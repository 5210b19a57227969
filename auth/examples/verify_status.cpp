// What a robot controller does with SAFETY_STATUS_AUTH (docs/security.md):
// it takes the permission to move only from a status whose tag, channel,
// age and seq check out with the deployment's key, and moves only while such
// a status with motion_allowed = true keeps arriving within its own
// deadline (positive logic: silence, forgery and replay all mean "stop").
//
// Built from the header-only verifier, the generated LCM types, LCM and
// libsodium alone. Prints one line per message on the channel:
//   accepted seq=<status seq> motion_allowed=<0|1> reason=<reason>
//   refused: <why>
// and exits after --count accepted statuses (0: run until killed), or with 3
// when none was accepted for --timeout-ms.
#include <lcm/lcm-cpp.hpp>

#include <chrono>
#include <iostream>
#include <string>

#include "tofguard/auth/auth_key.hpp"
#include "tofguard/auth/message_verifier.hpp"
#include "tofguard/authenticated_message_t.hpp"
#include "tofguard/safety_status_t.hpp"

namespace {

int64_t wall_utime() {
  using namespace std::chrono;
  return duration_cast<microseconds>(system_clock::now().time_since_epoch()).count();
}

struct Controller {
  tofguard::auth::MessageVerifier verifier;
  std::string status_channel;
  int accepted = 0;

  // Raw bytes, not LCM's typed subscription: decode_authenticated_message
  // bounds the allocation before decoding.
  void on_message(const lcm::ReceiveBuffer* buffer, const std::string&) {
    const auto m = tofguard::auth::decode_authenticated_message(buffer->data, buffer->data_size);
    if (!m) {
      std::cout << "refused: not an authenticated_message_t" << std::endl;
      return;
    }
    std::string refusal;
    const auto status = verifier.open<tofguard::safety_status_t>(*m, status_channel, wall_utime(), &refusal);
    if (!status) {
      std::cout << "refused: " << refusal << std::endl;
      return;  // a controller would count it and keep its deadline running
    }
    ++accepted;
    std::cout << "accepted seq=" << status->seq << " motion_allowed=" << (status->motion_allowed ? 1 : 0)
              << " reason=" << status->reason << std::endl;
  }
};

}  // namespace

int main(int argc, char** argv) {
  std::string key_file, url = "udpm://239.255.76.67:7667?ttl=0", channel = "SAFETY_STATUS";
  int64_t max_age_ms = 250, count = 0, timeout_ms = 5000;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string arg = argv[i], value = argv[i + 1];
    if (arg == "--key") {
      key_file = value;
    } else if (arg == "--url") {
      url = value;
    } else if (arg == "--channel") {
      channel = value;
    } else if (arg == "--max-age-ms") {
      max_age_ms = std::stoll(value);
    } else if (arg == "--count") {
      count = std::stoll(value);
    } else if (arg == "--timeout-ms") {
      timeout_ms = std::stoll(value);
    }
  }
  if (key_file.empty() || argc % 2 == 0) {
    std::cerr << "usage: tofguard-verify-status-example --key FILE [--url URL] [--channel SAFETY_STATUS]\n"
                 "       [--max-age-ms 250] [--count N] [--timeout-ms 5000]\n";
    return 2;
  }
  try {
    Controller controller{
        tofguard::auth::MessageVerifier(tofguard::auth::read_auth_key_file(key_file), max_age_ms * 1000),
        channel};
    lcm::LCM lcm(url);
    if (!lcm.good()) {
      std::cerr << "cannot open LCM at " << url << "\n";
      return 2;
    }
    // The signed status travels on <channel>_AUTH; the plain one on
    // <channel> is for people and logs, never a permission.
    lcm.subscribe(channel + "_AUTH", &Controller::on_message, &controller);
    auto last_accepted = std::chrono::steady_clock::now();
    int seen = 0;
    while (count == 0 || controller.accepted < count) {
      lcm.handleTimeout(100);
      if (controller.accepted != seen) {
        seen = controller.accepted;
        last_accepted = std::chrono::steady_clock::now();
      } else if (std::chrono::steady_clock::now() - last_accepted > std::chrono::milliseconds(timeout_ms)) {
        std::cout << "no accepted status for " << timeout_ms << " ms: stop" << std::endl;
        return 3;
      }
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
}
