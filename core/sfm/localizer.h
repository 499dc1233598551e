#pragma once
// Relocalisation: the pose of a photo or video frame against a localisation map
// (localization_map.h), with no prior pose.
//   1. retrieval: the query's SIFT descriptors are quantised in the map's vocabulary and the
//      inverted file ranks the keyframes; the best `num_keyframes` are kept;
//   2. 2D-3D matching: each query descriptor's nearest neighbours among the retrieved keyframes'
//      observations (one kd-forest over every observation, built with the localizer, whose
//      neighbours from other keyframes are skipped), Lowe's ratio test against the nearest
//      observation of a different map point, then one query per map point (the closest);
//   3. pose: P3P in LO-RANSAC and robust LM refinement for a known camera, DLT in RANSAC with the
//      focal refined for an unknown one (core/geometry/absolute_pose.h);
//   4. gates: a pose counts only with at least `min_inliers` inliers that are at least
//      `min_inlier_ratio` of the 2D-3D matches (COLMAP's image registration gates). A photo of an
//      unrelated scene gives few matches, and RANSAC's best pose among them few inliers in a
//      small share of them: it is reported as not registered, with the reason.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/features/kdtree.h"
#include "core/features/sift/sift.h"
#include "core/geometry/absolute_pose.h"
#include "core/math/camera_intrinsics.h"
#include "core/sfm/localization_map.h"

namespace reconar {

struct LocalizerOptions {
  int num_keyframes = 10;     // retrieved keyframes matched against
  double max_ratio = 0.8;     // Lowe's ratio (distances, not squared)
  int max_leaf_checks = 128;  // kd-forest search budget per query descriptor
  int leaf_size = 4;          // of the kd-forest (KdForestOptions::leaf_size: recall for speed)
  int min_inliers = 30;
  double min_inlier_ratio = 0.25;
  AbsolutePoseOptions pose;  // its min_inliers is replaced by min_inliers

  Status Check() const;
};

// The camera of a query: known intrinsics, or only a focal prior (EXIF, or a default) for the
// unknown-focal solver. ResolveQueryCamera picks one.
struct QueryCamera {
  int width = 0;
  int height = 0;
  std::optional<RadialCamera> known;
  double focal_prior_px = 0.0;  // used when `known` is empty
  std::string source;           // "intrinsics", "map", "exif prior", "default prior"
};

// The camera of a query image of this size: `intrinsics` when given (scaled to the size, same
// aspect ratio); else the map's camera for images of this aspect ratio (the median of its
// keyframes' parameters, scaled), unless an EXIF focal of the query disagrees with it by more than
// the mapper's EXIF trust window (0.7-1.4); else the EXIF focal, else 1.2 max(width, height), as a
// prior. InvalidArgument when `intrinsics` has another aspect ratio.
Result<QueryCamera> ResolveQueryCamera(const LocalizationMap& map, int width, int height,
                                       const std::optional<CameraIntrinsics>& intrinsics, double exif_focal_px);

struct LocalizationResult {
  bool registered = false;
  std::string reason;  // why not, when not registered
  Rigid3 cam_from_world;
  RadialCamera camera;  // the query camera (focal refined when it was unknown)
  std::string camera_source;
  int num_features = 0;
  int num_matches = 0;  // 2D-3D matches after the ratio test and the one-per-point rule
  int num_inliers = 0;
  double mean_inlier_error_px = 0.0;
  std::vector<int> keyframes;         // retrieved, best first
  std::vector<int> inlier_keypoints;  // query keypoint index of each inlier
  std::vector<int> inlier_points;     // map point of each inlier
  double seconds_retrieval = 0.0;
  double seconds_matching = 0.0;
  double seconds_pose = 0.0;
};

class Localizer {
 public:
  // Borrows the map, which must outlive the localizer. InvalidArgument on bad options.
  static Result<Localizer> Create(const LocalizationMap* map, const LocalizerOptions& options);

  // Safe to call from several threads at once. InvalidArgument for inconsistent features; every
  // localisation failure is a result with registered = false and the reason.
  Result<LocalizationResult> Localize(const SiftFeatures& features, const QueryCamera& camera) const;

  const LocalizationMap& map() const { return *map_; }
  const LocalizerOptions& options() const { return options_; }

 private:
  // Every keyframe observation's descriptor in one kd-forest, built once: a query searches it and
  // keeps only the neighbours of the retrieved keyframes.
  struct ObservationIndex {
    std::vector<uint8_t> descriptors;  // 128 bytes per observation, keyframe by keyframe
    std::vector<int32_t> point_of;
    std::vector<int32_t> keyframe_of;
    KdForest forest;  // borrows `descriptors`
  };
  Localizer(const LocalizationMap* map, const LocalizerOptions& options, std::unique_ptr<ObservationIndex> index)
      : map_(map), options_(options), index_(std::move(index)) {}
  const LocalizationMap* map_;
  LocalizerOptions options_;
  std::unique_ptr<ObservationIndex> index_;
};

}  // namespace reconar
