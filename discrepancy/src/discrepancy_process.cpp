#include "discrepancy_process.hpp"

namespace tofguard::discrepancy {

ProcessInfo process_info() {
  return {"tofguard-discrepancy",
          "Pairs camera and rendered frames and computes I_dis = I_gen - I_ToF: TOF_DEPTH, TOF_RENDERED, TOF_LABELS -> SAFETY_DISCREPANCY."};
}

}  // namespace tofguard::discrepancy
