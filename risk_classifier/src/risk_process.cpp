#include "risk_process.hpp"

namespace tofguard::risk {

ProcessInfo process_info() {
  return {"tofguard-risk",
          "Classifies the risk of every frame and fires deadlines: SAFETY_DISCREPANCY, SAFETY_HEARTBEAT -> SAFETY_RISK."};
}

}  // namespace tofguard::risk
