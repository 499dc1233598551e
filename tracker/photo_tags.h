#pragma once
// AprilTags in a set of photographs (the `tags` stage of `reconar reconstruct`): each photo is
// decoded upright (EXIF orientation, as the feature stage reads it), turned grey and searched
// with TagDetector; the corners come out in the SfM pixel convention (core/sfm/tag_observations.h).
// An id seen twice in one photo is dropped there (which print is which cannot be told).
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/sfm/tag_observations.h"
#include "tracker/tag_detector.h"

namespace reconar {

struct PhotoTagOptions {
  TagFamily family = TagFamily::kTag36h11;
  // Quad decimation: photos up to this long side are searched at full resolution (libapriltag
  // finds small tags there that decimation 2 misses); larger ones at decimation 2.
  int full_resolution_max_side = 2048;
  int num_threads = 0;  // 0: one per core
  bool show_progress = true;

  Status Check() const;
};

struct PhotoTagReport {
  int photos = 0;
  int photos_with_tags = 0;
  int detections = 0;
  int duplicates_dropped = 0;
  double seconds = 0.0;
};

// Every detection in one photo, duplicates kept.
struct PhotoDetections {
  std::string image_name;  // the file name
  int width = 0;           // the upright photo's size, pixels
  int height = 0;
  // TagDetector's output: id, hamming, decision margin, corners in libapriltag's order and the
  // program's pixel convention (centre of the top-left pixel at (0, 0)).
  std::vector<TagDetection> detections;
};

// Each photo decoded, turned grey and searched as the tags stage does (one entry per path, in
// order; what `reconar tags PHOTO...` prints). Errors name the photo that could not be read.
Result<std::vector<PhotoDetections>> DetectAllTagsInPhotos(const std::vector<std::string>& paths,
                                                           const PhotoTagOptions& options);

// The tags stage's observations: DetectAllTagsInPhotos without the ids seen twice in a photo,
// sorted by id. One entry per path, named by the file name (as features/images.txt names the
// photos). Errors name the photo that could not be read.
Result<TagDetectionsFile> DetectTagsInPhotos(const std::vector<std::string>& paths, const PhotoTagOptions& options,
                                             PhotoTagReport* report = nullptr);

}  // namespace reconar
