// tofguard-bench's logic, short (apps/tofguard-bench/chain_bench.hpp): the
// default arm at 176x144 and 10 Hz for 3 s through the real observer chain,
// and the two-camera scene (config/sim-two-cameras.yaml) for 2 s at 30 Hz.
// Asserts that every frame went through every stage, none was dropped, and
// the report has its rows, the floors' included (renders, compute_discrepancy
// calls and LCM hops counted); never a wall-clock latency (the machine may
// be loaded). That the renderer renders frames ahead: from the joint states
// without a plan, from the plan with --plan.
#include <gtest/gtest.h>

#include <filesystem>
#include <iostream>

#include "chain_bench.hpp"
#include "tool_support.hpp"

namespace tofguard::test {
namespace {

// The default arm at 176x144, 10 Hz for 3 s.
BenchOptions smoke_options() {
  BenchOptions options;
  options.arms = {"default"};
  options.resolutions = {{176, 144}};
  options.rate_hz = 10;
  options.seconds = 3;
  options.shared_dir = shared_dir();
  return options;
}

TEST(BenchSmoke, FramesGoThroughEveryStageAtTenHertz) {
  BenchOptions options = smoke_options();
  // Two idle listeners on each URL while the floors are measured: every
  // hop and relay must still arrive.
  options.floor_listeners = 2;
  const BenchReport report = run_bench(options, std::cerr);
  ASSERT_EQ(report.steps.size(), 1u);
  const BenchStep& step = report.steps.front();
  EXPECT_EQ(step.frames_sent, 30);
  EXPECT_EQ(step.frames_rendered, step.frames_sent);
  EXPECT_EQ(step.frames_judged, step.frames_sent);
  EXPECT_EQ(step.frames_verdict, step.frames_sent);
  EXPECT_EQ(step.frames_dropped, 0);
  EXPECT_EQ(step.end_to_end.count, step.frames_sent);
  EXPECT_GT(step.triangles, 0u);
  for (const char* p : {"tofguard-renderer", "tofguard-discrepancy", "tofguard-risk", "tofguard-intervene"})
    EXPECT_EQ(step.cpu_percent.count(p), 1u) << p;

  // config/sim.yaml has a key: tofguard-risk publishes each verdict signed
  // first, and the stage ends at that copy (the one tofguard-intervene acts
  // on). Nearly every frame's first copy is the signed one: a bench that
  // read only SAFETY_RISK would count none.
  EXPECT_GE(step.frames_verdict_signed_first, step.frames_verdict * 9 / 10) << step.frames_verdict;
  // No plan: tofguard-renderer guesses each next frame from the joint
  // states (renderer.prediction.from_joint_states in config/sim.yaml). The
  // hits begin once it has learned the period from the step's frames, as
  // with a plan (below); a hit at other joints than its frame's would not
  // be SAFE.
  ASSERT_GE(step.prediction_hits, 0) << "no heartbeat of tofguard-renderer said its prediction counts";
  EXPECT_EQ(step.prediction_hits + step.prediction_misses + step.frames_without_prediction, step.frames_sent);
  EXPECT_GE(step.prediction_hits, step.frames_sent / 3);
  EXPECT_GE(step.frames_safe, step.frames_sent * 9 / 10);
  const std::string markdown = bench_markdown(report);
  std::cout << markdown;
  EXPECT_NE(markdown.find("tofguard-renderer rendered " + std::to_string(step.prediction_hits) +
                          " of 30 frames ahead from the joint states"),
            std::string::npos)
      << markdown;
  for (const char* column : {"TOF_DEPTH → TOF_RENDERED", "TOF_RENDERED → SAFETY_DISCREPANCY",
                             "SAFETY_DISCREPANCY → SAFETY_RISK", "TOF_DEPTH → SAFETY_RISK", "CPU %"})
    EXPECT_NE(markdown.find(column), std::string::npos) << column;
  EXPECT_NE(markdown.find("| default | "), std::string::npos);
  EXPECT_NE(markdown.find("| 176x144 | 10 | 30 | 0 | "), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("nproc"), std::string::npos);

  // The floors: measured with the chain stopped, a row per arm and size.
  ASSERT_EQ(report.floors.size(), 1u);
  const BenchFloors& floors = report.floors.front();
  EXPECT_EQ(floors.arm, "default");
  EXPECT_EQ(floors.width, 176);
  EXPECT_EQ(floors.height, 144);
  EXPECT_EQ(floors.listeners, 2);
  EXPECT_NE(markdown.find("With 2 idle LCM instances on each URL"), std::string::npos);
  EXPECT_EQ(floors.render.count, options.floor_frames);
  EXPECT_GT(floors.discrepancy_compute.count, 0);
  for (const HopFloor* hop : {&floors.image_hop, &floors.discrepancy_hop, &floors.risk_hop}) {
    EXPECT_EQ(hop->sent, 30);
    EXPECT_GT(hop->latency.count, 0);
    EXPECT_GT(hop->bytes, 0u);
  }
  // Each relay's messages in and out, of the sizes of its stage's input
  // and output (the image's, the discrepancy_t's, the risk_t's).
  for (const RelayFloor* relay : {&floors.discrepancy_relay, &floors.risk_relay}) {
    EXPECT_EQ(relay->sent, 30);
    EXPECT_GT(relay->latency.count, 0);
  }
  EXPECT_EQ(floors.discrepancy_relay.in_bytes, floors.image_hop.bytes);
  EXPECT_EQ(floors.discrepancy_relay.out_bytes, floors.discrepancy_hop.bytes);
  EXPECT_EQ(floors.risk_relay.in_bytes, floors.discrepancy_hop.bytes);
  EXPECT_EQ(floors.risk_relay.out_bytes, floors.risk_hop.bytes);
  // The stages' floors are made of them.
  EXPECT_DOUBLE_EQ(risk_stage_floor_ms(floors), floors.risk_relay.latency.p50_ms);
  EXPECT_DOUBLE_EQ(discrepancy_stage_floor_ms(floors),
                   floors.discrepancy_compute.p50_ms + floors.discrepancy_relay.latency.p50_ms);
  // A depth_image_t of 176x144 int16 pixels.
  EXPECT_GT(floors.image_hop.bytes, 176u * 144u * 2u);
  for (const char* column :
       {"render floor p50 / p99 / max", "compute_discrepancy p50 / p99 / max",
        "LCM hop floor p50 / p99 / max, TOF_DEPTH / TOF_RENDERED", "LCM hop floor, SAFETY_DISCREPANCY",
        "LCM hop floor, SAFETY_RISK", "relay floor, TOF_RENDERED → SAFETY_DISCREPANCY",
        "relay floor, SAFETY_DISCREPANCY → SAFETY_RISK", "render p50 / floor", "discrepancy p50 / floor",
        "risk p50 / floor"})
    EXPECT_NE(markdown.find(column), std::string::npos) << column;
  EXPECT_NE(markdown.find("| default | 176x144 | 10 | "), std::string::npos) << markdown;

  const std::string plot = output_dir() + "/bench_smoke/bench.png";
  plot_bench(report, plot);
  EXPECT_GT(std::filesystem::file_size(plot), 1000u);
}

// --plan: the bench publishes the arm's path as its plan, and
// tofguard-renderer renders frames ahead from it. Each frame of the step is
// counted once as a hit, a miss or a frame without a prediction. The hits
// begin once the renderer has learned the camera's period from the step's
// frames (the warm-up's one-at-a-time frames teach it a wrong one, and
// after 5 misses in a row it predicts only every 8th frame until a hit:
// RendererService): at least a third of the 30 frames.
TEST(BenchSmoke, WithThePlanFramesAreRenderedAhead) {
  BenchOptions options = smoke_options();
  options.floors = false;
  options.plan = true;
  const BenchReport report = run_bench(options, std::cerr);
  ASSERT_EQ(report.steps.size(), 1u);
  const BenchStep& step = report.steps.front();
  EXPECT_EQ(step.frames_verdict, step.frames_sent);
  EXPECT_EQ(step.frames_dropped, 0);
  // A hit rendered at other joints or another time than its frame's would
  // be judged a model-reality mismatch (config/sim.yaml's joints move up to
  // 4.5 degrees a frame at 10 Hz): the verdicts stay SAFE, but for the odd
  // warning.
  EXPECT_GE(step.frames_safe, step.frames_sent * 9 / 10);
  ASSERT_GE(step.prediction_hits, 0) << "no heartbeat of tofguard-renderer said its prediction counts";
  EXPECT_EQ(step.prediction_hits + step.prediction_misses + step.frames_without_prediction, step.frames_sent);
  EXPECT_GE(step.prediction_hits, step.frames_sent / 3);
  const std::string markdown = bench_markdown(report);
  std::cout << markdown;
  EXPECT_NE(markdown.find("tofguard-renderer rendered " + std::to_string(step.prediction_hits) + " of 30"),
            std::string::npos)
      << markdown;
}

// The two-camera deployment as it is (config/sim-two-cameras.yaml, both
// cameras commissioned), the side camera exposing half a period after the
// mast camera (its frames made at their own instant of the arm's path):
// each camera's frames go through its own renderer and discrepancy process
// to a verdict of their own (by seq), SAFE, a row per camera; no floors
// (one camera's stages alone).
TEST(BenchSmoke, TwoCamerasEachFrameGetsItsOwnVerdict) {
  BenchOptions options = smoke_options();
  options.arms = {"two-cameras"};
  options.rate_hz = 30;  // the cameras' own rate
  options.seconds = 2;
  options.camera_offset_ms = 16.7;
  const BenchReport report = run_bench(options, std::cerr);
  ASSERT_EQ(report.steps.size(), 2u);
  EXPECT_TRUE(report.floors.empty());
  const std::string ids[2] = {"tof-mast", "tof-side"};
  for (size_t c = 0; c < 2; ++c) {
    const BenchStep& step = report.steps[c];
    EXPECT_EQ(step.arm, "two-cameras " + ids[c]);
    EXPECT_EQ(step.frames_sent, 60);
    EXPECT_EQ(step.frames_rendered, step.frames_sent) << step.arm;
    EXPECT_EQ(step.frames_judged, step.frames_sent) << step.arm;
    EXPECT_EQ(step.frames_verdict, step.frames_sent) << step.arm;
    EXPECT_EQ(step.frames_dropped, 0) << step.arm;
    EXPECT_EQ(step.end_to_end.count, step.frames_sent) << step.arm;
    EXPECT_GE(step.frames_safe, step.frames_sent * 9 / 10) << step.arm;
    for (const char* p : {"tofguard-renderer", "tofguard-discrepancy", "tofguard-risk", "tofguard-intervene"})
      EXPECT_EQ(step.cpu_percent.count(p), 1u) << step.arm << ": " << p;
  }
  const std::string markdown = bench_markdown(report);
  std::cout << markdown;
  EXPECT_NE(markdown.find("| two-cameras tof-side | "), std::string::npos) << markdown;
}

// A deployment of config/ runs at its cameras' own size and rate, and its
// cameras expose within a frame period: anything else is refused before
// any process starts, saying what was asked and what it must be.
TEST(BenchSmoke, ADeploymentAtAnotherSizeOrOffsetIsRefused) {
  BenchOptions options = smoke_options();
  options.arms = {"two-cameras"};
  options.resolutions = {{320, 240}};
  try {
    run_bench(options, std::cerr);
    ADD_FAILURE() << "ran config/sim-two-cameras.yaml at 320x240";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("tof-mast is 176x144 at 30 Hz, asked 320x240 at 10 Hz"),
              std::string::npos)
        << e.what();
  }
  options = smoke_options();
  options.arms = {"two-cameras"};
  options.rate_hz = 30;
  options.camera_offset_ms = 32;
  try {
    run_bench(options, std::cerr);
    ADD_FAILURE() << "ran two cameras 32 ms apart at 30 Hz";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "--camera-offset-ms 32: 2 cameras must expose within the 33.333 ms period"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace tofguard::test
