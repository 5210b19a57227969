#pragma once
// The `lcm` power-cut actuator (intervention.power_cut: lcm, docs/intervene.md):
// power_relay_t on SAFETY_POWER, and with a key signed on SAFETY_POWER_AUTH
// first (power_enabled = true is a permission too), for a power controller
// that listens to LCM with its own deadline.
#include <cstdint>
#include <string>

#include <lcm/lcm-cpp.hpp>

#include "tofguard/auth/message_signer.hpp"
#include "tofguard/intervene/power_actuator.hpp"

namespace tofguard::intervene {

class LcmPowerActuator : public PowerActuator {
 public:
  // `signer` null: insecure (plain messages only); else it outlives this.
  LcmPowerActuator(lcm::LCM& lcm, std::string channel, std::string auth_channel, auth::MessageSigner* signer);
  std::string set_power(bool enabled, const std::string& reason) override;

 private:
  lcm::LCM& lcm_;
  std::string channel_;
  std::string auth_channel_;
  auth::MessageSigner* signer_;  // null: insecure
  int64_t seq_ = 0;
};

}  // namespace tofguard::intervene
