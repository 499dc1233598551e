#pragma once
// OverlayRenderer: the AR overlay of one video stream. Per frame:
//   BeginFrame()                                  clear colour and depth of the offscreen target
//   DrawBackground(frame, 3)                      the camera frame (uploaded into a reused texture)
//   DrawMesh(mesh, intrinsics, cam_from_model)    a model placed on a tag (render/model_placement.h)
//   DrawTagAxes(intrinsics, cam_from_tag, size)   the tag's axes and outline
//   ReadRgb(&image) and/or PresentToDefaultFramebuffer(w, h) then EglContext::SwapBuffers()
// The target has the size given at creation (normally the frame's). A camera-frame point X (x
// right, y down, z forward) is drawn at the pixel CameraIntrinsics::Project(X) gives (k1, k2
// ignored; see render/camera_projection.h). After the first frame, a frame of the same size
// makes no heap allocation. Poses arrive as plain data (Rigid3): render never includes tracker.
// All calls need the GLES 3 context that was current at Create (platform/egl/egl_context.h).
#include <Eigen/Core>
#include <cstdint>
#include <memory>

#include "core/base/image.h"
#include "core/base/status.h"
#include "core/math/camera_intrinsics.h"
#include "core/math/rigid3.h"
#include "render/camera_projection.h"
#include "render/mesh_drawable.h"
#include "render/model_placement.h"
#include "render/offscreen_target.h"
#include "render/tag_axes_drawable.h"
#include "render/video_background.h"

namespace reconar {

struct OverlayRendererOptions {
  int width = 640;  // target size in pixels, normally the video frame's
  int height = 480;
  int samples = 0;   // multisample anti-aliasing of the overlay (0 = off; clamped to GL_MAX_SAMPLES)
  DepthRange depth;  // camera-frame depths drawn
  std::array<float, 3> clear_color = {0.0f, 0.0f, 0.0f};  // where no background is drawn

  // InvalidArgument naming the first offending field.
  Status Check() const;
};

class OverlayRenderer {
 public:
  using Options = OverlayRendererOptions;

  // Compiles the shaders and allocates the target. Needs a current GLES 3 context; errors carry
  // shader logs or the GL error.
  static Result<std::unique_ptr<OverlayRenderer>> Create(const Options& options);

  int width() const { return target_.width(); }
  int height() const { return target_.height(); }

  Status BeginFrame();
  // Uploads the frame (interleaved, width = channels * pixels, any stride; channels 1, 3 or 4)
  // and draws it over the whole target, stretched if its size differs.
  Status DrawBackground(ImageView<const uint8_t> frame, int channels = 3);
  // `intrinsics` are in the pixels of the target (or, when their width/height are set, of an
  // image of that size, rescaled to the target: IntrinsicsForTarget).
  Status DrawMesh(const MeshDrawable& mesh, const CameraIntrinsics& intrinsics, const Eigen::Matrix4d& cam_from_model,
                  const MeshStyle& style = MeshStyle());
  Status DrawTagAxes(const CameraIntrinsics& intrinsics, const Rigid3& cam_from_tag, double tag_size_m,
                     const TagAxesStyle& style = TagAxesStyle());

  // The frame drawn so far, RGB, row 0 at the top (see OffscreenTarget::ReadRgb).
  Status ReadRgb(Image<uint8_t>* rgb) { return target_.ReadRgb(rgb); }
  // Letterboxed blit to the window's default framebuffer; call EglContext::SwapBuffers after.
  Status PresentToDefaultFramebuffer(int window_width, int window_height) {
    return target_.PresentToDefaultFramebuffer(window_width, window_height);
  }

  // clip_from_cam for these intrinsics on this target.
  Eigen::Matrix4d ClipFromCam(const CameraIntrinsics& intrinsics) const;

 private:
  OverlayRenderer(const Options& options, OffscreenTarget target, VideoBackground background, MeshPipeline mesh,
                  TagAxesDrawable axes);

  Options options_;
  OffscreenTarget target_;
  VideoBackground background_;
  MeshPipeline mesh_pipeline_;
  TagAxesDrawable axes_;
};

}  // namespace reconar
