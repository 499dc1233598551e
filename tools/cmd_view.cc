// reconar view: the AR overlay. A model drawn on a tracked AprilTag over live or recorded video,
// shown in a window (X11, or full screen through GBM/KMS on a board without a desktop), or
// written as one PNG per frame.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/base/atomic_file.h"
#include "core/base/json_reader.h"
#include "core/pipeline/project.h"
#include "core/sfm/model_io.h"
#include "core/io/image_write.h"
#include "core/mesh/glb_io.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/simplify.h"
#include "platform/camera/frame_source.h"
#include "platform/egl/egl_context.h"
#include "render/mesh_drawable.h"
#include "render/model_placement.h"
#include "render/overlay_renderer.h"
#include "tools/ar_args.h"
#include "tools/commands.h"
#include "tracker/tag_layout.h"
#include "tracker/tag_tracker.h"

namespace reconar::tools {
namespace {

constexpr char kHelp[] =
    "usage: reconar view --model MODEL (--camera DEVICE | --frames DIR|FILE.frames)\n"
    "                    --intrinsics K --tag-size METRES [options]\n"
    "       reconar view --project DIR (--camera DEVICE | --frames DIR|FILE.frames) [options]\n"
    "\n"
    "Tracks an AprilTag in the video and draws MODEL (.ply or .glb mesh or point cloud) standing on\n"
    "it. Without --out the overlay is shown live: in an X11 window when DISPLAY is set, otherwise\n"
    "full screen through DRM/KMS ('q' or Escape quits the window). With --out, one PNG per frame\n"
    "is written to DIR instead (headless, no display needed).\n"
    "  --model FILE          mesh or point cloud to show (.ply, .glb)\n"
    "  --project DIR         a project of `reconar reconstruct --tag-size`: its mesh (or dense, or\n"
    "                        sparse points) at true size, posed from all of its tags in view at once\n"
    "                        (tags.layout), with its tag size, family and camera (scaled to the frame\n"
    "                        size; --intrinsics overrides); the --model-* options do not apply\n"
    "  --camera DEVICE       /dev/videoN, libcamera or libcamera:N\n"
    "  --frames PATH         a folder of JPEG/PNG frames or a .frames recording\n"
    "  --out DIR             write DIR/<frame>.png instead of showing a window\n"
    "  --tag-id N            the tag the model stands on (default: the lowest id in view)\n"
    "Model placement on the tag (tag frame: x right, y up, z out of the tag, metres):\n"
    "  --model-height M      scale the model to this height (default: the tag size)\n"
    "  --model-scale S       or: a fixed scale from model units to metres (1 for metric models)\n"
    "  --model-up AXIS       the model's up axis: x, y, z, -x, -y or -z (default y)\n"
    "  --model-rotate DEG    turn the model about the tag's z axis\n"
    "  --model-offset X,Y,Z  move the model in the tag frame (metres)\n"
    "Display:\n"
    "  --no-axes             do not draw the tag's axes and outline\n"
    "  --point-size PX       point size for point clouds (default 3)\n"
    "  --samples N           multisample anti-aliasing (default 0: off)\n"
    "  --max-faces N         draw a mesh of more triangles simplified to N (default 500000; 0: all)\n"
    "  --smooth              draw at the tracker's smoothed pose (less jitter on a still camera, but\n"
    "                        it lags behind fast motion); default: each frame's measured pose\n"
    "  --window auto|x11|gbm (default auto)\n"
    "  --max-frames N        stop after N frames\n";

Result<Eigen::Vector3d> ParseAxis(const std::string& text) {
  const bool negative = !text.empty() && text[0] == '-';
  const std::string axis = negative ? text.substr(1) : text;
  Eigen::Vector3d v;
  if (axis == "x") {
    v = Eigen::Vector3d::UnitX();
  } else if (axis == "y") {
    v = Eigen::Vector3d::UnitY();
  } else if (axis == "z") {
    v = Eigen::Vector3d::UnitZ();
  } else {
    return InvalidArgument("--model-up: '" + text + "' is not one of x, y, z, -x, -y, -z");
  }
  return negative ? Eigen::Vector3d(-v) : v;
}

Result<Eigen::Vector3d> ParseVector(const std::string& name, const std::string& text) {
  Eigen::Vector3d v;
  char extra = 0;
  if (std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &v.x(), &v.y(), &v.z(), &extra) != 3 || !v.allFinite()) {
    return InvalidArgument("--" + name + ": '" + text + "' is not X,Y,Z");
  }
  return v;
}

Result<Mesh> ReadModel(const std::string& path) {
  const std::string extension = LowercaseExtension(path);
  if (extension == ".ply") return ReadPly(path);
  if (extension == ".glb") return ReadGlb(path);
  return InvalidArgument(path + ": unknown model format (expected .ply or .glb)");
}

Result<ModelPlacement> PlacementFromArgs(const Args& args, const Mesh& mesh, double tag_size) {
  auto up = ParseAxis(args.Get("model-up", "y"));
  if (!up.ok()) return up.status();
  ModelPlacement placement;
  if (args.Has("model-scale")) {
    auto scale = args.GetDouble("model-scale", 1.0, 1e-9, 1e9);
    if (!scale.ok()) return scale.status();
    placement.scale = *scale;
    placement.rotation = Eigen::Quaterniond::FromTwoVectors(*up, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  } else {
    auto height = args.GetDouble("model-height", tag_size, 1e-6, 1e6);
    if (!height.ok()) return height.status();
    auto standing = ModelPlacement::StandingOnTag(mesh, *height, *up);
    if (!standing.ok()) return standing.status();
    placement = *standing;
  }
  auto degrees = args.GetDouble("model-rotate", 0.0, -360.0, 360.0);
  if (!degrees.ok()) return degrees.status();
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(*degrees * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  placement.rotation = turn * placement.rotation;
  placement.offset = turn * placement.offset;
  if (args.Has("model-offset")) {
    auto offset = ParseVector("model-offset", args.Get("model-offset"));
    if (!offset.ok()) return offset.status();
    placement.offset += *offset;
  }
  return placement;
}

// What `--project DIR` brings: the model in metres in the world frame, where each tag sits in it,
// the tags' size and family, and the photos' camera.
struct ProjectScene {
  std::string model_path;
  TagLayout layout;  // world_from_tag of every registered tag (PROJECT/tags.layout)
  TrackerDefaults tracker;
};

Result<ProjectScene> LoadProjectScene(const std::string& dir) {
  const Project project(dir);
  ProjectScene scene;
  // The mesh, else the dense points, else the sparse points.
  for (const std::string& path : {project.MeshDir() + "/mesh.ply", project.DensePointsPath(), project.SparseDir() + "/points.ply"}) {
    scene.model_path = path;
    std::error_code error;
    if (std::filesystem::exists(path, error)) break;
  }
  RECONAR_ASSIGN_OR_RETURN(const JsonValue tags, ReadJsonFile(project.TagsJsonPath()));
  const JsonValue* metric = tags.Find("metric");
  if (metric == nullptr || !metric->is_bool() || !metric->bool_value()) {
    const JsonValue* reason = tags.Find("reason");
    return FailedPrecondition(project.TagsJsonPath() + ": the model is not in metres (" +
                              (reason != nullptr && reason->is_string() ? reason->string() : "no tag registered") +
                              "); show it with --model and --model-height");
  }
  const JsonValue* size = tags.Find("tag_size_m");
  const JsonValue* family = tags.Find("family");
  if (size == nullptr || !size->is_number() || family == nullptr || !family->is_string()) {
    return FileError(StatusCode::kCorruptData, project.TagsJsonPath(), "no tag_size_m or family");
  }
  scene.tracker.tag_size = size->number();
  scene.tracker.family = family->string();
  RECONAR_ASSIGN_OR_RETURN(scene.layout, ReadTagLayout(project.TagLayoutPath()));
  if (auto model = ReadColmapTextModel(project.SparseDir()); model.ok() && !model->cameras.empty()) {
    scene.tracker.intrinsics = model->cameras.front().Intrinsics();
  }
  return scene;
}

// The photo camera for video of another size with the same aspect ratio (a phone's video mode).
Result<CameraIntrinsics> ScaledTo(const CameraIntrinsics& photo, int width, int height) {
  if (photo.width == width && photo.height == height) return photo;
  if (photo.width <= 0 || std::abs(static_cast<double>(photo.width) * height - static_cast<double>(photo.height) * width) >
                              0.01 * photo.width * height) {
    return InvalidArgument("the project's photos are " + std::to_string(photo.width) + "x" + std::to_string(photo.height) +
                           ", the video " + std::to_string(width) + "x" + std::to_string(height) +
                           ": pass --intrinsics for this camera");
  }
  const double s = static_cast<double>(width) / photo.width;
  CameraIntrinsics scaled = photo;
  scaled.width = width;
  scaled.height = height;
  scaled.fx *= s;
  scaled.fy *= s;
  scaled.cx = (photo.cx + 0.5) * s - 0.5;  // pixel centres at integer coordinates
  scaled.cy = (photo.cy + 0.5) * s - 0.5;
  return scaled;
}

// The tag the model stands on this frame: --tag-id if measured, else the lowest id measured in this
// frame. A tag the tracker still follows but did not find in this frame has only a stale pose.
const TrackedTag* ChooseTag(const TagTrackerFrameReport& report, int wanted_id) {
  const TrackedTag* chosen = nullptr;
  for (const TrackedTag& tag : report.tags) {
    if (tag.state == TagTrackState::kLost || !tag.measured) continue;
    if (wanted_id >= 0 && tag.id != wanted_id) continue;
    if (chosen == nullptr || tag.id < chosen->id) chosen = &tag;
  }
  return chosen;
}

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

struct Latency {
  std::vector<double> track_ms, render_ms, frame_ms;
  static double Median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  }
};

}  // namespace

int RunView(int argc, char** argv, int first) {
  std::set<std::string> valued = kTrackerValuedOptions;
  valued.insert({"model", "project", "camera", "frames", "out", "tag-id", "model-height", "model-scale", "model-up",
                 "model-rotate", "model-offset", "point-size", "samples", "window", "max-frames", "max-faces"});
  Args args(valued, {"no-axes", "smooth"});
  if (Status s = args.Parse(argc, argv, first); !s.ok()) return Fail(s);
  if (args.Has("help")) {
    std::fputs(kHelp, stdout);
    std::fputs(kTrackerOptionsHelp, stdout);
    return 0;
  }
  if (!args.positionals().empty() || args.Has("model") == args.Has("project") || args.Has("camera") == args.Has("frames")) {
    std::fputs(kHelp, stderr);
    std::fputs(kTrackerOptionsHelp, stderr);
    return 2;
  }
  std::optional<ProjectScene> scene;
  if (args.Has("project")) {
    auto loaded = LoadProjectScene(args.Get("project"));
    if (!loaded.ok()) return Fail(loaded.status());
    scene = std::move(*loaded);
  }
  auto tracker_options = TrackerOptionsFromArgs(args, scene ? scene->tracker : TrackerDefaults());
  if (!tracker_options.ok()) return Fail(tracker_options.status());
  auto tag_id = args.GetInt("tag-id", -1, -1, 1 << 20);
  if (!tag_id.ok()) return Fail(tag_id.status());
  auto max_frames = args.GetInt("max-frames", 0, 0, 2000000000);
  if (!max_frames.ok()) return Fail(max_frames.status());
  auto samples = args.GetInt("samples", 0, 0, 16);
  if (!samples.ok()) return Fail(samples.status());
  auto point_size = args.GetDouble("point-size", 3.0, 0.5, 64.0);
  if (!point_size.ok()) return Fail(point_size.status());
  const bool to_files = args.Has("out");
  const std::string out_dir = args.Get("out");
  EglContextOptions egl_options;
  if (to_files) {
    egl_options.kind = EglContextKind::kSurfaceless;
  } else {
    const std::string window = args.Get("window", "auto");
    if (window == "auto") {
      egl_options.kind = EglContextKind::kAuto;
    } else if (window == "x11") {
      egl_options.kind = EglContextKind::kX11Window;
    } else if (window == "gbm") {
      egl_options.kind = EglContextKind::kGbm;
    } else {
      return Fail(InvalidArgument("--window: '" + window + "' is not auto, x11 or gbm"));
    }
  }

  const std::string model_path = scene ? scene->model_path : args.Get("model");
  auto mesh = ReadModel(model_path);
  if (!mesh.ok()) return Fail(mesh.status());
  auto max_faces = args.GetInt("max-faces", static_cast<int>(kHandheldMaxFaces), 0, 1 << 30);
  if (!max_faces.ok()) return Fail(max_faces.status());
  if (*max_faces > 0 && mesh->triangles.size() > static_cast<size_t>(*max_faces)) {
    SimplifyOptions simplify;
    simplify.target_faces = static_cast<size_t>(*max_faces);
    auto simplified = SimplifyMesh(simplify, &*mesh);
    if (!simplified.ok()) return Fail(simplified.status().WithContext(model_path));
    std::printf("%s: simplified from %zu to %zu faces for drawing (%.1fs; --max-faces)\n", model_path.c_str(),
                simplified->faces_before, simplified->faces_after, simplified->seconds);
  }
  Result<ModelPlacement> placement = ModelPlacement();
  if (!scene) placement = PlacementFromArgs(args, *mesh, tracker_options->tag_size);
  if (!placement.ok()) return Fail(placement.status());
  if (to_files) {
    if (Status s = CreateDirectories(out_dir); !s.ok()) return Fail(s);
  }

  FrameSourceOptions source_options;
  source_options.want_rgb = true;
  const std::string source_spec = args.Has("camera") ? args.Get("camera") : args.Get("frames");
  auto source = OpenFrameSource(source_spec, source_options);
  if (!source.ok()) return Fail(source.status());
  auto first_frame = (*source)->Next();
  if (!first_frame.ok()) {
    if (IsEndOfStream(first_frame.status())) return Fail(FailedPrecondition(source_spec + ": no frames"));
    return Fail(first_frame.status());
  }
  if (scene && !args.Has("intrinsics")) {
    auto scaled = ScaledTo(tracker_options->intrinsics, first_frame->width, first_frame->height);
    if (!scaled.ok()) {
      (*source)->Release(*first_frame);
      return Fail(scaled.status());
    }
    tracker_options->intrinsics = *scaled;
  }
  auto tracker = TagTracker::Create(*tracker_options);
  if (!tracker.ok()) {
    (*source)->Release(*first_frame);
    return Fail(tracker.status());
  }
  egl_options.width = first_frame->width;
  egl_options.height = first_frame->height;
  auto context = EglContext::Create(egl_options);
  if (!context.ok()) {
    (*source)->Release(*first_frame);
    Status status = context.status();
    if (!to_files) status = status.WithContext("no display for the live view (use --out DIR to write PNGs instead)");
    return Fail(status);
  }
  if (!to_files && !(*context)->has_surface()) {
    (*source)->Release(*first_frame);
    return Fail(FailedPrecondition(
        "no display for the live view: DISPLAY is not set and there is no DRM device under /dev/dri "
        "(use --out DIR to write PNGs instead)"));
  }
  OverlayRendererOptions render_options;
  render_options.width = first_frame->width;
  render_options.height = first_frame->height;
  render_options.samples = *samples;
  auto renderer = OverlayRenderer::Create(render_options);
  if (!renderer.ok()) return Fail(renderer.status());
  auto drawable = MeshDrawable::Upload(*mesh);
  if (!drawable.ok()) return Fail(drawable.status());
  MeshStyle style;
  style.point_size_px = static_cast<float>(*point_size);
  std::fprintf(stderr, "reconar view: %s; %s %s; model %s (%d vertices, %lld triangles)\n",
               (*source)->Describe().c_str(), EglContextKindName((*context)->kind()), (*context)->renderer().c_str(),
               model_path.c_str(), drawable->vertex_count(), static_cast<long long>(drawable->triangle_count()));

  const CameraIntrinsics& intrinsics = tracker_options->intrinsics;
  TagTrackerFrameReport report;
  TagDetectionList layout_detections(tracker_options->max_tags);
  Image<uint8_t> rgb;
  Latency latency;
  long frames = 0;
  long frames_with_model = 0;
  const bool stderr_is_terminal = ::isatty(STDERR_FILENO) != 0;
  Result<Frame> frame = std::move(first_frame);
  while (true) {
    if (!frame.ok()) {
      if (IsEndOfStream(frame.status())) break;
      return Fail(frame.status());
    }
    const auto frame_start = std::chrono::steady_clock::now();
    if (Status s = (*tracker)->Track(frame->gray, &report); !s.ok()) {
      (*source)->Release(*frame);
      return Fail(s.WithContext(std::string(frame->name)));
    }
    latency.track_ms.push_back(report.total_ms);
    const auto render_start = std::chrono::steady_clock::now();
    Status drawn = (*renderer)->BeginFrame();
    if (drawn.ok()) drawn = (*renderer)->DrawBackground(frame->rgb, 3);
    if (scene && drawn.ok()) {
      // The model is in the world frame: its pose from every project tag in view at once.
      layout_detections.Clear();
      for (const TrackedTag& t : report.tags) {
        if (t.measured) layout_detections.Add(t.detection);
      }
      if (auto board = EstimateBoardPose(scene->layout, layout_detections, intrinsics); board.ok()) {
        drawn = (*renderer)->DrawMesh(*drawable, intrinsics, board->cam_from_layout.Matrix(), style);
        for (const LayoutTag& t : scene->layout.tags()) {
          if (!drawn.ok() || args.Has("no-axes")) break;
          const bool seen = std::any_of(layout_detections.begin(), layout_detections.end(),
                                        [&](const TagDetection& d) { return d.id == t.id; });
          if (seen) drawn = (*renderer)->DrawTagAxes(intrinsics, board->cam_from_layout * t.layout_from_tag, t.size);
        }
        ++frames_with_model;
      }
    }
    const TrackedTag* tag = scene ? nullptr : ChooseTag(report, *tag_id);
    if (tag != nullptr && drawn.ok()) {
      const Rigid3& cam_from_tag = args.Has("smooth") ? tag->smoothed_cam_from_tag : tag->cam_from_tag;
      drawn = (*renderer)->DrawMesh(*drawable, intrinsics, CamFromModel(cam_from_tag, *placement), style);
      if (drawn.ok() && !args.Has("no-axes")) {
        drawn = (*renderer)->DrawTagAxes(intrinsics, cam_from_tag, tracker_options->tag_size);
      }
      ++frames_with_model;
    }
    if (drawn.ok()) {
      if (to_files) {
        drawn = (*renderer)->ReadRgb(&rgb);
      } else {
        drawn = (*renderer)->PresentToDefaultFramebuffer((*context)->width(), (*context)->height());
        if (drawn.ok()) drawn = (*context)->SwapBuffers();
      }
    }
    latency.render_ms.push_back(MsSince(render_start));
    latency.frame_ms.push_back(MsSince(frame_start));
    const std::string name = OutputName(*frame);
    (*source)->Release(*frame);
    if (!drawn.ok()) return Fail(drawn.WithContext(name));
    if (to_files) {
      const std::string path = out_dir + "/" + name;
      if (Status s = WritePng(path, rgb.view(), 3); !s.ok()) return Fail(s);
    }
    ++frames;
    if (!to_files && (*context)->PollEvents().should_quit()) break;
    if (*max_frames > 0 && frames >= *max_frames) break;
    if (stderr_is_terminal && frames % 10 == 0) std::fprintf(stderr, "\rreconar view: %ld frames", frames);
    frame = (*source)->Next();
  }
  std::fprintf(stderr,
               "%sreconar view: %ld frames, model drawn on %ld; median ms per frame: track %.2f, render %.2f, "
               "track + render %.2f%s\n",
               stderr_is_terminal ? "\r" : "", frames, frames_with_model, Latency::Median(latency.track_ms), Latency::Median(latency.render_ms),
               Latency::Median(latency.frame_ms), to_files ? " (render includes the readback)" : "");
  if (to_files) std::fprintf(stderr, "reconar view: wrote %ld PNGs to %s\n", frames, out_dir.c_str());
  return 0;
}

}  // namespace reconar::tools
