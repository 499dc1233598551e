#pragma once
// Small EGL helpers shared by the routes of EglContext (internal to platform/egl).
#include <EGL/egl.h>

#include <string>

#include "core/base/status.h"

namespace reconar {

// "EGL_BAD_DISPLAY (0x3008)" for an eglGetError() code.
std::string EglErrorName(EGLint error);

// "what failed: EGL_BAD_... (0x....)" with the current eglGetError(); `code` chooses the Status code.
Status EglFailure(StatusCode code, const std::string& what);

// True when the space-separated extension list contains `name` exactly.
bool HasExtension(const char* extensions, const char* name);

// eglGetPlatformDisplayEXT(platform, native_display, NULL) plus eglInitialize. Unsupported when
// the client extensions lack EGL_EXT_platform_base or `platform_extension`.
Result<EGLDisplay> OpenPlatformDisplay(EGLenum platform, void* native_display, const char* platform_extension,
                                       const char* alternative_extension);

}  // namespace reconar
