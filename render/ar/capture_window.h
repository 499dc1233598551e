#pragma once
// The capture's preview shown live (`reconar capture --window`): each picture the capture draws
// (render/ar/capture_preview.h) letterboxed into an X11 window, or full screen through DRM/KMS
// (platform/egl/egl_context.h), on the capturing thread. 'q', Escape or the window's close button
// ask the capture to stop; it then ends as on SIGINT.
#include <memory>
#include <string>

#include "core/base/image.h"
#include "core/base/status.h"
#include "platform/egl/egl_context.h"
#include "render/overlay_renderer.h"

namespace reconar {

class CaptureWindow {
 public:
  // Opens the display now, so that a missing one is reported before the capture starts:
  // FailedPrecondition "no display for the capture's window: ..." (EglContext::Create's reason),
  // also for kAuto on a machine with neither DISPLAY nor a DRM device. `width` x `height`: the X11
  // window's first size (the picture is letterboxed into whatever size it has); `title` its title.
  static Result<std::unique_ptr<CaptureWindow>> Open(EglContextKind kind, int width = 640, int height = 480,
                                                     const std::string& title = "reconar capture");
  // `reconar capture --window NAME`: "x11", "gbm", or "auto" = an X11 window when DISPLAY is set;
  // "none", and "auto" without DISPLAY, give no window (nullptr, not an error). Unlike the view,
  // auto never takes the screen over DRM/KMS: over ssh to a board, the console stays the person's.
  // InvalidArgument "--window: 'tv' is not auto, x11, gbm or none"; else as Open.
  static Result<std::unique_ptr<CaptureWindow>> OpenByName(const std::string& name, int width, int height,
                                                           const std::string& title = "reconar capture");

  // Shows a 3-channel picture; the drawing target follows its size. False once the person asked to
  // stop. Errors: GL or presentation failures (a display that went away).
  Result<bool> Show(const Image<uint8_t>& rgb);

  std::string Describe() const;  // "x11 window (llvmpipe ...)"

 private:
  explicit CaptureWindow(std::unique_ptr<EglContext> context) : context_(std::move(context)) {}
  std::unique_ptr<EglContext> context_;
  std::unique_ptr<OverlayRenderer> renderer_;  // sized to the last picture
};

}  // namespace reconar
