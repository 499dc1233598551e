#include "render/ar/capture_window.h"

namespace reconar {

Result<std::unique_ptr<CaptureWindow>> CaptureWindow::Open(EglContextKind kind, int width, int height) {
  EglContextOptions options;
  options.kind = kind;
  options.width = width;
  options.height = height;
  options.title = "reconar capture";
  Result<std::unique_ptr<EglContext>> context = EglContext::Create(options);
  if (!context.ok()) {
    return FailedPrecondition("no display for the capture's window: " + context.status().message() +
                              " (--out-preview DIR writes the pictures instead)");
  }
  if (!(*context)->has_surface()) {
    return FailedPrecondition(
        "no display for the capture's window: DISPLAY is not set and there is no DRM device under /dev/dri "
        "(--out-preview DIR writes the pictures instead)");
  }
  return std::unique_ptr<CaptureWindow>(new CaptureWindow(std::move(context).value()));
}

Result<bool> CaptureWindow::Show(const Image<uint8_t>& rgb) {
  if (!renderer_ || renderer_->width() != rgb.width() || renderer_->height() != rgb.height()) {
    OverlayRendererOptions options;
    options.width = rgb.width();
    options.height = rgb.height();
    renderer_.reset();
    RECONAR_ASSIGN_OR_RETURN(renderer_, OverlayRenderer::Create(options));
  }
  RECONAR_RETURN_IF_ERROR(renderer_->BeginFrame());
  RECONAR_RETURN_IF_ERROR(renderer_->DrawBackground(rgb.view(), 3));
  RECONAR_RETURN_IF_ERROR(renderer_->PresentToDefaultFramebuffer(context_->width(), context_->height()));
  RECONAR_RETURN_IF_ERROR(context_->SwapBuffers());
  return !context_->PollEvents().should_quit();
}

std::string CaptureWindow::Describe() const {
  return std::string(EglContextKindName(context_->kind())) + " " + std::to_string(context_->width()) + "x" +
         std::to_string(context_->height()) + " (" + context_->renderer() + ")";
}

}  // namespace reconar
