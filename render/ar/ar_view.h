#pragma once
// ArView: the AR overlay of `reconar view`. An ArSession (frames and their poses) drawn by the
// OverlayRenderer: the video as background, the model at cam_from_world * world_from_model, the
// axes of the world's tags in view; then shown in a window (X11, or full screen through GBM/KMS)
// or written as one PNG per frame.
#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "core/base/status.h"
#include "core/measure/measurement.h"
#include "core/mesh/mesh.h"
#include "platform/egl/egl_context.h"
#include "render/ar/ar_project.h"
#include "render/ar/ar_session.h"
#include "render/ar/exposure_match.h"
#include "render/mesh_drawable.h"
#include "render/model_placement.h"
#include "render/overlay_renderer.h"

namespace reconar {

// What the view draws over the video (with a design from `reconar compare`, space or 'l' in the
// window steps through them): the as-built model; the model and the registered design over it,
// semi-transparent; the as-built points coloured by their deviation, with the design.
enum class ArLayer { kAsBuilt, kDesign, kDeviation };
const char* ArLayerName(ArLayer layer);  // "as-built", "design", "deviation"

struct ArViewOptions {
  ArSessionOptions session;  // frames.want_rgb is forced on
  // Non-empty: write OUT_DIR/<frame>.png (headless) instead of showing a window.
  std::string out_dir;
  EglContextKind window = EglContextKind::kAuto;  // when out_dir is empty
  // world_from_model: the model's place in the world (a tag's frame); nullopt: the model is already
  // in the world frame (a project's model, in metres).
  std::optional<ModelPlacement> placement;
  MeshStyle style;
  int samples = 0;  // multisample anti-aliasing (0 = off)
  bool draw_axes = true;
  // Set with measure_pixels: each posed frame, the distance between the model's surface under these
  // two pixels (the view's tap-to-measure), drawn with its σ into the PNGs or the window. In a
  // window without measure_pixels, two clicks (taps) on the picture set them, a third starts again.
  std::shared_ptr<ProjectMeasurer> measurer;
  std::optional<std::array<Eigen::Vector2d, 2>> measure_pixels;
  ArLayer layer = ArLayer::kAsBuilt;  // the first layer shown (kDesign, kDeviation need a design)
  float design_opacity = 0.45f;
  std::array<float, 3> design_colour = {0.1f, 0.85f, 0.95f};
  // A textured model brought to each frame's exposure (exposure_match.h); false: drawn as the
  // texture holds it.
  bool match_exposure = true;
  ExposureMatchOptions exposure;
};

// The frame's measure (ArViewOptions::measure_pixels).
struct ViewMeasurement {
  bool measured = false;  // false: no pose, or `error` says why
  MeasuredItem item;
  std::string error;
  double ms = 0.0;  // placing the two points and measuring
};

struct ArViewReport {
  ArSessionReport session;  // the frames, the sources of their poses, the tracking times
  long frames_with_model = 0;
  // Medians over the frames, milliseconds: drawing (with the readback when writing PNGs), and
  // tracking and drawing together.
  double median_render_ms = 0.0;
  double median_frame_ms = 0.0;
  std::array<float, 3> exposure_gain = {1.0f, 1.0f, 1.0f};  // the last frame's (match_exposure)
};

class ArView {
 public:
  // Creates out_dir, opens the session, the EGL context (surfaceless for PNGs, else a window; no
  // display is FailedPrecondition saying to use --out) and the renderer, and uploads the model.
  // `design` (may be null): the layers kDesign and kDeviation; InvalidArgument when options.layer
  // asks for one without it. A textured model is drawn with its texture, unlit (the photos
  // already hold the light).
  static Result<std::unique_ptr<ArView>> Open(const ArViewOptions& options, const ArModel& model,
                                              const ArDesign* design = nullptr);
  ~ArView();

  // "SOURCE; EGL-ROUTE RENDERER; model MODEL_NAME (N vertices, M triangles)".
  std::string Describe(const std::string& model_name) const;
  // Every frame until the stream ends, max_frames, or the window is closed ('q', Escape).
  // `each_frame` (if set) is called after each frame is drawn, with the session (the frame, its
  // pose and its sources).
  Result<ArViewReport> Run(const std::function<void(const ArSession& session)>& each_frame = nullptr);

  // The last frame's measure, when ArViewOptions::measure_pixels is set.
  const ViewMeasurement& measurement() const { return measurement_; }
  // The gain the textured model is drawn with (ArViewOptions::match_exposure); 1 otherwise.
  std::array<float, 3> exposure_gain() const;

 private:
  ArView(const ArViewOptions& options, std::unique_ptr<ArSession> session, std::unique_ptr<EglContext> context,
         std::unique_ptr<OverlayRenderer> renderer, MeshDrawable model, std::optional<MeshDrawable> design,
         std::optional<MeshDrawable> deviation);
  // The frame, the model and the tags' axes at this frame's pose; true in *drawn_model when the
  // model was drawn.
  Status Draw(bool* drawn_model);
  // The model drawn small and compared with the frame (exposure_match.h).
  Status MatchExposure(const CameraIntrinsics& intrinsics, const Eigen::Matrix4d& cam_from_model);

  ArViewOptions options_;
  std::unique_ptr<ArSession> session_;
  std::unique_ptr<EglContext> context_;
  std::unique_ptr<OverlayRenderer> renderer_;
  MeshDrawable model_;
  std::optional<MeshDrawable> design_, deviation_;
  Image<uint8_t> rgb_;
  // The line between the measured pixels (or the ring of a first tap) and the label, into rgb_.
  void DrawMeasureMarks();
  // Window clicks, in window pixels, into measure pixels (see ArViewOptions::measurer).
  void TakeTaps(const std::vector<std::array<int, 2>>& taps);

  ViewMeasurement measurement_;
  std::optional<Eigen::Vector2d> first_tap_;
  // With match_exposure and a textured model: the small drawing and its comparison.
  std::unique_ptr<OverlayRenderer> exposure_renderer_;
  std::optional<MeshDrawable> exposure_proxy_;
  std::optional<ExposureMatcher> exposure_;
  Image<uint8_t> exposure_model_, exposure_frame_;
};

}  // namespace reconar
