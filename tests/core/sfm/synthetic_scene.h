#pragma once
// A synthetic scene for the mapper's tests: cameras with known poses around points with known
// positions, their noisy keypoints and pairwise matches (with planted wrong ones), and the model
// the mapper should find. Test support only.
#include <Eigen/Core>
#include <vector>

#include "core/sfm/mapper.h"
#include "core/sfm/mapper_model.h"

namespace reconar::testing {

struct SceneOptions {
  int num_cameras = 10;
  int num_points = 2000;
  double ring_radius = 10.0;
  // Camera heights vary by +- this (elevations +-17 degrees) and cameras are rolled by up to +-
  // max_roll_deg, like hand-held photos. A flatter ring (+-1.5) is close to a critical motion for
  // self-calibration: the vertical principal point and the aspect ratio trade against a common
  // tilt of the cameras and a vertical stretch of the scene, and the poses come out ~0.2 degrees
  // off for reasons that have nothing to do with the mapper.
  double height_amplitude = 3.0;
  double max_roll_deg = 5.0;
  double noise_px = 0.4;           // standard deviation per pixel coordinate
  double wrong_fraction = 0.15;    // wrong matches added per pair, relative to its true matches
  int wrong_real_real = 3;         // of which at most this many join two true tracks
  int min_common_points = 40;      // pairs sharing fewer points get no MapperPair
  double visible_within_deg = 75;  // a point is seen when its normal is this close to the view ray
  double detection_rate = 0.9;
  double focal_prior_factor = 1.2;  // focal prior = this x max(width, height), as without EXIF
  unsigned seed = 1;
  // When not empty: the camera centres (num_cameras is their count), instead of the ring; each
  // camera still looks at a point near the origin.
  std::vector<Eigen::Vector3d> centres;
  bool distortion = true;  // the true camera has TrueCamera()'s k1; otherwise none
};

// The true camera: 1000 x 750 px, focal 900, principal point a few pixels off the centre, a
// little barrel distortion (about 4 px at the corners).
SfmCamera TrueCamera();

// The radial distortion factor - 1 at normalised radius 0.6 (540 px at the true focal): k1 and k2
// trade against each other, their sum at a radius less so.
double RadialFactorAt06(const SfmCamera& camera);

struct Scene {
  SfmCamera camera;
  std::vector<Rigid3> poses;
  std::vector<Eigen::Vector3d> points;
  std::vector<MapperImage> images;
  std::vector<MapperPair> pairs;
  // Per image and keypoint: the true point it observes, or -1 for a clutter keypoint (one that
  // exists only as the end of a wrong match).
  std::vector<std::vector<int>> point_of_keypoint;
  int num_true_matches = 0;
  int num_wrong_matches = 0;
};

// Cameras on a ring (height varying by +-3) around the origin, each looking at a point near
// the origin; points uniform in a 6 x 6 x 4 box, each with a random normal so that it is seen
// only from one side (opposite cameras share nothing, neighbours share most). Keypoints are the
// true projections plus Gaussian noise; every pair sharing enough points gets its true matches
// plus wrong_fraction wrong ones: a few join keypoints of two different true points (merging two
// tracks), a quarter join a true keypoint to a clutter keypoint, the rest join two clutter
// keypoints. Wrong matches keep each pair one-to-one, like the matcher's output.
Scene MakeScene(const SceneOptions& options);

// A ring of num_cameras with exact keypoints (no noise) and no wrong matches: every track is one
// true point.
Scene MakeExactScene(int num_cameras, int num_points);

// The mapper's default options on one thread (the tests' results do not depend on the count).
MapperOptions SingleThreaded();

// The model at the truth: every image registered at its true pose with one shared camera (the
// true one), the tracks of the scene's matches, and a point at the true position for each track
// whose keypoints all observe one true point (with all of them as observations).
MapperModel TrueModel(const Scene& scene);

// Removes `image` from the model as if it had not been registered: no pose, no observation.
void Unregister(MapperModel* model, int image);

// The registration tests' scene: 8 cameras on the ring, 1000 points, 0.4 px noise.
Scene RegistrationRing();

// The true model with `image` unregistered and only the first `keep` of its true points left; the
// other tracks through it lose their points (their matches become two-view matches). Expects
// (gtest) that it sees exactly `keep` points.
MapperModel TrueModelWithFewPointsSeenBy(const Scene& scene, int image, int keep);

// Expects (gtest) the two models equal to the bit: cameras, poses, observations, points.
void ExpectIdenticalModels(const Reconstruction& a, const Reconstruction& b);

// The true point a model point observes (that of its first observation), or -1 for clutter.
int TruePointOf(const Scene& scene, const SfmPoint& point);

}  // namespace reconar::testing
