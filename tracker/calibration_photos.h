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

}  // namespace reconar
