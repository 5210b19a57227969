#pragma once
// A headless OpenGL ES 3 context through EGL: no window, no X display.
// Platforms: EGL_PLATFORM_DEVICE_EXT (what works on an NVIDIA GPU; Mesa
// also offers its software device there) and EGL_PLATFORM_SURFACELESS_MESA
// (Mesa: llvmpipe on a CPU-only machine). Rendering goes into framebuffer
// objects, so the context needs no surface (EGL_KHR_surfaceless_context).
#include <stdexcept>
#include <string>

#include <EGL/egl.h>

namespace tofguard::renderer {

enum class EglPlatform {
  kAuto,         // device first, then surfaceless
  kDevice,       // EGL_PLATFORM_DEVICE_EXT only
  kSurfaceless,  // EGL_PLATFORM_SURFACELESS_MESA only
};

// Thrown when no usable context can be created; what() is one line naming
// what was tried and what failed.
class RenderError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Reads TOFGUARD_EGL_PLATFORM ("device", "surfaceless", unset or "auto").
EglPlatform egl_platform_from_environment();

// One context, usable by one thread at a time. make_current() binds it to
// the calling thread (cheap when it already is).
class EglContext {
 public:
  explicit EglContext(EglPlatform platform);
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  void make_current();
  // e.g. "EGL device platform, GL_RENDERER llvmpipe (LLVM 15.0.6, 256 bits)".
  const std::string& description() const { return description_; }

 private:
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  std::string description_;
};

}  // namespace tofguard::renderer
