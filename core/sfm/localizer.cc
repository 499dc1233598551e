#include "core/sfm/localizer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "core/base/elapsed.h"
#include "core/base/median.h"
#include "core/features/descriptor_distance.h"
#include "core/features/kdtree.h"
#include "core/sfm/mapper.h"

namespace reconar {
namespace {

using Clock = std::chrono::steady_clock;

// Neighbours searched per query descriptor, among which the nearest of a retrieved keyframe and
// the nearest of another point there are sought.
constexpr int kNeighbours = 16;

}  // namespace

Status LocalizerOptions::Check() const {
  if (num_keyframes < 1) return InvalidArgument("LocalizerOptions: num_keyframes must be >= 1");
  if (!(max_ratio > 0.0 && max_ratio <= 1.0)) return InvalidArgument("LocalizerOptions: max_ratio must be in (0, 1]");
  if (max_leaf_checks < 1) return InvalidArgument("LocalizerOptions: max_leaf_checks must be >= 1");
  if (leaf_size < 1) return InvalidArgument("LocalizerOptions: leaf_size must be >= 1");
  if (min_inliers < 4) return InvalidArgument("LocalizerOptions: min_inliers must be >= 4");
  if (!(min_inlier_ratio >= 0.0 && min_inlier_ratio <= 1.0)) {
    return InvalidArgument("LocalizerOptions: min_inlier_ratio must be in [0, 1]");
  }
  AbsolutePoseOptions pose_options = pose;
  pose_options.min_inliers = min_inliers;
  return pose_options.Check();
}

Result<QueryCamera> ResolveQueryCamera(const LocalizationMap& map, int width, int height,
                                       const std::optional<CameraIntrinsics>& intrinsics, double exif_focal_px) {
  if (width <= 0 || height <= 0) return InvalidArgument("query image size must be positive");
  QueryCamera camera;
  camera.width = width;
  camera.height = height;
  if (intrinsics) {
    CameraIntrinsics given = *intrinsics;
    if (given.width <= 0 || given.height <= 0) {
      given.width = width;
      given.height = height;
    }
    RECONAR_ASSIGN_OR_RETURN(const CameraIntrinsics scaled, ScaleIntrinsicsToFrame(given, width, height));
    camera.known = scaled.Camera();
    camera.source = "intrinsics";
    return camera;
  }
  std::vector<double> focal, aspect, cx, cy, k1, k2;
  int reference_width = 0, reference_height = 0;
  for (const MapKeyframe& keyframe : map.keyframes) {
    if (!SameAspectRatio(keyframe.width, keyframe.height, width, height)) continue;
    if (reference_width == 0) {
      reference_width = keyframe.width;
      reference_height = keyframe.height;
    }
    // Keyframes of another resolution with this aspect ratio are brought to the first's size.
    CameraIntrinsics own;
    own.width = keyframe.width;
    own.height = keyframe.height;
    own.fx = keyframe.camera.focal;
    own.fy = keyframe.camera.fy();
    own.cx = keyframe.camera.cx;
    own.cy = keyframe.camera.cy;
    const CameraIntrinsics at_reference = ScaledIntrinsics(own, reference_width, reference_height);
    focal.push_back(at_reference.fx);
    aspect.push_back(keyframe.camera.aspect);
    cx.push_back(at_reference.cx);
    cy.push_back(at_reference.cy);
    k1.push_back(keyframe.camera.k1);
    k2.push_back(keyframe.camera.k2);
  }
  if (!focal.empty()) {
    CameraIntrinsics median;
    median.width = reference_width;
    median.height = reference_height;
    median.fx = Median(focal);
    median.fy = median.fx * Median(aspect);
    median.cx = Median(cx);
    median.cy = Median(cy);
    median.k1 = Median(k1);
    median.k2 = Median(k2);
    const CameraIntrinsics scaled = ScaledIntrinsics(median, width, height);
    const MapperOptions mapper;
    const double ratio = exif_focal_px > 0.0 ? scaled.fx / exif_focal_px : 1.0;
    if (ratio >= mapper.focal_prior_min_ratio && ratio <= mapper.focal_prior_max_ratio) {
      camera.known = scaled.Camera();
      camera.source = "map";
      return camera;
    }
  }
  if (exif_focal_px > 0.0) {
    camera.focal_prior_px = exif_focal_px;
    camera.source = "exif prior";
  } else {
    camera.focal_prior_px = 1.2 * std::max(width, height);
    camera.source = "default prior";
  }
  return camera;
}

Result<Localizer> Localizer::Create(const LocalizationMap* map, const LocalizerOptions& options) {
  if (map == nullptr) return InvalidArgument("Localizer: no map");
  RECONAR_RETURN_IF_ERROR(options.Check());
  auto index = std::make_unique<ObservationIndex>();
  const size_t total = static_cast<size_t>(map->num_observations());
  index->descriptors.reserve(total * kDescriptorSize);
  index->point_of.reserve(total);
  index->keyframe_of.reserve(total);
  for (size_t f = 0; f < map->keyframes.size(); ++f) {
    const MapKeyframe& keyframe = map->keyframes[f];
    index->descriptors.insert(index->descriptors.end(), keyframe.descriptors.begin(), keyframe.descriptors.end());
    index->point_of.insert(index->point_of.end(), keyframe.point_ids.begin(), keyframe.point_ids.end());
    index->keyframe_of.insert(index->keyframe_of.end(), keyframe.point_ids.size(), static_cast<int32_t>(f));
  }
  KdForestOptions forest_options;
  forest_options.max_leaf_checks = options.max_leaf_checks;
  forest_options.leaf_size = options.leaf_size;
  RECONAR_ASSIGN_OR_RETURN(index->forest, KdForest::Build(index->descriptors.data(),
                                                          static_cast<int>(index->point_of.size()), forest_options));
  return Localizer(map, options, std::move(index));
}

Result<LocalizationResult> Localizer::Localize(const SiftFeatures& features, const QueryCamera& camera) const {
  const int num_features = static_cast<int>(features.keypoints.size());
  if (features.descriptors.size() != features.keypoints.size() * kDescriptorSize) {
    return InvalidArgument("localize: " + std::to_string(features.descriptors.size()) + " descriptor bytes for " +
                           std::to_string(num_features) + " keypoints");
  }
  const LocalizationMap& map = *map_;
  LocalizationResult result;
  result.num_features = num_features;
  result.camera_source = camera.source;
  if (num_features < options_.min_inliers) {
    result.reason = "too few features (" + std::to_string(num_features) + ", at least " +
                    std::to_string(options_.min_inliers) + " needed)";
    return result;
  }

  // 1. Retrieval.
  auto start = Clock::now();
  std::vector<int32_t> words(static_cast<size_t>(num_features));
  for (int i = 0; i < num_features; ++i)
    words[static_cast<size_t>(i)] = map.vocabulary.Quantize(features.descriptor(static_cast<size_t>(i)));
  RetrievalScratch retrieval_scratch;
  retrieval_scratch.Reserve(num_features, map.keyframe_index.num_images());
  std::vector<RetrievalCandidate> candidates;
  candidates.reserve(static_cast<size_t>(options_.num_keyframes));
  map.keyframe_index.Query(words.data(), num_features, options_.num_keyframes, &retrieval_scratch, &candidates);
  for (const RetrievalCandidate& candidate : candidates) {
    if (candidate.score > 0.0f) result.keyframes.push_back(candidate.image);
  }
  result.seconds_retrieval = SecondsSince(start);
  if (result.keyframes.empty()) {
    result.reason = "no keyframe shares a visual word with the image";
    return result;
  }

  // 2. 2D-3D matching against the retrieved keyframes' observations.
  start = Clock::now();
  const ObservationIndex& index = *index_;
  std::vector<char> retrieved(map.keyframes.size(), 0);
  for (int f : result.keyframes) retrieved[static_cast<size_t>(f)] = 1;
  KdSearchScratch search_scratch(index.forest);
  // Per map point, the closest query keypoint that passed the ratio test and its distance.
  std::vector<int> best_query(map.points.size(), -1);
  std::vector<int> best_distance(map.points.size(), std::numeric_limits<int>::max());
  std::vector<int> touched;
  const double ratio_squared = options_.max_ratio * options_.max_ratio;
  for (int q = 0; q < num_features; ++q) {
    int indices[kNeighbours], distances[kNeighbours];
    const int found = index.forest.Search(features.descriptor(static_cast<size_t>(q)), kNeighbours,
                                          options_.max_leaf_checks, indices, distances, &search_scratch);
    // The nearest observation in a retrieved keyframe; the ratio test compares it with the nearest
    // observation of any other point (ambiguity does not depend on retrieval), and passes when
    // every neighbour found is of the same point.
    int nearest = -1;
    for (int k = 0; k < found && nearest < 0; ++k) {
      if (retrieved[static_cast<size_t>(index.keyframe_of[static_cast<size_t>(indices[k])])]) nearest = k;
    }
    if (nearest < 0) continue;
    const int point = index.point_of[static_cast<size_t>(indices[nearest])];
    const int distance = distances[nearest];
    int second_distance = std::numeric_limits<int>::max();
    for (int k = 0; k < found; ++k) {
      if (index.point_of[static_cast<size_t>(indices[k])] != point) {
        second_distance = distances[k];
        break;
      }
    }
    if (!(static_cast<double>(distance) < ratio_squared * static_cast<double>(second_distance))) continue;
    int& best = best_distance[static_cast<size_t>(point)];
    if (distance < best) {
      if (best_query[static_cast<size_t>(point)] < 0) touched.push_back(point);
      best = distance;
      best_query[static_cast<size_t>(point)] = q;
    }
  }
  std::sort(touched.begin(), touched.end());
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> world;
  std::vector<int> match_keypoint;
  pixels.reserve(touched.size());
  world.reserve(touched.size());
  for (int point : touched) {
    const int q = best_query[static_cast<size_t>(point)];
    const SiftKeypoint& keypoint = features.keypoints[static_cast<size_t>(q)];
    pixels.emplace_back(keypoint.x, keypoint.y);
    world.push_back(map.points[static_cast<size_t>(point)]);
    match_keypoint.push_back(q);
  }
  result.num_matches = static_cast<int>(touched.size());
  result.seconds_matching = SecondsSince(start);
  if (result.num_matches < options_.min_inliers) {
    result.reason = "too few 2D-3D matches (" + std::to_string(result.num_matches) + ", at least " +
                    std::to_string(options_.min_inliers) + " needed)";
    return result;
  }

  // 3. Pose.
  start = Clock::now();
  AbsolutePoseOptions pose_options = options_.pose;
  pose_options.min_inliers = options_.min_inliers;
  RadialCamera query_camera;
  Result<AbsolutePoseResult> pose = InvalidArgument("unset");
  if (camera.known) {
    query_camera = *camera.known;
    pose = EstimateAbsolutePose(pixels, world, query_camera, pose_options);
  } else {
    query_camera.focal = camera.focal_prior_px;
    query_camera.cx = 0.5 * (camera.width - 1);
    query_camera.cy = 0.5 * (camera.height - 1);
    pose = EstimateAbsolutePoseUnknownFocal(pixels, world, query_camera, pose_options);
  }
  result.seconds_pose = SecondsSince(start);
  if (!pose.ok()) return pose.status();
  if (!pose->success()) {
    result.reason = pose->reason;
    return result;
  }
  result.num_inliers = pose->num_inliers;
  const double inlier_ratio = static_cast<double>(pose->num_inliers) / result.num_matches;
  if (inlier_ratio < options_.min_inlier_ratio) {
    result.reason = "inliers are " + std::to_string(pose->num_inliers) + " of " + std::to_string(result.num_matches) +
                    " matches, below the ratio " + std::to_string(options_.min_inlier_ratio);
    return result;
  }
  result.registered = true;
  result.cam_from_world = pose->cam_from_world;
  result.camera = query_camera;
  result.camera.focal = pose->focal;
  result.mean_inlier_error_px = pose->mean_inlier_error_px;
  for (int i : pose->inliers) {
    result.inlier_keypoints.push_back(match_keypoint[static_cast<size_t>(i)]);
    result.inlier_points.push_back(touched[static_cast<size_t>(i)]);
  }
  return result;
}

}  // namespace reconar
