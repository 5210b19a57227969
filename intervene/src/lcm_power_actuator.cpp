#include "tofguard/intervene/lcm_power_actuator.hpp"

#include <utility>

#include "tofguard/auth/signed_publish.hpp"
#include "tofguard/common/clock.hpp"
#include "tofguard/power_relay_t.hpp"

namespace tofguard::intervene {

LcmPowerActuator::LcmPowerActuator(lcm::LCM& lcm, std::string channel, std::string auth_channel,
                                   auth::MessageSigner* signer)
    : lcm_(lcm), channel_(std::move(channel)), auth_channel_(std::move(auth_channel)), signer_(signer) {}

std::string LcmPowerActuator::set_power(bool enabled, const std::string& reason) {
  power_relay_t message;
  message.utime = wall_utime();
  message.seq = seq_++;
  message.power_enabled = enabled;
  message.reason = reason;
  return auth::publish_signed(lcm_, signer_, channel_, auth_channel_, message, wall_utime());
}

}  // namespace tofguard::intervene
