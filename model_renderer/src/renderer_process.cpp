#include "renderer_process.hpp"

namespace tofguard::renderer {

ProcessInfo process_info() {
  return {"tofguard-renderer",
          "Renders the arm's model at the reported joint angles from the camera's pose: TOF_DEPTH, JOINT_STATE, CAMERA_POSE -> TOF_RENDERED, TOF_LABELS."};
}

}  // namespace tofguard::renderer
