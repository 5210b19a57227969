// The renderer's time from a camera frame to its TOF_RENDERED / TOF_LABELS
// messages (RendererService::render: joint interpolation, camera pose,
// rendering or the prediction, conversion to the wire types), with and
// without a plan (PLANNED_TRAJECTORY). With the plan the next frame is
// rendered ahead while the process is idle (not timed here: it happens
// between frames), so a frame that matches only costs the comparison and the
// conversion. LCM transport is not included. Results: docs/benchmarks.md.
//
//   build/bin/tofguard-prediction-bench --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true   (one command line)
#include <benchmark/benchmark.h>

#include "tofguard/common/depth_frame.hpp"
#include "tofguard/deployment/config.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/renderer/renderer_service.hpp"

namespace tofguard::renderer {
namespace {

constexpr int64_t kT0 = 1'700'000'000'000'000;
constexpr int64_t kPeriodUs = 33'333;

const deployment::Config& sim_config() {
  static const deployment::Config config =
      deployment::load_config(std::string(TOFGUARD_SOURCE_DIR) + "/config/sim.yaml", nullptr);
  return config;
}

// The sim arm's centre pose (joints_sim.motion centres).
const std::map<std::string, double> kJoints = {{"a1", -0.3}, {"a2", 0.7}, {"a3", 0.0}, {"a4", 1.1},
                                               {"a5", 0.0},  {"a6", 0.6}, {"a7", 0.0}};

joint_state_t joints_at(int64_t utime) {
  joint_state_t s;
  s.utime = utime;
  s.robot_id = sim_config().robot.id;
  for (const auto& [name, value] : kJoints) {
    s.name.push_back(name);
    s.position.push_back(value);
    s.velocity.push_back(0);
  }
  s.num_joints = static_cast<int32_t>(s.name.size());
  return s;
}

// A flat wall 1.5 m away filling the frame (what it shows does not matter).
depth_image_t frame_at(int64_t utime, int64_t seq) {
  const CameraSettings& camera = sim_config().camera;
  return make_depth_image(camera.id, camera.intrinsics, utime, seq, /*calibrated=*/true,
                          std::vector<float>(camera.intrinsics.width * camera.intrinsics.height, 1.5f));
}

planned_trajectory_t hold_plan() {
  planned_trajectory_t p;
  p.utime = kT0;
  for (const auto& [name, value] : kJoints) p.joint_name.push_back(name);
  p.num_joints = static_cast<int32_t>(p.joint_name.size());
  p.point_utime = {kT0, kT0 + 3'600'000'000};
  p.num_points = 2;
  for (int i = 0; i < 2; ++i) {
    p.position.emplace_back();
    for (const auto& [name, value] : kJoints) p.position.back().push_back(value);
  }
  return p;
}

void frame_to_rendered(benchmark::State& state, bool with_plan) {
  RendererService service(deployment::renderer_process_settings(sim_config()));
  if (with_plan) service.on_plan(hold_plan());
  int64_t utime = kT0;
  int64_t seq = 0;
  int64_t next_joint_utime = kT0 - 100'000;
  auto next_frame = [&] {
    utime += kPeriodUs;
    for (; next_joint_utime <= utime + 10'000; next_joint_utime += 10'000)
      service.on_joint_state(joints_at(next_joint_utime));
    return frame_at(utime, ++seq);
  };
  // Two frames to learn the period.
  service.render(next_frame());
  service.render(next_frame());
  for (auto _ : state) {
    state.PauseTiming();
    const depth_image_t frame = next_frame();
    service.render_prediction();  // the idle time between frames
    state.ResumeTiming();
    RenderedFrame out = service.render(frame);
    benchmark::DoNotOptimize(out);
    if (!out.labels.usable) state.SkipWithError(out.labels.unusable_reason.c_str());
  }
  state.counters["hits"] = static_cast<double>(service.prediction_stats().hits);
  state.counters["misses"] = static_cast<double>(service.prediction_stats().misses);
}

void BM_FrameToRendered_NoPlan(benchmark::State& state) { frame_to_rendered(state, false); }
void BM_FrameToRendered_PlanHit(benchmark::State& state) { frame_to_rendered(state, true); }
BENCHMARK(BM_FrameToRendered_NoPlan)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FrameToRendered_PlanHit)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace tofguard::renderer

BENCHMARK_MAIN();
