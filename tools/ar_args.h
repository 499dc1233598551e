#pragma once
// Command-line options shared by the AR subcommands (track, view, calibrate).
#include <optional>
#include <set>
#include <string>

#include "core/base/status.h"
#include "core/math/camera_intrinsics.h"
#include "render/ar/ar_project.h"
#include "tools/args.h"
#include "tracker/tag_tracker.h"

namespace reconar::tools {

// "fx,fy,cx,cy" or "fx,fy,cx,cy,k1,k2" (pixels, the centre of the top-left pixel at (0, 0)), or
// the path of an intrinsics file written by `reconar calibrate`.
Result<CameraIntrinsics> IntrinsicsFromArg(const std::string& value);

// Values to use where the command line gives none (`reconar view --project` reads them from the
// project); without them --intrinsics and --tag-size are required.
struct TrackerDefaults {
  std::optional<CameraIntrinsics> intrinsics;
  std::optional<double> tag_size;
  std::optional<std::string> family;
  bool track_tags = true;  // false (a project without tags): only the camera is read, no tag option
};

// --project DIR (with --no-map, without its map): the project, and in *defaults the camera, tag
// size and family it gives (without tags: track_tags false); nullopt without --project. Errors of
// LoadArProject.
Result<std::optional<ArProject>> ProjectFromArgs(const Args& args, TrackerDefaults* defaults);

// --intrinsics, --tag-size, --family, --decimate, --threads, --full-frame-interval, --max-tags;
// only --intrinsics when defaults.track_tags is false.
Result<TagTrackerOptions> TrackerOptionsFromArgs(const Args& args, const TrackerDefaults& defaults = {});
inline const std::set<std::string> kTrackerValuedOptions = {"intrinsics", "tag-size", "family", "decimate",
                                                              "threads", "full-frame-interval", "max-tags"};
inline constexpr char kTrackerOptionsHelp[] =
    "  --intrinsics K        fx,fy,cx,cy[,k1,k2] in pixels, or a file from `reconar calibrate`\n"
    "  --tag-size METRES     edge of the tag's black square (all tags)\n"
    "  --family F            tag family (default tag36h11)\n"
    "  --decimate D          quad decimation of full-frame searches (default 2; 1 finds smaller tags)\n"
    "  --full-frame-interval N   search the whole frame every N frames for new tags (default 10)\n"
    "  --max-tags N          tags followed at once (default 16)\n"
    "  --threads N           libapriltag threads (default 1)\n";

}  // namespace reconar::tools
