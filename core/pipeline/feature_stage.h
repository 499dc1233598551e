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
  // Texture-poor photos: when a photo yields fewer than texture_poor_min_features features, the
  // contrast threshold is halved and the photo extracted again, down to
  // texture_poor_min_contrast_threshold (three halvings of Lowe's 0.04; COLMAP's default is 0.02 in
  // these units) or until the count is reached (the image's summary says so). A plaster figure on
  // velvet gives a hundred features at 0.04, too few for a sparse ring's neighbours to match
  // (dinoSparseRing). Off (0) by default; `--texture-poor` sets 1000 (UseTexturePoorSettings in
  // core/pipeline/reconstruct.h says why not always).
  int texture_poor_min_features = 0;
  double texture_poor_min_contrast_threshold = 0.005;
};

struct ImageFeatureSummary {
  ProjectImage image;
  int num_features = 0;
  double contrast_threshold = 0;  // the one used (below SiftOptions' for a texture-poor photo)
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
