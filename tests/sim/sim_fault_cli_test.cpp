// tofguard-sim-fault as a real process over real LCM (private network
// namespace): the encoder fault and each camera fault arrive as the messages
// the simulator takes; bad arguments are usage errors (exit 2) that publish
// nothing.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <cmath>
#include <optional>

#include "tofguard/sim_camera_fault_t.hpp"
#include "tofguard/sim_controller_fault_t.hpp"
#include "tofguard/sim_joint_fault_t.hpp"
#include "tool_support.hpp"
#include "two_camera_config.hpp"

namespace tofguard::test {
namespace {

struct Listener {
  lcm::LCM lcm{"udpm://239.255.76.67:7667?ttl=0"};
  std::optional<std::string> camera_channel;
  std::optional<sim_joint_fault_t> joint;
  std::optional<sim_camera_fault_t> camera;
  std::optional<sim_controller_fault_t> controller;
  Listener() {
    lcm.subscribe("SIM_JOINT_FAULT", &Listener::on_joint, this);
    lcm.subscribe("SIM_CAMERA_FAULT.*", &Listener::on_camera, this);
    lcm.subscribe("SIM_CONTROLLER_FAULT", &Listener::on_controller, this);
  }
  void on_controller(const lcm::ReceiveBuffer*, const std::string&, const sim_controller_fault_t* m) {
    controller = *m;
  }
  void on_joint(const lcm::ReceiveBuffer*, const std::string&, const sim_joint_fault_t* m) { joint = *m; }
  void on_camera(const lcm::ReceiveBuffer*, const std::string& channel, const sim_camera_fault_t* m) {
    camera = *m;
    camera_channel = channel;
  }
  std::string config = source_dir() + "/config/sim.yaml";
  // Runs the tool on `config` and handles what it published.
  int run(const std::vector<std::string>& args, std::string* err = nullptr) {
    std::vector<std::string> argv = {bin_dir() + "/tofguard-sim-fault", "--config", config};
    argv.insert(argv.end(), args.begin(), args.end());
    const int code = run_command("sim-fault", argv, nullptr, err);
    while (lcm.handleTimeout(100) > 0) {
    }
    return code;
  }
};

TEST(SimFaultCli, EncoderFault) {
  Listener l;
  ASSERT_EQ(l.run({"--joint", "a4", "--offset-deg", "10"}), 0);
  ASSERT_TRUE(l.joint);
  EXPECT_EQ(l.joint->joint, "a4");
  EXPECT_NEAR(l.joint->offset, 0.174533, 1e-6);
}

// A drive ignores the limit too; "--ignore-speed-limit off" ends both.
TEST(SimFaultCli, AJointDrivenAndTheControllerFixed) {
  Listener l;
  ASSERT_EQ(l.run({"--drive-joint", "a1", "--drive-rad-s", "-1.5"}), 0);
  ASSERT_TRUE(l.controller);
  EXPECT_TRUE(l.controller->ignore_speed_limit);
  EXPECT_EQ(l.controller->drive_joint, "a1");
  EXPECT_DOUBLE_EQ(l.controller->drive_rad_s, -1.5);
  ASSERT_EQ(l.run({"--ignore-speed-limit", "off"}), 0);
  EXPECT_FALSE(l.controller->ignore_speed_limit);
  EXPECT_EQ(l.controller->drive_joint, "");
  EXPECT_EQ(l.controller->drive_rad_s, 0);
}

TEST(SimFaultCli, IntrudingObjectWithItsBox) {
  Listener l;
  ASSERT_EQ(l.run({"--camera-fault", "intruding_object", "--size-m", "0.1,0.2,0.3", "--position-m",
                   "1,-2,0.5", "--duration-s", "4.5"}),
            0);
  ASSERT_TRUE(l.camera);
  EXPECT_EQ(l.camera->kind, sim_camera_fault_t::INTRUDING_OBJECT);
  EXPECT_EQ(l.camera->camera_id, "tof-mast");
  EXPECT_DOUBLE_EQ(l.camera->duration_s, 4.5);
  EXPECT_DOUBLE_EQ(l.camera->object_size_m[1], 0.2);
  EXPECT_DOUBLE_EQ(l.camera->object_position_m[1], -2);
  EXPECT_DOUBLE_EQ(l.camera->object_velocity_m_per_s[0], 0);
}

TEST(SimFaultCli, PoseDriftStallAndClear) {
  Listener l;
  ASSERT_EQ(l.run({"--camera-fault", "pose_drift", "--duration-s", "0.01", "--drift-m-per-s", "5,0,0"}), 0);
  ASSERT_TRUE(l.camera);
  EXPECT_EQ(l.camera->kind, sim_camera_fault_t::POSE_DRIFT);
  EXPECT_DOUBLE_EQ(l.camera->drift_translation_m_per_s[0], 5);
  ASSERT_EQ(l.run({"--camera-fault", "stall"}), 0);
  EXPECT_EQ(l.camera->kind, sim_camera_fault_t::STALL);
  EXPECT_DOUBLE_EQ(l.camera->duration_s, 1000);
  ASSERT_EQ(l.run({"--camera-fault", "clear"}), 0);
  EXPECT_EQ(l.camera->kind, sim_camera_fault_t::CLEAR);
}

TEST(SimFaultCli, BadArgumentsAreUsageErrorsAndPublishNothing) {
  Listener l;
  std::string err;
  EXPECT_EQ(l.run({"--camera-fault", "melted"}, &err), 2);
  EXPECT_NE(err.find("unknown kind 'melted'"), std::string::npos) << err;
  EXPECT_EQ(l.run({"--camera-fault", "intruding_object", "--position-m", "1,2"}, &err), 2);
  EXPECT_NE(err.find("--position-m: expected X,Y,Z"), std::string::npos) << err;
  EXPECT_EQ(l.run({"--camera-fault", "intruding_object"}, &err), 2);  // no box size
  EXPECT_EQ(l.run({"--camera-fault", "stall", "--duration-s", "-1"}, &err), 2);
  EXPECT_EQ(l.run({"--joint", "a4", "--offset-deg", "ten"}, &err), 2);
  EXPECT_EQ(l.run({"--joint", "a4"}, &err), 2);
  EXPECT_EQ(l.run({"--drive-joint", "a1", "--drive-rad-s", "fast"}, &err), 2);
  EXPECT_NE(err.find("expected --drive-joint NAME --drive-rad-s SPEED"), std::string::npos) << err;
  EXPECT_EQ(l.run({"--drive-joint", "a1"}, &err), 2);
  // Without a config there is no camera id to address.
  const int code =
      run_command("sim-fault", {bin_dir() + "/tofguard-sim-fault", "--camera-fault", "stall"}, nullptr, &err);
  EXPECT_EQ(code, 2);
  EXPECT_NE(err.find("needs the camera: --config FILE"), std::string::npos) << err;
  EXPECT_FALSE(l.camera);
  EXPECT_FALSE(l.joint);
  EXPECT_FALSE(l.controller);
}

// With several cameras a camera fault names its camera (--camera ID) and
// goes to that camera's channel; a joint fault needs none.
TEST(SimFaultCli, WithTwoCamerasACameraFaultNamesItsCamera) {
  Listener l;
  l.config = two_camera_config("sim-fault-two-cameras");
  ASSERT_EQ(l.run({"--joint", "a4", "--offset-deg", "10"}), 0);
  EXPECT_TRUE(l.joint);
  std::string err;
  EXPECT_EQ(l.run({"--camera-fault", "stall"}, &err), 2);
  EXPECT_NE(err.find("--camera ID when it has several"), std::string::npos) << err;
  EXPECT_FALSE(l.camera);
  ASSERT_EQ(l.run({"--camera", "tof-side", "--camera-fault", "stall"}), 0);
  ASSERT_TRUE(l.camera);
  EXPECT_EQ(l.camera->camera_id, "tof-side");
  EXPECT_EQ(l.camera_channel, "SIM_CAMERA_FAULT/tof-side");
  EXPECT_EQ(l.run({"--camera", "tof-roof", "--camera-fault", "stall"}, &err), 2);
  EXPECT_NE(err.find("no camera 'tof-roof'"), std::string::npos) << err;
}

}  // namespace
}  // namespace tofguard::test
