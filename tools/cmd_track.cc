// reconar track: AprilTag 6-DoF tracking over a camera or recorded frames, one line per frame; the
// runtime is render/ar/ar_session.h, this command parses, calls and prints.
#include <cstdio>
#include <string>

#include "render/ar/ar_project.h"
#include "render/ar/ar_session.h"
#include "tools/ar_args.h"
#include "tools/ar_output.h"
#include "tools/commands.h"

namespace reconar::tools {
namespace {

constexpr char kHelp[] =
    "usage: reconar track SOURCE --intrinsics K --tag-size METRES [options]\n"
    "       reconar track SOURCE --project DIR [options]\n"
    "\n"
    "Tracks AprilTags in 6-DoF. SOURCE is a camera (/dev/videoN, libcamera[:N]), a folder of\n"
    "JPEG/PNG frames, or a recording (.frames). Each frame's tags are searched first where the\n"
    "previous poses predict them, then in the whole frame when that fails.\n"
    "With --json, prints one JSON object per frame on stdout:\n"
    "  {\"frame\": NAME, \"tags\": [{\"id\": N, \"corners\": [[x,y] x4], \"cam_from_tag\":\n"
    "   {\"R\": [9, row-major], \"t\": [3]}, \"rms_px\": E}], \"ms\": T}\n"
    "Corners are in libapriltag's order, in the pixel convention of --intrinsics (centre of the\n"
    "top-left pixel at (0, 0)). The tag frame has its origin at the tag centre, x right, y up and\n"
    "z out of the tag toward the viewer; t is in metres. \"ms\" is the tracking time of the frame.\n"
    "With --project, the frames are posed in the project's world frame from its tags (tags.layout)\n"
    "and its localisation map (map/map.rmap) together; each JSON line also has \"source\" (tags,\n"
    "map, tags+map or none), \"state\" (the map tracker's: tracking, relocalising or lost),\n"
    "\"cam_from_world\", \"map_inliers\", \"relocalised\", \"fused_map_points\" and \"metric\" /\n"
    "\"units\" (true / \"metres\"; false / \"model\" for a project without tags: its map alone poses\n"
    "the frames, in the model's own frame and arbitrary units).\n"
    "Without --json, prints a short line per frame. A summary goes to stderr.\n"
    "  --layout FILE         multi-tag layout (tag_layout.h format): also prints the layout's pose\n"
    "                        (\"cam_from_layout\"), and searches the layout's tags not found yet where\n"
    "                        that pose puts them (\"predicted\": regions searched, tags found;\n"
    "                        \"predicted\": true on a tag found so); --max-tags is raised to the\n"
    "                        layout's tag count\n"
    "  --project DIR         a project of `reconar reconstruct`: its map and camera (the photos' of\n"
    "                        the frame size, or scaled to it; --intrinsics overrides), and with\n"
    "                        --tag-size its tags, tag size and family\n"
    "  --no-map              with --project: tags only (a project with tags)\n"
    "  --max-frames N        stop after N frames\n"
    "  --json                JSON lines on stdout\n";

}  // namespace

int RunTrack(int argc, char** argv, int first) {
  std::set<std::string> valued = kTrackerValuedOptions;
  valued.insert({"layout", "project", "max-frames"});
  Args args(valued, {"json", "no-map"});
  const CommandUsage usage = {1, 1, {}, [](const Args& a) { return !(a.Has("layout") && a.Has("project")); }};
  const std::string help = std::string(kHelp) + kTrackerOptionsHelp;
  if (const auto exit_code = ParseCommand(&args, argc, argv, first, help, usage)) return *exit_code;
  ArSessionOptions options;
  options.source = args.positionals()[0];
  options.frames.want_rgb = false;
  TrackerDefaults defaults;
  auto project = ProjectFromArgs(args, &defaults);
  if (!project.ok()) return Fail(project.status());
  if (*project) UseArProject(**project, args.Has("intrinsics"), &options);
  auto tracker_options = TrackerOptionsFromArgs(args, defaults);
  if (!tracker_options.ok()) return Fail(tracker_options.status());
  options.pose.tracker = *tracker_options;
  auto max_frames = args.GetInt("max-frames", 0, 0, 2000000000);
  if (!max_frames.ok()) return Fail(max_frames.status());
  options.max_frames = *max_frames;
  if (args.Has("layout")) {
    auto layout = ReadTagLayout(args.Get("layout"));
    if (!layout.ok()) return Fail(layout.status());
    options.pose.layout = std::move(*layout);
  }
  const bool json = args.Has("json");
  auto session = ArSession::Open(options);
  if (!session.ok()) return Fail(session.status());
  std::fprintf(stderr, "reconar track: %s%s\n", (*session)->Describe().c_str(),
               !options.map ? "" : options.track_tags ? "; posed by the project's tags and map" : "; posed by the project's map");
  if (*project && !(*project)->has_tags) {
    std::fprintf(stderr, "reconar track: %s\n", (*project)->no_tags_note.c_str());
  }

  auto report = (*session)->Run([json](const ArSession& frame) -> Result<bool> {
    std::printf("%s\n", (json ? ArFrameJson(frame) : ArFrameText(frame)).c_str());
    std::fflush(stdout);
    return true;
  });
  if (!report.ok()) return Fail(report.status());
  const ArSessionReport& r = *report;
  std::string tags_seen = options.track_tags ? ", tags in " + std::to_string(r.frames_with_tags) + " (" +
                                                   std::to_string(r.tag_instances) + " tag instances)"
                                             : "";
  std::fprintf(stderr, "reconar track: %ld frames%s; tracking %.2f ms/frame mean, %.2f median, %.2f max\n", r.frames,
               tags_seen.c_str(), r.mean_track_ms, r.median_track_ms, r.max_track_ms);
  if (options.track_tags && !options.pose.layout.empty()) {
    std::fprintf(stderr, "reconar track: %ld of the tag instances found by prediction (%ld predicted regions)\n",
                 r.predicted_found, r.predicted_searched);
  }
  if (options.map) {
    std::fprintf(stderr, "reconar track: %s%s\n", PoseSourceSummary(r.frames_by_source).c_str(),
                 (*session)->metric() ? "" : "; poses in model units");
  }
  return 0;
}

}  // namespace reconar::tools
