#pragma once
// The localisation map of a project (PROJECT/map/map.rmap): what a camera needs to find its pose
// against the reconstruction without a tag in view.
//  - points: the sparse model's 3D points in the project's world frame (metres in the world tag's
//    frame when tags registered the model), each with one representative SIFT descriptor: the
//    medoid of the descriptors that observed it (the one with the least summed distance to the
//    others), which frame-to-frame tracking matches against;
//  - keyframes: every registered photo's pose, camera and size, and its observations of map
//    points (keypoint, point id, the observing descriptor), which relocalisation matches against;
//  - a vocabulary tree trained on the keyframes' descriptors and a tf-idf inverted file over the
//    keyframes, which retrieval uses to pick the keyframes a query shares most with.
//
// File format (little-endian, core/base/binary_io.h):
//   char magic[8] = "RCNRMAP\0"; uint32 version = 1; uint64 payload_bytes; uint32 payload_crc32;
//   payload: the header fields, points, keyframes, vocabulary, inverted file (localization_map_io.cc).
// The reader checks magic, version, size and checksum before parsing, then checks every count and
// index while parsing: a damaged, truncated or foreign file is an error naming the file and the
// reason, never a crash (tests/core/sfm/localization_map_fuzz.cc).

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/base/status.h"
#include "core/features/vocabulary_tree.h"
#include "core/math/radial_camera.h"
#include "core/math/rigid3.h"
#include "core/sfm/reconstruction.h"

namespace reconar {

struct MapKeyframe {
  std::string name;  // the photo's file name in the project
  int width = 0;
  int height = 0;
  RadialCamera camera;
  Rigid3 cam_from_world;
  // Observations of map points, one per keypoint that has a 3D point.
  std::vector<Eigen::Vector2f> keypoints;  // pixels
  std::vector<int32_t> point_ids;          // into LocalizationMap::points
  std::vector<uint8_t> descriptors;        // 128 bytes per observation

  int num_observations() const { return static_cast<int>(point_ids.size()); }
};

struct LocalizationMap {
  // "metres, world tag N" when tags registered the model, else "arbitrary".
  std::string frame;
  bool metric = false;
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<uint8_t, 3>> colors;  // RGB per point
  std::vector<uint8_t> point_descriptors;      // 128 bytes per point (the medoid)
  std::vector<MapKeyframe> keyframes;
  VocabularyTree vocabulary;
  InvertedFile keyframe_index;  // image i = keyframes[i]

  int num_points() const { return static_cast<int>(points.size()); }
  int num_observations() const;
  size_t memory_bytes() const;
};

struct MapBuildOptions {
  VocabularyTreeOptions vocabulary;
  // Observations kept per point for the medoid (a random subset beyond this, seeded).
  int max_medoid_candidates = 16;
  int num_threads = 1;  // <= 0: one per core; the map does not depend on it

  Status Check() const;
};

struct MapBuildReport {
  int keyframes = 0;
  int points = 0;
  int observations = 0;
  int words = 0;
  double seconds_descriptors = 0.0;
  double seconds_vocabulary = 0.0;
  double seconds_index = 0.0;
  size_t memory_bytes = 0;
};

// The descriptors (count * 128 bytes, keypoint order of the model's image) of a model image:
// the project's feature file of that image.
using ImageDescriptorLoader = std::function<Result<std::vector<uint8_t>>(const SfmImage& image)>;

// A map from a sparse model: registered images become keyframes, non-deleted points map points
// (renumbered densely). `frame`/`metric` describe the model's world frame. FailedPrecondition
// when the model has no registered image or no point; errors of the loader pass through.
Result<LocalizationMap> BuildLocalizationMap(const Reconstruction& model, const ImageDescriptorLoader& load_descriptors,
                                             const std::string& frame, bool metric, const MapBuildOptions& options,
                                             MapBuildReport* report = nullptr);

// Atomic write (core/base/atomic_file.h).
Status WriteLocalizationMap(const std::string& path, const LocalizationMap& map);
// InvalidArgument naming the file and what is wrong for a foreign, damaged or truncated file;
// NotFound / IoError naming it when it is missing or cannot be read.
Result<LocalizationMap> ReadLocalizationMap(const std::string& path);
// The same from bytes already in memory (`what` names them in errors): the fuzz target.
Result<LocalizationMap> ParseLocalizationMap(std::string_view bytes, const std::string& what);

}  // namespace reconar
