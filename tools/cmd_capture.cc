// reconar capture SOURCE PROJECT_DIR: keyframes from a live camera (or a folder, or a recording)
// through the keyframe gate into PROJECT_DIR/images, with a status line each second of video and
// advice for the person holding the camera (render/ar/capture_session.h).
#include <atomic>
#include <csignal>
#include <cstdio>
#include <memory>
#include <string>

#include "render/ar/capture_session.h"
#ifdef RECONAR_HAVE_VIEW
#include "render/ar/capture_window.h"
#endif
#include "tools/ar_args.h"
#include "tools/args.h"
#include "tools/commands.h"
#include "tools/reconstruct_command.h"

namespace reconar::tools {
namespace {

constexpr char kHelp[] =
    "usage: reconar capture SOURCE PROJECT_DIR [options]\n"
    "\n"
    "Watches the video of SOURCE and keeps the frames that serve a reconstruction: sharp, well\n"
    "exposed, and either with enough parallax since the last keyframe or about to lose sight of\n"
    "it (docs/capture.md gives the rules). Each keyframe is written as\n"
    "PROJECT_DIR/images/keyframe_NNNNN.jpg with EXIF, atomically. A status line each second of\n"
    "video says what to do (\"too fast\", \"too dark\", \"move sideways\", \"go back: lost\").\n"
    "Stop with Ctrl-C, or q or Escape in the window (the keyframes taken stay). Re-running on a\n"
    "folder or a recording replays it and keeps the keyframes already written; on a camera it adds\n"
    "to them.\n"
    "SOURCE: /dev/videoN, libcamera[:N], a folder of images, or a .frames recording.\n"
    "  --intrinsics K        fx,fy,cx,cy[,k1,k2] or a file from `reconar calibrate`: the focal goes\n"
    "                        into each keyframe's EXIF (a 35 mm equivalent)\n"
    "  --max-keyframes N     stop after N keyframes (default: until the source ends or Ctrl-C)\n"
    "  --width W --height H  camera capture size (default 640x480)\n"
    "  --no-live             do not grow the sparse model in the background (by default each\n"
    "                        keyframe's features and matches are computed as it is taken and it is\n"
    "                        registered into PROJECT_DIR/live/; `reconstruct` reuses that work)\n"
    "  --worker-threads N    threads matching each keyframe for the live model (default 0: one\n"
    "                        per core but the one the capture keeps; the model is the same)\n"
    "  --realtime            replay a folder or recording at the pace of its timestamps\n"
    "  --out-preview DIR     the view with the gate's verdict (border: green keyframe, blue keep\n"
    "                        moving, red refused), the keyframes (green once registered) and the\n"
    "                        coverage ring (directions the object has been seen from) and the\n"
    "                        tags in view (--tag-family, tag36h11 by default), as\n"
    "                        DIR/preview_FFFFFF.png each keyframe and second, and DIR/latest.png\n"
    "  --window auto|x11|gbm|none  the same view live, every frame: auto (default) an X11 window\n"
    "                        when DISPLAY is set, else none; gbm full screen through DRM/KMS\n"
    "  --reconstruct         then run `reconar reconstruct PROJECT_DIR/images PROJECT_DIR`\n"
    "  --tag-size M --tag-family F  passed on to `reconstruct` (metres, tag36h11 by default)\n"
    "  --json                one JSON object per event on stdout (status, keyframe, warning, end)\n";

std::atomic<bool> g_stop{false};
void OnInterrupt(int) { g_stop.store(true); }

void PrintEvent(const CaptureEvent& event, bool json) {
  const GateFrameReport& g = event.gate;
  if (json) {
    std::printf("%s\n", CaptureEventJson(event).c_str());
    std::fflush(stdout);
    return;
  }
  if (event.kind == CaptureEvent::Kind::kWarning) {
    std::fprintf(stderr, "warning: %s\n", event.message.c_str());
  } else if (event.kind == CaptureEvent::Kind::kRegistered) {
    std::fprintf(stderr, "           registered: %s (%d in the live model)\n", event.path.c_str(), event.registered);
  } else if (event.kind == CaptureEvent::Kind::kKeyframe) {
    std::fprintf(stderr, "%7.1f s  keyframe %d: %s%s\n", event.video_seconds, event.keyframes, event.path.c_str(),
                 event.kept ? " (already there)" : "");
  } else {
    char map[48] = "";
    if (event.map_version > 0) {
      std::snprintf(map, sizeof(map), "  model: %s",
                    event.map_pose_found ? "posed" : MapTrackingStateName(event.map_state));
    }
    std::fprintf(stderr, "%7.1f s  %d keyframes, %d registered%s  %-14s  parallax %4.1f %%  overlap %3.0f %%  %s\n",
                 event.video_seconds, event.keyframes, event.registered, map, GateVerdictName(g.verdict),
                 100.0 * g.parallax, 100.0 * g.overlap, g.advice);
  }
}

}  // namespace

int RunCapture(int argc, char** argv, int first) {
  Args args({"intrinsics", "max-keyframes", "width", "height", "tag-size", "tag-family", "out-preview", "window",
             "worker-threads"},
            {"json", "reconstruct", "no-live", "realtime"});
  if (const auto exit_code = ParseCommand(&args, argc, argv, first, kHelp, 2, 2)) return *exit_code;
  CaptureOptions options;
  options.source = args.positionals()[0];
  options.project_dir = args.positionals()[1];
  auto max_keyframes = args.GetInt("max-keyframes", 0, 0, 1 << 20);
  if (!max_keyframes.ok()) return Fail(max_keyframes.status());
  options.max_keyframes = *max_keyframes;
  auto width = args.GetInt("width", options.source_options.width, 0, 1 << 15);
  auto height = args.GetInt("height", options.source_options.height, 0, 1 << 15);
  if (!width.ok()) return Fail(width.status());
  if (!height.ok()) return Fail(height.status());
  options.source_options.width = *width;
  options.source_options.height = *height;
  if (args.Has("intrinsics")) {
    auto intrinsics = IntrinsicsFromArg(args.Get("intrinsics"));
    if (!intrinsics.ok()) return Fail(intrinsics.status());
    options.focal_px = intrinsics->fx;
  }
  auto worker_threads = args.GetInt("worker-threads", options.live.worker_threads, 0, 256);
  if (!worker_threads.ok()) return Fail(worker_threads.status());
  options.live.worker_threads = *worker_threads;
  options.reconstruct_live = !args.Has("no-live");
  options.replay_in_real_time = args.Has("realtime");
  if (args.Has("out-preview")) options.preview_dir = args.Get("out-preview");
  if (args.Has("tag-family")) options.preview_tag_family = args.Get("tag-family");
  const bool json = args.Has("json");
  const std::string window_name = args.Get("window", "auto");
#ifdef RECONAR_HAVE_VIEW
  auto window = CaptureWindow::OpenByName(window_name, options.source_options.width, options.source_options.height,
                                          "reconar capture: " + options.project_dir);
  if (!window.ok()) return Fail(window.status());
  if (*window) {
    std::fprintf(stderr, "reconar capture: showing the view in %s\n", (*window)->Describe().c_str());
    options.show_preview = [&window](const Image<uint8_t>& rgb) { return (*window)->Show(rgb); };
  }
#else
  if (window_name != "auto" && window_name != "none") {
    return Fail(Unsupported("--window: this build has no display support (RECONAR_WITH_GLES=OFF)"));
  }
#endif
  std::signal(SIGINT, OnInterrupt);
  auto report = reconar::RunCapture(
      options, [json](const CaptureEvent& event) { PrintEvent(event, json); }, &g_stop);
  std::signal(SIGINT, SIG_DFL);
  if (!report.ok()) return Fail(report.status());
  if (json) {
    std::printf("%s\n", CaptureReportJson(*report).c_str());
  } else {
    std::printf(
        "%s: %d frames, %d keyframes in %s/images (%d already there); passed over: %d blurred, %d badly exposed, "
        "%d too close, %d lost, %d corrupt; gate %.2f ms per frame (median); %s\n",
        report->source.c_str(), report->frames, report->keyframes, options.project_dir.c_str(), report->keyframes_kept,
        report->blurred, report->bad_exposure, report->too_close, report->lost, report->corrupt, report->median_gate_ms,
        report->stop_reason.c_str());
    if (report->live) {
      const LiveReconstructionReport& live = report->live_model;
      std::printf(
          "live model: %d of %zu keyframes registered, %d points, in %s/live; keyframe to registration %.1f s "
          "(median), %.1f s (95th percentile)\n",
          live.registered, live.keyframes.size(), live.points, options.project_dir.c_str(), live.median_latency_seconds,
          live.p95_latency_seconds);
      if (report->maps_used > 0) {
        std::printf(
            "followed against the live model: %d of %d frames posed, %d maps (built in %.1f s), %.1f ms per frame "
            "(median); baseline from the poses for %d frames\n",
            report->frames_map_posed, report->frames, report->maps_used, live.seconds_maps, report->median_map_track_ms,
            report->frames_map_motion);
      }
    }
  }
  if (report->source_failed || report->window_failed) {
    std::fprintf(stderr, "reconar: error: %s (the %d keyframes taken are kept)\n", report->stop_reason.c_str(),
                 report->keyframes);
    return 1;
  }
  if (!args.Has("reconstruct")) return 0;
  // `reconar reconstruct PROJECT_DIR/images PROJECT_DIR` with the capture's --tag-size and --tag-family.
  auto reconstruct = ReconstructOptionsFromArgs(args);
  if (!reconstruct.ok()) return Fail(reconstruct.status());
  auto paths = CollectImagePaths({options.project_dir + "/images"});
  if (!paths.ok()) return Fail(paths.status());
  return ReconstructAndPrint(*paths, Project(options.project_dir), *reconstruct, /*json=*/false);
}

}  // namespace reconar::tools
