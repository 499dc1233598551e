#include "render/ar/ar_view.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

#include "core/base/atomic_file.h"
#include "core/base/median.h"
#include "core/io/image_write.h"
#include "core/base/bitmap_text.h"

namespace reconar {
namespace {

// The small drawing's clear colour: pixels the model does not cover (exposure_match.h).
constexpr std::array<uint8_t, 3> kExposureKey = {255, 0, 255};

// The PNG for a frame: its file name with .png, or frameNNNNNN.png for a device or a recording.
std::string OutputName(const Frame& frame) {
  std::string name(frame.name);
  if (name.find('/') != std::string::npos || name.find('#') != std::string::npos || name.empty()) {
    char text[32];
    std::snprintf(text, sizeof(text), "frame%06lld", static_cast<long long>(frame.index));
    return std::string(text) + ".png";
  }
  const size_t dot = name.rfind('.');
  return (dot == std::string::npos ? name : name.substr(0, dot)) + ".png";
}

double MsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void SetPixel(int x, int y, const std::array<uint8_t, 3>& colour, Image<uint8_t>* rgb) {
  if (x < 0 || y < 0 || x >= rgb->width() || y >= rgb->height()) return;
  uint8_t* pixel = rgb->row(y) + 3 * x;
  pixel[0] = colour[0];
  pixel[1] = colour[1];
  pixel[2] = colour[2];
}

// A line `width` pixels wide from a to b, and a ring round each end.
void DrawMeasureLine(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const std::array<uint8_t, 3>& colour,
                     Image<uint8_t>* rgb) {
  const double length = (b - a).norm();
  const int steps = std::max(1, static_cast<int>(2.0 * length));
  for (int k = 0; k <= steps; ++k) {
    const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(k) / steps);
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) SetPixel(static_cast<int>(std::lround(p.x())) + dx, static_cast<int>(std::lround(p.y())) + dy, colour, rgb);
    }
  }
  for (const Eigen::Vector2d& end : {a, b}) {
    for (int k = 0; k < 64; ++k) {
      const double angle = 2.0 * M_PI * k / 64;
      for (double radius : {6.0, 7.0}) {
        SetPixel(static_cast<int>(std::lround(end.x() + radius * std::cos(angle))),
                 static_cast<int>(std::lround(end.y() + radius * std::sin(angle))), colour, rgb);
      }
    }
  }
}

// "0.1271 m +- 1.2 mm" (or the reason there is none) on a dark box beside the line's middle.
void DrawMeasureLabel(const ViewMeasurement& measurement, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                      Image<uint8_t>* rgb) {
  char text[96];
  if (measurement.measured && measurement.item.unit == "m") {
    std::snprintf(text, sizeof(text), "%.4f m +- %.1f mm", measurement.item.value, 1000.0 * measurement.item.sigma);
  } else if (measurement.measured) {
    std::snprintf(text, sizeof(text), "%.4g +- %.2g (model units)", measurement.item.value, measurement.item.sigma);
  } else {
    std::snprintf(text, sizeof(text), "no surface under a point");
  }
  const int scale = std::max(2, rgb->height() / 240);
  const int width = TextWidthPx(text, scale), height = kGlyphHeight * scale;
  const Eigen::Vector2d middle = 0.5 * (a + b);
  const int x = std::clamp(static_cast<int>(middle.x()) - width / 2, 0, std::max(0, rgb->width() - width));
  const int y = std::clamp(static_cast<int>(middle.y()) + 12, 0, std::max(0, rgb->height() - height - 2 * scale));
  for (int row = y - scale; row < y + height + scale; ++row) {
    for (int column = x - scale; column < x + width + scale; ++column) SetPixel(column, row, {0, 0, 0}, rgb);
  }
  DrawText(text, x, y, scale, {255, 255, 0}, rgb);
}

}  // namespace

const char* ArLayerName(ArLayer layer) {
  switch (layer) {
    case ArLayer::kAsBuilt:
      return "as-built";
    case ArLayer::kDesign:
      return "design";
    case ArLayer::kDeviation:
      return "deviation";
  }
  return "?";
}

Result<std::unique_ptr<ArView>> ArView::Open(const ArViewOptions& options, const ArModel& model, const ArDesign* design) {
  if (design == nullptr && options.layer != ArLayer::kAsBuilt) {
    return InvalidArgument(std::string("the ") + ArLayerName(options.layer) + " layer needs a design (reconar compare)");
  }
  const bool to_files = !options.out_dir.empty();
  if (to_files) RECONAR_RETURN_IF_ERROR(CreateDirectories(options.out_dir));
  ArSessionOptions session_options = options.session;
  session_options.frames.want_rgb = true;
  RECONAR_ASSIGN_OR_RETURN(std::unique_ptr<ArSession> session, ArSession::Open(session_options));
  EglContextOptions egl_options;
  egl_options.kind = to_files ? EglContextKind::kSurfaceless : options.window;
  egl_options.width = session->width();
  egl_options.height = session->height();
  auto context = to_files ? EglContext::Create(egl_options) : EglContext::CreateOnScreen(egl_options);
  if (!context.ok()) {
    Status status = context.status();
    if (!to_files) status = status.WithContext("no display for the live view (use --out DIR to write PNGs instead)");
    return status;
  }
  OverlayRendererOptions render_options;
  render_options.width = session->width();
  render_options.height = session->height();
  render_options.samples = options.samples;
  RECONAR_ASSIGN_OR_RETURN(std::unique_ptr<OverlayRenderer> renderer, OverlayRenderer::Create(render_options));
  RECONAR_ASSIGN_OR_RETURN(MeshDrawable drawable,
                           MeshDrawable::Upload(model.mesh, model.texture.empty() ? nullptr : &model.texture));
  std::optional<MeshDrawable> design_drawable, deviation_drawable;
  if (design != nullptr) {
    RECONAR_ASSIGN_OR_RETURN(design_drawable, MeshDrawable::Upload(design->design));
    RECONAR_ASSIGN_OR_RETURN(deviation_drawable, MeshDrawable::Upload(design->deviation));
  }
  std::unique_ptr<OverlayRenderer> exposure_renderer;
  std::optional<MeshDrawable> exposure_proxy;
  if (options.match_exposure && drawable.has_texture()) {
    RECONAR_ASSIGN_OR_RETURN(const Mesh proxy,
                             ExposureProxy(model.mesh, model.texture, options.exposure.proxy_max_faces));
    RECONAR_ASSIGN_OR_RETURN(exposure_proxy, MeshDrawable::Upload(proxy));
    OverlayRendererOptions small;
    small.width = std::max(8, options.exposure.sample_width);
    small.height = std::max(8, static_cast<int>(std::lround(static_cast<double>(small.width) * session->height() /
                                                            session->width())));
    small.clear_color = {1.0f, 0.0f, 1.0f};  // kExposureKey: where the model is not
    RECONAR_ASSIGN_OR_RETURN(exposure_renderer, OverlayRenderer::Create(small));
  }
  auto view = std::unique_ptr<ArView>(new ArView(options, std::move(session), std::move(*context), std::move(renderer),
                                                 std::move(drawable), std::move(design_drawable),
                                                 std::move(deviation_drawable)));
  if (exposure_renderer) {
    view->exposure_.emplace(options.exposure);
    view->exposure_model_ = Image<uint8_t>(exposure_renderer->width(), exposure_renderer->height(), 3);
    view->exposure_frame_ = Image<uint8_t>(exposure_renderer->width(), exposure_renderer->height(), 3);
    view->exposure_renderer_ = std::move(exposure_renderer);
    view->exposure_proxy_ = std::move(exposure_proxy);
  }
  return view;
}

std::array<float, 3> ArView::exposure_gain() const {
  return exposure_ ? exposure_->gain() : std::array<float, 3>{1.0f, 1.0f, 1.0f};
}

Status ArView::MatchExposure(const CameraIntrinsics& intrinsics, const Eigen::Matrix4d& cam_from_model) {
  if (!exposure_) return Status::Ok();
  MeshStyle plain = options_.style;
  plain.shading = false;
  plain.gain = {1.0f, 1.0f, 1.0f};
  RECONAR_RETURN_IF_ERROR(exposure_renderer_->BeginFrame());
  RECONAR_RETURN_IF_ERROR(exposure_renderer_->DrawMesh(*exposure_proxy_, intrinsics, cam_from_model, plain));
  RECONAR_RETURN_IF_ERROR(exposure_renderer_->ReadRgb(&exposure_model_));
  BoxReduce(session_->frame().rgb, session_->width(), session_->height(), &exposure_frame_);
  exposure_->Update(exposure_->Estimate(exposure_model_, exposure_frame_, kExposureKey));
  return Status::Ok();
}

ArView::ArView(const ArViewOptions& options, std::unique_ptr<ArSession> session, std::unique_ptr<EglContext> context,
               std::unique_ptr<OverlayRenderer> renderer, MeshDrawable model, std::optional<MeshDrawable> design,
               std::optional<MeshDrawable> deviation)
    : options_(options),
      session_(std::move(session)),
      context_(std::move(context)),
      renderer_(std::move(renderer)),
      model_(std::move(model)),
      design_(std::move(design)),
      deviation_(std::move(deviation)) {}

ArView::~ArView() = default;

std::string ArView::Describe(const std::string& model_name) const {
  return session_->Describe() + "; " + EglContextKindName(context_->kind()) + " " + context_->renderer() + "; model " +
         model_name + " (" + std::to_string(model_.vertex_count()) + " vertices, " +
         std::to_string(model_.triangle_count()) + " triangles)";
}

Status ArView::Draw(bool* drawn_model) {
  *drawn_model = false;
  const WorldPose& found = session_->pose();
  if (found.found && exposure_ && options_.layer == ArLayer::kAsBuilt) {
    const Eigen::Matrix4d cam_from_model = options_.placement ? CamFromModel(found.cam_from_world, *options_.placement)
                                                              : found.cam_from_world.Matrix();
    RECONAR_RETURN_IF_ERROR(MatchExposure(session_->intrinsics(), cam_from_model));
  }
  RECONAR_RETURN_IF_ERROR(renderer_->BeginFrame());
  RECONAR_RETURN_IF_ERROR(renderer_->DrawBackground(session_->frame().rgb, 3));
  const WorldPose& pose = session_->pose();
  measurement_ = ViewMeasurement();
  if (!pose.found) return Status::Ok();
  const CameraIntrinsics& intrinsics = session_->intrinsics();
  if (options_.measurer && options_.measure_pixels) {
    const auto start = std::chrono::steady_clock::now();
    const std::array<Eigen::Vector2d, 2>& pixels = *options_.measure_pixels;
    Result<MeasuredItem> item =
        options_.measurer->MeasureBetweenPixels(pose.cam_from_world, intrinsics.Camera(), pixels[0], pixels[1]);
    measurement_.measured = item.ok();
    if (item.ok()) measurement_.item = std::move(*item);
    if (!item.ok()) measurement_.error = item.status().message();
    measurement_.ms = MsSince(start);
  }
  const Eigen::Matrix4d cam_from_model =
      options_.placement ? CamFromModel(pose.cam_from_world, *options_.placement) : pose.cam_from_world.Matrix();
  const bool deviation_layer = options_.layer == ArLayer::kDeviation && deviation_;
  MeshStyle model_style = options_.style;
  if (!deviation_layer && model_.has_texture()) {
    model_style.shading = false;
    model_style.gain = exposure_gain();
  }
  RECONAR_RETURN_IF_ERROR(
      renderer_->DrawMesh(deviation_layer ? *deviation_ : model_, intrinsics, cam_from_model, model_style));
  if (options_.layer != ArLayer::kAsBuilt && design_) {
    MeshStyle design_style = options_.style;
    design_style.opacity = options_.design_opacity;
    design_style.color = options_.design_colour;
    RECONAR_RETURN_IF_ERROR(renderer_->DrawMesh(*design_, intrinsics, cam_from_model, design_style));
  }
  *drawn_model = true;
  if (!options_.draw_axes) return Status::Ok();
  for (const LayoutTag& tag : pose.markers) {
    RECONAR_RETURN_IF_ERROR(renderer_->DrawTagAxes(intrinsics, pose.cam_from_world * tag.layout_from_tag, tag.size));
  }
  return Status::Ok();
}

void ArView::DrawMeasureMarks() {
  if (!options_.measure_pixels) {
    DrawMeasureLine(*first_tap_, *first_tap_, {255, 255, 0}, &rgb_);
    return;
  }
  const std::array<Eigen::Vector2d, 2>& pixels = *options_.measure_pixels;
  const std::array<uint8_t, 3> colour =
      measurement_.measured ? std::array<uint8_t, 3>{255, 255, 0} : std::array<uint8_t, 3>{255, 64, 64};
  DrawMeasureLine(pixels[0], pixels[1], colour, &rgb_);
  DrawMeasureLabel(measurement_, pixels[0], pixels[1], &rgb_);
}

void ArView::TakeTaps(const std::vector<std::array<int, 2>>& taps) {
  const Letterbox box = LetterboxIn(renderer_->width(), renderer_->height(), context_->width(), context_->height());
  for (const std::array<int, 2>& tap : taps) {
    Eigen::Vector2d pixel;
    if (!box.ImagePixel(renderer_->width(), renderer_->height(), tap[0], tap[1], &pixel.x(), &pixel.y())) continue;
    if (first_tap_ && !options_.measure_pixels) {  // the second tap: measure from the first
      options_.measure_pixels = std::array<Eigen::Vector2d, 2>{*first_tap_, pixel};
    } else {  // the first, or a third that starts again
      first_tap_ = pixel;
      options_.measure_pixels.reset();
    }
  }
}

Result<ArViewReport> ArView::Run(const std::function<void(const ArSession& session)>& each_frame) {
  const bool to_files = !options_.out_dir.empty();
  std::vector<double> render_ms, frame_ms;
  ArViewReport report;
  const auto draw_frame = [&](const ArSession& session) -> Result<bool> {
    const auto render_start = std::chrono::steady_clock::now();
    bool drawn_model = false;
    Status drawn = Draw(&drawn_model);
    if (drawn_model) ++report.frames_with_model;
    if (drawn.ok()) {
      const bool marks = session.pose().found && (options_.measure_pixels || first_tap_);
      if (to_files) {
        drawn = renderer_->ReadRgb(&rgb_);
        if (drawn.ok() && marks) DrawMeasureMarks();
      } else {
        if (marks) {  // the marks are drawn on the CPU: read the frame back, mark it, show that
          drawn = renderer_->ReadRgb(&rgb_);
          if (drawn.ok()) DrawMeasureMarks();
          if (drawn.ok()) drawn = renderer_->BeginFrame();
          if (drawn.ok()) drawn = renderer_->DrawBackground(static_cast<const Image<uint8_t>&>(rgb_).view(), 3);
        }
        if (drawn.ok()) drawn = renderer_->PresentToDefaultFramebuffer(context_->width(), context_->height());
        if (drawn.ok()) drawn = context_->SwapBuffers();
      }
    }
    render_ms.push_back(MsSince(render_start));
    frame_ms.push_back(MsSince(session.frame_start()));
    const std::string name = OutputName(session.frame());
    if (!drawn.ok()) return drawn.WithContext(name);
    if (to_files) RECONAR_RETURN_IF_ERROR(WritePng(options_.out_dir + "/" + name, rgb_.view(), 3));
    if (each_frame) each_frame(session);
    if (to_files) return true;
    const WindowEvents events = context_->PollEvents();
    if (options_.measurer) TakeTaps(events.taps);
    if (design_ && events.next_layer_presses > 0) {
      options_.layer = static_cast<ArLayer>((static_cast<int>(options_.layer) + events.next_layer_presses) % 3);
      std::fprintf(stderr, "showing the %s layer\n", ArLayerName(options_.layer));
    }
    return !events.should_quit();
  };
  RECONAR_ASSIGN_OR_RETURN(report.session, session_->Run(draw_frame));
  report.median_render_ms = Median(std::move(render_ms));
  report.median_frame_ms = Median(std::move(frame_ms));
  report.exposure_gain = exposure_gain();
  return report;
}

}  // namespace reconar
