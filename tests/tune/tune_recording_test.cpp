// tofguard-tune refuses recordings it cannot tune on, with one line and exit
// code 1: too few frames, an arm that does not move, something in view that
// the model does not have. The recordings are written in-process
// (nominal_log.hpp: the EGL renderer and the ToF error model, lcm::LogFile);
// the tool runs as the real executable.
#include <gtest/gtest.h>

#include <string>

#include "nominal_log.hpp"
#include "tool_support.hpp"
#include "unseen_camera.hpp"

namespace tofguard::test {
namespace {

struct ToolRun {
  int code = 0;
  std::string out, err;
};

ToolRun run_tune(const std::string& config, const std::string& log) {
  ToolRun run;
  run.code = run_command("tofguard-tune", {bin_dir() + "/tofguard-tune", "--config", config, "--log", log},
                         &run.out, &run.err);
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

TEST_F(TuneRecording, RefusesAMissingLog) {
  expect_refused(run_tune(config_path_, output_dir() + "/no-such.lcmlog"), "cannot open");
}

}  // namespace
}  // namespace tofguard::test
