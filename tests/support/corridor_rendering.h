#pragma once
// What the straight and the L-shaped corridor (corridor_walk.cc, corridor_turn.cc) share: the
// panels' pictures, the walker's hand-held camera, and rendering the frames by ray tracing with
// supersampling. Internal to the corridor module.
#include <Eigen/Core>
#include <algorithm>
#include <functional>
#include <string>
#include <vector>

#include "tests/support/corridor_walk.h"
#include "tests/support/dead_leaves.h"
#include "tests/support/supersampling.h"

namespace reconar::testing::corridor {

// InvalidArgument "`who`: unusable options" for options no corridor can be rendered with.
Status CheckWalkOptions(const CorridorWalkOptions& options, const std::string& who);

// `count` dead-leaves pictures of the options' size and contrast, seeds options.seed + index.
std::vector<RgbTexture> PanelTextures(const CorridorWalkOptions& options, int count);

// Frame i's camera with its eye on the walk's path at `on_path`, heading `heading` radians (a turn
// about +y; 0 looks down +z, pi / 2 down +x): swaying sideways, bobbing, and turning a little.
GroundTruthCamera HandHeldCamera(const CorridorWalkOptions& options, int i, const Eigen::Vector3d& on_path,
                                 double heading);

// The view of `scene` (anything with Eigen::Vector3f Trace(origin, direction): the colour seen from
// `origin` along `direction`, world frame) through `camera`, supersampled.
template <typename Scene>
Image<uint8_t> RenderView(const Scene& scene, const GroundTruthCamera& camera, int supersampling) {
  const int s = supersampling;
  Image<float> fine(s * camera.width, s * camera.height, 3);
  const Eigen::Matrix3d world_from_cam = camera.cam_from_world_rotation.transpose();
  const Eigen::Vector3d centre = camera.Centre();
  const double focal = camera.K(0, 0), cx = camera.K(0, 2), cy = camera.K(1, 2);
  for (int y = 0; y < fine.height(); ++y) {
    float* row = fine.row(y);
    const double py = FineSampleCoordinate(y, s);
    for (int x = 0; x < fine.width(); ++x) {
      const double px = FineSampleCoordinate(x, s);
      const Eigen::Vector3f colour =
          scene.Trace(centre, world_from_cam * Eigen::Vector3d((px - cx) / focal, (py - cy) / focal, 1.0));
      std::copy(colour.data(), colour.data() + 3, row + 3 * x);
    }
  }
  return ToBytes(AverageSamples(fine, s));
}

// Renders each camera's view by `render` into `out_dir` as walk_NN.png (zero-padded to the last
// frame's digits, so that a plain string sort keeps the walk's order too), frames on
// options.threads threads; the true cameras by file name.
Result<GroundTruthByName> RenderWalkFrames(const std::string& out_dir, const CorridorWalkOptions& options,
                                           const std::vector<GroundTruthCamera>& cameras,
                                           const std::function<Image<uint8_t>(const GroundTruthCamera&)>& render);

}  // namespace reconar::testing::corridor
