#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/io/image_io.h"
#include "tests/support/corridor_walk.h"
#include "tests/support/run_command.h"

namespace reconar::testing {
namespace {

// The heading of a camera's optical axis in degrees: 0 down +z, 90 down +x.
double HeadingDeg(const GroundTruthCamera& camera) {
  const Eigen::Vector3d axis = camera.cam_from_world_rotation.row(2).transpose();
  return std::atan2(axis.x(), axis.z()) * 180.0 / M_PI;
}

// The walker's own turns (3 degrees of yaw) and pitch and roll (1.5 and 1) bound the heading's wobble.
constexpr double kWobbleDeg = 3.5;

void ExpectTurn(const CorridorTurnOptions& options) {
  const int middle = options.turn_frame < 0 ? options.walk.frames / 2 : options.turn_frame;
  const double half = 0.5 * options.turn_steps;
  for (int i = 0; i < options.walk.frames; ++i) {
    const Result<GroundTruthCamera> camera = CorridorTurnCamera(options, i);
    ASSERT_TRUE(camera.ok()) << camera.status().ToString();
    double expected = options.turn_deg;
    if (i <= middle - half) expected = 0.0;
    if (i == middle) expected = 0.5 * options.turn_deg;
    if (i <= middle - half || i == middle || i >= middle + half) {
      EXPECT_NEAR(HeadingDeg(*camera), expected, kWobbleDeg) << "frame " << i;
    }
    if (i > 0) {
      // A step between frames: the arc's chord and the sway change it a little.
      const double stride = (camera->Centre() - CorridorTurnCamera(options, i - 1)->Centre()).norm();
      EXPECT_NEAR(stride, options.walk.step_m, 0.25) << "frame " << i;
    }
  }
}

TEST(CorridorTurnTest, TheWalkTurnsRightByNinetyDegreesOverFourStepsHalfWay) {
  const CorridorTurnOptions options;
  ExpectTurn(options);
  // The second leg runs along +x: the last camera is well down it, about at the first leg's end.
  const GroundTruthCamera last = *CorridorTurnCamera(options, options.walk.frames - 1);
  EXPECT_GT(last.Centre().x(), 4.0);
  EXPECT_LT(std::abs(last.Centre().z() - CorridorTurnCamera(options, 16)->Centre().z()), 0.3);
}

TEST(CorridorTurnTest, TheTurnsAngleSideAndPlaceAreOptions) {
  CorridorTurnOptions options;
  options.walk.frames = 40;
  options.turn_deg = -60.0;
  options.turn_frame = 10;
  options.turn_steps = 5;
  ExpectTurn(options);
}

TEST(CorridorTurnTest, RefusesATurnItCannotWalk) {
  CorridorTurnOptions options;
  options.turn_deg = 5.0;
  EXPECT_EQ(CorridorTurnCamera(options, 0).status().code(), StatusCode::kInvalidArgument);
  options.turn_deg = 90.0;
  options.turn_frame = 1;  // the turn would start before the first frame
  EXPECT_EQ(CorridorTurnCamera(options, 0).status().code(), StatusCode::kInvalidArgument);
  options.turn_frame = -1;
  options.turn_steps = 30;  // an arc too wide for the corner
  EXPECT_EQ(CorridorTurnCamera(options, 0).status().code(), StatusCode::kInvalidArgument);
  options.turn_steps = 4;
  options.walk.length_m = 8.0;  // the second leg ends before the walk does
  EXPECT_EQ(CorridorTurnCamera(options, 0).status().code(), StatusCode::kInvalidArgument);
}

// The colour of the pixel where `camera` projects `point`, and whether it lies in the image.
bool ColourAt(const GroundTruthCamera& camera, const Image<uint8_t>& image, const Eigen::Vector3d& point,
              Eigen::Vector3i* colour) {
  const Eigen::Vector3d seen = camera.K * (camera.cam_from_world_rotation * point + camera.cam_from_world_translation);
  if (seen.z() <= 0.0) return false;
  const long u = std::lround(seen.x() / seen.z()), v = std::lround(seen.y() / seen.z());
  if (u < 0 || v < 0 || u >= image.width() || v >= image.height()) return false;
  const uint8_t* pixel = image.row(static_cast<int>(v)) + 3 * u;
  *colour = Eigen::Vector3i(pixel[0], pixel[1], pixel[2]);
  return true;
}

// Rendered small with flat panels (no dead leaves: each panel one colour): the second leg's end wall,
// a known rectangle, is where the true cameras put it in every frame that sees it whole. Points on
// it show its colour; points 3 m before it on the floor, ceiling and side walls show others.
TEST(CorridorTurnTest, TheEndWallIsWhereTheTrueCamerasPutIt) {
  CorridorTurnOptions options;
  options.walk.width = 160;
  options.walk.height = 120;
  options.walk.focal_px = 130.0;
  options.walk.supersampling = 1;
  options.walk.texture_width_px = 8;
  options.walk.texture_contrast = 0.0;
  const Result<CorridorTurnLayout> layout = CorridorTurnLayoutOf(options);
  ASSERT_TRUE(layout.ok()) << layout.status().ToString();
  const std::string dir = MakeTestDirectory("corridor_turn_end_wall");
  const Result<GroundTruthByName> truth = RenderCorridorTurn(dir, options);
  ASSERT_TRUE(truth.ok()) << truth.status().ToString();
  ASSERT_EQ(truth->size(), static_cast<size_t>(options.walk.frames));
  // The end wall's frame: `along` the second leg (+x), `right` of a walker going down it (-z).
  const Eigen::Vector3d along(1.0, 0.0, 0.0), right(0.0, 0.0, -1.0), down(0.0, 1.0, 0.0);
  const Eigen::Vector3d centre = Eigen::Vector3d(0.0, 0.0, layout->corner_z_m) + layout->end_wall_m * along +
                                 0.5 * (options.walk.eye_above_floor_m - options.walk.ceiling_above_eye_m) * down;
  const double half_width = options.walk.half_width_m;
  const double half_height = 0.5 * (options.walk.eye_above_floor_m + options.walk.ceiling_above_eye_m);
  int frames_checked = 0;
  for (const auto& [name, camera] : *truth) {
    const Result<DecodedImage> image = ReadImage(dir + "/" + name);
    ASSERT_TRUE(image.ok()) << image.status().ToString();
    std::vector<Eigen::Vector3d> on_wall, before_wall;
    for (const double a : {-0.7, 0.0, 0.7}) {
      for (const double b : {-0.7, 0.0, 0.7})
        on_wall.push_back(centre + a * half_width * right + b * half_height * down);
      before_wall.push_back(centre - 3.0 * along + a * half_width * right + 1.0 * half_height * down);  // floor
      before_wall.push_back(centre - 3.0 * along + a * half_width * right - 1.0 * half_height * down);  // ceiling
      before_wall.push_back(centre - 3.0 * along + 1.0 * half_width * right + a * half_height * down);  // right wall
      before_wall.push_back(centre - 3.0 * along - 1.0 * half_width * right + a * half_height * down);  // left wall
    }
    Eigen::Vector3i wall_colour, colour;
    bool whole = ColourAt(camera, image->rgb, centre, &wall_colour);
    for (const Eigen::Vector3d& point : before_wall) whole = whole && ColourAt(camera, image->rgb, point, &colour);
    if (!whole) continue;
    ++frames_checked;
    for (const Eigen::Vector3d& point : on_wall) {
      ASSERT_TRUE(ColourAt(camera, image->rgb, point, &colour));
      EXPECT_LE((colour - wall_colour).cwiseAbs().maxCoeff(), 2) << name << " at " << point.transpose();
    }
    for (const Eigen::Vector3d& point : before_wall) {
      ColourAt(camera, image->rgb, point, &colour);
      EXPECT_GT((colour - wall_colour).cwiseAbs().maxCoeff(), 2) << name << " at " << point.transpose();
    }
  }
  std::printf("%d frames see the end wall whole\n", frames_checked);
  EXPECT_GE(frames_checked, 10);
}

}  // namespace
}  // namespace reconar::testing
