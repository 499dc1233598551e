// reconar track: AprilTag 6-DoF tracking over a camera or recorded frames, one line per frame; the
// runtime is render/ar/ar_session.h, this command parses, calls and prints.
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "core/base/json_writer.h"
#include "render/ar/ar_session.h"
#include "tools/ar_args.h"
#include "tools/commands.h"

namespace reconar::tools {
namespace {

constexpr char kHelp[] =
    "usage: reconar track SOURCE --intrinsics K --tag-size METRES [options]\n"
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
    "Without --json, prints a short line per frame. A summary goes to stderr.\n"
    "  --layout FILE         multi-tag layout (tag_layout.h format): also prints the layout's pose\n"
    "                        (\"cam_from_layout\"), and searches the layout's tags not found yet where\n"
    "                        that pose puts them (\"predicted\": regions searched, tags found;\n"
    "                        \"predicted\": true on a tag found so); --max-tags is raised to the\n"
    "                        layout's tag count\n"
    "  --max-frames N        stop after N frames\n"
    "  --json                JSON lines on stdout\n";

void WritePose(JsonWriter& json, const Rigid3& pose) {
  json.BeginObject().Key("R").BeginArray();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) json.Double(pose.rotation(r, c));
  }
  json.EndArray().Key("t").BeginArray();
  for (int i = 0; i < 3; ++i) json.Double(pose.translation(i));
  json.EndArray().EndObject();
}

std::string FrameJson(const Frame& frame, const TagTrackerFrameReport& report, bool with_layout,
                      const BoardPose* board) {
  JsonWriter json;
  json.BeginObject().Key("frame").String(std::string(frame.name)).Key("tags").BeginArray();
  for (const TrackedTag& tag : report.tags) {
    if (!tag.measured) continue;
    json.BeginObject().Key("id").Int(tag.id).Key("corners").BeginArray();
    for (const Eigen::Vector2d& corner : tag.detection.corners) {
      json.BeginArray().Double(corner.x()).Double(corner.y()).EndArray();
    }
    json.EndArray().Key("cam_from_tag");
    WritePose(json, tag.cam_from_tag);
    json.Key("rms_px").Double(tag.pose.rms_reprojection_px).Key("reacquired").Bool(tag.reacquired);
    if (with_layout) json.Key("predicted").Bool(tag.found_by_prediction);
    json.EndObject();
  }
  json.EndArray();
  if (board != nullptr) {
    json.Key("cam_from_layout");
    WritePose(json, board->cam_from_layout);
    json.Key("layout_tags").Int(board->tags_used).Key("layout_rms_px").Double(board->rms_reprojection_px);
  }
  if (with_layout) {
    json.Key("predicted").BeginObject().Key("searched").Int(report.predicted_searched);
    json.Key("found").Int(report.predicted_found).EndObject();
  }
  json.Key("search").String(SearchName(report.search)).Key("ms").Double(report.total_ms).EndObject();
  return json.str();
}

}  // namespace

int RunTrack(int argc, char** argv, int first) {
  std::set<std::string> valued = kTrackerValuedOptions;
  valued.insert({"layout", "max-frames"});
  Args args(valued, {"json"});
  if (Status s = args.Parse(argc, argv, first); !s.ok()) return Fail(s);
  if (args.Has("help")) {
    std::fputs(kHelp, stdout);
    std::fputs(kTrackerOptionsHelp, stdout);
    return 0;
  }
  if (args.positionals().size() != 1) {
    std::fputs(kHelp, stderr);
    std::fputs(kTrackerOptionsHelp, stderr);
    return 2;
  }
  ArSessionOptions options;
  options.source = args.positionals()[0];
  options.frames.want_rgb = false;
  auto tracker_options = TrackerOptionsFromArgs(args);
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
  std::fprintf(stderr, "reconar track: %s\n", (*session)->Describe().c_str());

  std::vector<double> frame_ms;
  long frames_with_tags = 0;
  long instances = 0;
  long predicted_found = 0;
  long predicted_searched = 0;
  const bool with_layout = !options.pose.layout.empty();
  for (;;) {
    auto more = (*session)->Step();
    if (!more.ok()) return Fail(more.status());
    if (!*more) break;
    const Frame& frame = (*session)->frame();
    const TagTrackerFrameReport& report = (*session)->tags().report();
    int measured = 0;
    for (const TrackedTag& tag : report.tags) measured += tag.measured ? 1 : 0;
    frames_with_tags += measured > 0 ? 1 : 0;
    instances += measured;
    predicted_found += report.predicted_found;
    predicted_searched += report.predicted_searched;
    frame_ms.push_back(report.total_ms);
    if (json) {
      std::printf("%s\n", FrameJson(frame, report, with_layout, (*session)->tags().board()).c_str());
    } else {
      std::printf("%.*s: %d tag(s)", static_cast<int>(frame.name.size()), frame.name.data(), measured);
      for (const TrackedTag& tag : report.tags) {
        if (!tag.measured) continue;
        const Eigen::Vector3d& t = tag.cam_from_tag.translation;
        std::printf("  id %d at (%.3f, %.3f, %.3f) m, %.2f px", tag.id, t.x(), t.y(), t.z(),
                    tag.pose.rms_reprojection_px);
      }
      if (report.predicted_searched > 0) {
        std::printf("  [%s + %d predicted (%d found), %.2f ms]\n", SearchName(report.search), report.predicted_searched,
                    report.predicted_found, report.total_ms);
      } else {
        std::printf("  [%s, %.2f ms]\n", SearchName(report.search), report.total_ms);
      }
    }
    std::fflush(stdout);
  }
  const long frames = (*session)->frames();
  std::vector<double> sorted = frame_ms;
  std::sort(sorted.begin(), sorted.end());
  double total = 0.0;
  for (double ms : frame_ms) total += ms;
  std::fprintf(stderr, "reconar track: %ld frames, tags in %ld; tracking %.2f ms/frame mean, %.2f median, %.2f max\n",
               frames, frames_with_tags, total / frames, sorted[sorted.size() / 2], sorted.back());
  if (with_layout) {
    std::fprintf(stderr, "reconar track: %ld tag instances, %ld of them found by prediction (%ld predicted regions)\n",
                 instances, predicted_found, predicted_searched);
  }
  return 0;
}

}  // namespace reconar::tools
