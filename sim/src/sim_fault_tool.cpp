#include "tofguard/sim/sim_fault_tool.hpp"

#include <lcm/lcm-cpp.hpp>

#include <cmath>
#include <iostream>
#include <map>
#include <sstream>

#include "tofguard/common/clock.hpp"
#include "tofguard/common/config_error.hpp"
#include "tofguard/sim_camera_fault_t.hpp"
#include "tofguard/sim_controller_fault_t.hpp"
#include "tofguard/sim_joint_fault_t.hpp"

namespace tofguard::sim {
namespace {

constexpr const char* kUsage =
    "usage: tofguard-sim-fault [--config FILE] --joint NAME --offset-deg DEGREES\n"
    "       tofguard-sim-fault [--config FILE] --ignore-speed-limit on|off\n"
    "       tofguard-sim-fault [--config FILE] --drive-joint NAME --drive-rad-s SPEED\n"
    "       tofguard-sim-fault [--config FILE] --camera-fault KIND [--duration-s S]\n"
    "           [--size-m X,Y,Z] [--position-m X,Y,Z] [--velocity-m-per-s X,Y,Z]\n"
    "           [--drift-m-per-s X,Y,Z] [--drift-rad-per-s X,Y,Z]\n"
    "  KIND: clear, frozen_image, stall, pose_drift, intruding_object\n";

// A whole string as one finite number; false otherwise.
bool parse_number(const std::string& text, double* out) {
  try {
    size_t used = 0;
    *out = std::stod(text, &used);
    return used == text.size() && std::isfinite(*out);
  } catch (const std::exception&) {
    return false;
  }
}

// "X,Y,Z" -> three finite numbers; false otherwise.
bool parse_vector(const std::string& text, double out[3]) {
  std::istringstream in(text);
  std::string part;
  for (int i = 0; i < 3; ++i) {
    if (!std::getline(in, part, ',') || !parse_number(part, &out[i])) return false;
  }
  return !std::getline(in, part, ',');
}

int usage_error(const std::string& why) {
  std::cerr << "tofguard-sim-fault: " << why << "\n" << kUsage;
  return kConfigErrorExitCode;
}

template <typename Message>
int publish(const SimFaultToolSettings& settings, const std::string& channel, const Message& message) {
  lcm::LCM lcm(settings.lcm.url);
  if (!lcm.good() || lcm.publish(channel, &message) != 0) {
    std::cerr << "tofguard-sim-fault: cannot publish on " << settings.lcm.url << "\n";
    return 3;
  }
  return 0;
}

// A sim_controller_fault_t (it replaces the fault the last one set) on
// SIM_CONTROLLER_FAULT; `said` printed once it is out.
int send_controller_fault(const SimFaultToolSettings& settings, bool ignore_speed_limit,
                          const std::string& drive_joint, double drive_rad_s, const std::string& said) {
  sim_controller_fault_t fault{};
  fault.utime = wall_utime();
  fault.ignore_speed_limit = ignore_speed_limit;
  fault.drive_joint = drive_joint;
  fault.drive_rad_s = drive_rad_s;
  const int code = publish(settings, settings.channels.sim_controller_fault, fault);
  if (code == 0) std::cout << said << std::endl;
  return code;
}

}  // namespace

ProcessInfo sim_fault_info() {
  ProcessInfo info{"tofguard-sim-fault",
                   "Injects faults into the running simulator (simulation only).\n"
                   "  --joint NAME --offset-deg DEGREES: an encoder fault in tofguard-joints-sim\n"
                   "    (0 clears it).\n"
                   "  --ignore-speed-limit on|off: tofguard-joints-sim's controller stops following\n"
                   "    SAFETY_SPEED_LIMIT (a bad plan at full speed) or follows it again (off also\n"
                   "    ends a drive).\n"
                   "  --drive-joint NAME --drive-rad-s SPEED: the controller ignores the limit and\n"
                   "    drives joint NAME at SPEED (rad/s, signed) on top of its motion.\n"
                   "  --camera-fault KIND: a fault in the simulated camera (SIM_CAMERA_FAULT):\n"
                   "    clear, frozen_image, stall, pose_drift (--drift-m-per-s X,Y,Z in the\n"
                   "    camera pose's frame, --drift-rad-per-s about the optical axes) or\n"
                   "    intruding_object (--size-m, --position-m, --velocity-m-per-s: a box in\n"
                   "    the world frame); --duration-s S (default 1000). With several cameras\n"
                   "    (cameras:) --camera ID names the camera.",
                   /*config_required=*/false};
  info.takes_arguments = true;
  return info;
}

int run_sim_fault(const SimFaultToolSettings& settings, const std::vector<std::string>& args) {
  if (args.size() % 2 != 0) return usage_error("expected --option VALUE pairs");
  std::map<std::string, std::string> options;
  for (size_t i = 0; i < args.size(); i += 2) options[args[i]] = args[i + 1];

  if (options.count("--camera-fault")) {
    static const std::map<std::string, int32_t> kinds = {
        {"clear", sim_camera_fault_t::CLEAR},
        {"frozen_image", sim_camera_fault_t::FROZEN_IMAGE},
        {"stall", sim_camera_fault_t::STALL},
        {"pose_drift", sim_camera_fault_t::POSE_DRIFT},
        {"intruding_object", sim_camera_fault_t::INTRUDING_OBJECT}};
    sim_camera_fault_t fault{};
    const std::string kind = options["--camera-fault"];
    if (!kinds.count(kind)) return usage_error("--camera-fault: unknown kind '" + kind + "'");
    fault.kind = kinds.at(kind);
    fault.camera_id = settings.camera_id;
    if (fault.camera_id.empty()) {
      return usage_error(
          "--camera-fault needs the camera: --config FILE, and --camera ID when it has several");
    }
    fault.duration_s = 1000;
    const std::map<std::string, double*> vectors = {{"--size-m", fault.object_size_m},
                                                    {"--position-m", fault.object_position_m},
                                                    {"--velocity-m-per-s", fault.object_velocity_m_per_s},
                                                    {"--drift-m-per-s", fault.drift_translation_m_per_s},
                                                    {"--drift-rad-per-s", fault.drift_rotation_rad_per_s}};
    for (const auto& [name, value] : options) {
      if (name == "--camera-fault") continue;
      if (name == "--duration-s") {
        double seconds = 0;
        if (!parse_number(value, &seconds) || !(seconds > 0 && seconds < 1e6)) {
          return usage_error("--duration-s: expected seconds in (0, 1e6)");
        }
        fault.duration_s = seconds;
      } else if (vectors.count(name)) {
        if (!parse_vector(value, vectors.at(name))) return usage_error(name + ": expected X,Y,Z");
      } else {
        return usage_error("unknown option '" + name + "'");
      }
    }
    if (fault.kind == sim_camera_fault_t::INTRUDING_OBJECT &&
        !(fault.object_size_m[0] > 0 && fault.object_size_m[1] > 0 && fault.object_size_m[2] > 0)) {
      return usage_error("intruding_object: --size-m needs three sizes > 0");
    }
    fault.utime = wall_utime();
    const int code = publish(settings, settings.channels.sim_camera_fault, fault);
    if (code == 0) std::cout << "camera fault: " << kind << " on " << fault.camera_id << std::endl;
    return code;
  }

  if (options.count("--ignore-speed-limit")) {
    const std::string value = options["--ignore-speed-limit"];
    if (options.size() != 1 || (value != "on" && value != "off")) {
      return usage_error("expected --ignore-speed-limit on|off alone");
    }
    return send_controller_fault(settings, value == "on", "", 0,
                                 value == "on" ? "controller fault: the arm ignores the speed limit"
                                               : "controller fault cleared: the arm follows the speed limit");
  }

  if (options.count("--drive-joint")) {
    double rad_s = 0;
    if (options.size() != 2 || !options.count("--drive-rad-s") ||
        !parse_number(options["--drive-rad-s"], &rad_s)) {
      return usage_error("expected --drive-joint NAME --drive-rad-s SPEED (rad/s) alone");
    }
    const std::string joint = options["--drive-joint"];
    std::ostringstream said;
    said << "controller fault: the arm ignores the speed limit and drives " << joint << " at " << rad_s
         << " rad/s (end it with --ignore-speed-limit off)";
    return send_controller_fault(settings, true, joint, rad_s, said.str());
  }

  sim_joint_fault_t fault;
  bool have_offset = false;
  for (const auto& [name, value] : options) {
    if (name == "--joint") {
      fault.joint = value;
    } else if (name == "--offset-deg") {
      double degrees = 0;
      have_offset = parse_number(value, &degrees);
      fault.offset = degrees * M_PI / 180.0;
    } else {
      return usage_error("unknown option '" + name + "'");
    }
  }
  if (fault.joint.empty() || !have_offset) return usage_error("expected --joint NAME --offset-deg DEGREES");
  fault.utime = wall_utime();
  const int code = publish(settings, settings.channels.sim_joint_fault, fault);
  if (code == 0) {
    std::cout << "encoder fault: " << fault.joint << " reports " << options["--offset-deg"]
              << " deg more than its true angle" << std::endl;
  }
  return code;
}

}  // namespace tofguard::sim
