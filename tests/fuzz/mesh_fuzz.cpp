// libFuzzer target: a mesh file, read as a URDF's <mesh> is read
// (load_scene -> assimp -> tofguard's triangle mesh, orientation and
// padding). The first byte picks the format (even: STL, odd: OBJ: the two
// formats tofguard's models use; assimp picks its importer by the file
// name's extension), the rest is the file. A file that cannot be used must
// end in ModelError, never in a crash or another exception.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_scratch.hpp"
#include "tofguard/robot_model/scene_model.hpp"

namespace {

const tofguard::fuzz::Scratch& scratch() {
  static const tofguard::fuzz::Scratch s;
  return s;
}

// One link with the mesh, scaled by a mirror (negative x: orient() must
// flip it) and padded.
std::string urdf_for(const std::string& mesh_file) {
  return "<?xml version=\"1.0\"?>\n<robot name=\"fuzz\">\n  <link name=\"base\">\n"
         "    <visual><geometry><mesh filename=\"" +
         mesh_file +
         "\" scale=\"-1 1 1\"/></geometry></visual>\n"
         "  </link>\n</robot>\n";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1 || size > 256 * 1024) return 0;
  const std::string mesh_file = data[0] % 2 == 0 ? "mesh.stl" : "mesh.obj";
  scratch().write(mesh_file, data + 1, size - 1);
  const std::string urdf = scratch().write("robot.urdf", urdf_for(mesh_file));
  tofguard::robot_model::SceneOptions options;
  options.padding_m = 0.01;
  // Half the inputs also through the simplifier (meshoptimizer).
  options.simplify_error_m = (data[0] / 2) % 2 == 0 ? 0.0 : 0.001;
  try {
    const tofguard::robot_model::SceneModel scene = tofguard::robot_model::load_scene(urdf, {}, options);
    volatile size_t sink = scene.num_triangles();
    (void)sink;
  } catch (const tofguard::robot_model::ModelError&) {
    // The expected outcome for a file that cannot be used.
  }
  return 0;
}
