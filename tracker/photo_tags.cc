#include "tracker/photo_tags.h"

#include <algorithm>
#include <chrono>
#include <map>
#include <memory>

#include "core/base/progress.h"
#include "core/base/thread_pool.h"
#include "core/io/image_io.h"

namespace reconar {
namespace {

std::string FileName(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

Status PhotoTagOptions::Check() const {
  if (full_resolution_max_side < 1) return InvalidArgument("PhotoTagOptions.full_resolution_max_side must be >= 1");
  return Status::Ok();
}

Result<std::vector<PhotoDetections>> DetectAllTagsInPhotos(const std::vector<std::string>& paths,
                                                           const PhotoTagOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  ThreadPool pool(ThreadPool::ResolveThreadCount(options.num_threads));
  // One detector per worker and decimation (libapriltag's detector is not reentrant).
  std::vector<std::unique_ptr<TagDetector>> full(static_cast<size_t>(pool.num_threads()));
  std::vector<std::unique_ptr<TagDetector>> decimated(static_cast<size_t>(pool.num_threads()));
  for (int w = 0; w < pool.num_threads(); ++w) {
    TagDetectorOptions detector;
    detector.family = options.family;
    detector.quad_decimate = 1.0f;
    RECONAR_ASSIGN_OR_RETURN(full[static_cast<size_t>(w)], TagDetector::Create(detector));
    detector.quad_decimate = 2.0f;
    RECONAR_ASSIGN_OR_RETURN(decimated[static_cast<size_t>(w)], TagDetector::Create(detector));
  }
  std::vector<PhotoDetections> photos(paths.size());
  std::vector<Status> errors(paths.size());
  std::unique_ptr<Progress> progress;
  if (options.show_progress) progress = std::make_unique<Progress>("tags", paths.size());
  pool.ParallelFor(0, paths.size(), [&](size_t i, int worker) {
    PhotoDetections& out = photos[i];
    out.image_name = FileName(paths[i]);
    auto decoded = ReadImage(paths[i]);
    if (!decoded.ok()) {
      errors[i] = decoded.status();
    } else {
      const Image<uint8_t> gray = ToGray8(decoded->rgb);
      out.width = gray.width();
      out.height = gray.height();
      const bool small = std::max(gray.width(), gray.height()) <= options.full_resolution_max_side;
      TagDetector& detector = small ? *full[static_cast<size_t>(worker)] : *decimated[static_cast<size_t>(worker)];
      TagDetectionList list(256);
      const Status status = detector.Detect(gray.view(), &list);
      if (!status.ok()) {
        errors[i] = status.WithContext(paths[i]);
      } else {
        out.detections.assign(list.begin(), list.end());
      }
    }
    if (progress) progress->Advance();
  });
  if (progress) progress->Finish();
  for (const Status& status : errors) RECONAR_RETURN_IF_ERROR(status);
  return photos;
}

Result<TagDetectionsFile> DetectTagsInPhotos(const std::vector<std::string>& paths, const PhotoTagOptions& options,
                                             PhotoTagReport* report) {
  const auto start = std::chrono::steady_clock::now();
  RECONAR_ASSIGN_OR_RETURN(const std::vector<PhotoDetections> photos, DetectAllTagsInPhotos(paths, options));
  TagDetectionsFile file;
  file.family = TagFamilyName(options.family);
  file.images.resize(paths.size());
  std::vector<int> duplicates(paths.size(), 0);
  for (size_t i = 0; i < photos.size(); ++i) {
    ImageTagObservations& out = file.images[i];
    out.image_name = photos[i].image_name;
    std::map<int, int> count;
    for (const TagDetection& d : photos[i].detections) ++count[d.id];
    for (const TagDetection& d : photos[i].detections) {
      if (count[d.id] != 1) {
        ++duplicates[i];
        continue;
      }
      TagObservation tag;
      tag.tag_id = d.id;
      for (size_t k = 0; k < 4; ++k) tag.corners[k] = d.corners[k];
      out.tags.push_back(tag);
    }
    std::sort(out.tags.begin(), out.tags.end(),
              [](const TagObservation& a, const TagObservation& b) { return a.tag_id < b.tag_id; });
  }
  if (report != nullptr) {
    *report = PhotoTagReport();
    report->photos = static_cast<int>(paths.size());
    for (size_t i = 0; i < paths.size(); ++i) {
      report->photos_with_tags += file.images[i].tags.empty() ? 0 : 1;
      report->detections += static_cast<int>(file.images[i].tags.size());
      report->duplicates_dropped += duplicates[i];
    }
    report->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return file;
}

}  // namespace reconar
