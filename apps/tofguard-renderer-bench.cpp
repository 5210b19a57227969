// Render + read-back per frame on whatever EGL gives (llvmpipe on a CPU-only
// machine): the default primitive arm with its environment, and the iiwa14
// and Kinova Gen3 visual meshes (exact and simplified to 1 mm), at 176x144,
// 320x240 and 640x480. Joint angles change every
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

// A robot from ../shared/robots seen from 2 m in front (see the scene
// tests), its visual meshes exact or simplified to `simplify_error_m`
// (robot_model::SceneOptions); null when ../shared is absent.
std::unique_ptr<BenchScene> shared_robot(const std::string& name, const std::string& relative_urdf,
                                         const std::vector<std::string>& relative_package_paths,
                                         const std::string& root_link, double camera_height_m,
                                         double simplify_error_m) {
  const auto shared = std::filesystem::path(TOFGUARD_SOURCE_DIR).parent_path() / "shared/robots";
  const auto urdf = shared / relative_urdf;
  if (!std::filesystem::exists(urdf)) return nullptr;
  robot_model::SceneOptions options;
  for (const std::string& p : relative_package_paths) options.package_paths.push_back((shared / p).string());
  options.simplify_error_m = simplify_error_m;
  auto s = std::make_unique<BenchScene>();
  const robot_model::SceneModel model = robot_model::load_scene(urdf.string(), {}, options);
  s->renderer = std::make_unique<DepthRenderer>(model, 0.1, 8.0);
  s->joints = model.actuated_joint_names;
  s->pose.frame_id = root_link;
  s->pose.translation_m = Eigen::Vector3d(2.0, 0, camera_height_m);
  s->pose.rotation = Eigen::Quaterniond(0.5, -0.5, -0.5, 0.5);
  int closed = 0;
  for (const robot_model::TriangleMesh& mesh : model.meshes) closed += mesh.closed_outward;
  std::cerr << name << " visual" << (simplify_error_m > 0 ? " (simplified)" : "") << ": "
            << model.num_triangles() << " triangles (" << model.num_source_triangles() << " in the files), "
            << model.shapes.size() << " shapes, " << closed - robot_model::kNumUnitMeshes << " of "
            << model.meshes.size() - robot_model::kNumUnitMeshes << " meshes closed (back faces culled); "
            << s->renderer->description() << "\n";
  return s;
}

std::unique_ptr<BenchScene> iiwa14(double simplify_error_m) {
  return shared_robot("iiwa14", "iiwa14/urdf/iiwa14_no_collision_relative.urdf", {}, "base", 0.65,
                      simplify_error_m);
}

std::unique_ptr<BenchScene> kinova_gen3(double simplify_error_m) {
  return shared_robot(
      "Kinova Gen3",
      "kinova_gen3/kortex_description/arms/gen3/7dof/urdf/GEN3-7DOF-NOVISION_FOR_URDF_ARM_V12.urdf",
      {"kinova_gen3"}, "base_link", 0.55, simplify_error_m);
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
    state.SkipWithError("../shared/robots is absent");
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
// Meshes exact, and simplified to 1 mm as config/sim.yaml's
// renderer.simplify_error_mm.
void BM_Iiwa14VisualMeshes(benchmark::State& state) {
  static const std::unique_ptr<BenchScene> scene = iiwa14(0);
  render_loop(state, scene.get());
}
void BM_Iiwa14VisualMeshesSimplified(benchmark::State& state) {
  static const std::unique_ptr<BenchScene> scene = iiwa14(0.001);
  render_loop(state, scene.get());
}
void BM_KinovaGen3VisualMeshes(benchmark::State& state) {
  static const std::unique_ptr<BenchScene> scene = kinova_gen3(0);
  render_loop(state, scene.get());
}
void BM_KinovaGen3VisualMeshesSimplified(benchmark::State& state) {
  static const std::unique_ptr<BenchScene> scene = kinova_gen3(0.001);
  render_loop(state, scene.get());
}

BENCHMARK(BM_EmptyScene)->Arg(176)->Arg(320)->Arg(640)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FriendArmWithEnvironment)->Arg(176)->Arg(320)->Arg(640)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Iiwa14VisualMeshes)->Arg(176)->Arg(320)->Arg(640)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Iiwa14VisualMeshesSimplified)->Arg(176)->Arg(320)->Arg(640)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_KinovaGen3VisualMeshes)->Arg(176)->Arg(320)->Arg(640)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_KinovaGen3VisualMeshesSimplified)->Arg(176)->Arg(320)->Arg(640)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace tofguard::renderer

BENCHMARK_MAIN();
