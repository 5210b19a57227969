#include "intervention_process.hpp"

namespace tofguard::intervention {

ProcessInfo process_info() {
  return {"tofguard-intervene",
          "Publishes the permission to move (positive logic) and drives the power-cut relay: SAFETY_RISK, SAFETY_RESET -> SAFETY_STATUS."};
}

}  // namespace tofguard::intervention
