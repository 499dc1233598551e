// reconar view: the AR overlay. A model drawn on a tracked AprilTag (or a project's tags) over live
// or recorded video, shown in a window or written as one PNG per frame; the runtime is
// render/ar/ar_view.h, this command parses, calls and prints.
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include "render/ar/ar_project.h"
#include "render/ar/ar_view.h"
#include "tools/ar_args.h"
#include "tools/ar_output.h"
#include "tools/commands.h"
#include "tools/view_measure.h"

namespace reconar::tools {
namespace {

constexpr char kHelp[] =
    "usage: reconar view --model MODEL (--camera DEVICE | --frames DIR|FILE.frames)\n"
    "                    --intrinsics K --tag-size METRES [options]\n"
    "       reconar view --project DIR (--camera DEVICE | --frames DIR|FILE.frames) [options]\n"
    "\n"
    "Tracks an AprilTag in the video and draws MODEL (.ply, .obj or .glb mesh or point cloud) standing on\n"
    "it. Without --out the overlay is shown live: in an X11 window when DISPLAY is set, otherwise\n"
    "full screen through DRM/KMS ('q' or Escape quits the window). With --out, one PNG per frame\n"
    "is written to DIR instead (headless, no display needed).\n"
    "  --model FILE          mesh or point cloud to show (.ply, .obj, .glb)\n"
    "  --project DIR         a project of `reconar reconstruct`: its mesh (or dense, or sparse points)\n"
    "                        where it was reconstructed, posed from its localisation map\n"
    "                        (map/map.rmap) and, with --tag-size, from all of its tags in view at once\n"
    "                        (tags.layout: metres, so the model stays in place with or without a tag\n"
    "                        in view); without tags the map alone poses the frames, in the model's\n"
    "                        own units; with the photos' camera (of the frame size, or scaled to it;\n"
    "                        --intrinsics overrides); the --model-* options do not apply\n"
    "  --no-map              with --project: pose from the tags only (a project with tags)\n"
    "  --json                one JSON line per frame on stdout, as `reconar track --json` prints\n"
    "                        (with --project: the pose's source and the map tracker's state)\n"
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
    "  --no-exposure-match   draw a textured model as its texture holds it (default: brought to each\n"
    "                        frame's exposure, from the model drawn small against the frame)\n"
    "  --point-size PX       point size for point clouds (default 3)\n"
    "  --samples N           multisample anti-aliasing (default 0: off)\n"
    "  --max-faces N         draw a mesh of more triangles simplified to N (default 500000; 0: all)\n"
    "  --smooth              draw at the tracker's smoothed pose (less jitter on a still camera, but\n"
    "                        it lags behind fast motion); default: each frame's measured pose\n"
    "  --window auto|x11|gbm (default auto)\n"
    "  --max-frames N        stop after N frames\n"
    "  --measure \"X1,Y1 X2,Y2\"  with --project: each frame, the distance +- sigma between the model's\n"
    "                        surface under these two pixels, drawn and in --json (in a window: click\n"
    "                        two points instead)\n"
    "As built against the design (after `reconar compare PROJECT DESIGN`):\n"
    "  --design DESIGN       with --project: the registered design (PROJECT/compare) drawn\n"
    "                        semi-transparent over the model, or over the as-built points coloured\n"
    "                        by their deviation (blue inside, white on, red outside the design)\n"
    "  --layer NAME          what is shown first: as-built, design (default with --design) or\n"
    "                        deviation; in a window space or 'l' steps through them. To see the\n"
    "                        design as a miniature on a tag instead, give it as --model with the\n"
    "                        placement options.\n";

Result<Eigen::Vector3d> ParseAxis(const std::string& text) {
  const bool negative = !text.empty() && text[0] == '-';
  const std::string axis = negative ? text.substr(1) : text;
  const int index = axis == "x" ? 0 : axis == "y" ? 1 : axis == "z" ? 2 : -1;
  if (index < 0) return InvalidArgument("--model-up: '" + text + "' is not one of x, y, z, -x, -y, -z");
  const Eigen::Vector3d v = Eigen::Vector3d::Unit(index);
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

Result<ModelPlacement> PlacementFromArgs(const Args& args, const Mesh& mesh, double tag_size) {
  RECONAR_ASSIGN_OR_RETURN(const Eigen::Vector3d up, ParseAxis(args.Get("model-up", "y")));
  ModelPlacement placement;
  if (args.Has("model-scale")) {
    RECONAR_ASSIGN_OR_RETURN(const double scale, args.GetDouble("model-scale", 1.0, 1e-9, 1e9));
    placement = ModelPlacement::Scaled(scale, up);
  } else {
    RECONAR_ASSIGN_OR_RETURN(const double height, args.GetDouble("model-height", tag_size, 1e-6, 1e6));
    RECONAR_ASSIGN_OR_RETURN(placement, ModelPlacement::StandingOnTag(mesh, height, up));
  }
  RECONAR_ASSIGN_OR_RETURN(const double degrees, args.GetDouble("model-rotate", 0.0, -360.0, 360.0));
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  if (args.Has("model-offset")) {
    RECONAR_ASSIGN_OR_RETURN(offset, ParseVector("model-offset", args.Get("model-offset")));
  }
  return placement.Turned(degrees, offset);
}

}  // namespace

int RunView(int argc, char** argv, int first) {
  std::set<std::string> valued = kTrackerValuedOptions;
  valued.insert({"model", "project", "camera", "frames", "out", "tag-id", "model-height", "model-scale", "model-up",
                 "model-rotate", "model-offset", "point-size", "samples", "window", "max-frames", "max-faces", "measure",
                 "design", "layer"});
  Args args(valued, {"no-axes", "no-exposure-match", "smooth", "no-map", "json"});
  // A model or a project, and a camera or frames: one of each.
  const CommandUsage usage = {0, 0, {}, [](const Args& a) {
                                return a.Has("model") != a.Has("project") && a.Has("camera") != a.Has("frames");
                              }};
  const std::string help = std::string(kHelp) + kTrackerOptionsHelp;
  if (const auto exit_code = ParseCommand(&args, argc, argv, first, help, usage)) return *exit_code;
  TrackerDefaults defaults;
  auto loaded = ProjectFromArgs(args, &defaults);
  if (!loaded.ok()) return Fail(loaded.status());
  const std::optional<ArProject>& project = *loaded;
  ArViewOptions options;
  ArSessionOptions& session = options.session;
  auto tracker_options = TrackerOptionsFromArgs(args, defaults);
  if (!tracker_options.ok()) return Fail(tracker_options.status());
  session.pose.tracker = *tracker_options;
  if (project) UseArProject(*project, args.Has("intrinsics"), &session);
  session.pose.smoothed = args.Has("smooth");
  session.source = args.Has("camera") ? args.Get("camera") : args.Get("frames");
  auto tag_id = args.GetInt("tag-id", -1, -1, 1 << 20);
  if (!tag_id.ok()) return Fail(tag_id.status());
  session.pose.tag_id = *tag_id;
  auto max_frames = args.GetInt("max-frames", 0, 0, 2000000000);
  if (!max_frames.ok()) return Fail(max_frames.status());
  session.max_frames = *max_frames;
  auto samples = args.GetInt("samples", 0, 0, 16);
  if (!samples.ok()) return Fail(samples.status());
  options.samples = *samples;
  auto point_size = args.GetDouble("point-size", 3.0, 0.5, 64.0);
  if (!point_size.ok()) return Fail(point_size.status());
  options.style.point_size_px = static_cast<float>(*point_size);
  options.draw_axes = !args.Has("no-axes");
  options.match_exposure = !args.Has("no-exposure-match");
  if (Status measure = ReadMeasureArgs(args, &options); !measure.ok()) return Fail(measure);
  options.out_dir = args.Get("out");
  const bool to_files = args.Has("out");
  if (!to_files) {
    auto window = OnScreenKindFromName(args.Get("window", "auto"));
    if (!window.ok()) return Fail(window.status());
    options.window = *window;
  }

  const std::string model_path = project ? project->model_path : args.Get("model");
  auto max_faces = args.GetInt("max-faces", static_cast<int>(kHandheldMaxFaces), 0, 1 << 30);
  if (!max_faces.ok()) return Fail(max_faces.status());
  auto model = LoadArModel(model_path, static_cast<size_t>(*max_faces));
  if (!model.ok()) return Fail(model.status());
  if (const auto& simplified = model->simplified) {
    // On stderr with --json: stdout holds only the frames' JSON lines.
    std::fprintf(args.Has("json") ? stderr : stdout, "%s: simplified from %zu to %zu faces for drawing (%.1fs; --max-faces)\n", model_path.c_str(),
                simplified->faces_before, simplified->faces_after, simplified->seconds);
  }
  if (!project) {
    auto placement = PlacementFromArgs(args, model->mesh, tracker_options->tag_size);
    if (!placement.ok()) return Fail(placement.status());
    options.placement = *placement;
  }
  std::optional<ArDesign> design;
  if (args.Has("design")) {
    if (!project) return Fail(InvalidArgument("--design needs --project (the project `reconar compare` compared)"));
    auto loaded_design = LoadArDesign(args.Get("project"), args.Get("design"));
    if (!loaded_design.ok()) return Fail(loaded_design.status());
    design = std::move(*loaded_design);
    options.layer = ArLayer::kDesign;
  }
  if (args.Has("layer")) {
    const std::string layer = args.Get("layer");
    if (layer == "as-built") {
      options.layer = ArLayer::kAsBuilt;
    } else if (layer == "design" || layer == "deviation") {
      if (!design) return Fail(InvalidArgument("--layer " + layer + " needs --design"));
      options.layer = layer == "design" ? ArLayer::kDesign : ArLayer::kDeviation;
    } else {
      return Fail(InvalidArgument("--layer: '" + layer + "' is not as-built, design or deviation"));
    }
  }
  auto view = ArView::Open(options, *model, design ? &*design : nullptr);
  if (!view.ok()) return Fail(view.status());
  std::fprintf(stderr, "reconar view: %s\n", (*view)->Describe(model_path).c_str());
  if (project && !project->has_tags) {
    std::fprintf(stderr, "reconar view: %s; the model is drawn where it was reconstructed\n",
                 project->no_tags_note.c_str());
  }
  const bool stderr_is_terminal = ::isatty(STDERR_FILENO) != 0;
  const bool json = args.Has("json");
  auto report = (*view)->Run([&](const ArSession& frame) {
    if (json) {
      std::printf("%s\n", WithMeasurement(ArFrameJson(frame), (*view)->measurement()).c_str());
      std::fflush(stdout);
    }
    if (stderr_is_terminal && frame.frames() % 10 == 0) {
      std::fprintf(stderr, "\rreconar view: %ld frames", frame.frames());
    }
  });
  if (!report.ok()) return Fail(report.status());
  std::fprintf(stderr,
               "%sreconar view: %ld frames, model drawn on %ld; median ms per frame: track %.2f, render %.2f, "
               "track + render %.2f%s\n",
               stderr_is_terminal ? "\r" : "", report->session.frames, report->frames_with_model,
               report->session.median_track_ms, report->median_render_ms, report->median_frame_ms,
               to_files ? " (render includes the readback)" : "");
  if ((*view)->exposure_gain() != std::array<float, 3>{1.0f, 1.0f, 1.0f}) {
    std::fprintf(stderr, "reconar view: the texture brought to the video's exposure, last gain %.2f %.2f %.2f\n",
                 report->exposure_gain[0], report->exposure_gain[1], report->exposure_gain[2]);
  }
  if (session.map) {
    std::fprintf(stderr, "reconar view: %s%s\n", PoseSourceSummary(report->session.frames_by_source).c_str(),
                 session.map->metric ? "" : "; poses in model units");
  }
  if (to_files) {
    std::fprintf(stderr, "reconar view: wrote %ld PNGs to %s\n", report->session.frames, options.out_dir.c_str());
  }
  return 0;
}

}  // namespace reconar::tools
