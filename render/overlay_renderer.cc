#include "render/overlay_renderer.h"

#include <string>
#include <utility>

#include "render/gl_error.h"

namespace reconar {

Status OverlayRendererOptions::Check() const {
  if (width <= 0 || height <= 0) {
    return InvalidArgument("OverlayRendererOptions: width/height must be positive, got " + std::to_string(width) + "x" +
                           std::to_string(height));
  }
  if (samples < 0) return InvalidArgument("OverlayRendererOptions.samples must be >= 0");
  return depth.Check();
}

OverlayRenderer::OverlayRenderer(const Options& options, OffscreenTarget target, VideoBackground background,
                                 MeshPipeline mesh, TagAxesDrawable axes)
    : options_(options),
      target_(std::move(target)),
      background_(std::move(background)),
      mesh_pipeline_(std::move(mesh)),
      axes_(std::move(axes)) {}

Result<std::unique_ptr<OverlayRenderer>> OverlayRenderer::Create(const Options& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  if (glGetString(GL_VERSION) == nullptr) {
    return FailedPrecondition("OverlayRenderer: no current OpenGL ES context (create an EglContext first)");
  }
  RECONAR_ASSIGN_OR_RETURN(OffscreenTarget target,
                           OffscreenTarget::Create(options.width, options.height, options.samples));
  RECONAR_ASSIGN_OR_RETURN(VideoBackground background, VideoBackground::Create());
  RECONAR_ASSIGN_OR_RETURN(MeshPipeline mesh, MeshPipeline::Create());
  RECONAR_ASSIGN_OR_RETURN(TagAxesDrawable axes, TagAxesDrawable::Create());
  return std::unique_ptr<OverlayRenderer>(
      new OverlayRenderer(options, std::move(target), std::move(background), std::move(mesh), std::move(axes)));
}

Eigen::Matrix4d OverlayRenderer::ClipFromCam(const CameraIntrinsics& intrinsics) const {
  return ClipFromCamera(IntrinsicsForTarget(intrinsics, width(), height()), width(), height(), options_.depth);
}

Status OverlayRenderer::BeginFrame() {
  target_.Bind();
  glDisable(GL_SCISSOR_TEST);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glDepthMask(GL_TRUE);
  glClearColor(options_.clear_color[0], options_.clear_color[1], options_.clear_color[2], 1.0f);
  glClearDepthf(1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  return CheckGlError("OverlayRenderer::BeginFrame");
}

Status OverlayRenderer::DrawBackground(ImageView<const uint8_t> frame, int channels) {
  RECONAR_RETURN_IF_ERROR(background_.Upload(frame, channels));
  target_.Bind();
  return background_.Draw();
}

Status OverlayRenderer::DrawMesh(const MeshDrawable& mesh, const CameraIntrinsics& intrinsics,
                                 const Eigen::Matrix4d& cam_from_model, const MeshStyle& style) {
  if (!intrinsics.valid()) return InvalidArgument("OverlayRenderer::DrawMesh: intrinsics need fx, fy > 0");
  target_.Bind();
  return mesh_pipeline_.Draw(mesh, ClipFromCam(intrinsics), cam_from_model, style);
}

Status OverlayRenderer::DrawTagAxes(const CameraIntrinsics& intrinsics, const Rigid3& cam_from_tag, double tag_size_m,
                                    const TagAxesStyle& style) {
  if (!intrinsics.valid()) return InvalidArgument("OverlayRenderer::DrawTagAxes: intrinsics need fx, fy > 0");
  target_.Bind();
  return axes_.Draw(ClipFromCam(intrinsics), cam_from_tag, tag_size_m, style);
}

}  // namespace reconar
