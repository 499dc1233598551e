#pragma once
// The tags in photos taken for calibration (`reconar calibrate`): each photo decoded (core/io),
// turned grey and searched with one TagDetector, as a CalibrationImage (tracker/calibration.h).
#include <string>
#include <vector>

#include "core/base/status.h"
#include "tracker/calibration.h"
#include "tracker/tag_detector.h"

namespace reconar {

struct CalibrationPhotoOptions {
  TagDetectorOptions detector;  // `reconar calibrate` searches at quad_decimate 1 (small tags in photos)
  bool show_progress = true;    // a progress line on stderr
};

// One image per path, in order; *tags_found (if given) counts the detections. Errors name the
// photo that could not be read or searched; errors of TagDetector::Create.
Result<std::vector<CalibrationImage>> DetectCalibrationImages(const std::vector<std::string>& paths,
                                                              const CalibrationPhotoOptions& options,
                                                              int* tags_found = nullptr);

struct PhotoCalibrationReport {
  CalibrationReport calibration;
  int tags_found = 0;  // detections in all the photos
  size_t images = 0;   // photos searched
};

// `reconar calibrate`: the tags in the photos (DetectCalibrationImages), the intrinsics from their
// corners (CalibrateIntrinsics; `targets` gives the tag size and the optional layout, its images
// are filled here) written to `intrinsics_path` (core/io/intrinsics_file.h, atomically).
Result<PhotoCalibrationReport> CalibrateFromPhotos(const std::vector<std::string>& paths,
                                                   CalibrationObservations targets,
                                                   const CalibrationPhotoOptions& photo_options,
                                                   const CalibrationOptions& options,
                                                   const std::string& intrinsics_path);

}  // namespace reconar
