#include "core/pipeline/localize_photos.h"

#include <chrono>
#include <filesystem>
#include <memory>

#include "core/base/elapsed.h"
#include "core/base/json_writer.h"
#include "core/math/rigid3_json.h"
#include "core/base/progress.h"
#include "core/base/thread_pool.h"
#include "core/io/focal_prior.h"
#include "core/io/gray.h"
#include "core/io/image_io.h"
#include "core/pipeline/reconstruct.h"

namespace reconar {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

LocalizePhotosOptions::LocalizePhotosOptions() : sift(ReconstructOptions().features.sift) {}

Status LocalizePhotosOptions::Check() const {
  RECONAR_RETURN_IF_ERROR(localizer.Check());
  RECONAR_RETURN_IF_ERROR(sift.Check());
  if (intrinsics && !intrinsics->valid()) return InvalidArgument("--intrinsics: the focal lengths must be positive");
  return Status::Ok();
}

Result<std::vector<PhotoLocalization>> LocalizePhotos(const LocalizationMap& map, const std::vector<std::string>& paths,
                                                      const LocalizePhotosOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  RECONAR_ASSIGN_OR_RETURN(const Localizer localizer, Localizer::Create(&map, options.localizer));
  std::vector<PhotoLocalization> photos(paths.size());
  const int threads =
      std::max(1, std::min<int>(ThreadPool::ResolveThreadCount(options.num_threads), static_cast<int>(paths.size())));
  ThreadPool pool(threads);
  std::vector<std::unique_ptr<SiftExtractor>> extractors(static_cast<size_t>(pool.num_threads()));
  std::optional<Progress> progress;
  if (options.show_progress) progress.emplace("localize", paths.size());
  std::vector<Status> failures(paths.size());
  pool.ParallelFor(0, paths.size(), [&](size_t i, int worker) {
    const auto start = Clock::now();
    PhotoLocalization& photo = photos[i];
    photo.path = paths[i];
    photo.image = std::filesystem::path(paths[i]).filename().string();
    auto decoded = ReadImage(paths[i]);
    if (!decoded.ok()) {
      photo.error = decoded.status().message();
      if (progress) progress->Advance();
      return;
    }
    const Image<float> gray = ToGrayFloat(decoded->rgb);
    photo.width = gray.width();
    photo.height = gray.height();
    auto& extractor = extractors[static_cast<size_t>(worker)];
    if (!extractor) extractor = std::make_unique<SiftExtractor>(options.sift);
    auto features = extractor->Extract(gray.view());
    photo.seconds_features = SecondsSince(start);
    if (!features.ok()) {
      photo.error = paths[i] + ": " + features.status().message();
      if (progress) progress->Advance();
      return;
    }
    const FocalPrior prior = EstimateFocalPrior(decoded->exif, photo.width, photo.height);
    const double exif_focal = prior.source == FocalPrior::Source::kDefault ? 0.0 : prior.focal_px;
    auto camera = ResolveQueryCamera(map, photo.width, photo.height, options.intrinsics, exif_focal);
    if (!camera.ok()) {
      failures[i] = camera.status().WithContext(paths[i]);
    } else if (auto result = localizer.Localize(*features, *camera); !result.ok()) {
      failures[i] = result.status().WithContext(paths[i]);
    } else {
      photo.result = std::move(*result);
    }
    photo.seconds = SecondsSince(start);
    if (progress) progress->Advance();
  });
  if (progress) progress->Finish();
  for (const Status& failure : failures) RECONAR_RETURN_IF_ERROR(failure);
  return photos;
}

std::string PhotoLocalizationJson(const PhotoLocalization& photo) {
  const LocalizationResult& r = photo.result;
  JsonWriter json;
  json.BeginObject().Key("image").String(photo.image).Key("registered").Bool(r.registered);
  if (r.registered) {
    WriteRigid3Json(json.Key("cam_from_world"), r.cam_from_world);
    json.Key("camera").BeginObject().Key("width").Int(photo.width).Key("height").Int(photo.height);
    json.Key("fx").Double(r.camera.focal).Key("fy").Double(r.camera.fy()).Key("cx").Double(r.camera.cx);
    json.Key("cy").Double(r.camera.cy).Key("k1").Double(r.camera.k1).Key("k2").Double(r.camera.k2);
    json.Key("source").String(r.camera_source).EndObject();
  }
  json.Key("inliers").Int(r.num_inliers).Key("matches").Int(r.num_matches).Key("features").Int(r.num_features);
  json.Key("ms").Double(photo.seconds * 1000.0);
  const std::string reason = !photo.error.empty() ? photo.error : r.reason;
  json.Key("reason").String(reason);
  json.EndObject();
  return json.str();
}

}  // namespace reconar
