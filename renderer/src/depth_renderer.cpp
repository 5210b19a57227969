#include "tofguard/renderer/depth_renderer.hpp"
#include "tofguard/renderer/rendered_kinematics.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include <GLES3/gl3.h>

#include "tofguard/common/demand.hpp"

namespace tofguard::renderer {
namespace {

constexpr size_t kMaxExtraObjects = 1000;

// Linear Z is computed from the optical-frame position in the vertex shader
// and interpolated perspective-correctly, so on every (planar) triangle it
// is the exact Z of the surface, not the non-linear depth buffer.
//
// What changes from draw to draw (the mesh's pose and its label) comes in
// as per-instance vertex attributes (divisor 1, one instance per draw) from
// a buffer written once a frame, not as uniforms: Mesa's llvmpipe copies a
// draw's changed uniforms into a 1 MB upload buffer and takes a new one when
// it is full, which with a heap that keeps its memory (keep_heap_resident)
// grew tofguard-renderer's RSS by 1 MB steps (one every ~11 s at 30 Hz) as
// the freed buffers were split by small blocks. clip_from_optical, the one
// uniform, is set only when the intrinsics change.
constexpr GLuint kPositionLocation = 0;
constexpr GLuint kOpticalFromMeshLocation = 1;  // a mat4: locations 1-4, a column each
constexpr GLuint kLabelLocation = 5;
constexpr const char* kVertexShader = R"(#version 300 es
layout(location = 0) in vec3 position;
layout(location = 1) in mat4 optical_from_mesh;
layout(location = 5) in int label;
uniform mat4 clip_from_optical;
out highp float z_optical_m;
flat out int label_of_draw;
void main() {
  vec4 p = optical_from_mesh * vec4(position, 1.0);
  z_optical_m = p.z;
  label_of_draw = label;
  gl_Position = clip_from_optical * p;
}
)";

// One RG32UI attachment: the float's bits and the label, read back with one
// glReadPixels. (32-bit integer formats are colour-renderable in every ES 3.0
// implementation; R32F needs EXT_color_buffer_float.)
constexpr const char* kFragmentShader = R"(#version 300 es
precision highp float;
precision highp int;
in highp float z_optical_m;
flat in int label_of_draw;
layout(location = 0) out uvec2 depth_bits_and_label;
void main() {
  depth_bits_and_label = uvec2(floatBitsToUint(z_optical_m), uint(label_of_draw));
}
)";

std::string gl_error_text(GLenum error) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "GL error 0x%04x", static_cast<unsigned>(error));
  return buffer;
}

GLuint compile(GLenum type, const char* source) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[1024] = {};
    glGetShaderInfoLog(shader, sizeof log, nullptr, log);
    glDeleteShader(shader);
    throw RenderError(std::string("GL: shader does not compile: ") + log);
  }
  return shader;
}

Eigen::Matrix4f to_float(const Eigen::Matrix4d& m) { return m.cast<float>(); }

bool finite(const Eigen::Vector3d& v) { return std::isfinite(v.sum()); }

}  // namespace

ExtraObject ExtraObject::box(const Eigen::Vector3d& edges_m, const Eigen::Isometry3d& world_from_object) {
  return {Kind::kBox, edges_m, world_from_object};
}
ExtraObject ExtraObject::sphere(double radius_m, const Eigen::Isometry3d& world_from_object) {
  return {Kind::kSphere, Eigen::Vector3d(radius_m, radius_m, radius_m), world_from_object};
}
ExtraObject ExtraObject::cylinder(double radius_m, double length_m,
                                  const Eigen::Isometry3d& world_from_object) {
  return {Kind::kCylinder, Eigen::Vector3d(radius_m, radius_m, length_m), world_from_object};
}

Eigen::Matrix4d clip_from_optical(const Intrinsics& k, double near_m, double far_m) {
  // GL puts window x = (ndc_x + 1) * W / 2 and samples pixel column u at its
  // centre, window x = u + 0.5; OpenCV puts pixel u's centre at
  // fx*X/Z + cx. So window x = fx*X/Z + cx + 0.5, i.e.
  //   ndc_x = (2*fx/W) * X/Z + (2*(cx + 0.5)/W - 1).
  // Same for y with window row v = image row v: GL's window origin is at the
  // bottom and glReadPixels returns window row 0 first, so image row 0 (the
  // top) ends up first in memory, with no flip anywhere. (The image is
  // mirrored in y compared with a usual GL camera; the renderer does not
  // cull faces, so the changed winding does not matter.)
  // clip_w = Z; window depth runs -1..1 over Z = near..far.
  const double w = k.width, h = k.height, n = near_m, f = far_m;
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m(0, 0) = 2 * k.fx / w;
  m(0, 2) = 2 * (k.cx + 0.5) / w - 1;
  m(1, 1) = 2 * k.fy / h;
  m(1, 2) = 2 * (k.cy + 0.5) / h - 1;
  m(2, 2) = (f + n) / (f - n);
  m(2, 3) = -2 * f * n / (f - n);
  m(3, 2) = 1;
  return m;
}

struct DepthRenderer::Impl {
  struct DrawRange {
    GLsizei index_count = 0;
    size_t first_index_byte = 0;
    bool cull_back_faces = false;
  };
  // One draw's per-instance attributes, as the vertex shader reads them.
  struct DrawParams {
    float optical_from_mesh[16];  // column-major, as GL wants
    int32_t label;
  };
  static_assert(sizeof(DrawParams) == 17 * 4, "DrawParams is packed: the attribute stride");

  Impl(const robot_model::SceneModel& scene_in, double near, double far, EglPlatform platform)
      : scene(scene_in), context(platform), near_m(near), far_m(far) {
    upload();
  }

  ~Impl() {
    try {
      context.make_current();
    } catch (const RenderError&) {
      return;  // the context goes with EglContext's destructor anyway
    }
    glDeleteFramebuffers(1, &framebuffer);
    glDeleteRenderbuffers(2, renderbuffers);
    glDeleteBuffers(3, buffers);
    glDeleteVertexArrays(1, &vertex_array);
    glDeleteProgram(program);
  }

  void upload() {
    const GLuint vertex_shader = compile(GL_VERTEX_SHADER, kVertexShader);
    const GLuint fragment_shader = compile(GL_FRAGMENT_SHADER, kFragmentShader);
    program = glCreateProgram();
    glAttachShader(program, vertex_shader);
    glAttachShader(program, fragment_shader);
    glLinkProgram(program);
    glDeleteShader(vertex_shader);
    glDeleteShader(fragment_shader);
    GLint ok = GL_FALSE;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) throw RenderError("GL: shader program does not link");
    glUseProgram(program);
    clip_from_optical_location = glGetUniformLocation(program, "clip_from_optical");

    // Every mesh in one vertex buffer and one index buffer (ES 3.0 has no
    // base-vertex draws, so the indices are made absolute here).
    std::vector<float> vertices;
    std::vector<uint32_t> indices;
    for (const robot_model::TriangleMesh& mesh : scene.meshes) {
      const uint32_t base = static_cast<uint32_t>(vertices.size() / 3);
      ranges.push_back({static_cast<GLsizei>(mesh.indices.size()), indices.size() * sizeof(uint32_t),
                        mesh.closed_outward});
      for (const Eigen::Vector3f& v : mesh.vertices) vertices.insert(vertices.end(), {v.x(), v.y(), v.z()});
      for (uint32_t i : mesh.indices) indices.push_back(base + i);
    }
    glGenVertexArrays(1, &vertex_array);
    glBindVertexArray(vertex_array);
    glGenBuffers(3, buffers);
    glBindBuffer(GL_ARRAY_BUFFER, buffers[0]);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(float)), vertices.data(),
                 GL_STATIC_DRAW);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, buffers[1]);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size() * sizeof(uint32_t)),
                 indices.data(), GL_STATIC_DRAW);
    glEnableVertexAttribArray(kPositionLocation);
    glVertexAttribPointer(kPositionLocation, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
    for (GLuint column = 0; column < 4; ++column) {
      glEnableVertexAttribArray(kOpticalFromMeshLocation + column);
      glVertexAttribDivisor(kOpticalFromMeshLocation + column, 1);
    }
    glEnableVertexAttribArray(kLabelLocation);
    glVertexAttribDivisor(kLabelLocation, 1);

    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    // Back faces are skipped only for closed, outward-wound meshes
    // (TriangleMesh::closed_outward). clip_from_optical() keeps image rows
    // in GL window rows (v down = window y up), which mirrors the image
    // against GL's usual camera; so outward faces, counter-clockwise seen
    // from outside, arrive clockwise in window coordinates.
    glFrontFace(GL_CW);
    glCullFace(GL_BACK);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    glDisable(GL_DITHER);
    glGenFramebuffers(1, &framebuffer);
    glGenRenderbuffers(2, renderbuffers);
    const GLenum error = glGetError();
    if (error != GL_NO_ERROR) throw RenderError("GL: uploading the scene failed: " + gl_error_text(error));
  }

  // (Re)allocates the framebuffer when the image size changes; "" or why not.
  std::string ensure_framebuffer(int width, int height) {
    if (width == fb_width && height == fb_height) return "";
    glBindRenderbuffer(GL_RENDERBUFFER, renderbuffers[0]);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RG32UI, width, height);
    glBindRenderbuffer(GL_RENDERBUFFER, renderbuffers[1]);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, renderbuffers[0]);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, renderbuffers[1]);
    const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
      fb_width = fb_height = 0;
      return "GL: framebuffer " + std::to_string(width) + "x" + std::to_string(height) + " incomplete (" +
             gl_error_text(status) + ")";
    }
    // RG_INTEGER when the implementation offers it, else RGBA_INTEGER (which
    // every ES 3.0 implementation reads from an unsigned integer buffer).
    GLint format = 0, type = 0;
    glGetIntegerv(GL_IMPLEMENTATION_COLOR_READ_FORMAT, &format);
    glGetIntegerv(GL_IMPLEMENTATION_COLOR_READ_TYPE, &type);
    read_channels = (format == GL_RG_INTEGER && type == GL_UNSIGNED_INT) ? 2 : 4;
    readback.resize(static_cast<size_t>(width) * height * read_channels);
    fb_width = width;
    fb_height = height;
    return "";
  }

  void add_draw(int mesh_index, const Eigen::Matrix4d& optical_from_mesh, int label) {
    DrawParams params{};
    const Eigen::Matrix4f m = to_float(optical_from_mesh);
    std::memcpy(params.optical_from_mesh, m.data(), sizeof params.optical_from_mesh);
    params.label = label;
    draw_meshes.push_back(mesh_index);
    draw_params.push_back(params);
  }

  // Writes every draw's attributes into buffers[2] (grown when a frame has
  // more draws than any before) and draws each mesh as one instance whose
  // attributes start at its own record.
  void draw_all() {
    const GLsizeiptr bytes = static_cast<GLsizeiptr>(draw_params.size() * sizeof(DrawParams));
    glBindBuffer(GL_ARRAY_BUFFER, buffers[2]);
    if (bytes > draw_params_capacity_bytes) {
      glBufferData(GL_ARRAY_BUFFER, bytes, draw_params.data(), GL_DYNAMIC_DRAW);
      draw_params_capacity_bytes = bytes;
    } else {
      glBufferSubData(GL_ARRAY_BUFFER, 0, bytes, draw_params.data());
    }
    constexpr GLsizei stride = sizeof(DrawParams);
    for (size_t i = 0; i < draw_meshes.size(); ++i) {
      const size_t record = i * sizeof(DrawParams);
      for (GLuint column = 0; column < 4; ++column) {
        glVertexAttribPointer(kOpticalFromMeshLocation + column, 4, GL_FLOAT, GL_FALSE, stride,
                              reinterpret_cast<const void*>(record + column * 4 * sizeof(float)));
      }
      glVertexAttribIPointer(kLabelLocation, 1, GL_INT, stride,
                             reinterpret_cast<const void*>(record + offsetof(DrawParams, label)));
      const DrawRange& range = ranges[draw_meshes[i]];
      if (range.cull_back_faces != culling) {
        culling = range.cull_back_faces;
        culling ? glEnable(GL_CULL_FACE) : glDisable(GL_CULL_FACE);
      }
      glDrawElementsInstanced(GL_TRIANGLES, range.index_count, GL_UNSIGNED_INT,
                              reinterpret_cast<const void*>(range.first_index_byte), 1);
    }
  }

  RenderResult render_at(const robot_model::LinkPoses& poses, const Eigen::Isometry3d& world_from_optical,
                         const Intrinsics& intrinsics, const std::vector<ExtraObject>& extra_objects) {
    RenderResult result;
    result.width = intrinsics.width;
    result.height = intrinsics.height;
    result.link_names = scene.link_names();
    result.num_robot_links = scene.num_robot_links;
    const auto unusable = [&](const std::string& why) {
      result.unusable_reason = why;
      return result;
    };
    if (!poses.usable) return unusable(poses.unusable_reason);
    if (poses.world_from_link.size() != scene.links.size())
      return unusable("link poses do not match the scene");
    // A caller of this public API may hand in intrinsics it assembled field
    // by field: refused as unusable, not DEMANDed.
    if (const auto v = intrinsics.check()) return unusable("intrinsics: " + v->line());
    if (!world_from_optical.matrix().allFinite()) return unusable("camera pose is not finite");
    if (extra_objects.size() > kMaxExtraObjects) {
      return unusable("more than " + std::to_string(kMaxExtraObjects) + " extra objects");
    }
    for (size_t i = 0; i < extra_objects.size(); ++i) {
      const ExtraObject& o = extra_objects[i];
      if (!finite(o.size_m) || o.size_m.minCoeff() <= 0 || !o.world_from_object.matrix().allFinite()) {
        return unusable("extra object " + std::to_string(i) + ": sizes must be positive and the pose finite");
      }
    }
    try {
      context.make_current();
    } catch (const RenderError& e) {
      return unusable(e.what());
    }
    result.world_from_link = poses.world_from_link;
    result.world_from_optical = world_from_optical;
    if (const std::string why = ensure_framebuffer(intrinsics.width, intrinsics.height); !why.empty()) {
      return unusable(why);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    glViewport(0, 0, intrinsics.width, intrinsics.height);
    const GLuint zero[4] = {0, 0, 0, 0};
    glClearBufferuiv(GL_COLOR, 0, zero);
    const GLfloat far_depth = 1.0f;
    glClearBufferfv(GL_DEPTH, 0, &far_depth);
    const Eigen::Matrix4f projection = to_float(clip_from_optical(intrinsics, near_m, far_m));
    if (!projection_set || projection != last_projection) {
      glUniformMatrix4fv(clip_from_optical_location, 1, GL_FALSE, projection.data());
      last_projection = projection;
      projection_set = true;
    }

    const Eigen::Isometry3d optical_from_world = world_from_optical.inverse();
    draw_meshes.clear();
    draw_params.clear();
    for (const robot_model::Shape& shape : scene.shapes) {
      // SceneModel::links: the robot's first, then the environment's.
      const int label = label_of_link(shape.link_index, scene.num_robot_links);
      const Eigen::Matrix4d optical_from_mesh =
          (optical_from_world * poses.world_from_link[shape.link_index] * shape.link_from_shape).matrix() *
          shape.scale.homogeneous().asDiagonal();
      add_draw(shape.mesh_index, optical_from_mesh, label);
    }
    for (size_t i = 0; i < extra_objects.size(); ++i) {
      const ExtraObject& o = extra_objects[i];
      const int mesh = o.kind == ExtraObject::Kind::kBox      ? robot_model::kUnitBox
                       : o.kind == ExtraObject::Kind::kSphere ? robot_model::kUnitSphere
                                                              : robot_model::kUnitCylinder;
      const Eigen::Matrix4d optical_from_mesh =
          (optical_from_world * o.world_from_object).matrix() * o.size_m.homogeneous().asDiagonal();
      add_draw(mesh, optical_from_mesh, kLabelExtraObjectFirst + static_cast<int>(i));
    }
    draw_all();

    // glReadPixels writes width * height texels of read_channels uint32 each
    // into readback: a buffer sized for another framebuffer would be a heap
    // overrun, not a bad image.
    const size_t pixels = static_cast<size_t>(intrinsics.width) * intrinsics.height;
    TOFGUARD_DEMAND(fb_width == intrinsics.width && fb_height == intrinsics.height &&
                        readback.size() == pixels * static_cast<size_t>(read_channels),
                    "readback buffer does not match the " + std::to_string(intrinsics.width) + "x" +
                        std::to_string(intrinsics.height) + " framebuffer");
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, intrinsics.width, intrinsics.height,
                 read_channels == 2 ? GL_RG_INTEGER : GL_RGBA_INTEGER, GL_UNSIGNED_INT, readback.data());
    if (const GLenum error = glGetError(); error != GL_NO_ERROR)
      return unusable("GL: " + gl_error_text(error));

    result.depth_m.resize(pixels);
    result.labels.resize(pixels);
    for (size_t i = 0; i < pixels; ++i) {
      const uint32_t* texel = &readback[i * read_channels];
      float z;
      std::memcpy(&z, &texel[0], sizeof z);
      result.depth_m[i] = z;
      result.labels[i] = static_cast<int16_t>(texel[1]);
    }
    result.usable = true;
    return result;
  }

  robot_model::SceneModel scene;
  EglContext context;
  double near_m;
  double far_m;
  GLuint program = 0;
  GLint clip_from_optical_location = -1;
  bool projection_set = false;
  Eigen::Matrix4f last_projection;
  GLuint vertex_array = 0;
  // The meshes' vertices, their indices, and the draws' per-instance
  // attributes (DrawParams).
  GLuint buffers[3] = {0, 0, 0};
  // This frame's draws: the mesh and its attributes.
  std::vector<int> draw_meshes;
  std::vector<DrawParams> draw_params;
  GLsizeiptr draw_params_capacity_bytes = 0;
  GLuint framebuffer = 0;
  GLuint renderbuffers[2] = {0, 0};
  std::vector<DrawRange> ranges;
  int fb_width = 0;
  int fb_height = 0;
  int read_channels = 4;
  std::vector<uint32_t> readback;
  bool culling = false;
};

DepthRenderer::DepthRenderer(const robot_model::SceneModel& scene, double near_m, double far_m)
    : DepthRenderer(scene, near_m, far_m, egl_platform_from_environment()) {}

DepthRenderer::DepthRenderer(const robot_model::SceneModel& scene, double near_m, double far_m,
                             EglPlatform platform) {
  if (!(std::isfinite(near_m) && std::isfinite(far_m) && near_m > 0 && far_m > near_m)) {
    throw std::invalid_argument("DepthRenderer: need 0 < near_m < far_m, got near_m " +
                                std::to_string(near_m) + ", far_m " + std::to_string(far_m));
  }
  if (scene.num_robot_links >= kMaxLabelledRobotLinks ||
      static_cast<int>(scene.links.size()) - scene.num_robot_links >= kMaxLabelledEnvironmentLinks) {
    throw std::invalid_argument(
        "DepthRenderer: at most 999 robot links and 1000 environment links can be labelled");
  }
  impl_ = std::make_unique<Impl>(scene, near_m, far_m, platform);
}

DepthRenderer::~DepthRenderer() = default;

RenderResult DepthRenderer::render(const robot_model::JointPositions& joints, const CameraPose& camera_pose,
                                   const Intrinsics& intrinsics,
                                   const std::vector<ExtraObject>& extra_objects) {
  robot_model::LinkPoses poses = robot_model::forward_kinematics(impl_->scene, joints);
  Eigen::Isometry3d world_from_optical = Eigen::Isometry3d::Identity();
  if (poses.usable) {
    std::string why;
    if (const auto pose = renderer::world_from_optical(impl_->scene, poses, camera_pose, &why)) {
      world_from_optical = *pose;
    } else {
      poses = {false, why, {}};
    }
  }
  return impl_->render_at(poses, world_from_optical, intrinsics, extra_objects);
}

RenderResult DepthRenderer::render_at(const robot_model::LinkPoses& link_poses,
                                      const Eigen::Isometry3d& world_from_optical,
                                      const Intrinsics& intrinsics,
                                      const std::vector<ExtraObject>& extra_objects) {
  return impl_->render_at(link_poses, world_from_optical, intrinsics, extra_objects);
}

const std::string& DepthRenderer::description() const { return impl_->context.description(); }

size_t DepthRenderer::num_triangles() const { return impl_->scene.num_triangles(); }

}  // namespace tofguard::renderer
