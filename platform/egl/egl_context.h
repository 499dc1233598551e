#pragma once
// EglContext: an EGL display with a current OpenGL ES context, optionally with an on-screen
// surface. Three routes:
//  - kSurfaceless: EGL_MESA_platform_surfaceless, no surface at all; render into an FBO and read
//    back (headless boards, CI). A plain eglGetDisplay(EGL_DEFAULT_DISPLAY) would try X11 and fail.
//  - kGbm: a DRM/KMS device (/dev/dri/card*), a GBM surface in the connector's preferred mode and
//    scan-out by drmModeSetCrtc / drmModePageFlip on every SwapBuffers (boards without X).
//  - kX11Window: an X11 window with an EGL window surface (desktops).
// kAuto picks kX11Window when DISPLAY is set, else kGbm when /dev/dri exists, else kSurfaceless.
// The context is made current on the creating thread; use the object from that thread only.
// This header does not include EGL or X11 headers (X11 macros such as Status would clash).
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "core/base/status.h"

namespace reconar {

enum class EglContextKind { kAuto, kSurfaceless, kGbm, kX11Window };

const char* EglContextKindName(EglContextKind kind);
// The on-screen routes a user names on a command line: "auto", "x11", "gbm".
// InvalidArgument "--window: 'tv' is not auto, x11 or gbm" otherwise.
Result<EglContextKind> OnScreenKindFromName(const std::string& name);
// True when DISPLAY names an X server, i.e. kAuto would pick kX11Window.
bool HasX11Display();

struct EglContextOptions {
  EglContextKind kind = EglContextKind::kAuto;
  // Size of the X11 window; unused by kSurfaceless (no surface) and kGbm (the mode decides).
  int width = 640;
  int height = 480;
  int gles_version = 3;  // major version of the OpenGL ES context: 2 or 3
  int samples = 0;       // multisampling of the window surface (0 = none); not for kSurfaceless
  std::string title = "reconar";
  // kGbm: the DRM device; empty = the first /dev/dri/card* that has a connected connector.
  std::string drm_device;

  // InvalidArgument naming the first offending field.
  Status Check() const;
};

// What happened in the window since the last PollEvents().
struct WindowEvents {
  bool close_requested = false;  // the window manager's close button (WM_DELETE_WINDOW)
  bool quit_key = false;         // 'q' or Escape pressed in the window
  int next_layer_presses = 0;    // space or 'l': show the next layer (as-built, design, deviation)
  bool resized = false;          // width() / height() changed
  // Presses of the first button (a mouse click, or a touch the window system turns into one),
  // window pixels (x, y) with row 0 at the top, in order.
  std::vector<std::array<int, 2>> taps;

  bool should_quit() const { return close_requested || quit_key; }
};

class NativeOutput;  // the GBM/KMS or X11 side, platform/egl/native_output.h

class EglContext {
 public:
  using Options = EglContextOptions;
  using Kind = EglContextKind;

  // Opens the display, creates the context (and surface) and makes it current.
  // FailedPrecondition when the route cannot work on this machine, e.g.
  //   kGbm without devices:   "no DRM device under /dev/dri"
  //   kX11Window, no server:  "cannot open X display \"\" (DISPLAY is not set)"
  // Unsupported when the route was not compiled in (no gbm/libdrm or x11 at build time) or the
  // EGL implementation lacks the platform extension; InvalidArgument for bad options.
  static Result<std::unique_ptr<EglContext>> Create(const Options& options);
  // Create for a context that must show something: kAuto on a machine with neither DISPLAY nor a
  // DRM device is FailedPrecondition "DISPLAY is not set and there is no DRM device under /dev/dri"
  // instead of falling back to kSurfaceless; kSurfaceless is InvalidArgument.
  static Result<std::unique_ptr<EglContext>> CreateOnScreen(const Options& options);

  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  Kind kind() const { return kind_; }  // the resolved route, never kAuto
  bool has_surface() const;            // false for kSurfaceless
  // The drawable's size in pixels: the window or scan-out mode; options' size for kSurfaceless.
  int width() const;
  int height() const;
  const std::string& renderer() const { return renderer_; }      // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  const std::string& gl_version() const { return gl_version_; }  // GL_VERSION
  const std::string& egl_vendor() const { return egl_vendor_; }  // EGL_VENDOR

  // Makes this context current on the calling thread again (after another context was used).
  Status MakeCurrent();
  // Shows the default framebuffer: eglSwapBuffers, plus the KMS page flip for kGbm. For
  // kSurfaceless there is nothing to show; it only flushes (glFinish) and returns Ok.
  Status SwapBuffers();
  // Drains the window's event queue (X11). Other routes report no events.
  WindowEvents PollEvents();

 private:
  struct Egl;  // EGL handles, defined in egl_context.cc
  EglContext();

  Kind kind_ = Kind::kSurfaceless;
  int surfaceless_width_ = 0;
  int surfaceless_height_ = 0;
  std::string renderer_;
  std::string gl_version_;
  std::string egl_vendor_;
  // Declared before egl_ so that the EGL surface and context are destroyed before the window.
  std::unique_ptr<NativeOutput> output_;  // null for kSurfaceless
  std::unique_ptr<Egl> egl_;
};

}  // namespace reconar
