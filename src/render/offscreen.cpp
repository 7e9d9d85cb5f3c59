#include "render/offscreen.hpp"
#include "render/gl_driver.hpp"

#define GL_GLEXT_PROTOTYPES
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>

#include <cstdio>

namespace arwb::render {
namespace {

std::string egl_error(const char* what) {
  char b[96];
  std::snprintf(b, sizeof b, "%s failed (EGL error 0x%04x)", what, static_cast<unsigned>(eglGetError()));
  return b;
}

}  // namespace

OffscreenContext::OffscreenContext() {
  auto get_platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!get_platform_display) {
    error_ = "offscreen OpenGL: EGL has no eglGetPlatformDisplayEXT (install libegl-mesa0)";
    return;
  }
  EGLDisplay d = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (d == EGL_NO_DISPLAY) {
    error_ = "offscreen OpenGL: no surfaceless EGL display (install libegl-mesa0)";
    return;
  }
  EGLint major = 0, minor = 0;
  if (!eglInitialize(d, &major, &minor)) {
    error_ = "offscreen OpenGL: " + egl_error("eglInitialize");
    return;
  }
  display_ = d;
  keep_gl_driver_loaded();  // loaded by eglInitialize; see gl_driver.hpp
  if (!eglBindAPI(EGL_OPENGL_API)) {
    error_ = "offscreen OpenGL: " + egl_error("eglBindAPI");
    return;
  }
  const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                               EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  EGLContext c = eglCreateContext(d, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attributes);
  if (c == EGL_NO_CONTEXT) {
    error_ = "offscreen OpenGL: " + egl_error("eglCreateContext (OpenGL 3.3 core)");
    return;
  }
  context_ = c;
  if (!eglMakeCurrent(d, EGL_NO_SURFACE, EGL_NO_SURFACE, c)) error_ = "offscreen OpenGL: " + egl_error("eglMakeCurrent");
}

OffscreenContext::~OffscreenContext() {
  if (display_) {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (context_) eglDestroyContext(display_, context_);
    eglTerminate(display_);
  }
}

std::string OffscreenContext::renderer() const {
  if (!ok()) return {};
  const auto* r = glGetString(GL_RENDERER);
  return r ? reinterpret_cast<const char*>(r) : "";
}

}  // namespace arwb::render
