// reconar localize PROJECT IMAGE|DIR...: the pose of each photo against the project's localisation
// map.
#include <cstdint>
#include <cstdio>

#include "core/pipeline/localize_photos.h"
#include "core/pipeline/project.h"
#include "tools/ar_args.h"
#include "tools/args.h"
#include "tools/commands.h"

namespace reconar::tools {
namespace {

constexpr char kHelp[] =
    "usage: reconar localize PROJECT_DIR IMAGE|DIR... [--intrinsics K] "
    "[--json] [--threads N]\n"
    "\n"
    "Finds where each photo was taken, in the project's world frame (metres in "
    "the frame of the\n"
    "world tag when the project was registered by tags), from the project's "
    "localisation map\n"
    "(PROJECT_DIR/map/map.rmap; `reconar map` builds it). No tag needs to be "
    "visible.\n"
    "The camera: --intrinsics when given; else the project's own camera when "
    "the photo has the\n"
    "same aspect ratio (and an EXIF focal, if any, agrees with it); else the "
    "focal is estimated.\n"
    "A photo is registered only with at least 30 inlier matches making at "
    "least 25 % of its\n"
    "matches to the map; otherwise it is reported as not registered, with the "
    "reason.\n"
    "  --intrinsics K   fx,fy,cx,cy[,k1,k2] in pixels, or a file from `reconar "
    "calibrate`\n"
    "  --threads N      photos at a time (default: one per core)\n"
    "  --json           one JSON object per photo: {\"image\", \"registered\", "
    "\"cam_from_world\":\n"
    "                   {\"R\": [9, row-major], \"t\": [3]}, \"camera\": "
    "{...}, \"inliers\", \"matches\",\n"
    "                   \"features\", \"ms\", \"reason\"}\n"
    "exit code 0 when the run completed (whether or not photos registered).\n";

}  // namespace

int RunLocalize(int argc, char** argv, int first) {
  Args args({"intrinsics", "threads"}, {"json"});
  if (const auto exit_code = ParseCommand(&args, argc, argv, first, kHelp, 2, SIZE_MAX)) return *exit_code;
  LocalizePhotosOptions options;
  if (args.Has("intrinsics")) {
    auto intrinsics = IntrinsicsFromArg(args.Get("intrinsics"));
    if (!intrinsics.ok()) return Fail(intrinsics.status());
    options.intrinsics = *intrinsics;
  }
  auto threads = args.GetThreads();
  if (!threads.ok()) return Fail(threads.status());
  options.num_threads = *threads;
  const Project project(args.positionals()[0]);
  auto map = ReadLocalizationMap(project.MapPath());
  if (!map.ok()) return Fail(map.status());
  const std::vector<std::string> inputs(args.positionals().begin() + 1, args.positionals().end());
  auto paths = CollectImagePaths(inputs);
  if (!paths.ok()) return Fail(paths.status());
  auto photos = LocalizePhotos(*map, *paths, options);
  if (!photos.ok()) return Fail(photos.status());
  int registered = 0;
  for (const PhotoLocalization& photo : *photos) {
    registered += photo.result.registered ? 1 : 0;
    if (args.Has("json")) {
      std::printf("%s\n", PhotoLocalizationJson(photo).c_str());
    } else if (photo.result.registered) {
      const Eigen::Vector3d center = CameraCenterInWorld(photo.result.cam_from_world);
      std::printf(
          "%s: registered, centre %.4f %.4f %.4f, %d inliers of %d "
          "matches, %.0f ms\n",
          photo.image.c_str(), center.x(), center.y(), center.z(), photo.result.num_inliers, photo.result.num_matches,
          photo.seconds * 1000.0);
    } else {
      std::printf("%s: not registered: %s\n", photo.image.c_str(),
                  (photo.error.empty() ? photo.result.reason : photo.error).c_str());
    }
  }
  std::fprintf(stderr, "localize: %d of %zu photos registered against %s (%s)\n", registered, photos->size(),
               project.MapPath().c_str(), map->frame.c_str());
  return 0;
}

}  // namespace reconar::tools
