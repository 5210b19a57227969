// Render + read-back per frame on whatever EGL gives (llvmpipe on a CPU-only
// machine): the default primitive arm with its environment, and the iiwa14
// visual meshes, at 176x144, 320x240 and 640x480. Joint angles change every
// iteration (forward kinematics included). Results: docs/benchmarks.md.
//
//   build/bin/tofguard-renderer-bench --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true   (one command line)
#include <benchmark/benchmark.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include "tofguard/renderer/depth_renderer.hpp"

namespace tofguard::renderer {
namespace {

struct BenchScene {
  std::unique_ptr<DepthRenderer> renderer;
  std::vector<std::string> joints;
  CameraPose pose;
};

Intrinsics intrinsics_at(int width) {
  // The sim camera's field of view (config/sim.yaml) at each size.
  const double s = width / 176.0;
  return {width, static_cast<int>(std::lround(144 * s)), 221.0 * s, 220.5 * s, 87.3 * s, 71.8 * s};
}

BenchScene* friend_arm() {
  static std::unique_ptr<BenchScene> scene = [] {
    auto s = std::make_unique<BenchScene>();
    const std::string models = std::string(TOFGUARD_SOURCE_DIR) + "/config/models/";
    const robot_model::SceneModel model =
        robot_model::load_scene(models + "friend_arm.urdf", {models + "wheelchair_environment.urdf"}, {});
    s->renderer = std::make_unique<DepthRenderer>(model, 0.1, 8.0);
    s->joints = model.actuated_joint_names;
    s->pose.frame_id = "world";
    s->pose.translation_m = Eigen::Vector3d(-0.35, -0.20, 1.55);
    s->pose.rotation = Eigen::Quaterniond(0.298836239, -0.640856382, 0.640856382, -0.298836239);
    std::cerr << "friend_arm + environment: " << model.num_triangles() << " triangles, "
              << model.shapes.size() << " shapes; " << s->renderer->description() << "\n";
    return s;
  }();
  return scene.get();
}

BenchScene* iiwa14() {
  static std::unique_ptr<BenchScene> scene = []() -> std::unique_ptr<BenchScene> {
    const auto urdf = std::filesystem::path(TOFGUARD_SOURCE_DIR).parent_path() /
                      "shared/robots/iiwa14/urdf/"
                      "iiwa14_no_collision_relative.urdf";
    if (!std::filesystem::exists(urdf)) return nullptr;
    auto s = std::make_unique<BenchScene>();
    const robot_model::SceneModel model = robot_model::load_scene(urdf.string(), {}, {});
    s->renderer = std::make_unique<DepthRenderer>(model, 0.1, 8.0);
    s->joints = model.actuated_joint_names;
    // 2 m in front of the arm, looking back at it (see the scene tests).
    s->pose.frame_id = "base";
    s->pose.translation_m = Eigen::Vector3d(2.0, 0, 0.65);
    s->pose.rotation = Eigen::Quaterniond(0.5, -0.5, -0.5, 0.5);
    int closed = 0;
    for (const robot_model::TriangleMesh& mesh : model.meshes) closed += mesh.closed_outward;
    std::cerr << "iiwa14 visual: " << model.num_triangles() << " triangles, " << model.shapes.size()
              << " shapes, " << closed - robot_model::kNumUnitMeshes << " of "
              << model.meshes.size() - robot_model::kNumUnitMeshes << " meshes closed (back faces culled); "
              << s->renderer->description() << "\n";
    return s;
  }();
  return scene.get();
}

// The fixed cost of a frame: clear, no geometry, read back.
BenchScene* empty_scene() {
  static std::unique_ptr<BenchScene> scene = [] {
    auto s = std::make_unique<BenchScene>();
    const std::string path = (std::filesystem::temp_directory_path() / "tofguard_bench_empty.urdf").string();
    std::ofstream(path) << "<robot name=\"empty\"><link name=\"world\"/></robot>";
    const robot_model::SceneModel model = robot_model::load_scene(path, {}, {});
    s->renderer = std::make_unique<DepthRenderer>(model, 0.1, 8.0);
    s->pose.frame_id = "world";
    return s;
  }();
  return scene.get();
}

void render_loop(benchmark::State& state, BenchScene* scene) {
  if (scene == nullptr) {
    state.SkipWithError("../shared/robots/iiwa14 is absent");
    return;
  }
  const Intrinsics k = intrinsics_at(static_cast<int>(state.range(0)));
  robot_model::JointPositions joints;
  int i = 0;
  size_t seen = 0;
  for (auto _ : state) {
    for (size_t j = 0; j < scene->joints.size(); ++j)
      joints[scene->joints[j]] = 0.3 + 0.001 * (i % 100) * (j + 1);
    const RenderResult r = scene->renderer->render(joints, scene->pose, k);
    if (!r.usable) {
      state.SkipWithError(r.unusable_reason.c_str());
      return;
    }
    seen = 0;
    for (int16_t label : r.labels) seen += label != 0;
    benchmark::DoNotOptimize(r.depth_m.data());
    ++i;
  }
  state.counters["triangles"] = static_cast<double>(scene->renderer->num_triangles());
  state.counters["covered_px"] = static_cast<double>(seen);
}

void BM_EmptyScene(benchmark::State& state) { render_loop(state, empty_scene()); }
void BM_FriendArmWithEnvironment(benchmark::State& state) { render_loop(state, friend_arm()); }
void BM_Iiwa14VisualMeshes(benchmark::State& state) { render_loop(state, iiwa14()); }

BENCHMARK(BM_EmptyScene)->Arg(176)->Arg(320)->Arg(640)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FriendArmWithEnvironment)->Arg(176)->Arg(320)->Arg(640)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Iiwa14VisualMeshes)->Arg(176)->Arg(320)->Arg(640)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace tofguard::renderer

BENCHMARK_MAIN();
