#pragma once
// What the AR commands (track, view) print for a frame: one JSON line, or a short text line.
#include <string>

#include "render/ar/ar_session.h"

namespace reconar::tools {

// {"frame": NAME, "tags": [{"id", "corners", "cam_from_tag", "rms_px", "reacquired"[, "predicted"]}...],
//  ["cam_from_layout", "layout_tags", "layout_rms_px" when the layout was posed,]
//  ["predicted": {"searched", "found"} with a layout,]
//  ["source", "state", "cam_from_world", "map_inliers", "relocalised", "fused_map_points",
//   "metric", "units" ("metres", or "model": a project without tags) with a map,]
//  "search": S, "ms": T}
std::string ArFrameJson(const ArSession& session);
// "NAME: N tag(s)  id .. at (x, y, z) m, e px ...  [map: STATE, N inliers; pose: SOURCE[, model units]]
//  [SEARCH + N predicted (M found), T ms]"
std::string ArFrameText(const ArSession& session);
// "posed by tags+map A, tags B, map C; not posed D": every kind that poses, in PoseSourceKind's order.
std::string PoseSourceSummary(const PoseSourceCounts& frames_by_source);

}  // namespace reconar::tools
