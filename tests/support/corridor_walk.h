#pragma once
// A walk forward down a corridor whose walls, floor, ceiling and end wall are papered with panels
// of "dead leaves" pictures (dead_leaves.h, each panel a different one): rendered views with exact
// poses, for the forward-motion structure-from-motion test (the paper's corridor case). The camera
// looks down the corridor and sways, bobs and turns a little as a person walking does. The
// corridor is straight, or L-shaped with the walk turning round its corner. Test support only.
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
  int threads = 1;                   // frames (and pictures) rendered in parallel; 0: one per core
};

// Renders the walk into `out_dir` as walk_NN.png and returns each view's true camera by file
// name. InvalidArgument for unusable options; the PNG writer's error for a file it cannot write.
Result<GroundTruthByName> RenderCorridorWalk(const std::string& out_dir, const CorridorWalkOptions& options = {});

// An L-shaped corridor: the walk goes down a first leg along +z, walks round the corner on an arc
// (the heading turning evenly over `turn_steps` steps, centred on frame `turn_frame`) and on down
// the second leg, the same sway, bob and small turns about the heading all along. The legs have the
// straight corridor's cross-section and panels; the second leg's end wall is `walk.length_m` from
// the start along the legs' centre lines, which meet at the corner on the z axis. Positive turns
// are to the right (towards +x; y is down).
struct CorridorTurnOptions {
  CorridorWalkOptions walk;
  double turn_deg = 90.0;  // 15..135 in magnitude
  int turn_frame = -1;     // the frame half way round the corner; -1: frames / 2
  int turn_steps = 4;      // >= 1, turn_frame >= turn_steps / 2 (the turn starts at or after frame 0)
};

// Frame i's true camera, without rendering. InvalidArgument for unusable options (as below).
Result<GroundTruthCamera> CorridorTurnCamera(const CorridorTurnOptions& options, int i);

// Where the corridor turns: the legs' centre lines meet at (0, 0, corner_z_m), and the second leg
// runs from there along (sin turn, 0, cos turn) to its end wall, end_wall_m away.
struct CorridorTurnLayout {
  double corner_z_m = 0.0;
  double end_wall_m = 0.0;
};
Result<CorridorTurnLayout> CorridorTurnLayoutOf(const CorridorTurnOptions& options);

// Renders the walk round the corner into `out_dir` as walk_NN.png and returns each view's true
// camera by file name. InvalidArgument for unusable options, or a second leg that ends within 1 m
// of the last camera; the PNG writer's error for a file it cannot write.
Result<GroundTruthByName> RenderCorridorTurn(const std::string& out_dir, const CorridorTurnOptions& options = {});

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
