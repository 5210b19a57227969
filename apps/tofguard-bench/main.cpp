// tofguard-bench: the observer chain's speed as real processes over real LCM
// (chain_bench.hpp beside this file): latency per stage,
// frames dropped and CPU per process, per arm and camera size, at one rate or
// ramping. Run it through scripts/bench (a private network namespace).
//
//   tofguard-bench [--arms default,iiwa14,kinova,sim,two-cameras] [--resolutions 176x144,320x240,640x480]
//                  [--rate-hz 30] [--seconds 10] [--ramp] [--ramp-step-s 3] [--ramp-max-hz 1920]
//                  [--shared DIR] [--markdown FILE] [--plot FILE.png] [--frames FILE.csv] [--no-floors]
//                  [--floor-listeners N] [--plan] [--no-joint-prediction] [--camera-offset-ms MS]
//
// --arms: the campaign's arms (default, iiwa14, kinova: the ideal camera
// at each size asked), or a deployment of config/ as it is, at its cameras'
// 176x144 and 30 Hz: sim (config/sim.yaml, its camera commissioned),
// two-cameras (config/sim-two-cameras.yaml: both cameras' frames at each
// instant, a row per camera; no floors, no --ramp). --camera-offset-ms MS:
// camera c exposes c * MS after camera 0 (cameras triggered in turn), each
// frame showing the arm at its own instant (BenchOptions::camera_offset_ms).
//
// Each step's measured frames come after 20 at its rate that are not
// measured (the chain's steady state at that rate; chain_bench.cpp,
// kLeadInFrames).
//
// --ramp: 30, 60, 120 ... Hz, --ramp-step-s each, up to the first rate with
// a dropped frame, a stage's p99 above the frame period or a publisher that
// could not keep the rate, then two rates between the last one sustained and
// that one, each halving the gap (240, 480: 360, then 300 or 420); reports
// the highest rate sustained.
//
// After each arm and size, with its chain stopped, the floors (BenchFloors):
// DepthRenderer::render and compute_discrepancy in this process along the
// same joint path, and one LCM hop of each stage's message size on a scratch
// channel of the chain's URL at the run's rate; a table of them with each
// stage's p50 over its floor. --no-floors skips them.
//
// --plan: the bench also publishes the arm's path as the controller's plan
// (PLANNED_TRAJECTORY), so that tofguard-renderer renders each next frame
// ahead while it waits; the report gives the renderer's hits and misses per
// step (BenchOptions::plan). Without it each next frame is guessed from the
// joint states (renderer.prediction.from_joint_states in config/sim.yaml);
// --no-joint-prediction turns that off, so that every frame is rendered
// when it comes (BenchOptions::joint_prediction). The hits and misses are
// reported either way.
//
// --floor-listeners N: N idle LCM instances on each URL while the hops and
// relays are measured, as many as the chain has processes (BenchOptions::
// floor_listeners; default 0).
//
// --frames FILE.csv: every frame's stage latencies (bench_frames_csv), to
// see which frames make the tail.
//
// Prints the Markdown table (with the machine and the date) to stdout.
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "chain_bench.hpp"
#include "report_format.hpp"
#include "tofguard/common/resident_heap.hpp"
#include "tool_support.hpp"

namespace {

int usage(const std::string& why) {
  std::cerr << "tofguard-bench: " << why
            << "\nusage: tofguard-bench [--arms default,iiwa14,kinova,sim,two-cameras] [--resolutions "
               "176x144,320x240,640x480] "
               "[--rate-hz 30] [--seconds 10] [--ramp] [--ramp-step-s 3] [--ramp-max-hz 1920] [--shared DIR] "
               "[--markdown FILE] [--plot FILE.png] [--frames FILE.csv] [--no-floors] [--floor-listeners N] "
               "[--plan] [--no-joint-prediction] [--camera-offset-ms MS]\n";
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace tofguard::test;
  // As the renderer and discrepancy processes (the floors run in here).
  tofguard::keep_heap_resident();
  BenchOptions options;
  options.shared_dir = shared_dir();
  std::string markdown_path;
  std::string plot_path;
  std::string frames_path;
  for (int i = 1; i < argc; ++i) {
    const std::string option = argv[i];
    if (option == "--ramp") {
      options.ramp = true;
      continue;
    }
    if (option == "--no-floors") {
      options.floors = false;
      continue;
    }
    if (option == "--plan") {
      options.plan = true;
      continue;
    }
    if (option == "--no-joint-prediction") {
      options.joint_prediction = false;
      continue;
    }
    if (option == "-h" || option == "--help") return usage("the observer chain's speed");
    if (i + 1 >= argc) return usage(option + ": expected a value");
    const std::string value = argv[++i];
    try {
      if (option == "--arms") {
        options.arms = split_list(value);
      } else if (option == "--resolutions") {
        options.resolutions.clear();
        for (const std::string& r : split_list(value)) {
          const size_t x = r.find('x');
          if (x == std::string::npos) return usage("--resolutions: expected WIDTHxHEIGHT, got '" + r + "'");
          options.resolutions.emplace_back(std::stoi(r.substr(0, x)), std::stoi(r.substr(x + 1)));
        }
      } else if (option == "--rate-hz") {
        options.rate_hz = std::stod(value);
      } else if (option == "--seconds") {
        options.seconds = std::stod(value);
      } else if (option == "--ramp-step-s") {
        options.ramp_step_s = std::stod(value);
      } else if (option == "--ramp-max-hz") {
        options.ramp_max_hz = std::stod(value);
      } else if (option == "--shared") {
        options.shared_dir = value;
      } else if (option == "--markdown") {
        markdown_path = value;
      } else if (option == "--plot") {
        plot_path = value;
      } else if (option == "--frames") {
        frames_path = value;
      } else if (option == "--camera-offset-ms") {
        options.camera_offset_ms = std::stod(value);
        if (!(options.camera_offset_ms >= 0))
          return usage("--camera-offset-ms: expected 0 or more, got " + value);
      } else if (option == "--floor-listeners") {
        options.floor_listeners = std::stoi(value);
        if (options.floor_listeners < 0 || options.floor_listeners > 16)
          return usage("--floor-listeners: expected 0 to 16, got " + value);
      } else {
        return usage("unknown option " + option);
      }
    } catch (const std::exception&) {
      return usage(option + ": expected a number, got '" + value + "'");
    }
  }
  if (!(options.rate_hz > 0) || !(options.seconds > 0) || !(options.ramp_step_s > 0))
    return usage("--rate-hz, --seconds and --ramp-step-s must be positive");
  for (const auto& [w, h] : options.resolutions)
    if (w <= 0 || h <= 0) return usage("--resolutions: sizes must be positive");
  try {
    const BenchReport report = run_bench(options, std::cerr);
    const std::string markdown = bench_markdown(report);
    std::cout << markdown << std::flush;
    if (!markdown_path.empty()) {
      std::ofstream out(markdown_path);
      out << markdown;
      if (!out) throw std::runtime_error(markdown_path + ": cannot write the table");
    }
    if (!frames_path.empty()) {
      std::ofstream out(frames_path);
      out << bench_frames_csv(report);
      if (!out) throw std::runtime_error(frames_path + ": cannot write the frames");
    }
    if (!plot_path.empty()) {
      plot_bench(report, plot_path);
      std::cerr << "plot: " << plot_path << "\n";
    }
  } catch (const std::exception& e) {
    std::cerr << "tofguard-bench: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
