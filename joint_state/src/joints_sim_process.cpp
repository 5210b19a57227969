#include "joints_sim_process.hpp"

namespace tofguard::joints_sim {

ProcessInfo process_info() {
  return {"tofguard-joints-sim",
          "Simulated arm: publishes JOINT_STATE at 100 Hz and halts when SAFETY_STATUS withdraws permission."};
}

}  // namespace tofguard::joints_sim
