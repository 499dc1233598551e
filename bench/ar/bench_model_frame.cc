// What drawing a project's model costs the AR view per frame, textured (mesh/textured.glb) against
// vertex-coloured (mesh/mesh.ply, at most kHandheldMaxFaces as `reconar view` loads it): on a
// surfaceless EGL context, at 640x480 and 1280x720, the frame being a registered photo resized to
// that size (uploaded as the video background each frame, as a live frame is) and the model drawn
// from that photo's pose (its camera scaled to the frame's width, rows cropped evenly, undistorted),
// then read back (which waits for the GPU). Photos are decoded up front.
//   bench_model_frame PROJECT [frames=12] [repeats=3]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench/common/bench_images.h"
#include "core/io/image_io.h"
#include "core/mesh/simplify.h"
#include "core/pipeline/project.h"
#include "core/sfm/model_io.h"
#include "platform/egl/egl_context.h"
#include "render/ar/ar_project.h"
#include "render/mesh_drawable.h"
#include "render/overlay_renderer.h"

namespace reconar {
namespace {

using Clock = std::chrono::steady_clock;

// The photo's camera scaled to the frame's width, its principal point moved by the rows cropped
// evenly above and below (a 4:3 photo seen as a 16:9 frame, as a sensor mode crops it).
CameraIntrinsics CroppedToFrame(const CameraIntrinsics& photo, int width, int height) {
  const double scale = static_cast<double>(width) / photo.width;
  CameraIntrinsics frame = ScaledIntrinsics(photo, width, static_cast<int>(std::lround(photo.height * scale)));
  frame.cy -= 0.5 * (frame.height - height);
  frame.height = height;
  return frame;
}

bool Check(const Status& status) {
  if (!status.ok()) std::fprintf(stderr, "bench_model_frame: %s\n", status.ToString().c_str());
  return status.ok();
}

int Run(const std::string& project_dir, int frames, int repeats) {
  const Project project(project_dir);
  auto model = ReadColmapTextModel(project.SparseDir());
  if (!Check(model.ok() ? Status::Ok() : model.status())) return 1;
  auto paths = project.PhotoPathsByName();
  if (!Check(paths.ok() ? Status::Ok() : paths.status())) return 1;
  std::vector<const SfmImage*> poses;
  for (const SfmImage& image : model->images) {
    if (image.registered) poses.push_back(&image);
  }
  if (poses.empty()) return Check(FailedPrecondition(project_dir + ": no registered photo")) ? 0 : 1;
  // Every k-th registered photo, `frames` of them.
  std::vector<const SfmImage*> chosen;
  const size_t step = std::max<size_t>(1, poses.size() / static_cast<size_t>(frames));
  for (size_t i = 0; i < poses.size() && chosen.size() < static_cast<size_t>(frames); i += step) chosen.push_back(poses[i]);
  std::vector<Image<uint8_t>> photos;
  for (const SfmImage* image : chosen) {
    auto decoded = ReadImage(paths->at(image->name));
    if (!Check(decoded.ok() ? Status::Ok() : decoded.status())) return 1;
    photos.push_back(std::move(decoded->rgb));
  }

  struct Variant {
    const char* label;
    std::string path;
    size_t max_faces;
  };
  const Variant variants[2] = {{"textured", project.MeshDir() + "/textured.glb", 0},
                               {"vertex-coloured", project.MeshDir() + "/mesh.ply", kHandheldMaxFaces}};
  std::vector<ArModel> models;
  for (const Variant& variant : variants) {
    auto loaded = LoadArModel(variant.path, variant.max_faces);
    if (!Check(loaded.ok() ? Status::Ok() : loaded.status())) return 1;
    models.push_back(std::move(*loaded));
  }
  EglContextOptions egl;
  egl.kind = EglContextKind::kSurfaceless;
  auto context = EglContext::Create(egl);
  if (!Check(context.ok() ? Status::Ok() : context.status())) return 1;
  std::printf("renderer: %s; %zu frames (registered photos as the video), %d runs\n", (*context)->renderer().c_str(),
              chosen.size(), repeats);
  for (size_t k = 0; k < models.size(); ++k) {
    std::printf("  %-16s %s: %zu triangles%s\n", variants[k].label, variants[k].path.c_str(),
                models[k].mesh.triangles.size(),
                models[k].texture.empty()
                    ? ""
                    : (", texture " + std::to_string(models[k].texture.size()) + " page(s), the first " +
                       std::to_string(models[k].texture[0].image.width()) + " x " +
                       std::to_string(models[k].texture[0].image.height()))
                          .c_str());
  }
  std::printf("%-10s %-16s %12s %12s %12s\n", "size", "model", "median ms", "p90 ms", "fps");
  for (const auto& [width, height] : {std::pair<int, int>(640, 480), std::pair<int, int>(1280, 720)}) {
    std::vector<Image<uint8_t>> frames_rgb;
    for (const Image<uint8_t>& photo : photos) {
      // Scaled to the frame's width, the rows beyond its height cropped evenly (as CroppedToFrame).
      const int scaled_height = static_cast<int>(std::lround(static_cast<double>(photo.height()) * width / photo.width()));
      const Image<uint8_t> scaled = bench::ResizeBilinear(photo, width, std::max(height, scaled_height));
      Image<uint8_t> frame(width, height, 3);
      const int top = (scaled.height() - height) / 2;
      for (int y = 0; y < height; ++y) std::copy(scaled.row(top + y), scaled.row(top + y) + 3 * width, frame.row(y));
      frames_rgb.push_back(std::move(frame));
    }
    OverlayRendererOptions render_options;
    render_options.width = width;
    render_options.height = height;
    auto renderer = OverlayRenderer::Create(render_options);
    if (!Check(renderer.ok() ? Status::Ok() : renderer.status())) return 1;
    double medians[2] = {0.0, 0.0};
    for (size_t k = 0; k < models.size(); ++k) {
      const ArModel& ar_model = models[k];
      auto drawable = MeshDrawable::Upload(ar_model.mesh, ar_model.texture.empty() ? nullptr : &ar_model.texture);
      if (!Check(drawable.ok() ? Status::Ok() : drawable.status())) return 1;
      MeshStyle style;
      style.shading = ar_model.texture.empty();  // as the AR view draws each
      std::vector<double> ms;
      Image<uint8_t> overlay;
      for (int run = 0; run < repeats; ++run) {
        for (size_t i = 0; i < chosen.size(); ++i) {
          const SfmCamera& camera = model->cameras[static_cast<size_t>(chosen[i]->camera_id)];
          CameraIntrinsics photo_camera = camera.Intrinsics();
          photo_camera.k1 = photo_camera.k2 = 0.0;
          const CameraIntrinsics intrinsics = CroppedToFrame(photo_camera, width, height);
          const Clock::time_point start = Clock::now();
          if (!Check((*renderer)->BeginFrame()) || !Check((*renderer)->DrawBackground(frames_rgb[i].view(), 3)) ||
              !Check((*renderer)->DrawMesh(*drawable, intrinsics, chosen[i]->cam_from_world.Matrix(), style)) ||
              !Check((*renderer)->ReadRgb(&overlay))) {
            return 1;
          }
          ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
        }
      }
      std::vector<double> sorted = ms;
      std::sort(sorted.begin(), sorted.end());
      medians[k] = bench::Median(ms);
      char label[32];
      std::snprintf(label, sizeof(label), "%dx%d", width, height);
      std::printf("%-10s %-16s %12.2f %12.2f %12.1f\n", label, variants[k].label, medians[k],
                  sorted[sorted.size() * 9 / 10], 1000.0 / medians[k]);
    }
    std::printf("%-10s textured / vertex-coloured: %.2f\n", "", medians[0] / medians[1]);
  }
  return 0;
}

}  // namespace
}  // namespace reconar

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_model_frame PROJECT [frames=12] [repeats=3]\n");
    return 2;
  }
  return reconar::Run(argv[1], argc > 2 ? std::max(1, std::atoi(argv[2])) : 12,
                      argc > 3 ? std::max(1, std::atoi(argv[3])) : 3);
}
