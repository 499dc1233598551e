#pragma once
// Feature stage: decode each photo, take its focal prior from EXIF, extract SIFT, write
// <project>/features/<name>.rfeat (and optionally Lowe .key files). Unreadable photos are
// skipped with a warning naming the file and the reason; the others proceed.
#include <memory>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/features/sift/sift.h"
#include "core/pipeline/project.h"

namespace reconar {

struct FeatureStageOptions {
  SiftOptions sift;
  int num_threads = 0;          // images in parallel; <= 0: one per core
  std::string key_output;       // "" none; a .key path for one image, else a directory
  bool show_progress = true;
};

struct ImageFeatureSummary {
  ProjectImage image;
  int num_features = 0;
  double seconds = 0;
  std::string focal_explanation;
  std::vector<std::string> warnings;
};

struct FeatureStageReport {
  std::vector<ImageFeatureSummary> extracted;
  std::vector<std::string> skipped;  // "path: reason" per unreadable photo
  double seconds = 0;
};

// What the stage does for one photo: decode it, take its focal prior, extract SIFT (with the
// fallbacks above), reusing its extractors from call to call. An unreadable photo's error names it.
class PhotoFeatureExtractor {
 public:
  explicit PhotoFeatureExtractor(const FeatureStageOptions& options);
  ~PhotoFeatureExtractor();
  PhotoFeatureExtractor(PhotoFeatureExtractor&&) noexcept;
  Result<ImageFeatureSummary> Extract(const std::string& path, SiftFeatures* features);

 private:
  FeatureStageOptions options_;
  std::unique_ptr<SiftExtractor> configured_;
  std::unique_ptr<SiftExtractor> fallback_;  // first octave 0, for a photo whose doubled octave overflows the arena
};

// The settings under which PROJECT/stages.txt records the stage (stage_record.h).
std::string FeatureStageSettings(const FeatureStageOptions& options);

// Extracts features for every path. With `project` non-null the results are written there and the
// image list is (re)written. Fails only when no image could be processed or an output cannot be
// written; per-image input problems go to report->skipped.
Result<FeatureStageReport> RunFeatureStage(const std::vector<std::string>& image_paths, const Project* project,
                                           const FeatureStageOptions& options,
                                           std::vector<SiftFeatures>* features_out = nullptr);

// The project's image list names exactly these paths, in this order, and every feature file exists.
bool FeaturesUpToDate(const Project& project, const std::vector<std::string>& paths);

}  // namespace reconar
