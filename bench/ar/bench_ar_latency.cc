// AR latency per frame: tag tracking (TagTracker, 1 thread) + overlay rendering (background upload,
// Stanford bunny standing on the tag, tag axes, readback) on a surfaceless EGL context, over the
// 93 real frames of ../shared/data/apriltag_ar_video_id12, at 640x480 as recorded and at 1280x960
// (frames upscaled bilinearly; K by ScaleIntrinsicsToFrame, as the AR runtime scales it). Frames
// are decoded up front: the figures are what a live loop spends after the camera hands over a frame.
//   bench_ar_latency [repeats=3]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench/common/bench_images.h"
#include "core/io/image_io.h"
#include "core/mesh/mesh_io.h"
#include "platform/egl/egl_context.h"
#include "render/ar/ar_project.h"
#include "render/mesh_drawable.h"
#include "render/model_placement.h"
#include "render/overlay_renderer.h"
#include "tests/support/ar_video.h"
#include "tracker/tag_tracker.h"

namespace reconar {
namespace {

using Clock = std::chrono::steady_clock;

double MillisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

bool Check(const Status& status) {
  if (!status.ok()) std::fprintf(stderr, "bench_ar_latency: %s\n", status.ToString().c_str());
  return status.ok();
}

int Run(int repeats) {
  const std::string data = RECONAR_SHARED_DATA_DIR;
  std::vector<Image<uint8_t>> rgb_frames;
  for (int i = 0; i < 93; ++i) {
    char name[64];
    std::snprintf(name, sizeof(name), "/apriltag_ar_video_id12/frames/frame%04d.jpg", i);
    auto decoded = ReadImage(data + name);
    if (!Check(decoded.ok() ? Status::Ok() : decoded.status())) return 1;
    rgb_frames.push_back(std::move(decoded->rgb));
  }
  auto bunny = ReadPly(data + "/stanford_bunny/reconstruction/bun_zipper.ply");
  if (!Check(bunny.ok() ? Status::Ok() : bunny.status())) return 1;
  auto placement = ModelPlacement::StandingOnTag(*bunny, 0.14);
  if (!Check(placement.ok() ? Status::Ok() : placement.status())) return 1;
  EglContextOptions egl;
  egl.kind = EglContextKind::kSurfaceless;
  auto context = EglContext::Create(egl);
  if (!Check(context.ok() ? Status::Ok() : context.status())) return 1;
  std::printf("renderer: %s; bunny %zu triangles; %d runs over 93 frames, 1 tracker thread\n",
              (*context)->renderer().c_str(), bunny->triangles.size(), repeats);
  std::printf("%-10s %10s %10s %14s %14s %8s\n", "size", "track", "render", "track+render", "p90 total", "tagged");

  for (const auto& size : {std::pair<int, int>(640, 480), std::pair<int, int>(1280, 960)}) {
    const int width = size.first, height = size.second;
    std::vector<Image<uint8_t>> rgb, gray;
    for (const Image<uint8_t>& frame : rgb_frames) {
      rgb.push_back(width == 640 ? frame : bench::ResizeBilinear(frame, width, height));
      gray.push_back(ToGray8(rgb.back()));
    }
    auto scaled = ScaleIntrinsicsToFrame(testing::ArVideoCamera(), width, height);
    if (!Check(scaled.ok() ? Status::Ok() : scaled.status())) return 1;
    TagTrackerOptions options;
    options.intrinsics = *scaled;
    options.tag_size = testing::kArVideoTagSize;
    OverlayRendererOptions render_options;
    render_options.width = width;
    render_options.height = height;
    auto renderer = OverlayRenderer::Create(render_options);
    if (!Check(renderer.ok() ? Status::Ok() : renderer.status())) return 1;
    auto mesh = MeshDrawable::Upload(*bunny);
    if (!Check(mesh.ok() ? Status::Ok() : mesh.status())) return 1;
    std::vector<double> track_ms, render_ms, total_ms;
    int tagged = 0;
    Image<uint8_t> overlay;
    for (int run = 0; run < repeats; ++run) {
      auto tracker = TagTracker::Create(options);
      if (!Check(tracker.ok() ? Status::Ok() : tracker.status())) return 1;
      TagTrackerFrameReport report;
      tagged = 0;
      for (size_t i = 0; i < gray.size(); ++i) {
        const Clock::time_point start = Clock::now();
        if (!Check((*tracker)->Track(gray[i].view(), &report))) return 1;
        const double track = MillisecondsSince(start);
        const Clock::time_point render_start = Clock::now();
        if (!Check((*renderer)->BeginFrame()) || !Check((*renderer)->DrawBackground(rgb[i].view(), 3))) return 1;
        for (const TrackedTag& tag : report.tags) {
          if (!tag.measured) continue;
          ++tagged;
          if (!Check((*renderer)->DrawMesh(*mesh, options.intrinsics, CamFromModel(tag.cam_from_tag, *placement))) ||
              !Check((*renderer)->DrawTagAxes(options.intrinsics, tag.cam_from_tag, options.tag_size))) {
            return 1;
          }
        }
        if (!Check((*renderer)->ReadRgb(&overlay))) return 1;
        const double render = MillisecondsSince(render_start);
        track_ms.push_back(track);
        render_ms.push_back(render);
        total_ms.push_back(track + render);
      }
    }
    std::vector<double> sorted = total_ms;
    std::sort(sorted.begin(), sorted.end());
    char label[32];
    std::snprintf(label, sizeof(label), "%dx%d", width, height);
    std::printf("%-10s %10.2f %10.2f %14.2f %14.2f %5d/93\n", label, bench::Median(track_ms), bench::Median(render_ms),
                bench::Median(total_ms), sorted[sorted.size() * 9 / 10], tagged);
  }
  return 0;
}

}  // namespace
}  // namespace reconar

int main(int argc, char** argv) { return reconar::Run(argc > 1 ? std::max(1, std::atoi(argv[1])) : 3); }
