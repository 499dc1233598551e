#pragma once
// A walk forward down a corridor whose walls, floor, ceiling and end wall are papered with panels
// of "dead leaves" pictures (each panel a different one): rendered views with exact poses, for the forward-motion
// structure-from-motion test (the paper's corridor case). The camera looks down the corridor and
// sways, bobs and turns a little as a person walking does. Test support only.
#include <cstdint>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "tests/support/sfm_evaluation.h"

namespace reconar::testing {

// World frame: x to the right, y down, z down the corridor; the eye starts at the origin.
struct CorridorWalkOptions {
  int frames = 29;
  int width = 640;
  int height = 480;
  double focal_px = 520.0;
  double step_m = 0.4;               // forward, per frame
  double half_width_m = 2.0;         // walls at x = +-half_width_m
  double eye_above_floor_m = 1.6;    // floor at y = +eye_above_floor_m
  double ceiling_above_eye_m = 1.4;  // ceiling at y = -ceiling_above_eye_m
  double length_m = 24.0;            // end wall at z = length_m
  double panel_length_m = 4.0;       // one photo per panel this long
  int texture_width_px = 1024;       // each panel's picture is this wide and 3/4 as high
  double texture_contrast = 30.0;    // grey levels either side of a panel's wall colour
  uint32_t seed = 1;                 // of the panels' pictures
  int supersampling = 2;             // samples per pixel along each axis
};

// Renders the walk into `out_dir` as walk_NN.png and returns each view's true camera by file
// name. InvalidArgument for unusable options; the PNG writer's error for a file it cannot write.
Result<GroundTruthByName> RenderCorridorWalk(const std::string& out_dir, const CorridorWalkOptions& options = {});

// The capture tests' hand-held video: a slow walk of 90 frames 5 cm apart, rendered into `out_dir`
// (created).
struct CorridorVideo {
  CorridorWalkOptions walk;
  GroundTruthByName truth;
  std::vector<std::string> names;  // the frames' file names, in order
  double length_m() const { return walk.step_m * (walk.frames - 1); }
};
Result<CorridorVideo> RenderCorridorVideo(const std::string& out_dir);

}  // namespace reconar::testing
