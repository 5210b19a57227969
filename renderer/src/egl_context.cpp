#include "tofguard/renderer/egl_context.hpp"

#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <vector>

#include <EGL/eglext.h>
#include <GLES3/gl3.h>

namespace tofguard::renderer {
namespace {

// eglTerminate ends every context on a display, and every DepthRenderer of
// a process shares the display: count the users, terminate with the last.
std::mutex display_mutex;
std::map<EGLDisplay, int> display_users;

bool has_extension(const char* extensions, const char* name) {
  if (extensions == nullptr) return false;
  const size_t length = std::strlen(name);
  for (const char* at = std::strstr(extensions, name); at != nullptr; at = std::strstr(at + 1, name)) {
    const bool starts = at == extensions || at[-1] == ' ';
    const bool ends = at[length] == '\0' || at[length] == ' ';
    if (starts && ends) return true;
  }
  return false;
}

std::string egl_error_text() {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "EGL error 0x%04x", static_cast<unsigned>(eglGetError()));
  return buffer;
}

// Initialises `display` and creates an ES 3.0 context on it; on failure
// returns EGL_NO_CONTEXT and says why in `why`.
EGLContext create_context(EGLDisplay display, std::string* why) {
  if (display == EGL_NO_DISPLAY) {
    *why = "no display (" + egl_error_text() + ")";
    return EGL_NO_CONTEXT;
  }
  {
    std::lock_guard<std::mutex> lock(display_mutex);
    EGLint major = 0, minor = 0;
    if (display_users[display] == 0 && !eglInitialize(display, &major, &minor)) {
      *why = "eglInitialize failed (" + egl_error_text() + ")";
      display_users.erase(display);
      return EGL_NO_CONTEXT;
    }
    ++display_users[display];
  }
  const auto release = [&] {
    std::lock_guard<std::mutex> lock(display_mutex);
    if (--display_users[display] == 0) {
      eglTerminate(display);
      display_users.erase(display);
    }
  };
  const char* extensions = eglQueryString(display, EGL_EXTENSIONS);
  if (!has_extension(extensions, "EGL_KHR_surfaceless_context")) {
    *why = "no EGL_KHR_surfaceless_context";
    release();
    return EGL_NO_CONTEXT;
  }
  if (!eglBindAPI(EGL_OPENGL_ES_API)) {
    *why = "eglBindAPI(EGL_OPENGL_ES_API) failed (" + egl_error_text() + ")";
    release();
    return EGL_NO_CONTEXT;
  }
  const EGLint config_attributes[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_ES3_BIT, EGL_SURFACE_TYPE,
                                      EGL_PBUFFER_BIT, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint num_configs = 0;
  if (!eglChooseConfig(display, config_attributes, &config, 1, &num_configs) || num_configs < 1) {
    if (!has_extension(extensions, "EGL_KHR_no_config_context")) {
      *why = "no ES 3 config";
      release();
      return EGL_NO_CONTEXT;
    }
    config = EGL_NO_CONFIG_KHR;
  }
  const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 0, EGL_NONE};
  const EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attributes);
  if (context == EGL_NO_CONTEXT) {
    *why = "eglCreateContext(ES 3.0) failed (" + egl_error_text() + ")";
    release();
    return EGL_NO_CONTEXT;
  }
  if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
    *why = "eglMakeCurrent without a surface failed (" + egl_error_text() + ")";
    eglDestroyContext(display, context);
    release();
    return EGL_NO_CONTEXT;
  }
  return context;
}

}  // namespace

EglPlatform egl_platform_from_environment() {
  const char* value = std::getenv("TOFGUARD_EGL_PLATFORM");
  if (value == nullptr || std::strcmp(value, "") == 0 || std::strcmp(value, "auto") == 0)
    return EglPlatform::kAuto;
  if (std::strcmp(value, "device") == 0) return EglPlatform::kDevice;
  if (std::strcmp(value, "surfaceless") == 0) return EglPlatform::kSurfaceless;
  throw RenderError(std::string("TOFGUARD_EGL_PLATFORM must be auto, device or surfaceless, got '") + value +
                    "'");
}

EglContext::EglContext(EglPlatform platform) {
  const char* client_extensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  const auto get_platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (get_platform_display == nullptr || !has_extension(client_extensions, "EGL_EXT_platform_base")) {
    throw RenderError(
        "EGL: no EGL_EXT_platform_base (eglGetPlatformDisplayEXT); cannot render without a display");
  }
  std::string tried;
  const auto note = [&](const std::string& what) { tried += (tried.empty() ? "" : "; ") + what; };

  if (platform != EglPlatform::kSurfaceless) {
    const auto query_devices =
        reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    const auto query_device_string =
        reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
    EGLint num_devices = 0;
    if (!has_extension(client_extensions, "EGL_EXT_platform_device") || query_devices == nullptr ||
        !query_devices(0, nullptr, &num_devices) || num_devices < 1) {
      note("device platform: no EGL devices");
    } else {
      std::vector<EGLDeviceEXT> devices(num_devices);
      query_devices(num_devices, devices.data(), &num_devices);
      // Hardware devices first: on a machine with a GPU, Mesa's software
      // device must not win.
      std::vector<EGLDeviceEXT> ordered;
      for (int pass = 0; pass < 2; ++pass) {
        for (EGLint i = 0; i < num_devices; ++i) {
          const char* device_extensions =
              query_device_string != nullptr ? query_device_string(devices[i], EGL_EXTENSIONS) : nullptr;
          const bool software = has_extension(device_extensions, "EGL_MESA_device_software");
          if (software == (pass == 1)) ordered.push_back(devices[i]);
        }
      }
      for (size_t i = 0; i < ordered.size() && context_ == EGL_NO_CONTEXT; ++i) {
        const EGLDisplay display = get_platform_display(EGL_PLATFORM_DEVICE_EXT, ordered[i], nullptr);
        std::string why;
        context_ = create_context(display, &why);
        if (context_ != EGL_NO_CONTEXT) {
          display_ = display;
          description_ = "EGL device platform";
        } else {
          note("device " + std::to_string(i) + ": " + why);
        }
      }
    }
  }
  if (context_ == EGL_NO_CONTEXT && platform != EglPlatform::kDevice) {
    if (!has_extension(client_extensions, "EGL_MESA_platform_surfaceless")) {
      note("surfaceless platform: no EGL_MESA_platform_surfaceless");
    } else {
      const EGLDisplay display =
          get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
      std::string why;
      context_ = create_context(display, &why);
      if (context_ != EGL_NO_CONTEXT) {
        display_ = display;
        description_ = "EGL surfaceless platform";
      } else {
        note("surfaceless platform: " + why);
      }
    }
  }
  if (context_ == EGL_NO_CONTEXT) throw RenderError("EGL: no headless OpenGL ES 3 context: " + tried);
  const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  description_ += std::string(", GL_RENDERER ") + (renderer != nullptr ? renderer : "?");
}

EglContext::~EglContext() {
  if (context_ == EGL_NO_CONTEXT) return;
  if (eglGetCurrentContext() == context_)
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(display_, context_);
  std::lock_guard<std::mutex> lock(display_mutex);
  if (--display_users[display_] == 0) {
    eglTerminate(display_);
    display_users.erase(display_);
  }
}

void EglContext::make_current() {
  if (eglGetCurrentContext() == context_) return;
  if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
    throw RenderError("EGL: eglMakeCurrent failed (" + egl_error_text() + ")");
  }
}

}  // namespace tofguard::renderer
