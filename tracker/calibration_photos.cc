#include "tracker/calibration_photos.h"

#include <memory>

#include "core/base/progress.h"
#include "core/io/gray.h"
#include "core/io/image_io.h"
#include "core/io/intrinsics_file.h"

namespace reconar {

Result<std::vector<CalibrationImage>> DetectCalibrationImages(const std::vector<std::string>& paths,
                                                              const CalibrationPhotoOptions& options, int* tags_found) {
  RECONAR_ASSIGN_OR_RETURN(std::unique_ptr<TagDetector> detector, TagDetector::Create(options.detector));
  std::vector<CalibrationImage> images;
  images.reserve(paths.size());
  TagDetectionList detections(256);
  int total_tags = 0;
  std::unique_ptr<Progress> progress;
  if (options.show_progress) progress = std::make_unique<Progress>("calibrate: detecting tags", paths.size());
  for (const std::string& path : paths) {
    RECONAR_ASSIGN_OR_RETURN(const DecodedImage image, ReadImage(path));
    const Image<uint8_t> gray = ToGray8(image.rgb);
    if (Status s = detector->Detect(gray.view(), &detections); !s.ok()) return s.WithContext(path);
    total_tags += detections.size();
    if (progress) progress->Advance();
    images.push_back(MakeCalibrationImage(path, gray.width(), gray.height(), detections));
  }
  if (progress) progress->Finish();
  if (tags_found != nullptr) *tags_found = total_tags;
  return images;
}

Result<PhotoCalibrationReport> CalibrateFromPhotos(const std::vector<std::string>& paths,
                                                   CalibrationObservations targets,
                                                   const CalibrationPhotoOptions& photo_options,
                                                   const CalibrationOptions& options,
                                                   const std::string& intrinsics_path) {
  PhotoCalibrationReport report;
  RECONAR_ASSIGN_OR_RETURN(targets.images, DetectCalibrationImages(paths, photo_options, &report.tags_found));
  report.images = targets.images.size();
  RECONAR_ASSIGN_OR_RETURN(report.calibration, CalibrateIntrinsics(targets, options));
  RECONAR_RETURN_IF_ERROR(WriteIntrinsics(intrinsics_path, report.calibration.intrinsics));
  return report;
}

}  // namespace reconar
