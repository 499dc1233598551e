// reconar track: AprilTag 6-DoF tracking over a camera or recorded frames, one line per frame; the
// runtime is render/ar/ar_session.h, this command parses, calls and prints.
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

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
    "\"cam_from_world\", \"map_inliers\", \"relocalised\" and \"fused_map_points\".\n"
    "Without --json, prints a short line per frame. A summary goes to stderr.\n"
    "  --layout FILE         multi-tag layout (tag_layout.h format): also prints the layout's pose\n"
    "                        (\"cam_from_layout\"), and searches the layout's tags not found yet where\n"
    "                        that pose puts them (\"predicted\": regions searched, tags found;\n"
    "                        \"predicted\": true on a tag found so); --max-tags is raised to the\n"
    "                        layout's tag count\n"
    "  --project DIR         a project of `reconar reconstruct --tag-size`: its tags, map, tag size,\n"
    "                        family and camera (scaled to the frame size; --intrinsics overrides)\n"
    "  --no-map              with --project: tags only\n"
    "  --max-frames N        stop after N frames\n"
    "  --json                JSON lines on stdout\n";

}  // namespace

int RunTrack(int argc, char** argv, int first) {
  std::set<std::string> valued = kTrackerValuedOptions;
  valued.insert({"layout", "project", "max-frames"});
  Args args(valued, {"json", "no-map"});
  if (Status s = args.Parse(argc, argv, first); !s.ok()) return Fail(s);
  if (args.Has("help")) {
    std::fputs(kHelp, stdout);
    std::fputs(kTrackerOptionsHelp, stdout);
    return 0;
  }
  if (args.positionals().size() != 1 || (args.Has("layout") && args.Has("project"))) {
    std::fputs(kHelp, stderr);
    std::fputs(kTrackerOptionsHelp, stderr);
    return 2;
  }
  ArSessionOptions options;
  options.source = args.positionals()[0];
  options.frames.want_rgb = false;
  TrackerDefaults defaults;
  auto project = ProjectFromArgs(args, &defaults);
  if (!project.ok()) return Fail(project.status());
  if (*project) {
    options.pose.layout = std::move((*project)->layout);
    options.map = std::move((*project)->map);
    options.scale_intrinsics_to_video = !args.Has("intrinsics");
  }
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
               options.map ? "; posed by the project's tags and map" : "");

  std::vector<double> frame_ms;
  long frames_with_tags = 0;
  long tag_instances = 0;
  long predicted_found = 0;
  long predicted_searched = 0;
  long frames_by_source[4] = {0, 0, 0, 0};
  for (;;) {
    auto more = (*session)->Step();
    if (!more.ok()) return Fail(more.status());
    if (!*more) break;
    int measured = 0;
    for (const TrackedTag& tag : (*session)->tags().report().tags) measured += tag.measured ? 1 : 0;
    frames_with_tags += measured > 0 ? 1 : 0;
    tag_instances += measured;
    predicted_found += (*session)->tags().report().predicted_found;
    predicted_searched += (*session)->tags().report().predicted_searched;
    ++frames_by_source[static_cast<int>((*session)->sources().source())];
    frame_ms.push_back((*session)->pose().track_ms);
    std::printf("%s\n", (json ? ArFrameJson(**session) : ArFrameText(**session)).c_str());
    std::fflush(stdout);
  }
  const long frames = (*session)->frames();
  std::vector<double> sorted = frame_ms;
  std::sort(sorted.begin(), sorted.end());
  double total = 0.0;
  for (double ms : frame_ms) total += ms;
  std::fprintf(stderr,
               "reconar track: %ld frames, tags in %ld (%ld tag instances); tracking %.2f ms/frame mean, %.2f "
               "median, %.2f max\n",
               frames, frames_with_tags, tag_instances, total / frames, sorted[sorted.size() / 2], sorted.back());
  if (!options.pose.layout.empty()) {
    std::fprintf(stderr, "reconar track: %ld of the tag instances found by prediction (%ld predicted regions)\n",
                 predicted_found, predicted_searched);
  }
  if (options.map) {
    std::fprintf(stderr, "reconar track: %s\n", PoseSourceCounts(frames_by_source).c_str());
  }
  return 0;
}

}  // namespace reconar::tools
