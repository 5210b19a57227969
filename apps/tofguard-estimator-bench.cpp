// Estimation time (tofguard-estimator's work) for the default arm in the
// side-reach pose with a 10 degree encoder offset on a4, joints and camera
// free, at 176x144 (the embedded default) and 320x240 (the same field of
// view), on one frame and on the 3 frames an estimate is made of
// (config/sim.yaml). Frames from the simulated ToF camera.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <vector>

#include "scaled_intrinsics.hpp"
#include "simulated_frames.hpp"
#include "tofguard/deployment/config.hpp"
#include "tofguard/deployment/process_settings.hpp"
#include "tofguard/estimator/motion_estimator.hpp"

namespace tofguard::estimator {
namespace {

// state.range(0) x state.range(1) pixels; state.range(2) frames estimated
// jointly (estimator.frames_per_estimate: the frame and the ones 33 and 67
// ms before it, the arm moving 0.5 degrees a frame per joint).
void BM_Estimate(benchmark::State& state) {
  // As tofguard-estimator runs (apps/tofguard-estimator.cpp): no llvmpipe render
  // threads, unless the environment says otherwise.
  setenv("LP_NUM_THREADS", "0", /*overwrite=*/0);
  const deployment::Config config =
      deployment::load_config(std::string(TOFGUARD_SOURCE_DIR) + "/config/sim.yaml", nullptr);
  tofguard::test::SimulatedFrames frames(config);
  EstimatorOptions options;
  options.noise.sigma_at_0m_mm = config.discrepancy.noise_sigma_at_0m_mm;
  options.noise.sigma_per_m2_mm = config.discrepancy.noise_sigma_per_m2_mm;
  MotionEstimator estimator(frames.scene(), &frames.renderer(), options);
  const robot_model::JointPositions truth = {{"a1", -0.6}, {"a2", 1.3}, {"a3", -0.4}, {"a4", 1.2},
                                             {"a5", 0.6},  {"a6", 1.0}, {"a7", -0.4}};
  const Eigen::Isometry3d camera = config.camera.pose.frame_from_optical();
  const Intrinsics intrinsics = tofguard::test::scaled_intrinsics(
      config.camera.intrinsics, static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  uint64_t frame_index = 0;
  const std::vector<EstimatorFrame> estimated = frames.frames_with_offset(
      truth, camera, intrinsics, "a4", 10 * M_PI / 180, static_cast<int>(state.range(2)), &frame_index);
  double iterations = 0, offset = 0;
  for (auto _ : state) {
    const EstimateResult r = estimator.estimate(estimated);
    if (!r.usable) state.SkipWithError(r.unusable_reason.c_str());
    iterations = r.iterations;
    offset = r.joints[3].offset() * 180 / M_PI;
  }
  state.counters["gn_iterations"] = iterations;
  state.counters["a4_offset_deg"] = offset;
}
BENCHMARK(BM_Estimate)
    ->ArgNames({"width", "height", "frames"})
    ->Args({176, 144, 1})
    ->Args({320, 240, 1})
    ->Args({176, 144, 3})
    ->Args({320, 240, 3})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(3.0);

}  // namespace
}  // namespace tofguard::estimator

BENCHMARK_MAIN();
