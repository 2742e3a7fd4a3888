// Headless EGL context creation. Order: Mesa's surfaceless platform (llvmpipe, Mesa GPU drivers),
// then the EGL device platform (NVIDIA's driver has no surfaceless platform). MFR_EGL_PLATFORM
// (= surfaceless | device) forces one.
#include "mfr/gl/context.hpp"

#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#include "mfr/error.hpp"

namespace mfr::gl {
namespace {

bool hasExtension(const char* list, const char* name) {
  if (!list) return false;
  const std::size_t n = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += n)
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  return false;
}

std::string eglErrorName(EGLint e) {
  switch (e) {
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    default:
      return "EGL error " + std::to_string(e);
  }
}

struct DebugState {
  std::mutex mutex;
  std::string firstError;
};
DebugState& debugState() {
  static DebugState s;
  return s;
}

void GLAPIENTRY debugCallback(GLenum, GLenum type, GLuint, GLenum severity, GLsizei length, const GLchar* message,
                              const void*) {
  (void)severity;
  if (type != GL_DEBUG_TYPE_ERROR) return;  // compiler warnings and performance notes are not errors
  auto& s = debugState();
  std::lock_guard lock(s.mutex);
  if (s.firstError.empty())
    s.firstError.assign(message, length >= 0 ? static_cast<std::size_t>(length) : std::strlen(message));
}

}  // namespace

struct HeadlessContext::Impl {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  ContextInfo info;
};

HeadlessContext::HeadlessContext(bool debug) : impl_(std::make_unique<Impl>()) {
  const char* clientExts = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  const char* forced = std::getenv("MFR_EGL_PLATFORM");
  std::vector<std::pair<std::string, EGLDisplay>> candidates;
  const bool wantSurfaceless = !forced || std::string(forced) == "surfaceless";
  const bool wantDevice = !forced || std::string(forced) == "device";
  if (wantSurfaceless && hasExtension(clientExts, "EGL_MESA_platform_surfaceless"))
    candidates.emplace_back("surfaceless",
                            eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr));
  if (wantDevice && hasExtension(clientExts, "EGL_EXT_platform_device")) {
    EGLDeviceEXT devices[16];
    EGLint count = 0;
    if (eglQueryDevicesEXT(16, devices, &count))
      for (EGLint i = 0; i < count; ++i)
        candidates.emplace_back("device", eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr));
  }
  std::string lastError =
      "no EGL platform for headless rendering (need EGL_MESA_platform_surfaceless or EGL_EXT_platform_device)";
  for (auto& [platform, display] : candidates) {
    if (display == EGL_NO_DISPLAY) continue;
    EGLint major = 0, minor = 0;
    if (!eglInitialize(display, &major, &minor)) {
      lastError = platform + ": eglInitialize failed (" + eglErrorName(eglGetError()) + ")";
      continue;
    }
    if (!eglBindAPI(EGL_OPENGL_API)) {
      lastError = platform + ": no desktop OpenGL API";
      eglTerminate(display);
      continue;
    }
    const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                              4,
                              EGL_CONTEXT_MINOR_VERSION,
                              5,
                              EGL_CONTEXT_OPENGL_PROFILE_MASK,
                              EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                              EGL_CONTEXT_OPENGL_DEBUG,
                              debug ? EGL_TRUE : EGL_FALSE,
                              EGL_NONE};
    // EGL_KHR_no_config_context: no config needed when rendering only into FBOs.
    EGLContext ctx = eglCreateContext(display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attribs);
    if (ctx == EGL_NO_CONTEXT) {
      lastError = platform + ": no OpenGL 4.5 core context (" + eglErrorName(eglGetError()) + ")";
      eglTerminate(display);
      continue;
    }
    if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
      lastError = platform + ": eglMakeCurrent failed (" + eglErrorName(eglGetError()) + ")";
      eglDestroyContext(display, ctx);
      eglTerminate(display);
      continue;
    }
    impl_->display = display;
    impl_->context = ctx;
    if (debug) installDebugOutput();
    impl_->info = queryContextInfo();
    impl_->info.platform = platform;
    if (epoxy_gl_version() < 45) {
      const std::string v = impl_->info.version;
      eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      eglDestroyContext(display, ctx);
      eglTerminate(display);
      impl_->context = EGL_NO_CONTEXT;
      throw Error("OpenGL", "version 4.5 core required, got " + v);
    }
    return;
  }
  throw Error("OpenGL", lastError);
}

HeadlessContext::~HeadlessContext() {
  if (impl_ && impl_->context != EGL_NO_CONTEXT) {
    eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(impl_->display, impl_->context);
    // The display is left initialised: other contexts of this process may share it.
  }
}

void HeadlessContext::makeCurrent() {
  if (!eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, impl_->context))
    throw Error("OpenGL", "eglMakeCurrent failed (" + eglErrorName(eglGetError()) + ")");
}

const ContextInfo& HeadlessContext::info() const {
  return impl_->info;
}

void installDebugOutput() {
  glEnable(GL_DEBUG_OUTPUT);
  glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);  // errors are attributed to the call that caused them
  glDebugMessageCallback(debugCallback, nullptr);
  glDebugMessageControl(GL_DONT_CARE, GL_DONT_CARE, GL_DONT_CARE, 0, nullptr, GL_TRUE);
}

void checkErrors(const char* where) {
  std::string message;
  {
    auto& s = debugState();
    std::lock_guard lock(s.mutex);
    message.swap(s.firstError);
  }
  GLenum err = glGetError();
  if (message.empty() && err != GL_NO_ERROR)
    message = "glGetError 0x" + [&] {
      char buf[16];
      std::snprintf(buf, sizeof buf, "%04X", err);
      return std::string(buf);
    }();
  while (err != GL_NO_ERROR) err = glGetError();
  if (!message.empty()) throw Error("OpenGL", std::string(where) + ": " + message);
}

void discardErrors() {
  {
    auto& s = debugState();
    std::lock_guard lock(s.mutex);
    s.firstError.clear();
  }
  while (glGetError() != GL_NO_ERROR) {
  }
}

ContextInfo queryContextInfo() {
  ContextInfo info;
  const auto str = [](GLenum e) {
    const auto* s = reinterpret_cast<const char*>(glGetString(e));
    return std::string(s ? s : "");
  };
  info.vendor = str(GL_VENDOR);
  info.renderer = str(GL_RENDERER);
  info.version = str(GL_VERSION);
  info.fragmentShaderInterlock = epoxy_has_gl_extension("GL_ARB_fragment_shader_interlock") ||
                                 epoxy_has_gl_extension("GL_NV_fragment_shader_interlock") ||
                                 epoxy_has_gl_extension("GL_INTEL_fragment_shader_ordering");
  info.shaderInt64 = epoxy_has_gl_extension("GL_ARB_gpu_shader_int64");
  return info;
}

}  // namespace mfr::gl
