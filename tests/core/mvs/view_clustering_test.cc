// View clustering on synthetic scenes: rings of cameras around cylinders of sparse points, where
// visibility follows from geometry (a point is seen when it faces the camera within 60 degrees
// and projects inside the image).
#include "core/math/rigid3.h"
#include "core/mvs/view_clustering.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

namespace reconar {
namespace {

struct SceneOptions {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  int cameras = 24;
  double ring_radius = 5.0;
  double far_copies_factor = 0.0;  // > 0: every camera gets a copy this many times farther away
  int points = 2000;               // on a cylinder of radius 1, height 2 (z up)
};

// Camera looking at `target` from `centre`, y down (world z up).
Rigid3 LookAt(const Eigen::Vector3d& centre, const Eigen::Vector3d& target) {
  const Rigid3 cam_from_world = CamFromWorldLookingAt(centre, target, Eigen::Vector3d::UnitZ());
  Rigid3 pose;
  pose.rotation = cam_from_world.rotation;
  pose.translation = cam_from_world.translation;
  return pose;
}

void AddScene(const SceneOptions& options, Reconstruction* rec) {
  if (rec->cameras.empty()) {
    SfmCamera camera;
    camera.width = 640;
    camera.height = 480;
    camera.focal = 600.0;
    camera.cx = 319.5;
    camera.cy = 239.5;
    rec->cameras.push_back(camera);
  }
  const size_t first_image = rec->images.size();
  for (int copy = 0; copy < (options.far_copies_factor > 0.0 ? 2 : 1); ++copy) {
    const double radius = options.ring_radius * (copy == 0 ? 1.0 : options.far_copies_factor);
    for (int i = 0; i < options.cameras; ++i) {
      const double angle = 2.0 * M_PI * i / options.cameras;
      SfmImage image;
      image.name = "img" + std::to_string(rec->images.size());
      image.camera_id = 0;
      image.registered = true;
      const Eigen::Vector3d centre = options.centre + radius * Eigen::Vector3d(std::cos(angle), std::sin(angle), 0.3);
      image.cam_from_world = LookAt(centre, options.centre);
      rec->images.push_back(image);
    }
  }
  const SfmCamera& camera = rec->cameras[0];
  for (int p = 0; p < options.points; ++p) {
    // Golden-angle spiral over the cylinder: deterministic and even.
    const double angle = p * 2.399963229728653;
    const double height = -1.0 + 2.0 * (p + 0.5) / options.points;
    const Eigen::Vector3d normal(std::cos(angle), std::sin(angle), 0.0);
    SfmPoint point;
    point.position = options.centre + normal + Eigen::Vector3d(0, 0, height);
    for (size_t i = first_image; i < rec->images.size(); ++i) {
      SfmImage& image = rec->images[i];
      const Eigen::Vector3d to_camera = (image.Center() - point.position).normalized();
      if (to_camera.dot(normal) < std::cos(M_PI / 3)) continue;
      const Eigen::Vector3d cam = image.cam_from_world * point.position;
      const Eigen::Vector2d pixel = camera.Project(cam);
      if (cam.z() <= 0 || pixel.x() < 0 || pixel.y() < 0 || pixel.x() > 639 || pixel.y() > 479) continue;
      point.track.push_back({static_cast<int>(i), static_cast<int>(image.keypoints.size())});
      image.keypoints.push_back(pixel);
      image.point3d_ids.push_back(static_cast<int>(rec->points.size()));
    }
    if (point.track.size() >= 2) rec->points.push_back(point);
  }
}

// Fraction of the points of each kept image that some cluster holds min(3, kept views) views of
// (all views have comparable resolution in these scenes unless far copies are added).
std::vector<double> CoveragePerImage(const Reconstruction& rec, const ViewClustering& clustering,
                                     const std::set<int>& excluded_views = {}) {
  const std::set<int> kept(clustering.kept_images.begin(), clustering.kept_images.end());
  std::vector<int> total(rec.images.size(), 0), covered(rec.images.size(), 0);
  for (const SfmPoint& point : rec.points) {
    std::vector<int> views;
    for (const TrackElement& e : point.track) {
      if (kept.count(e.image_id) && !excluded_views.count(e.image_id)) views.push_back(e.image_id);
    }
    if (views.size() < 2) continue;
    const size_t need = std::min<size_t>(3, views.size());
    bool is_covered = false;
    for (const std::vector<int>& cluster : clustering.clusters) {
      size_t k = 0;
      for (int v : views) k += std::binary_search(cluster.begin(), cluster.end(), v) ? 1 : 0;
      is_covered |= k >= need;
    }
    for (int v : views) {
      ++total[static_cast<size_t>(v)];
      covered[static_cast<size_t>(v)] += is_covered ? 1 : 0;
    }
  }
  std::vector<double> ratio;
  for (int image : clustering.kept_images) {
    if (total[static_cast<size_t>(image)] > 0) {
      ratio.push_back(static_cast<double>(covered[static_cast<size_t>(image)]) / total[static_cast<size_t>(image)]);
    }
  }
  return ratio;
}

void ExpectPartition(const Reconstruction& rec, const ViewClustering& clustering) {
  std::set<int> all(clustering.kept_images.begin(), clustering.kept_images.end());
  for (int removed : clustering.removed_images) EXPECT_TRUE(all.insert(removed).second) << removed;
  EXPECT_EQ(all.size(), rec.images.size());
  std::set<int> clustered;
  for (const std::vector<int>& cluster : clustering.clusters) {
    EXPECT_TRUE(std::is_sorted(cluster.begin(), cluster.end()));
    clustered.insert(cluster.begin(), cluster.end());
  }
  EXPECT_EQ(clustered, std::set<int>(clustering.kept_images.begin(), clustering.kept_images.end()));
}

TEST(ViewClustering, RingSplitsIntoBoundedClustersThatCoverThePoints) {
  Reconstruction rec;
  SceneOptions scene;
  scene.cameras = 48;
  AddScene(scene, &rec);
  for (const bool remove_redundant : {false, true}) {
    ViewClusteringOptions options;
    options.max_cluster_size = 10;
    options.remove_redundant = remove_redundant;
    auto clustering = ClusterViews(rec, options);
    ASSERT_TRUE(clustering.ok()) << clustering.status().ToString();
    ExpectPartition(rec, *clustering);
    EXPECT_FALSE(clustering->from_camera_geometry);
    for (const std::vector<int>& cluster : clustering->clusters) EXPECT_LE(cluster.size(), 10u);
    for (double ratio : CoveragePerImage(rec, *clustering)) EXPECT_GE(ratio, 0.7);
    EXPECT_GE(clustering->covered_fraction, 0.7);
    if (remove_redundant) {
      // 48 views 7.5 degrees apart see each point from about 18 of them: most are redundant.
      EXPECT_GT(clustering->removed_images.size(), 24u);
    } else {
      EXPECT_GE(clustering->clusters.size(), 5u);
    }
    std::printf("48-view ring, remove_redundant %d: %zu kept, %zu removed, %zu clusters, %.3f of %d points covered\n",
                remove_redundant, clustering->kept_images.size(), clustering->removed_images.size(),
                clustering->clusters.size(), clustering->covered_fraction, clustering->points_considered);
  }
}

TEST(ViewClustering, RemovedImagesLeaveEveryPointWellSeen) {
  Reconstruction rec;
  SceneOptions scene;
  scene.cameras = 36;
  AddScene(scene, &rec);
  auto clustering = ClusterViews(rec, ViewClusteringOptions());
  ASSERT_TRUE(clustering.ok()) << clustering.status().ToString();
  const std::set<int> kept(clustering->kept_images.begin(), clustering->kept_images.end());
  for (const SfmPoint& point : rec.points) {
    size_t views = 0, kept_views = 0;
    for (const TrackElement& e : point.track) {
      ++views;
      kept_views += kept.count(e.image_id);
    }
    EXPECT_GE(kept_views, std::min<size_t>(3, views));
  }
}

TEST(ViewClustering, FarCopiesAreTheRedundantOnes) {
  Reconstruction rec;
  SceneOptions scene;
  scene.cameras = 12;
  scene.far_copies_factor = 2.5;  // same directions, 2.5x less resolution
  AddScene(scene, &rec);
  auto clustering = ClusterViews(rec, ViewClusteringOptions());
  ASSERT_TRUE(clustering.ok()) << clustering.status().ToString();
  ExpectPartition(rec, *clustering);
  for (int removed = 12; removed < 24; ++removed) {
    EXPECT_TRUE(std::binary_search(clustering->removed_images.begin(), clustering->removed_images.end(), removed))
        << "far image " << removed << " kept";
  }
  for (int near = 0; near < 12; ++near) {
    EXPECT_TRUE(std::binary_search(clustering->kept_images.begin(), clustering->kept_images.end(), near))
        << "near image " << near << " removed";
  }
}

TEST(ViewClustering, SmallSceneIsOneCluster) {
  Reconstruction rec;
  SceneOptions scene;
  scene.cameras = 12;
  AddScene(scene, &rec);
  ViewClusteringOptions options;
  options.remove_redundant = false;
  auto clustering = ClusterViews(rec, options);
  ASSERT_TRUE(clustering.ok()) << clustering.status().ToString();
  ASSERT_EQ(clustering->clusters.size(), 1u);
  EXPECT_EQ(clustering->clusters[0].size(), 12u);
  EXPECT_TRUE(clustering->removed_images.empty());
  EXPECT_DOUBLE_EQ(clustering->covered_fraction, 1.0);
}

TEST(ViewClustering, SeparateScenesNeverShareACluster) {
  Reconstruction rec;
  SceneOptions scene;
  scene.cameras = 16;
  AddScene(scene, &rec);
  scene.centre = Eigen::Vector3d(100.0, 0.0, 0.0);
  AddScene(scene, &rec);
  ViewClusteringOptions options;
  options.max_cluster_size = 30;
  options.remove_redundant = false;
  auto clustering = ClusterViews(rec, options);
  ASSERT_TRUE(clustering.ok()) << clustering.status().ToString();
  ASSERT_EQ(clustering->clusters.size(), 2u);
  for (const std::vector<int>& cluster : clustering->clusters) {
    const bool first_scene = cluster.front() < 16;
    for (int image : cluster) EXPECT_EQ(image < 16, first_scene);
  }
}

TEST(ViewClustering, WithoutPointsNeighboursComeFromTheCameras) {
  Reconstruction rec;
  SceneOptions scene;
  scene.cameras = 40;
  scene.points = 0;
  AddScene(scene, &rec);
  ViewClusteringOptions options;
  options.max_cluster_size = 12;
  auto clustering = ClusterViews(rec, options);
  ASSERT_TRUE(clustering.ok()) << clustering.status().ToString();
  EXPECT_TRUE(clustering->from_camera_geometry);
  ExpectPartition(rec, *clustering);

  // Every image finds both ring neighbours in some cluster with it, and clusters are arcs.
  for (int i = 0; i < 40; ++i) {
    for (int neighbour : {(i + 1) % 40, (i + 39) % 40}) {
      bool together = false;
      for (const std::vector<int>& cluster : clustering->clusters) {
        together |= std::binary_search(cluster.begin(), cluster.end(), i) &&
                    std::binary_search(cluster.begin(), cluster.end(), neighbour);
      }
      EXPECT_TRUE(together) << i << " and " << neighbour;
    }
  }
  for (const std::vector<int>& cluster : clustering->clusters) {
    EXPECT_LE(cluster.size(), 12u);
    EXPECT_GE(cluster.size(), 3u);
    // An arc: ring angles of the members span less than 180 degrees.
    int gaps = 0;
    for (size_t k = 0; k < cluster.size(); ++k) {
      const int next = cluster[(k + 1) % cluster.size()];
      gaps += ((next - cluster[k] + 40) % 40) > 1 ? 1 : 0;
    }
    EXPECT_LE(gaps, 1);
  }
}

TEST(ViewClustering, RejectsBadOptionsAndEmptyModels) {
  Reconstruction rec;
  EXPECT_EQ(ClusterViews(rec, ViewClusteringOptions()).status().code(), StatusCode::kFailedPrecondition);
  SceneOptions scene;
  AddScene(scene, &rec);
  ViewClusteringOptions options;
  options.max_cluster_size = 2;
  EXPECT_EQ(ClusterViews(rec, options).status().code(), StatusCode::kInvalidArgument);
  options = ViewClusteringOptions();
  options.coverage_ratio = 1.5;
  EXPECT_EQ(ClusterViews(rec, options).status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace reconar
