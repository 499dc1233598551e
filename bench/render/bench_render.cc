// Per-frame time of the AR overlay on a surfaceless EGL context (llvmpipe here): upload and draw
// the video background, draw the Stanford bunny (69,451 triangles) and the tag axes, read the
// frame back. Each phase ends with glFinish so that its work is charged to it (the GL queue is
// asynchronous); "pipelined" is the same frame without the intermediate glFinish calls.
// Usage: bench_render [frames=60] [shared_data_dir]
#include <GLES3/gl3.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench/common/bench_images.h"
#include "core/io/image_io.h"
#include "core/mesh/mesh_io.h"
#include "platform/egl/egl_context.h"
#include "render/overlay_renderer.h"
#include "tests/support/ar_video.h"

namespace reconar {
namespace {

using Clock = std::chrono::steady_clock;
using bench::Median;
using bench::ResizeBilinear;

double MillisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

struct Timings {
  std::vector<double> background, draw, readback, total, pipelined;
};

bool Check(const Status& status) {
  if (!status.ok()) std::fprintf(stderr, "bench_render: %s\n", status.ToString().c_str());
  return status.ok();
}

int Run(int frames, const std::string& data_dir) {
  auto context = EglContext::Create([] {
    EglContextOptions options;
    options.kind = EglContextKind::kSurfaceless;
    return options;
  }());
  if (!Check(context.status().ok() ? Status::Ok() : context.status())) return 1;
  auto video = ReadImage(data_dir + "/apriltag_ar_video_id12/frames/frame0000.jpg");
  if (!Check(video.ok() ? Status::Ok() : video.status())) return 1;
  auto bunny = ReadPly(data_dir + "/stanford_bunny/reconstruction/bun_zipper.ply");
  if (!Check(bunny.ok() ? Status::Ok() : bunny.status())) return 1;

  const CameraIntrinsics intrinsics = testing::ArVideoCamera();  // rescaled to each target by the renderer
  Rigid3 cam_from_tag;  // a tag 0.7 m away, tilted 50 degrees toward the camera
  cam_from_tag.rotation =
      (Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(-0.9, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  cam_from_tag.translation = Eigen::Vector3d(0.0, 0.03, 0.7);
  auto placement = ModelPlacement::StandingOnTag(*bunny, 0.15);
  if (!Check(placement.ok() ? Status::Ok() : placement.status())) return 1;
  const Eigen::Matrix4d cam_from_model = CamFromModel(cam_from_tag, *placement);

  std::printf("renderer: %s (%s)\n", (*context)->renderer().c_str(), (*context)->gl_version().c_str());
  std::printf("bunny: %zu vertices, %zu triangles; %d frames per size, median ms\n", bunny->positions.size(),
              bunny->triangles.size(), frames);
  std::printf("%-10s %12s %10s %10s %10s %11s\n", "size", "background", "draw", "readback", "total", "pipelined");
  for (const auto& size : {std::pair<int, int>(640, 480), std::pair<int, int>(1280, 720)}) {
    const Image<uint8_t> frame = ResizeBilinear(video->rgb, size.first, size.second);
    OverlayRendererOptions options;
    options.width = size.first;
    options.height = size.second;
    auto renderer = OverlayRenderer::Create(options);
    if (!Check(renderer.ok() ? Status::Ok() : renderer.status())) return 1;
    auto mesh = MeshDrawable::Upload(*bunny);
    if (!Check(mesh.ok() ? Status::Ok() : mesh.status())) return 1;
    Image<uint8_t> rendered;
    Timings timings;
    for (int i = -3; i < frames; ++i) {  // 3 warm-up frames (shader variants, first allocation)
      const Clock::time_point start = Clock::now();
      if (!Check((*renderer)->BeginFrame()) || !Check((*renderer)->DrawBackground(frame.view(), 3))) return 1;
      glFinish();
      const double background = MillisecondsSince(start);
      const Clock::time_point draw_start = Clock::now();
      if (!Check((*renderer)->DrawMesh(*mesh, intrinsics, cam_from_model)) ||
          !Check((*renderer)->DrawTagAxes(intrinsics, cam_from_tag, 0.14))) {
        return 1;
      }
      glFinish();
      const double draw = MillisecondsSince(draw_start);
      const Clock::time_point read_start = Clock::now();
      if (!Check((*renderer)->ReadRgb(&rendered))) return 1;
      const double readback = MillisecondsSince(read_start);

      const Clock::time_point pipelined_start = Clock::now();
      if (!Check((*renderer)->BeginFrame()) || !Check((*renderer)->DrawBackground(frame.view(), 3)) ||
          !Check((*renderer)->DrawMesh(*mesh, intrinsics, cam_from_model)) ||
          !Check((*renderer)->DrawTagAxes(intrinsics, cam_from_tag, 0.14)) || !Check((*renderer)->ReadRgb(&rendered))) {
        return 1;
      }
      const double pipelined = MillisecondsSince(pipelined_start);
      if (i < 0) continue;
      timings.background.push_back(background);
      timings.draw.push_back(draw);
      timings.readback.push_back(readback);
      timings.total.push_back(background + draw + readback);
      timings.pipelined.push_back(pipelined);
    }
    char label[32];
    std::snprintf(label, sizeof(label), "%dx%d", size.first, size.second);
    std::printf("%-10s %12.2f %10.2f %10.2f %10.2f %11.2f\n", label, Median(timings.background), Median(timings.draw),
                Median(timings.readback), Median(timings.total), Median(timings.pipelined));
  }
  return 0;
}

}  // namespace
}  // namespace reconar

int main(int argc, char** argv) {
  const int frames = argc > 1 ? std::max(1, std::atoi(argv[1])) : 60;
  const std::string data_dir = argc > 2 ? argv[2] : RECONAR_SHARED_DATA_DIR;
  return reconar::Run(frames, data_dir);
}
