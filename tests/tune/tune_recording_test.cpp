// tofguard-tune refuses recordings it cannot tune on, with one line and exit
// code 1: too few frames, an arm that does not move, something in view that
// the model does not have. The recordings are written in-process
// (nominal_log.hpp: the EGL renderer and the ToF error model, lcm::LogFile);
// the tool runs as the real executable.
#include <gtest/gtest.h>

#include <filesystem>
#include <iostream>
#include <regex>
#include <string>
#include <vector>

#include "tofguard/common/camera_profile.hpp"
#include "tofguard/sim/tof_error_model.hpp"

#include "nominal_log.hpp"
#include "tool_support.hpp"
#include "unseen_camera.hpp"

namespace tofguard::test {
namespace {

struct ToolRun {
  int code = 0;
  std::string out, err;
};

ToolRun run_tune(const std::string& config, const std::string& log,
                 const std::vector<std::string>& extra = {}) {
  ToolRun run;
  std::vector<std::string> argv = {bin_dir() + "/tofguard-tune", "--config", config, "--log", log};
  argv.insert(argv.end(), extra.begin(), extra.end());
  run.code = run_command("tofguard-tune", argv, &run.out, &run.err);
  return run;
}

// The one line on stderr.
void expect_refused(const ToolRun& run, const std::string& why) {
  EXPECT_EQ(run.code, 1) << run.out << run.err;
  EXPECT_NE(run.err.find(why), std::string::npos) << run.err;
  EXPECT_EQ(run.err.find('\n'), run.err.size() - 1) << "not one line: " << run.err;
}

class TuneRecording : public ::testing::Test {
 protected:
  void SetUp() override {
    config_path_ = unseen_camera_config("tune-refusals");
    config_ = deployment::load_config(config_path_, nullptr);
  }
  std::string log(const std::string& name, const NominalLogOptions& options) {
    const std::string path = output_dir() + "/tune-" + name + ".lcmlog";
    write_nominal_log(path, config_, options);
    return path;
  }
  std::string config_path_;
  deployment::Config config_;
};

TEST_F(TuneRecording, RefusesTooFewFrames) {
  NominalLogOptions options;
  options.seconds = 1;  // 25 frames
  expect_refused(run_tune(config_path_, log("short", options)), "too few frames");
}

TEST_F(TuneRecording, RefusesAnArmThatDoesNotMove) {
  NominalLogOptions options;
  options.seconds = 2.4;
  options.still = true;
  expect_refused(run_tune(config_path_, log("still", options)), "no motion");
}

TEST_F(TuneRecording, RefusesARecordingWithSomethingInView) {
  NominalLogOptions options;
  options.seconds = 2.4;
  renderer::ExtraObject box;
  box.size_m = Eigen::Vector3d(0.3, 0.3, 0.3);
  box.world_from_object.translation() =
      Eigen::Vector3d(0.10, -0.17, 1.0);  // record-scenario's object, larger
  options.objects.push_back(box);
  expect_refused(run_tune(config_path_, log("object", options)), "not nominal");
}

// Learning a camera profile (--profile-out) from a recording with an object
// in view: the object's pixels are not learned as offsets (they are beyond
// the tolerance in most of their frames), so the corrected frames still
// show it and the recording is refused; no profile is written.
TEST_F(TuneRecording, LearnsNoProfileFromARecordingWithSomethingInView) {
  NominalLogOptions options;
  options.seconds = 2.4;
  renderer::ExtraObject box;
  box.size_m = Eigen::Vector3d(0.3, 0.3, 0.3);
  box.world_from_object.translation() = Eigen::Vector3d(0.10, -0.17, 1.0);
  options.objects.push_back(box);
  const std::string profile = output_dir() + "/tune-object.profile.yaml";
  std::filesystem::remove(profile);
  const ToolRun run = run_tune(config_path_, log("object-profile", options), {"--profile-out", profile});
  expect_refused(run, "not nominal");
  EXPECT_FALSE(std::filesystem::exists(profile));
  EXPECT_NE(run.out.find("camera profile learned"), std::string::npos) << run.out;
}

// Commissioning a camera whose pose is off, on a camera with the static
// errors of a real one (draw_imperfect_camera(7)): no profile is learned
// from it, and the one line says why.
std::string refused_commissioning(const std::string& name, const Eigen::Vector3d& offset_m) {
  const std::string config = imperfect_camera_config(name, sim::draw_imperfect_camera(7, 4000));
  const deployment::Config loaded = deployment::load_config(config, nullptr);
  NominalLogOptions options;
  options.seconds = 2.4;
  options.camera_offset.translation() = offset_m;
  const std::string log = output_dir() + "/" + name + ".lcmlog";
  write_nominal_log(log, loaded, options);
  const std::string profile = output_dir() + "/" + name + ".profile.yaml";
  std::filesystem::remove(profile);
  const ToolRun run = run_tune(config, log, {"--profile-out", profile});
  std::cout << run.out.substr(0, run.out.find('\n', run.out.find("the pose against"))) << "\n" << run.err;
  EXPECT_EQ(run.code, 1) << run.err;
  EXPECT_FALSE(std::filesystem::exists(profile));
  return run.err;
}

// 3 cm along the optical axis: found as a pose error, by how much (the
// camera's static errors bias t_z's fit: its nominal recordings -0.7 cm, so
// about 2.3 cm). t_z's limit is the pose test's 2 cm (camera_profile_fit.hpp).
TEST_F(TuneRecording, FindsACameraPoseOffAlongItsAxisAsAPoseError) {
  const std::string err = refused_commissioning("tune-pose-off-z", Eigen::Vector3d(0, 0, 0.03));
  EXPECT_NE(err.find("the camera pose is off, not its depth: t_z (along the optical axis) fitted "),
            std::string::npos)
      << err;
  std::smatch fitted;
  ASSERT_TRUE(std::regex_search(err, fitted, std::regex(R"(fitted ([-0-9.]+) cm)"))) << err;
  EXPECT_GT(std::stod(fitted[1]), 2.0);
  EXPECT_LT(std::stod(fitted[1]), 4.0);
}

// 2 cm sideways (optical x): 2 m away a sideways shift and a turn about the
// camera's y axis move the scene almost alike, and the joint fit splits it
// (t_x 0.3 cm, r_y 0.2 deg); the recording is refused all the same, its
// pixels mismatching the model, and nothing is learned as depth.
TEST_F(TuneRecording, RefusesToLearnFromACameraMovedSideways) {
  const std::string err = refused_commissioning("tune-pose-off-x", Eigen::Vector3d(0.02, 0, 0));
  EXPECT_NE(err.find("not nominal"), std::string::npos) << err;
}

// A recording whose arm reports a joint 5 degrees off (a faulty encoder):
// nothing is learned as the camera's error, the recording is refused.
TEST_F(TuneRecording, RefusesToLearnFromAnArmWithAFaultyJoint) {
  NominalLogOptions options;
  options.seconds = 2.4;
  options.encoder_offset_rad["a4"] = 5.0 * M_PI / 180.0;
  const std::string profile = output_dir() + "/tune-faulty-joint.profile.yaml";
  std::filesystem::remove(profile);
  const ToolRun run = run_tune(config_path_, log("faulty-joint", options), {"--profile-out", profile});
  expect_refused(run, "not nominal");
  EXPECT_FALSE(std::filesystem::exists(profile));
}

// A profile of another camera (its id) named in the config: the config is
// refused when it is read, naming the key and both ids.
TEST_F(TuneRecording, RefusesAProfileOfAnotherCamera) {
  CameraProfile profile;
  profile.camera_id = "another-camera";
  profile.width = config_.camera.intrinsics.width;
  profile.height = config_.camera.intrinsics.height;
  profile.fx = config_.camera.intrinsics.fx;
  profile.fy = config_.camera.intrinsics.fy;
  profile.cx = config_.camera.intrinsics.cx;
  profile.cy = config_.camera.intrinsics.cy;
  profile.distance_correction_mm = {0.0};
  profile.measured_on = "nothing: a test of the check";
  profile.pixel_correction_mm.assign(static_cast<size_t>(profile.width * profile.height), 0.0f);
  const std::string profile_path = output_dir() + "/tune-another-camera.profile.yaml";
  write_file(profile_path, camera_profile_yaml(profile));
  std::string text = read_file(config_path_);
  const std::string anchor = "\n  max_depth_mm: 8000\n";
  ASSERT_NE(text.find(anchor), std::string::npos);
  text.insert(text.find(anchor) + anchor.size(), "  camera_profile: " + profile_path + "\n");
  const std::string config = output_dir() + "/tune-another-camera.yaml";
  write_file(config, text);
  const ToolRun run = run_tune(config, output_dir() + "/no-such.lcmlog");
  EXPECT_EQ(run.code, 2) << run.out << run.err;
  EXPECT_NE(run.err.find("discrepancy.camera_profile"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("another-camera"), std::string::npos) << run.err;
}

TEST_F(TuneRecording, RefusesAMissingLog) {
  expect_refused(run_tune(config_path_, output_dir() + "/no-such.lcmlog"), "cannot open");
}

}  // namespace
}  // namespace tofguard::test
