// Time to compare one camera frame with its rendered frame
// (compute_discrepancy) at 176x144 and 640x480, on a frame with a shifted
// link and an object in front of the arm (so blobs and near-arm distances
// are exercised) and with the simulated camera's noise.
//
// BM_ComputeDiscrepancySimulatedArm: the same on frames of the embedded
// default (config/sim.yaml) as the chain sees them: the simulated ToF
// camera's frame of the default arm along its path (tests/support's
// SimulatedFrames) against the renderer's frame and labels at the same
// joints, with config/sim.yaml's discrepancy settings. It prints a digest
// of the summaries of its frames (stderr): a change made for speed alone
// leaves it as it was.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "joint_motion.hpp"
#include "scaled_intrinsics.hpp"
#include "simulated_frames.hpp"
#include "synthetic_frames.hpp"
#include "tofguard/common/depth_frame.hpp"
#include "tofguard/common/worker_pool.hpp"
#include "tofguard/deployment/config.hpp"
#include "tofguard/discrepancy/discrepancy_image.hpp"
#include "tofguard/discrepancy/evidence.hpp"
#include "tofguard/discrepancy/joint_search.hpp"
#include "tofguard/renderer/depth_renderer.hpp"
#include "tofguard/renderer/rendered_kinematics.hpp"
#include "tofguard/renderer/renderer_service.hpp"
#include "tofguard/robot_model/arm_spheres.hpp"

namespace {

using tofguard::depth_image_t;
using tofguard::link_labels_t;

struct Frames {
  depth_image_t camera;
  depth_image_t rendered;
  link_labels_t labels;
};

// A floor at 2 m, three arm links at 1.5 m as boxes (scaled to the image),
// and, in the camera only, link 3 shifted and a box in front of link 1.
Frames make_frames(int width, int height) {
  const double s = width / 176.0;
  auto box = [&](std::vector<int16_t>* depth, std::vector<int16_t>* label, int u0, int v0, int u1, int v1,
                 int16_t d, int16_t l) {
    for (int v = static_cast<int>(v0 * s); v < static_cast<int>(v1 * s) && v < height; ++v) {
      for (int u = static_cast<int>(u0 * s); u < static_cast<int>(u1 * s) && u < width; ++u) {
        const int i = v * width + u;
        if (d < (*depth)[i]) {
          (*depth)[i] = d;
          if (label) (*label)[i] = l;
        }
      }
    }
  };
  Frames f{};  // value-initialised: the generated types leave their scalars uninitialised
  for (depth_image_t* m : {&f.camera, &f.rendered}) {
    m->utime = 1;
    m->seq = 1;
    m->camera_id = "bench";
    m->width = width;
    m->height = height;
    m->fx = m->fy = 200 * s;
    m->cx = width / 2.0;
    m->cy = height / 2.0;
    m->calibrated = true;
    m->num_pixels = width * height;
    m->depth_mm.assign(width * height, 2000);
    m->num_amplitude = 0;
  }
  f.labels.utime = 1;
  f.labels.seq = 1;
  f.labels.camera_id = "bench";
  f.labels.usable = true;
  f.labels.width = width;
  f.labels.height = height;
  f.labels.num_robot_links = 3;
  f.labels.num_links = 4;
  f.labels.link_name = {"base_link", "link1", "link2", "floor"};
  f.labels.num_pixels = width * height;
  f.labels.label.assign(width * height, tofguard::kLabelEnvironmentFirst);
  box(&f.rendered.depth_mm, &f.labels.label, 40, 100, 60, 140, 1500, 1);
  box(&f.rendered.depth_mm, &f.labels.label, 40, 60, 60, 100, 1500, 2);
  box(&f.rendered.depth_mm, &f.labels.label, 60, 60, 100, 80, 1500, 3);
  box(&f.camera.depth_mm, nullptr, 40, 100, 60, 140, 1500, 0);
  box(&f.camera.depth_mm, nullptr, 40, 60, 60, 100, 1500, 0);
  box(&f.camera.depth_mm, nullptr, 70, 60, 110, 80, 1500, 0);
  box(&f.camera.depth_mm, nullptr, 30, 110, 50, 130, 1400, 0);
  // The kinematics as rendered, so that the evidence stage runs (the
  // boxes are tests/support's default arm, scaled).
  tofguard::test::add_default_arm_kinematics(&f.labels);
  // The arm cover (so that the protective fields run): a sphere of 0.12 m
  // at each link box's centre (optical frame, m; fx = 200 px at 176 wide).
  f.labels.arm_cover_max_radius_m = 0.15;
  f.labels.num_arm_spheres = 3;
  f.labels.arm_sphere_link = {0, 1, 2};
  f.labels.arm_sphere_center_m = {{-0.285f, 0.36f, 1.5f}, {-0.285f, 0.06f, 1.5f}, {-0.06f, -0.015f, 1.5f}};
  f.labels.arm_sphere_radius_m = {0.12f, 0.12f, 0.12f};
  std::mt19937 rng(1);
  std::normal_distribution<double> unit(0, 1);
  for (int16_t& d : f.camera.depth_mm) {
    const double m = tofguard::metres_from_mm(d);
    d = static_cast<int16_t>(std::lround(d + unit(rng) * (4 + 1.2 * m * m)));
  }
  return f;
}

void BM_ComputeDiscrepancy(benchmark::State& state) {
  const Frames f = make_frames(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  // The third argument: evidence.max_pixels (0: every pixel).
  tofguard::discrepancy::DiscrepancyOptions options;
  options.evidence.max_pixels = static_cast<int>(state.range(2));
  for (auto _ : state) {
    auto frame = tofguard::discrepancy::compute_discrepancy(f.camera, f.rendered, f.labels, options);
    benchmark::DoNotOptimize(frame.summary.num_match);
  }
  state.SetItemsProcessed(state.iterations() * state.range(0) * state.range(1));
}
BENCHMARK(BM_ComputeDiscrepancy)
    ->Args({176, 144, 0})
    ->Args({640, 480, 0})
    ->Args({640, 480, 80000})
    ->Unit(benchmark::kMicrosecond);

// The naming search alone (joint_search.hpp) on the same frame: two
// joints, their links' points.
void BM_SearchJointOffsets(benchmark::State& state) {
  const Frames f = make_frames(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const tofguard::discrepancy::DiscrepancyOptions options;
  tofguard::discrepancy::LabelKinematics kinematics;
  if (!tofguard::discrepancy::read_label_kinematics(f.labels, f.labels.label.size(), &kinematics)) {
    state.SkipWithError("the bench frame's kinematics do not fit");
    return;
  }
  tofguard::discrepancy_t summary{};
  for (auto _ : state) {
    tofguard::discrepancy::search_joint_offsets(f.camera, f.rendered, f.labels, kinematics,
                                                options.tolerance.noise, options.evidence, &summary);
    benchmark::DoNotOptimize(summary.joint_search_gain.data());
  }
  state.counters["points"] = summary.search_points;
}
BENCHMARK(BM_SearchJointOffsets)->Args({176, 144})->Args({640, 480})->Unit(benchmark::kMicrosecond);

// The default arm's frames at width x height (config/sim.yaml's camera,
// the same field of view): 10 frames along its path at 30 Hz.
struct SimulatedArmFrames {
  tofguard::deployment::Config config;
  std::vector<Frames> frames;
};

SimulatedArmFrames make_simulated_arm_frames(int width, int height) {
  setenv("LP_NUM_THREADS", "0", /*overwrite=*/0);  // as tofguard-renderer at 176x144
  SimulatedArmFrames out;
  out.config =
      tofguard::deployment::load_config(std::string(TOFGUARD_SOURCE_DIR) + "/config/sim.yaml", nullptr);
  const tofguard::deployment::Config& config = out.config;
  tofguard::test::SimulatedFrames camera_frames(config);
  const tofguard::robot_model::SceneModel scene =
      tofguard::robot_model::load_scene(config.robot.urdf_path, config.environment.urdf_paths,
                                        tofguard::renderer::scene_options(config.renderer, config.robot));
  tofguard::renderer::DepthRenderer renderer(scene, config.renderer.near_m, config.renderer.far_m);
  const tofguard::robot_model::ArmSpheres cover =
      tofguard::robot_model::cover_arm_with_spheres(scene, config.renderer.arm_cover_cell_m);
  const tofguard::Intrinsics intrinsics =
      tofguard::test::scaled_intrinsics(config.camera.intrinsics, width, height);
  const Eigen::Isometry3d world_from_optical = config.camera.pose.frame_from_optical();
  for (int i = 0; i < 10; ++i) {
    tofguard::robot_model::JointPositions joints;
    for (const std::string& j : camera_frames.scene().actuated_joint_names) joints[j] = 0;
    for (const tofguard::sim::JointMotion& m : config.joints_sim.motion)
      joints[m.joint] = tofguard::test::joint_position(m, i / 30.0);
    Frames f;
    f.camera =
        tofguard::make_depth_image(config.camera.id, intrinsics, i + 1, i + 1, /*calibrated=*/true,
                                   camera_frames.capture(joints, world_from_optical, intrinsics, i + 1));
    const tofguard::renderer::RenderResult result = renderer.render(joints, config.camera.pose, intrinsics);
    f.rendered = tofguard::make_depth_image(config.camera.id, intrinsics, i + 1, i + 1, /*calibrated=*/true,
                                            result.depth_m);
    f.labels = tofguard::renderer::make_rendered_link_labels(f.camera, result, scene, cover);
    out.frames.push_back(std::move(f));
  }
  return out;
}

// state.range(2): discrepancy.worker_threads (0: none, all on the caller's
// thread). state.range(3): a pause between frames, ms (0: back to back; 33:
// frames at 30 Hz as tofguard-discrepancy gets them, the threads and the
// caches idle between frames; -33: the same pause with the caller spinning
// through it, so that its core never idles: the pair showed the worker put
// on the caller's core, WorkerPool), not timed; wall time then.
// The default arm's frames at width x height, made once per size (Google
// Benchmark calls a benchmark several times).
const SimulatedArmFrames& simulated_arm_frames(int64_t width, int64_t height) {
  static std::map<std::pair<int64_t, int64_t>, SimulatedArmFrames> made;
  const auto size = std::make_pair(width, height);
  if (made.count(size) == 0) {
    made[size] = make_simulated_arm_frames(static_cast<int>(size.first), static_cast<int>(size.second));
  }
  return made[size];
}

void BM_ComputeDiscrepancySimulatedArm(benchmark::State& state) {
  const SimulatedArmFrames& sim = simulated_arm_frames(state.range(0), state.range(1));
  const tofguard::discrepancy::DiscrepancyOptions options =
      tofguard::discrepancy::discrepancy_options(sim.config.discrepancy);
  std::unique_ptr<tofguard::WorkerPool> workers;
  if (state.range(2) > 0) workers = std::make_unique<tofguard::WorkerPool>(static_cast<int>(state.range(2)));
  // FNV-1a over the encoded summaries, utime and compute_us aside (as
  // tofguard-bench's floors).
  uint64_t digest = 0xcbf29ce484222325ULL;
  for (const Frames& f : sim.frames) {
    tofguard::discrepancy_t summary =
        tofguard::discrepancy::compute_discrepancy(f.camera, f.rendered, f.labels, options, workers.get())
            .summary;
    summary.utime = 0;
    summary.compute_us = 0;
    std::vector<uint8_t> encoded(static_cast<size_t>(summary.getEncodedSize()));
    summary.encode(encoded.data(), 0, static_cast<int>(encoded.size()));
    for (uint8_t byte : encoded) digest = (digest ^ byte) * 0x100000001b3ULL;
  }
  static std::map<std::vector<int64_t>, uint64_t> printed;
  const std::vector<int64_t> run = {state.range(0), state.range(1), state.range(2)};  // pauses: the same
  if (printed.count(run) == 0) {
    printed[run] = digest;
    std::fprintf(stderr, "BM_ComputeDiscrepancySimulatedArm/%d/%d/%d: digest of the summaries %016llx\n",
                 static_cast<int>(run[0]), static_cast<int>(run[1]), static_cast<int>(run[2]),
                 static_cast<unsigned long long>(digest));
  }
  size_t k = 0;
  const auto pause = std::chrono::milliseconds(std::abs(state.range(3)));
  const bool spin = state.range(3) < 0;
  for (auto _ : state) {
    if (pause.count() > 0) {
      state.PauseTiming();
      if (spin) {
        const auto until = std::chrono::steady_clock::now() + pause;
        while (std::chrono::steady_clock::now() < until) {
        }
      } else {
        std::this_thread::sleep_for(pause);
      }
      state.ResumeTiming();
    }
    const Frames& f = sim.frames[k++ % sim.frames.size()];
    auto frame =
        tofguard::discrepancy::compute_discrepancy(f.camera, f.rendered, f.labels, options, workers.get());
    benchmark::DoNotOptimize(frame.summary.num_match);
  }
  state.SetItemsProcessed(state.iterations() * state.range(0) * state.range(1));
}
BENCHMARK(BM_ComputeDiscrepancySimulatedArm)
    ->ArgNames({"width", "height", "threads", "pause_ms"})
    ->Args({176, 144, 0, 0})
    ->Args({176, 144, 2, 0})
    ->Args({176, 144, 0, 33})
    ->Args({176, 144, 2, 33})
    ->Args({176, 144, 0, -33})
    ->Args({176, 144, 2, -33})
    ->Args({640, 480, 0, 0})
    ->UseRealTime()
    ->Unit(benchmark::kMicrosecond);

// near_step_allowance_mm alone on the default arm's frames with
// config/sim.yaml's allowance (12 px from 1 cm steps, by link): the band,
// and the band before the arm's pixels that the scene's pixels take it in.
void BM_NearStepAllowanceSimulatedArm(benchmark::State& state) {
  const SimulatedArmFrames& sim = simulated_arm_frames(state.range(0), state.range(1));
  const tofguard::discrepancy::DiscrepancyOptions options =
      tofguard::discrepancy::discrepancy_options(sim.config.discrepancy);
  size_t k = 0;
  for (auto _ : state) {
    const Frames& f = sim.frames[k++ % sim.frames.size()];
    const std::vector<float> allowance = tofguard::discrepancy::near_step_allowance_mm(
        f.rendered, f.labels, options.evidence, sim.config.discrepancy.silhouette_jump_mm);
    benchmark::DoNotOptimize(allowance.data());
  }
}
BENCHMARK(BM_NearStepAllowanceSimulatedArm)
    ->ArgNames({"width", "height"})
    ->Args({176, 144})
    ->Unit(benchmark::kMicrosecond);

void BM_DepthHash(benchmark::State& state) {
  const Frames f = make_frames(176, 144);
  for (auto _ : state) benchmark::DoNotOptimize(tofguard::discrepancy::depth_hash(f.camera.depth_mm));
}
BENCHMARK(BM_DepthHash)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
