// A hand-held video with known poses, from one of our own reconstructions, through `reconar
// capture` (issue 18): the project's coloured mesh (reconar reconstruct of fountain-P11, say)
// rendered unlit with our GLES renderer along a smooth path through its sparse cameras, with a
// walker's sway (seeded), a 9-pixel motion blur on every seventh frame and a stretch at 60 %
// exposure. Then, in this process:
//   - the capture (keyframe gate and live model, as `reconar capture` runs them);
//   - the live model's cameras against the rendered poses (7-DoF aligned);
//   - `sfm` run afterwards on the same keyframes;
//   - `sfm` on every k-th frame, k giving as many frames as the capture kept.
//   bench_capture_handheld PROJECT OUT_DIR [frames=150] [map|parallax]
// (the gate's baseline: from the live model's poses where it has them, the default, or from the
// parallax alone)
// PROJECT holds mesh/mesh.ply (with vertex colours) and sparse/ (COLMAP text). OUT_DIR is
// replaced.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "core/base/prng.h"
#include "core/io/image_write.h"
#include "core/mesh/mesh_file.h"
#include "core/pipeline/reconstruct.h"
#include "core/sfm/model_io.h"
#include "platform/egl/egl_context.h"
#include "render/ar/capture_session.h"
#include "render/overlay_renderer.h"
#include "tests/support/frame_effects.h"
#include "tests/support/sfm_evaluation.h"

namespace {

namespace fs = std::filesystem;
using reconar::Image;

constexpr int kWidth = 640, kHeight = 480;

struct Pose {
  Eigen::Matrix3d cam_from_world;
  Eigen::Vector3d centre;
};

int Fail(const reconar::Status& status) {
  std::fprintf(stderr, "bench_capture_handheld: %s\n", status.ToString().c_str());
  return 1;
}

// The registered cameras' poses in name order.
std::vector<Pose> PathCameras(const reconar::Reconstruction& model) {
  std::vector<const reconar::SfmImage*> images;
  for (const reconar::SfmImage& image : model.images)
    if (image.registered) images.push_back(&image);
  std::sort(images.begin(), images.end(), [](auto* a, auto* b) { return a->name < b->name; });
  std::vector<Pose> poses;
  for (const reconar::SfmImage* image : images) poses.push_back({image->cam_from_world.rotation, image->Center()});
  return poses;
}

// Catmull-Rom through the centres, slerp between the rotations; u in [0, n-1].
Pose Interpolate(const std::vector<Pose>& keys, double u) {
  const int n = static_cast<int>(keys.size());
  const int j = std::min(n - 2, static_cast<int>(std::floor(u)));
  const double t = u - j;
  const auto at = [&](int k) { return keys[static_cast<size_t>(std::clamp(k, 0, n - 1))].centre; };
  const Eigen::Vector3d p0 = at(j - 1), p1 = at(j), p2 = at(j + 1), p3 = at(j + 2);
  Pose pose;
  pose.centre = 0.5 * ((2.0 * p1) + (-p0 + p2) * t + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t * t +
                       (-p0 + 3.0 * p1 - 3.0 * p2 + p3) * t * t * t);
  const Eigen::Quaterniond a(keys[static_cast<size_t>(j)].cam_from_world);
  const Eigen::Quaterniond b(keys[static_cast<size_t>(j + 1)].cam_from_world);
  pose.cam_from_world = a.slerp(t, b).toRotationMatrix();
  return pose;
}

// Registered cameras of a model against the truth, through `truth_name`.
struct Score {
  int registered = 0;
  double centre_mean = 0.0, rotation_mean = 0.0;
};
Score ScoreModel(const std::string& dir, const std::map<std::string, Pose>& truth,
                 const std::map<std::string, std::string>& truth_name) {
  Score score;
  auto model = reconar::ReadColmapTextModel(dir);
  if (!model.ok()) return score;
  std::vector<reconar::testing::CameraPose> estimated, reference;
  for (const reconar::SfmImage& image : model->images) {
    if (!image.registered) continue;
    const auto name = truth_name.find(image.name);
    if (name == truth_name.end()) continue;
    const Pose& pose = truth.at(name->second);
    ++score.registered;
    estimated.push_back({image.cam_from_world.rotation, image.Center()});
    reference.push_back({pose.cam_from_world, pose.centre});
  }
  auto errors = reconar::testing::CameraCenterErrors(estimated, reference);
  if (errors.ok()) {
    score.centre_mean = errors->centre_mean;
    score.rotation_mean = errors->rotation_mean_deg;
  }
  return score;
}

reconar::Status SparseOnly(const std::vector<std::string>& photos, const std::string& project) {
  reconar::ReconstructOptions options;
  options.run_dense = options.run_mesh = false;
  options.show_progress = false;
  options.num_threads = 2;
  return reconar::RunReconstruct(photos, reconar::Project(project), options).status();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: bench_capture_handheld PROJECT OUT_DIR [frames=150] [map|parallax]\n");
    return 2;
  }
  const std::string project = argv[1];
  const fs::path out = argv[2];
  const int frames = argc > 3 ? std::max(20, std::atoi(argv[3])) : 150;
  const std::string baseline = argc > 4 ? argv[4] : "map";
  if (baseline != "map" && baseline != "parallax") {
    return Fail(reconar::InvalidArgument("the baseline must be map or parallax, not " + baseline));
  }
  auto mesh = reconar::ReadMeshFile(project + "/mesh/mesh.ply");
  if (!mesh.ok()) return Fail(mesh.status());
  auto model = reconar::ReadColmapTextModel(project + "/sparse");
  if (!model.ok()) return Fail(model.status());
  const std::vector<Pose> keys = PathCameras(*model);
  if (keys.size() < 3) return Fail(reconar::InvalidArgument("the sparse model has fewer than 3 cameras"));
  const reconar::SfmCamera& camera = model->cameras.front();
  reconar::CameraIntrinsics intrinsics;
  intrinsics.width = kWidth;
  intrinsics.height = kHeight;
  intrinsics.fx = intrinsics.fy = camera.focal * kWidth / camera.width;
  intrinsics.cx = 0.5 * (kWidth - 1);
  intrinsics.cy = 0.5 * (kHeight - 1);
  double extent = 0.0;
  for (const Pose& key : keys) extent = std::max(extent, (key.centre - keys.front().centre).norm());

  reconar::EglContextOptions egl;
  egl.kind = reconar::EglContextKind::kSurfaceless;
  egl.width = kWidth;
  egl.height = kHeight;
  auto context = reconar::EglContext::Create(egl);
  if (!context.ok()) return Fail(context.status());
  reconar::OverlayRendererOptions target;
  target.width = kWidth;
  target.height = kHeight;
  target.clear_color = {0.5f, 0.5f, 0.5f};
  auto renderer = reconar::OverlayRenderer::Create(target);
  if (!renderer.ok()) return Fail(renderer.status());
  auto drawable = reconar::MeshDrawable::Upload(*mesh);
  if (!drawable.ok()) return Fail(drawable.status());
  reconar::MeshStyle unlit;
  unlit.shading = false;

  fs::remove_all(out);
  const fs::path video = out / "video";
  fs::create_directories(video);
  reconar::SplitMix64 random(1);
  double phase[6];
  for (double& p : phase) p = random.Uniform(0.0, 6.283185307179586);
  std::map<std::string, Pose> truth;
  std::vector<std::string> names;
  std::set<int> blurred;
  Image<uint8_t> rgb;
  for (int i = 0; i < frames; ++i) {
    Pose pose = Interpolate(keys, static_cast<double>(i) / (frames - 1) * static_cast<double>(keys.size() - 1));
    // A walker's sway: a few millimetres per metre of path, and half a degree.
    const double s = 0.004 * extent;
    pose.centre += s * Eigen::Vector3d(std::sin(0.27 * i + phase[0]), std::sin(0.19 * i + phase[1]),
                                       std::sin(0.33 * i + phase[2]));
    const Eigen::Vector3d wobble(std::sin(0.21 * i + phase[3]), std::sin(0.29 * i + phase[4]),
                                 std::sin(0.17 * i + phase[5]));
    pose.cam_from_world =
        Eigen::AngleAxisd(0.5 * M_PI / 180.0 * wobble.norm(), wobble.normalized()).toRotationMatrix() *
        pose.cam_from_world;
    Eigen::Matrix4d cam_from_model = Eigen::Matrix4d::Identity();
    cam_from_model.topLeftCorner<3, 3>() = pose.cam_from_world;
    cam_from_model.topRightCorner<3, 1>() = -pose.cam_from_world * pose.centre;
    reconar::Status status = (*renderer)->BeginFrame();
    if (status.ok()) status = (*renderer)->DrawMesh(*drawable, intrinsics, cam_from_model, unlit);
    if (status.ok()) status = (*renderer)->ReadRgb(&rgb);
    if (!status.ok()) return Fail(status);
    Image<uint8_t> frame = rgb;
    if (i % 7 == 3) {
      frame = reconar::testing::MotionBlurred(frame, 9);
      blurred.insert(i);
    }
    if (i >= frames * 2 / 5 && i < frames * 11 / 20) frame = reconar::testing::ExposureScaled(frame, 0.6);
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%04d.png", i);
    status = reconar::WritePng((video / name).string(), frame.view(), 3);
    if (!status.ok()) return Fail(status);
    truth[name] = pose;
    names.push_back(name);
  }

  reconar::CaptureOptions capture;
  capture.source = video.string();
  capture.project_dir = (out / "capture").string();
  capture.gate.use_map_poses = baseline == "map";
  std::map<std::string, std::string> frame_of_keyframe;
  int blurred_taken = 0;
  auto report = reconar::RunCapture(capture, [&](const reconar::CaptureEvent& event) {
    if (event.kind != reconar::CaptureEvent::Kind::kKeyframe) return;
    blurred_taken += blurred.count(static_cast<int>(event.frame_index)) ? 1 : 0;
    frame_of_keyframe[fs::path(event.path).filename().string()] = names[static_cast<size_t>(event.frame_index)];
  });
  if (!report.ok()) return Fail(report.status());
  const int keyframes = static_cast<int>(frame_of_keyframe.size());
  const Score live = ScoreModel(capture.project_dir + "/live", truth, frame_of_keyframe);
  std::vector<std::string> keyframe_paths = report->keyframe_files;
  // In the capture's project, mapping continues from the live model; in a project of its own, it starts over.
  reconar::Status status = SparseOnly(keyframe_paths, capture.project_dir);
  const Score continued = status.ok() ? ScoreModel(capture.project_dir + "/sparse", truth, frame_of_keyframe) : Score();
  status = SparseOnly(keyframe_paths, (out / "offline").string());
  const Score offline =
      status.ok() ? ScoreModel((out / "offline" / "sparse").string(), truth, frame_of_keyframe) : Score();

  const int k = std::max(1, static_cast<int>(std::lround(static_cast<double>(frames) / std::max(1, keyframes))));
  std::vector<std::string> every_kth;
  std::map<std::string, std::string> same;
  int kth_blurred = 0;
  for (int i = 0; i < frames && static_cast<int>(every_kth.size()) < keyframes; i += k) {
    every_kth.push_back((video / names[static_cast<size_t>(i)]).string());
    same[names[static_cast<size_t>(i)]] = names[static_cast<size_t>(i)];
    kth_blurred += blurred.count(i) ? 1 : 0;
  }
  status = SparseOnly(every_kth, (out / "every_kth").string());
  const Score kth = status.ok() ? ScoreModel((out / "every_kth" / "sparse").string(), truth, same) : Score();

  std::printf("%d frames rendered from %s (%zu cameras, path %.3f model units), %zu with motion blur, %d at 60 %%\n",
              frames, project.c_str(), keys.size(), extent, blurred.size(), frames * 11 / 20 - frames * 2 / 5);
  std::printf(
      "capture: %d keyframes, %d of them blurred; passed over %d judged blurred, %d badly exposed, %d too "
      "close, %d lost; gate %.2f ms per frame; baseline from %s (from the map poses for %d frames; %d of %d "
      "frames posed, %.2f ms per frame)\n",
      keyframes, blurred_taken, report->blurred, report->bad_exposure, report->too_close, report->lost,
      report->median_gate_ms, baseline.c_str(), report->frames_map_motion, report->frames_map_posed, report->frames,
      report->median_map_track_ms);
  std::printf(
      "live model:        %d of %d registered (%.1f %%), centre error mean %.4f %% of the path, rotation mean "
      "%.3f deg; keyframe to registration %.2f s median, %.2f s p95\n",
      live.registered, keyframes, 100.0 * live.registered / std::max(1, keyframes), 100.0 * live.centre_mean / extent,
      live.rotation_mean, report->live_model.median_latency_seconds, report->live_model.p95_latency_seconds);
  std::printf("sfm continued:     %d of %d registered, centre error mean %.4f %%, rotation mean %.3f deg\n",
              continued.registered, keyframes, 100.0 * continued.centre_mean / extent, continued.rotation_mean);
  std::printf("sfm on keyframes:  %d of %d registered, centre error mean %.4f %%, rotation mean %.3f deg\n",
              offline.registered, keyframes, 100.0 * offline.centre_mean / extent, offline.rotation_mean);
  std::printf(
      "every %d-th frame: %d of %zu registered (%d blurred among them), centre error mean %.4f %%, rotation "
      "mean %.3f deg\n",
      k, kth.registered, every_kth.size(), kth_blurred, 100.0 * kth.centre_mean / extent, kth.rotation_mean);
  return 0;
}
