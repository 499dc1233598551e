#pragma once
// `reconar localize PROJECT IMAGE|DIR...`: each photo decoded (EXIF orientation applied), its SIFT
// features extracted with the project's settings, its camera resolved (ResolveQueryCamera) and its
// pose found against the project's localisation map (core/sfm/localizer.h).

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/features/sift/sift.h"
#include "core/math/camera_intrinsics.h"
#include "core/sfm/localizer.h"

namespace reconar {

struct LocalizePhotosOptions {
  LocalizePhotosOptions();  // sift: the feature stage's defaults (ReconstructOptions)

  LocalizerOptions localizer;
  SiftOptions sift;
  std::optional<CameraIntrinsics> intrinsics;  // --intrinsics: the query camera, else resolved per photo
  int num_threads = 0;                         // photos at a time; 0: one per core
  bool show_progress = true;

  Status Check() const;
};

struct PhotoLocalization {
  std::string image;  // file name
  std::string path;
  int width = 0, height = 0;
  std::string error;  // the photo could not be read or its features extracted (then no result)
  LocalizationResult result;
  double seconds_features = 0.0;
  double seconds = 0.0;  // decode + features + localisation
};

// One result per path, in order; a photo that cannot be read is a result with `error`, not a failed
// call. InvalidArgument on bad options.
Result<std::vector<PhotoLocalization>> LocalizePhotos(const LocalizationMap& map, const std::vector<std::string>& paths,
                                                      const LocalizePhotosOptions& options);

// The one-line JSON of `reconar localize --json`: {"image", "registered", "cam_from_world": {"R":
// [9, row-major], "t": [3]}, "camera": {"width", "height", "fx", "fy", "cx", "cy", "k1", "k2",
// "source"}, "inliers", "matches", "ms", "reason"}.
std::string PhotoLocalizationJson(const PhotoLocalization& photo);

}  // namespace reconar
