#include "tests/core/sfm/synthetic_scene.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <string>

namespace reconar::testing {

double RadialFactorAt06(const SfmCamera& camera) {
  const double r2 = 0.36;
  return camera.k1 * r2 + camera.k2 * r2 * r2;
}

SfmCamera TrueCamera() {
  SfmCamera camera;
  camera.width = 1000;
  camera.height = 750;
  camera.focal = 900.0;
  camera.cx = 505.0;
  camera.cy = 371.0;
  camera.k1 = -0.02;
  return camera;
}

Scene MakeScene(const SceneOptions& options) {
  SceneOptions o = options;
  if (!o.centres.empty()) o.num_cameras = static_cast<int>(o.centres.size());
  std::mt19937 rng(o.seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  Scene scene;
  scene.camera = TrueCamera();
  if (!o.distortion) scene.camera.k1 = scene.camera.k2 = 0.0;
  const SfmCamera& cam = scene.camera;

  for (int i = 0; i < o.num_cameras; ++i) {
    const double angle = 2.0 * M_PI * i / o.num_cameras;
    const Eigen::Vector3d centre =
        o.centres.empty() ? Eigen::Vector3d(o.ring_radius * std::cos(angle), o.ring_radius * std::sin(angle),
                                            o.height_amplitude * std::sin(2.0 * angle + 0.3))
                          : o.centres[static_cast<size_t>(i)];
    const Eigen::Vector3d target(0.3 * uniform(rng), 0.3 * uniform(rng), 0.3 * uniform(rng));
    const Eigen::Vector3d forward = (target - centre).normalized();
    const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
    const Eigen::Vector3d down = forward.cross(right);
    Rigid3 pose;
    pose.rotation.row(0) = right.transpose();
    pose.rotation.row(1) = down.transpose();
    pose.rotation.row(2) = forward.transpose();
    const double roll = o.max_roll_deg * M_PI / 180.0 * uniform(rng);
    pose.rotation = Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).toRotationMatrix() * pose.rotation;
    pose.translation = -pose.rotation * centre;
    scene.poses.push_back(pose);
  }

  std::vector<Eigen::Vector3d> normals;
  for (int p = 0; p < o.num_points; ++p) {
    scene.points.emplace_back(3.0 * uniform(rng), 3.0 * uniform(rng), 2.0 * uniform(rng));
    normals.push_back(Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized());
  }

  // Observations; keypoint order within an image is shuffled.
  const double cos_visible = std::cos(o.visible_within_deg * M_PI / 180.0);
  std::vector<std::vector<int>> keypoint_of_point(static_cast<size_t>(o.num_cameras),
                                                  std::vector<int>(static_cast<size_t>(o.num_points), -1));
  scene.images.resize(static_cast<size_t>(o.num_cameras));
  scene.point_of_keypoint.resize(static_cast<size_t>(o.num_cameras));
  for (int i = 0; i < o.num_cameras; ++i) {
    MapperImage& image = scene.images[static_cast<size_t>(i)];
    image.name = "view" + std::to_string(i) + ".jpg";
    image.width = cam.width;
    image.height = cam.height;
    image.focal_prior = o.focal_prior_factor * std::max(cam.width, cam.height);
    image.focal_from_exif = false;
    std::vector<int> seen;
    for (int p = 0; p < o.num_points; ++p) {
      const Eigen::Vector3d& X = scene.points[static_cast<size_t>(p)];
      const Rigid3& pose = scene.poses[static_cast<size_t>(i)];
      const Eigen::Vector3d to_camera = (CameraCenterInWorld(pose) - X).normalized();
      const bool detected = unit(rng) < o.detection_rate;
      if (normals[static_cast<size_t>(p)].dot(to_camera) < cos_visible || !detected) continue;
      const Eigen::Vector3d c = pose * X;
      if (c.z() < 0.1) continue;
      const Eigen::Vector2d x = cam.Project(c);
      if (x.x() < 2.0 || x.y() < 2.0 || x.x() > cam.width - 3.0 || x.y() > cam.height - 3.0) continue;
      seen.push_back(p);
    }
    std::shuffle(seen.begin(), seen.end(), rng);
    for (int p : seen) {
      const Eigen::Vector2d x =
          cam.Project(scene.poses[static_cast<size_t>(i)] * (scene.points[static_cast<size_t>(p)]));
      keypoint_of_point[static_cast<size_t>(i)][static_cast<size_t>(p)] = static_cast<int>(image.keypoints.size());
      image.keypoints.push_back(x + o.noise_px * Eigen::Vector2d(gauss(rng), gauss(rng)));
      scene.point_of_keypoint[static_cast<size_t>(i)].push_back(p);
    }
  }

  const auto add_clutter = [&](int i) {
    MapperImage& image = scene.images[static_cast<size_t>(i)];
    image.keypoints.emplace_back(0.5 * (cam.width - 1) * (1.0 + uniform(rng)),
                                 0.5 * (cam.height - 1) * (1.0 + uniform(rng)));
    scene.point_of_keypoint[static_cast<size_t>(i)].push_back(-1);
    return static_cast<int>(image.keypoints.size()) - 1;
  };
  for (int a = 0; a < o.num_cameras; ++a) {
    for (int b = a + 1; b < o.num_cameras; ++b) {
      const std::vector<int>& ka = keypoint_of_point[static_cast<size_t>(a)];
      const std::vector<int>& kb = keypoint_of_point[static_cast<size_t>(b)];
      MapperPair pair;
      pair.matches.image_a = a;
      pair.matches.image_b = b;
      std::vector<int> only_a, only_b;  // true keypoints without a partner in the other image
      for (int p = 0; p < o.num_points; ++p) {
        const int xa = ka[static_cast<size_t>(p)], xb = kb[static_cast<size_t>(p)];
        if (xa >= 0 && xb >= 0) pair.matches.matches.push_back({xa, xb});
        if (xa >= 0 && xb < 0) only_a.push_back(xa);
        if (xa < 0 && xb >= 0) only_b.push_back(xb);
      }
      const int num_true = static_cast<int>(pair.matches.matches.size());
      if (num_true < o.min_common_points) continue;
      std::shuffle(only_a.begin(), only_a.end(), rng);
      std::shuffle(only_b.begin(), only_b.end(), rng);
      const int num_wrong = static_cast<int>(std::lround(o.wrong_fraction * num_true));
      for (int w = 0; w < num_wrong; ++w) {
        FeatureMatch m;
        if (w < o.wrong_real_real && !only_a.empty() && !only_b.empty()) {
          m = {only_a.back(), only_b.back()};
          only_a.pop_back();
          only_b.pop_back();
        } else if (w % 4 == 0 && !only_a.empty()) {
          m = {only_a.back(), add_clutter(b)};
          only_a.pop_back();
        } else if (w % 4 == 1 && !only_b.empty()) {
          m = {add_clutter(a), only_b.back()};
          only_b.pop_back();
        } else {
          m = {add_clutter(a), add_clutter(b)};
        }
        pair.matches.matches.push_back(m);
      }
      std::shuffle(pair.matches.matches.begin(), pair.matches.matches.end(), rng);
      scene.num_true_matches += num_true;
      scene.num_wrong_matches += num_wrong;
      scene.pairs.push_back(std::move(pair));
    }
  }
  return scene;
}

Scene MakeExactScene(int num_cameras, int num_points) {
  SceneOptions o;
  o.num_cameras = num_cameras;
  o.num_points = num_points;
  o.noise_px = 0.0;
  o.wrong_fraction = 0.0;
  return MakeScene(o);
}

MapperOptions SingleThreaded() {
  MapperOptions options;
  options.num_threads = 1;
  return options;
}

void Unregister(MapperModel* model, int image) {
  SfmImage& img = model->rec.images[static_cast<size_t>(image)];
  img.registered = false;
  img.cam_from_world = Rigid3();
  for (int& id : img.point3d_ids) {
    if (id < 0) continue;
    std::vector<TrackElement>& track = model->rec.points[static_cast<size_t>(id)].track;
    std::vector<TrackElement> kept;
    for (const TrackElement& e : track) {
      if (e.image_id != image) kept.push_back(e);
    }
    track = kept;
    id = -1;
  }
}

MapperModel TrueModel(const Scene& scene) {
  MapperModel model;
  model.rec.cameras.push_back(scene.camera);
  model.camera_prior.push_back(scene.camera.focal);
  model.camera_from_exif.push_back(false);
  std::vector<int> num_keypoints;
  for (size_t i = 0; i < scene.images.size(); ++i) {
    SfmImage image;
    image.name = scene.images[i].name;
    image.camera_id = 0;
    image.registered = true;
    image.cam_from_world = scene.poses[i];
    image.keypoints = scene.images[i].keypoints;
    image.point3d_ids.assign(image.keypoints.size(), -1);
    num_keypoints.push_back(static_cast<int>(image.keypoints.size()));
    model.rec.images.push_back(std::move(image));
  }
  model.failure.assign(scene.images.size(), "");
  model.tried_with.assign(scene.images.size(), -1);
  std::vector<PairMatches> matches;
  for (const MapperPair& pair : scene.pairs) matches.push_back(pair.matches);
  model.SetTracks(BuildTracks(num_keypoints, matches));
  for (size_t t = 0; t < model.tracks.tracks.size(); ++t) {
    const std::vector<TrackElement>& track = model.tracks.tracks[t];
    const int p =
        scene.point_of_keypoint[static_cast<size_t>(track[0].image_id)][static_cast<size_t>(track[0].keypoint_id)];
    bool one_point = p >= 0;
    for (const TrackElement& e : track) {
      one_point = one_point &&
                  scene.point_of_keypoint[static_cast<size_t>(e.image_id)][static_cast<size_t>(e.keypoint_id)] == p;
    }
    if (!one_point) continue;
    const int id = static_cast<int>(model.rec.points.size());
    SfmPoint point;
    point.position = scene.points[static_cast<size_t>(p)];
    model.rec.points.push_back(point);
    model.track_of_point.push_back(static_cast<int>(t));
    model.point_of_track[t] = id;
    for (const TrackElement& e : track) model.AddObservation(id, e.image_id, e.keypoint_id);
  }
  return model;
}

void ExpectIdenticalModels(const Reconstruction& a, const Reconstruction& b) {
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  for (size_t c = 0; c < a.cameras.size(); ++c) {
    EXPECT_EQ(a.cameras[c].focal, b.cameras[c].focal);
    EXPECT_EQ(a.cameras[c].cx, b.cameras[c].cx);
    EXPECT_EQ(a.cameras[c].cy, b.cameras[c].cy);
    EXPECT_EQ(a.cameras[c].k1, b.cameras[c].k1);
    EXPECT_EQ(a.cameras[c].k2, b.cameras[c].k2);
    EXPECT_EQ(a.cameras[c].aspect, b.cameras[c].aspect);
  }
  ASSERT_EQ(a.images.size(), b.images.size());
  for (size_t i = 0; i < a.images.size(); ++i) {
    EXPECT_EQ(a.images[i].registered, b.images[i].registered);
    EXPECT_EQ(a.images[i].camera_id, b.images[i].camera_id);
    EXPECT_TRUE(a.images[i].cam_from_world.rotation == b.images[i].cam_from_world.rotation) << i;
    EXPECT_TRUE(a.images[i].cam_from_world.translation == b.images[i].cam_from_world.translation) << i;
    EXPECT_EQ(a.images[i].point3d_ids, b.images[i].point3d_ids) << i;
  }
  ASSERT_EQ(a.points.size(), b.points.size());
  for (size_t p = 0; p < a.points.size(); ++p) {
    EXPECT_EQ(a.points[p].deleted, b.points[p].deleted);
    EXPECT_TRUE(a.points[p].position == b.points[p].position) << p;
    EXPECT_EQ(a.points[p].error, b.points[p].error);
    ASSERT_EQ(a.points[p].track.size(), b.points[p].track.size());
    for (size_t e = 0; e < a.points[p].track.size(); ++e) {
      EXPECT_EQ(a.points[p].track[e].image_id, b.points[p].track[e].image_id);
      EXPECT_EQ(a.points[p].track[e].keypoint_id, b.points[p].track[e].keypoint_id);
    }
  }
}

int TruePointOf(const Scene& scene, const SfmPoint& point) {
  const TrackElement& e = point.track.front();
  return scene.point_of_keypoint[static_cast<size_t>(e.image_id)][static_cast<size_t>(e.keypoint_id)];
}

Scene RegistrationRing() {
  SceneOptions o;
  o.num_cameras = 8;
  o.num_points = 1000;
  o.noise_px = 0.4;
  return MakeScene(o);
}

MapperModel TrueModelWithFewPointsSeenBy(const Scene& scene, int image, int keep) {
  MapperModel model = TrueModel(scene);
  Unregister(&model, image);
  int kept = 0;
  const std::vector<int>& track_of = model.tracks.track_of[static_cast<size_t>(image)];
  for (size_t kp = 0; kp < track_of.size(); ++kp) {
    const int t = track_of[kp];
    const int point = t < 0 ? -1 : model.point_of_track[static_cast<size_t>(t)];
    if (point < 0) continue;
    if (kept < keep && scene.point_of_keypoint[static_cast<size_t>(image)][kp] >= 0) {
      ++kept;
    } else {
      model.DeletePoint(point);
    }
  }
  EXPECT_EQ(model.CountVisiblePoints(image), keep);
  return model;
}

}  // namespace reconar::testing
