// libFuzzer target: a robot URDF, loaded as every process loads its scene
// (load_scene: urdfdom's parser, tofguard's kinematic tree, each link's
// geometry, meshes through assimp). A bad model must end in ModelError
// (one line naming the file, the link and the problem), never in a crash
// or another exception.
//
// The input is written to robot.urdf in a scratch folder that also holds
// the meshes of tests/fuzz/meshes/ (box.stl, box.obj), so that a
// URDF naming them by a relative, file:// or package://meshes/ URI
// reaches the mesh path too; the mesh parsers themselves are mesh_fuzz's.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include "fuzz_scratch.hpp"
#include "tofguard/robot_model/scene_model.hpp"

namespace {

namespace fs = std::filesystem;

const tofguard::fuzz::Scratch& scratch() {
  static const tofguard::fuzz::Scratch s;
  static const bool copied = [] {
    const fs::path meshes = fs::path(TOFGUARD_SOURCE_DIR) / "tests" / "fuzz" / "meshes";
    fs::create_directory(s.folder() / "meshes");
    for (const char* name : {"box.stl", "box.obj"}) {
      fs::copy_file(meshes / name, s.folder() / name);
      fs::copy_file(meshes / name, s.folder() / "meshes" / name);
    }
    return true;
  }();
  (void)copied;
  return s;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > 64 * 1024) return 0;
  const std::string path = scratch().write("robot.urdf", data, size);
  tofguard::robot_model::SceneOptions options;
  options.package_paths = {scratch().folder().string()};
  // Each input once with visual and once with collision geometry (a
  // process picks one by renderer.geometry), padded as a planner's margin.
  for (const auto source :
       {tofguard::robot_model::GeometrySource::kVisual, tofguard::robot_model::GeometrySource::kCollision}) {
    options.geometry = source;
    options.padding_m = source == tofguard::robot_model::GeometrySource::kVisual ? 0.0 : 0.01;
    try {
      const tofguard::robot_model::SceneModel scene = tofguard::robot_model::load_scene(path, {}, options);
      volatile size_t sink = scene.num_triangles();
      (void)sink;
    } catch (const tofguard::robot_model::ModelError&) {
      // The expected outcome for a bad model.
    }
  }
  return 0;
}
