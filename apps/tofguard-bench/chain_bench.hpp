#pragma once
// The observer chain's speed as processes: tofguard-renderer,
// -discrepancy, -risk and -intervene started from build/bin with a config
// made for the arm and camera size, fed over real LCM by the bench's own
// publisher with depth frames prepared beforehand (the simulated ToF camera's
// pipeline: the scene rendered at the arm's pose, its error model and the
// distance calibration) and joint states along a smooth path. Per frame the
// bench records, on its own monotonic clock, when it sent TOF_DEPTH and
// when TOF_RENDERED, SAFETY_DISCREPANCY and SAFETY_RISK for that frame's seq
// arrived; from that the latency of each stage, frames dropped, CPU per
// process (/proc) and, ramping the rate, the highest rate sustained.
//
// Beside each arm and size, the floors the stages are held against (the
// target: each stage within 2x of its floor), measured by the bench itself after
// the chain's processes are stopped: the renderer's scene rendered in this
// process along the same joint path at the same intrinsics, compute_discrepancy
// on the prepared frames, and one LCM hop of each stage's message size on a
// scratch channel of the chain's URL at the run's rate (BenchFloors).
//
// A measuring tool, not a test of timing: LCM must run in a private network
// namespace (scripts/bench, tests/netns/run-in-netns).
#include <cstdint>
#include <map>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "judge_campaign.hpp"
#include "tofguard/common/camera_geometry.hpp"

namespace tofguard::test {

struct BenchOptions {
  // default, iiwa14, kinova (the last two from `shared_dir`/robots).
  std::vector<std::string> arms = {"default"};
  // Camera sizes; the config's intrinsics scaled to each (same field of view).
  std::vector<std::pair<int, int>> resolutions = {{176, 144}};
  double rate_hz = 30;
  double seconds = 10;
  // With several cameras (--arms two-cameras), camera c exposes
  // c * camera_offset_ms after camera 0 (cameras triggered in turn, as
  // time-multiplexed ToF cameras are); each camera's frames then show the
  // arm at their own instant, carry it as utime, and its joint state comes
  // 1 ms before each as before camera 0's. 0: every camera at the same
  // instant, one frame right after the other. At most the frame period
  // less 2 ms over the cameras.
  double camera_offset_ms = 0;
  // Ramp: rates ramp_start_hz, twice that, ... up to ramp_max_hz, each for
  // ramp_step_s, stopping at the first rate with a dropped frame, a stage's
  // p99 above the frame period, or a publisher that could not keep the rate;
  // then ramp_refinements rates between the last rate sustained and that
  // one, each halving the gap.
  bool ramp = false;
  int ramp_refinements = 2;
  double ramp_start_hz = 30;
  double ramp_max_hz = 1920;
  double ramp_step_s = 3;
  // A TOF_DEPTH whose SAFETY_RISK has not come this long after it was sent
  // is dropped.
  int64_t result_timeout_us = 1000000;
  // Also publish the arm's path as the arm controller's plan
  // (PLANNED_TRAJECTORY: a point at every frame's capture time, sent in
  // chunks ahead of the frames), so that tofguard-renderer renders each next
  // frame ahead while it waits (renderer.prediction; docs/renderer.md) and
  // a frame within the tolerances of its plan is not rendered on its
  // critical path. The renderer's hits and misses are reported per step.
  // Off: no plan (the default); then each next frame is rendered ahead from
  // the joint states instead (renderer.prediction.from_joint_states, on in
  // config/sim.yaml) unless joint_prediction is off too.
  bool plan = false;
  // Off (--no-joint-prediction): the chain's renderer guesses no frame from
  // the joint states (from_joint_states: false), so that without a plan
  // every frame is rendered when it comes.
  bool joint_prediction = true;
  // Measure the floors (BenchFloors) after each arm and size's run;
  // floor_frames renders (and compute_discrepancy calls) back to back.
  bool floors = true;
  int floor_frames = 100;
  // Idle LCM instances on each URL while the hops and relays are measured
  // (--floor-listeners): in the chain every process has a socket on the
  // safety URL (and each image reader on the image URL), and the kernel
  // delivers every multicast message to each, in the sender's send call
  // (docs/benchmarks.md, "The floors with the chain's listeners"). 0: only the bench's own.
  int floor_listeners = 0;
  std::string shared_dir;
  // Configs, scenes and the processes' output files.
  std::string work_dir;
};

// p50 / p99 / max of one stage's latencies (nearest rank), ms; count 0:
// no frame reached the stage.
struct LatencySummary {
  int count = 0;
  double p50_ms = 0;
  double p99_ms = 0;
  double max_ms = 0;
};

// One rate held for a while on one arm and camera size.
struct BenchStep {
  std::string arm;
  int width = 0;
  int height = 0;
  size_t triangles = 0;  // the scene's (arm and environment) per render
  double rate_hz = 0;
  double sent_rate_hz = 0;  // what the publisher achieved (frames / time taken)
  int frames_sent = 0;
  int frames_rendered = 0;  // TOF_RENDERED arrived
  int frames_judged = 0;    // SAFETY_DISCREPANCY arrived
  int frames_verdict = 0;   // SAFETY_RISK arrived (at any time)
  int frames_dropped = 0;   // no SAFETY_RISK within result_timeout_us
  int frames_safe = 0;      // SAFETY_RISK arrived with level SAFE
  // Verdicts whose first copy to arrive was the signed one (SAFETY_RISK_AUTH,
  // which tofguard-risk publishes first when it has a key); the risk stage
  // ends at the first copy.
  int frames_verdict_signed_first = 0;
  // TOF_DEPTH sent -> TOF_RENDERED -> SAFETY_DISCREPANCY -> SAFETY_RISK, and
  // TOF_DEPTH sent -> SAFETY_RISK.
  LatencySummary render;
  LatencySummary discrepancy;
  // Within the discrepancy stage: tofguard-discrepancy's compute_discrepancy
  // (SAFETY_DISCREPANCY's compute_us).
  LatencySummary discrepancy_compute;
  LatencySummary risk;
  LatencySummary end_to_end;
  // Process name -> CPU time over the step / its wall time, percent of one
  // core; "tofguard-bench" is this process (publisher and receiver).
  std::map<std::string, double> cpu_percent;
  // tofguard-renderer's prediction over the step (from the plan with
  // BenchOptions::plan, else from the joint states), from its heartbeat's
  // status before the step and after its last verdict (hits: rendered ahead
  // and within the tolerances; misses: rendered ahead, not within them;
  // without: no prediction for the frame). -1: no heartbeat said.
  int prediction_hits = -1;
  int prediction_misses = -1;
  int frames_without_prediction = -1;
  // Each frame of the step, for a look at the tail (--frames FILE.csv):
  // its stages' latencies in ms as above, none where the stage's message
  // did not come (-1 in the CSV). A stage's latency may be below 0: the
  // bench can read a message after the next stage's (it wakes later than
  // the next process), and such a frame still counts in the stage's lists.
  struct Frame {
    int64_t seq = 0;
    std::optional<double> render_ms;
    std::optional<double> discrepancy_ms;
    std::optional<double> compute_ms;
    std::optional<double> risk_ms;
    std::optional<double> end_to_end_ms;
  };
  std::vector<Frame> frames;
};

// A ramp on one arm and camera size: the rates tried, the highest one
// sustained (0: not even the first) and why the next one was not.
struct BenchRamp {
  std::string arm;
  int width = 0;
  int height = 0;
  size_t triangles = 0;
  double sustained_hz = 0;
  std::string stopped_because;
  std::vector<BenchStep> steps;
};

// One LCM hop: messages of `bytes` bytes published by the bench on a
// scratch channel of one of the chain's URLs at the run's rate, each
// timestamped (monotonic) just before publish() as the bench stamps
// TOF_DEPTH, and on arrival by the bench's own receiver thread. latency.count:
// the messages that arrived (of `sent`).
struct HopFloor {
  size_t bytes = 0;
  int sent = 0;
  LatencySummary latency;
};

struct RelayFloor {
  size_t in_bytes = 0;
  size_t out_bytes = 0;
  int sent = 0;
  LatencySummary latency;
};

// The floors of one arm and camera size, measured by the bench alone (the
// chain's processes stopped, no chain process involved).
struct BenchFloors {
  std::string arm;
  int width = 0;
  int height = 0;
  double rate_hz = 0;  // the hops' rate: the run's (with --ramp, its first)
  int listeners = 0;   // BenchOptions::floor_listeners when they were measured
  // DepthRenderer::render (render, read-back, conversion to metres) in this
  // process: the scene tofguard-renderer loads (robot_model::load_scene with
  // renderer::scene_options), its near and far, the camera pose and
  // intrinsics of the run, the last step's joint path; floor_frames back to
  // back after 3 untimed.
  LatencySummary render;
  // discrepancy::compute_discrepancy on each prepared camera frame with its
  // model frame (TOF_RENDERED and TOF_LABELS as the renderer makes them at
  // the same joints), the config's parameters; count 0 when unusable.
  LatencySummary discrepancy_compute;
  // TOF_DEPTH / TOF_RENDERED (depth_image_t of the size) on lcm.image_url,
  // SAFETY_DISCREPANCY (discrepancy_t) and SAFETY_RISK (risk_t) on lcm.url,
  // each of the size the chain's messages had in the run.
  HopFloor image_hop;
  HopFloor discrepancy_hop;
  HopFloor risk_hop;
  // The relays: the shape of a stage that starts when a process receives a
  // message and ends when the bench receives the one it publishes. The bench
  // publishes `in_bytes`; a relay thread of its own (its own LCM instances)
  // publishes `out_bytes` at once on receiving it; the bench's receiver
  // thread receives both, and the latency is the second's receive time minus
  // the first's, as the stage's is. It holds the wake-ups a hop does not:
  // the relay's and the bench's after it, while the bench is woken by the
  // first message too (on 2 cores the two woken threads and the sender
  // contend). discrepancy_relay: TOF_RENDERED-sized in (lcm.image_url),
  // SAFETY_DISCREPANCY-sized out (lcm.url); risk_relay: SAFETY_DISCREPANCY-
  // sized in, SAFETY_RISK-sized out (lcm.url).
  RelayFloor discrepancy_relay;
  RelayFloor risk_relay;
};

// The floor of each stage (p50s summed), ms, and what it is made of: render
// = image hop (TOF_DEPTH to the renderer) + render + image hop (TOF_RENDERED
// back); discrepancy = compute_discrepancy + the discrepancy relay (the
// stage starts at the bench's receive of TOF_RENDERED, which
// tofguard-discrepancy receives at the same time); risk = the risk relay
// (the risk monitor's own work is not measured). 0 when a part is missing.
double render_stage_floor_ms(const BenchFloors& floors);
double discrepancy_stage_floor_ms(const BenchFloors& floors);
double risk_stage_floor_ms(const BenchFloors& floors);

struct BenchReport {
  std::string machine;               // nproc, CPU model, load
  std::string date;                  // UTC
  std::vector<BenchStep> steps;      // without --ramp: one per arm, size and camera
  std::vector<BenchRamp> ramps;      // with --ramp
  std::vector<BenchFloors> floors;   // one per arm and size (unless --no-floors)
  std::vector<std::string> skipped;  // arms skipped, with why
  BenchOptions options;              // what was run
};

// The campaign arm `name` (default, iiwa14, kinova; judge_campaign.hpp's
// scenes), nothing when its URDF is not under `shared_dir`; for a
// deployment of config/ (bench_scene_config) the default arm, whose size
// it must be run at. Throws std::invalid_argument for another name.
std::optional<CampaignArm> bench_arm(const std::string& name, const std::string& shared_dir,
                                     const std::string& scene_dir);

// The deployments the bench runs as they are, their cameras imperfect and
// commissioned (each with its own profile), at their cameras' own size and
// rate: "sim" config/sim.yaml, "two-cameras" config/sim-two-cameras.yaml
// (each camera's renderer and discrepancy process started with --camera,
// both cameras' frames sent at the same instant, camera c's seqs from
// c * 10^9 on, a step per camera). The file under the source tree, or ""
// for a campaign arm.
std::string bench_scene_config(const std::string& arm_name);

// `scene_config` (bench_scene_config's) as the bench's chain runs it: no
// tofguard-camera heartbeat required (the bench publishes the frames), no
// estimate, no occupant (the simulated frames show no user), written to
// output_dir()/<name>.yaml; returns the path. joint_prediction as
// write_bench_config's.
std::string write_scene_bench_config(const std::string& scene_config, const std::string& name,
                                     bool joint_prediction = true);

// config/sim.yaml for `arm` at `intrinsics` (its robot, environment,
// camera pose and rate), as the bench's chain runs it, written to
// output_dir()/<name>.yaml; returns the path.
// joint_prediction false: renderer.prediction.from_joint_states off.
std::string write_bench_config(const CampaignArm& arm, const Intrinsics& intrinsics, const std::string& name,
                               bool joint_prediction = true);

// Runs every arm and size of `options`; progress lines go to `log`. Throws
// std::runtime_error when a chain does not come up or a scene cannot be
// rendered.
BenchReport run_bench(const BenchOptions& options, std::ostream& log);

// The report as Markdown: machine and date, a row per step (latencies per
// stage, drops, CPU per process), for ramps the rate sustained, and the
// floors with each stage's p50 over its floor (a ramp's: its first step's,
// at the floors' rate).
std::string bench_markdown(const BenchReport& report);

// Every step's frames as CSV: arm, size, rate, seq and the stages' ms.
std::string bench_frames_csv(const BenchReport& report);

// A PNG: p50 and p99 latency per stage against the camera's pixels (a
// panel per arm), and the rate sustained (with --ramp; else the rate
// delivered) against the scene's triangles. Throws std::runtime_error when
// it cannot be written.
void plot_bench(const BenchReport& report, const std::string& path);

}  // namespace tofguard::test
