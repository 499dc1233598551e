#include "platform/egl/egl_util.h"

#include <EGL/eglext.h>

#include <cstdio>
#include <cstring>

namespace reconar {

std::string EglErrorName(EGLint error) {
  const char* name = "unknown EGL error";
  switch (error) {
    case EGL_SUCCESS:
      name = "EGL_SUCCESS";
      break;
    case EGL_NOT_INITIALIZED:
      name = "EGL_NOT_INITIALIZED";
      break;
    case EGL_BAD_ACCESS:
      name = "EGL_BAD_ACCESS";
      break;
    case EGL_BAD_ALLOC:
      name = "EGL_BAD_ALLOC";
      break;
    case EGL_BAD_ATTRIBUTE:
      name = "EGL_BAD_ATTRIBUTE";
      break;
    case EGL_BAD_CONFIG:
      name = "EGL_BAD_CONFIG";
      break;
    case EGL_BAD_CONTEXT:
      name = "EGL_BAD_CONTEXT";
      break;
    case EGL_BAD_CURRENT_SURFACE:
      name = "EGL_BAD_CURRENT_SURFACE";
      break;
    case EGL_BAD_DISPLAY:
      name = "EGL_BAD_DISPLAY";
      break;
    case EGL_BAD_MATCH:
      name = "EGL_BAD_MATCH";
      break;
    case EGL_BAD_NATIVE_PIXMAP:
      name = "EGL_BAD_NATIVE_PIXMAP";
      break;
    case EGL_BAD_NATIVE_WINDOW:
      name = "EGL_BAD_NATIVE_WINDOW";
      break;
    case EGL_BAD_PARAMETER:
      name = "EGL_BAD_PARAMETER";
      break;
    case EGL_BAD_SURFACE:
      name = "EGL_BAD_SURFACE";
      break;
    case EGL_CONTEXT_LOST:
      name = "EGL_CONTEXT_LOST";
      break;
    default:
      break;
  }
  char code[16];
  std::snprintf(code, sizeof(code), "0x%04X", static_cast<unsigned>(error));
  return std::string(name) + " (" + code + ")";
}

Status EglFailure(StatusCode code, const std::string& what) {
  return Status(code, what + ": " + EglErrorName(eglGetError()));
}

bool HasExtension(const char* extensions, const char* name) {
  if (extensions == nullptr) return false;
  const size_t length = std::strlen(name);
  for (const char* p = extensions; (p = std::strstr(p, name)) != nullptr; p += length) {
    const bool starts = p == extensions || p[-1] == ' ';
    const bool ends = p[length] == '\0' || p[length] == ' ';
    if (starts && ends) return true;
  }
  return false;
}

Result<EGLDisplay> OpenPlatformDisplay(EGLenum platform, void* native_display, const char* platform_extension,
                                       const char* alternative_extension) {
  const char* client_extensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!HasExtension(client_extensions, "EGL_EXT_platform_base")) {
    return Unsupported("EGL: the client extensions lack EGL_EXT_platform_base (EGL too old)");
  }
  if (!HasExtension(client_extensions, platform_extension) &&
      (alternative_extension == nullptr || !HasExtension(client_extensions, alternative_extension))) {
    return Unsupported(std::string("EGL: this EGL implementation does not offer ") + platform_extension);
  }
  auto get_platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (get_platform_display == nullptr) return Unsupported("EGL: eglGetPlatformDisplayEXT is missing");
  EGLDisplay display = get_platform_display(platform, native_display, nullptr);
  if (display == EGL_NO_DISPLAY) {
    return EglFailure(StatusCode::kFailedPrecondition,
                      std::string("EGL: eglGetPlatformDisplayEXT(") + platform_extension + ") failed");
  }
  EGLint major = 0;
  EGLint minor = 0;
  if (eglInitialize(display, &major, &minor) != EGL_TRUE) {
    return EglFailure(StatusCode::kFailedPrecondition,
                      std::string("EGL: eglInitialize on ") + platform_extension + " failed");
  }
  return display;
}

}  // namespace reconar
