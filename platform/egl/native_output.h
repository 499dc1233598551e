#pragma once
// NativeOutput (internal to platform/egl): the native side of an on-screen EGL surface, i.e. a GBM
// surface scanned out by KMS or an X11 window. EglContext drives it in this order:
//   Open*()  -> native_display() for eglGetPlatformDisplayEXT(platform(), ...)
//   choose an EGLConfig (matching required_visual_id() when non-zero)
//   CreateWindow(config's EGL_NATIVE_VISUAL_ID) -> native_window() for eglCreatePlatformWindowSurfaceEXT
//   per frame: Present() after eglSwapBuffers, PollEvents()
// Destroyed after the EGL surface that uses it.
#include <EGL/egl.h>

#include <cstdint>
#include <memory>
#include <string>

#include "core/base/status.h"
#include "platform/egl/egl_context.h"

namespace reconar {

class NativeOutput {
 public:
  virtual ~NativeOutput() = default;

  virtual EGLenum platform() const = 0;
  virtual void* native_display() const = 0;
  // A format the EGL config must have as EGL_NATIVE_VISUAL_ID (GBM); 0 = any.
  virtual EGLint required_visual_id() const { return 0; }
  virtual Status CreateWindow(EGLint visual_id) = 0;
  // What eglCreatePlatformWindowSurfaceEXT takes (for X11 a pointer to the Window id).
  virtual void* native_window() = 0;
  virtual int width() const = 0;
  virtual int height() const = 0;
  // Called after a successful eglSwapBuffers (KMS: lock the front buffer and flip to it).
  virtual Status Present() { return Status::Ok(); }
  virtual WindowEvents PollEvents() { return WindowEvents(); }
};

// kGbm: `device` empty = probe /dev/dri/card*. FailedPrecondition "no DRM device under /dev/dri"
// when nothing is there, or naming the device and the reason (no connected connector, no CRTC).
Result<std::unique_ptr<NativeOutput>> OpenKmsOutput(const std::string& device);

// kX11Window: FailedPrecondition "cannot open X display ..." without a server.
Result<std::unique_ptr<NativeOutput>> OpenX11Window(int width, int height, const std::string& title);

}  // namespace reconar
