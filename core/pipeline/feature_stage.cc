#include "core/pipeline/feature_stage.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>

#include "core/base/atomic_file.h"
#include "core/base/log.h"
#include "core/base/memory_usage.h"
#include "core/base/progress.h"
#include "core/base/thread_pool.h"
#include "core/features/sift/sift_io.h"
#include "core/io/focal_prior.h"
#include "core/io/image_io.h"
#include "core/pipeline/stage_record.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

std::string KeyPathFor(const FeatureStageOptions& options, const std::string& image_path, size_t num_images) {
  if (options.key_output.empty()) return "";
  std::error_code ec;
  if (num_images == 1 && !fs::is_directory(options.key_output, ec)) return options.key_output;
  return (fs::path(options.key_output) / fs::path(image_path).stem()).string() + ".key";
}

}  // namespace

PhotoFeatureExtractor::PhotoFeatureExtractor(const FeatureStageOptions& options) : options_(options) {}
PhotoFeatureExtractor::~PhotoFeatureExtractor() = default;
PhotoFeatureExtractor::PhotoFeatureExtractor(PhotoFeatureExtractor&&) noexcept = default;

Result<ImageFeatureSummary> PhotoFeatureExtractor::Extract(const std::string& path, SiftFeatures* features) {
  const auto start = Clock::now();
  auto decoded = ReadImage(path);
  if (!decoded.ok()) return decoded.status();
  ImageFeatureSummary summary;
  summary.warnings = decoded->warnings;
  const Image<float> gray = ToGrayFloat(decoded->rgb);
  const FocalPrior prior = EstimateFocalPrior(decoded->exif, gray.width(), gray.height());
  summary.image.name = fs::path(path).filename().string();
  summary.image.path = path;
  summary.image.width = gray.width();
  summary.image.height = gray.height();
  summary.image.focal_px = prior.focal_px;
  summary.image.focal_source = FocalPriorSourceName(prior.source);
  summary.focal_explanation = prior.explanation;

  if (!configured_) configured_ = std::make_unique<SiftExtractor>(options_.sift);
  SiftExtractor* used = configured_.get();
  auto result = used->Extract(gray.view());
  if (!result.ok() && result.status().code() == StatusCode::kResourceExhausted && options_.sift.first_octave < 0) {
    if (!fallback_) {
      SiftOptions fallback = options_.sift;
      fallback.first_octave = 0;
      fallback_ = std::make_unique<SiftExtractor>(fallback);
    }
    summary.warnings.push_back("first octave 0 used: " + result.status().message());
    used = fallback_.get();
    result = used->Extract(gray.view());
  }
  if (!result.ok()) return Status(result.status().code(), path + ": " + result.status().message());
  summary.num_features = static_cast<int>(result->keypoints.size());
  *features = std::move(result).value();
  summary.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return summary;
}

std::string FeatureStageSettings(const FeatureStageOptions& options) {
  const SiftOptions& sift = options.sift;
  return StageRecord::Settings({{"first_octave", sift.first_octave},
                                {"max_features", sift.max_features},
                                {"contrast_threshold", sift.contrast_threshold},
                                {"arena_mib", Mib(sift.arena_bytes)}});
}

Result<FeatureStageReport> RunFeatureStage(const std::vector<std::string>& image_paths, const Project* project,
                                           const FeatureStageOptions& options,
                                           std::vector<SiftFeatures>* features_out) {
  RECONAR_RETURN_IF_ERROR(options.sift.Check());
  const auto start = Clock::now();
  if (project != nullptr) RECONAR_RETURN_IF_ERROR(CreateDirectories(project->FeaturesDir()));
  if (!options.key_output.empty() && image_paths.size() > 1) {
    RECONAR_RETURN_IF_ERROR(CreateDirectories(options.key_output));
  }
  const size_t n = image_paths.size();
  const int threads = std::min<int>(ThreadPool::ResolveThreadCount(options.num_threads), static_cast<int>(n));
  ThreadPool pool(threads);
  std::vector<PhotoFeatureExtractor> extractors;
  for (int w = 0; w < pool.num_threads(); ++w) extractors.emplace_back(options);
  std::vector<std::optional<ImageFeatureSummary>> summaries(n);
  // Kept only for callers that asked for them; project runs stream each image's features to disk.
  std::vector<SiftFeatures> features(features_out != nullptr ? n : 0);
  std::vector<std::string> skipped(n);
  std::vector<Status> output_errors(n);
  std::optional<Progress> progress;
  if (options.show_progress) progress.emplace("features", n);

  pool.ParallelFor(0, n, [&](size_t i, int worker) {
    const std::string& path = image_paths[i];
    SiftFeatures extracted;
    auto summary = extractors[worker].Extract(path, &extracted);
    if (!summary.ok()) {
      skipped[i] = summary.status().message();
      if (progress) progress->Advance();
      return;
    }
    if (project != nullptr) {
      FeatureFile file{summary->image.width, summary->image.height, extracted};
      output_errors[i] = WriteFeatureFile(project->FeaturePath(summary->image.name), file);
    }
    const std::string key_path = KeyPathFor(options, path, n);
    if (output_errors[i].ok() && !key_path.empty()) output_errors[i] = WriteLoweKeyFile(key_path, extracted);
    if (features_out != nullptr) features[i] = std::move(extracted);
    summaries[i] = std::move(summary).value();
    if (progress) progress->Advance();
  });
  if (progress) progress->Finish();

  for (const Status& status : output_errors) RECONAR_RETURN_IF_ERROR(status);
  FeatureStageReport report;
  std::vector<ProjectImage> listed;
  for (size_t i = 0; i < n; ++i) {
    if (!skipped[i].empty()) {
      report.skipped.push_back(skipped[i]);
      continue;
    }
    listed.push_back(summaries[i]->image);
    report.extracted.push_back(std::move(*summaries[i]));
    if (features_out != nullptr) features_out->push_back(std::move(features[i]));
  }
  if (report.extracted.empty()) {
    std::string reasons;
    for (const std::string& s : report.skipped) reasons += "\n  " + s;
    return InvalidArgument("no image could be processed:" + reasons);
  }
  if (project != nullptr) RECONAR_RETURN_IF_ERROR(project->WriteImageList(listed));
  report.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return report;
}

bool FeaturesUpToDate(const Project& project, const std::vector<std::string>& paths) {
  auto list = project.ReadImageList();
  if (!list.ok() || list->size() != paths.size()) return false;
  for (size_t i = 0; i < paths.size(); ++i) {
    std::error_code error;
    // A project made before paths were kept absolute lists them as they were given.
    const std::filesystem::path listed = std::filesystem::absolute((*list)[i].path, error).lexically_normal();
    if (listed.string() != std::filesystem::path(paths[i]).lexically_normal().string() ||
        !std::filesystem::exists(project.FeaturePath((*list)[i].name), error)) {
      return false;
    }
  }
  return true;
}

}  // namespace reconar
