#include "render/ar/capture_window.h"

namespace reconar {

Result<std::unique_ptr<CaptureWindow>> CaptureWindow::Open(EglContextKind kind, int width, int height,
                                                           const std::string& title) {
  EglContextOptions options;
  options.kind = kind;
  options.width = width;
  options.height = height;
  options.title = title;
  Result<std::unique_ptr<EglContext>> context = EglContext::CreateOnScreen(options);
  if (!context.ok()) {
    return FailedPrecondition("no display for the capture's window: " + context.status().message() +
                              " (--out-preview DIR writes the pictures instead)");
  }
  return std::unique_ptr<CaptureWindow>(new CaptureWindow(std::move(context).value()));
}

Result<std::unique_ptr<CaptureWindow>> CaptureWindow::OpenByName(const std::string& name, int width, int height,
                                                                 const std::string& title) {
  if (name == "none") return std::unique_ptr<CaptureWindow>();
  Result<EglContextKind> kind = OnScreenKindFromName(name);
  if (!kind.ok()) return InvalidArgument("--window: '" + name + "' is not auto, x11, gbm or none");
  if (*kind == EglContextKind::kAuto) {
    if (!HasX11Display()) return std::unique_ptr<CaptureWindow>();
    kind = EglContextKind::kX11Window;
  }
  return Open(*kind, width, height, title);
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
