#include "core/pipeline/match_stage.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>

#include "core/base/atomic_file.h"
#include "core/base/fnv_hash.h"
#include "core/base/json_writer.h"
#include "core/base/log.h"
#include "core/base/progress.h"
#include "core/base/thread_pool.h"
#include "core/features/sift/sift_io.h"
#include "core/pipeline/feature_stage.h"
#include "core/pipeline/stage_record.h"

namespace reconar {
namespace {

using Clock = std::chrono::steady_clock;

std::vector<Eigen::Vector2d> Positions(const SiftFeatures& features, const std::vector<FeatureMatch>& matches,
                                       bool side_a) {
  std::vector<Eigen::Vector2d> points;
  points.reserve(matches.size());
  for (const FeatureMatch& m : matches) {
    const SiftKeypoint& kp = features.keypoints[side_a ? m.index_a : m.index_b];
    points.emplace_back(kp.x, kp.y);
  }
  return points;
}

// Every pair of a project no larger than the exhaustive limit; beyond, PairSelector's choice, fed
// the images in order (read from their files where the memory budget left them unloaded).
Result<std::vector<std::pair<int, int>>> ChoosePairs(const Project& project, const std::vector<ProjectImage>& images,
                                                     const std::vector<FeatureFile>& files, bool loaded,
                                                     const PairSelectionOptions& options, int threads) {
  const int n = static_cast<int>(images.size());
  std::vector<std::pair<int, int>> pairs;
  if (n <= options.exhaustive_up_to) {
    for (int i = 0; i < n; ++i) {
      for (int j = i + 1; j < n; ++j) pairs.emplace_back(i, j);
    }
    return pairs;
  }
  PairSelectionOptions on_threads = options;
  on_threads.vocabulary.num_threads = threads;
  RECONAR_ASSIGN_OR_RETURN(PairSelector selector, PairSelector::Create(on_threads));
  for (int j = 0; j < n; ++j) {
    const SiftFeatures* features = &files[static_cast<size_t>(j)].features;
    FeatureFile read;
    if (!loaded) {
      RECONAR_ASSIGN_OR_RETURN(read, ReadFeatureFile(project.FeaturePath(images[static_cast<size_t>(j)].name)));
      features = &read.features;
    }
    RECONAR_ASSIGN_OR_RETURN(const std::vector<int> partners,
                             selector.Add(features->descriptors.data(), static_cast<int>(features->keypoints.size())));
    for (const int i : partners) pairs.emplace_back(i, j);
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace

std::string ExtractAgainDigest(const std::map<std::string, std::string>& names) {
  if (names.empty()) return "";
  Fnv1a64 hash;
  for (const auto& entry : names) {
    hash.Add(entry.first);
    hash.Add("\n");
  }
  char text[40];
  std::snprintf(text, sizeof(text), " again=%zu:%016llx", names.size(), static_cast<unsigned long long>(hash.value()));
  return text;
}

namespace {

// Per image: the pairs it is in that verified (as a general or a planar two-view geometry).
std::vector<int> VerifiedPartners(const std::vector<std::optional<VerifiedPair>>& results, size_t num_images) {
  std::vector<int> partners(num_images, 0);
  for (const std::optional<VerifiedPair>& result : results) {
    if (!result || result->geometry.config == TwoViewGeometry::Config::kTooFewInliers) continue;
    ++partners[static_cast<size_t>(result->image_a)];
    ++partners[static_cast<size_t>(result->image_b)];
  }
  return partners;
}

}  // namespace

std::vector<ReextractionReason> PhotosToExtractAgain(const std::vector<int>& partners,
                                                     const std::vector<int>& feature_counts, int min_partners) {
  const size_t n = partners.size();
  std::vector<ReextractionReason> reasons(n, ReextractionReason::kNone);
  if (n == 0 || min_partners <= 0) return reasons;
  const auto median_of = [](std::vector<int> values) {  // the mean of the middle two for an even count
    std::sort(values.begin(), values.end());
    return 0.5 * (values[(values.size() - 1) / 2] + values[values.size() / 2]);
  };
  if (median_of(partners) < min_partners) {
    for (ReextractionReason& reason : reasons) reason = ReextractionReason::kTheSetMatchesPoorly;
    return reasons;
  }
  const double median_features = median_of(feature_counts);
  int texture_poor_bound = -1;  // the most features a poorly matched photo under the median has
  for (size_t i = 0; i < n; ++i) {
    if (partners[i] >= min_partners) continue;
    reasons[i] = ReextractionReason::kPoorlyMatched;
    if (feature_counts[i] < median_features) texture_poor_bound = std::max(texture_poor_bound, feature_counts[i]);
  }
  for (size_t i = 0; i < n; ++i) {
    if (reasons[i] == ReextractionReason::kNone && feature_counts[i] <= texture_poor_bound)
      reasons[i] = ReextractionReason::kAsTexturePoor;
  }
  return reasons;
}

std::string ReextractionReasonText(ReextractionReason reason, int partners, int min_partners) {
  const std::string matched = "matched with " + std::to_string(partners) + " other photo(s)";
  switch (reason) {
    case ReextractionReason::kNone: return "";
    case ReextractionReason::kPoorlyMatched: return matched + ", need " + std::to_string(min_partners);
    case ReextractionReason::kAsTexturePoor:
      return matched + ", but has no more features than a poorly matched photo with fewer than the set's median";
    case ReextractionReason::kTheSetMatchesPoorly:
      return matched + "; the set's median photo matched with fewer than " + std::to_string(min_partners);
    case ReextractionReason::kAskedFor: return "asked for";
  }
  return "";
}

double MatchBytesPerFeature(const MatchOptions& match, int workers) {
  // A descriptor and its keypoint, and in every worker's forest one point id per tree plus about
  // 2 / leaf_size nodes of 12 bytes per point (KdForest reserves that many).
  const double forest = match.num_trees * (sizeof(int32_t) + 2.0 * 12.0 / std::max(1, match.leaf_size));
  return 128.0 + sizeof(SiftKeypoint) + workers * forest;
}

Result<VerifiedPair> VerifyMatches(const SiftFeatures& a, int width_a, int height_a, const SiftFeatures& b,
                                   int width_b, int height_b, const std::vector<FeatureMatch>& putative,
                                   const TwoViewOptions& options) {
  VerifiedPair pair;
  pair.num_putative = static_cast<int>(putative.size());
  RECONAR_ASSIGN_OR_RETURN(pair.geometry, VerifyTwoView(Positions(a, putative, true), Positions(b, putative, false),
                                                        width_a, height_a, width_b, height_b, options));
  pair.inlier_matches.reserve(pair.geometry.inliers.size());
  for (int index : pair.geometry.inliers) pair.inlier_matches.push_back(putative[index]);
  return pair;
}

namespace {

// One pair's step: the matches of image i (features a) in image j (features b), both added to
// `matcher`, verified.
Result<VerifiedPair> MatchAndVerify(Matcher* matcher, int i, int j, const FeatureFile& a, const FeatureFile& b,
                                    const TwoViewOptions& options) {
  RECONAR_ASSIGN_OR_RETURN(const std::vector<FeatureMatch> putative, matcher->Match(i, j));
  RECONAR_ASSIGN_OR_RETURN(VerifiedPair pair, VerifyMatches(a.features, a.image_width, a.image_height, b.features,
                                                            b.image_width, b.image_height, putative, options));
  pair.image_a = i;
  pair.image_b = j;
  return pair;
}

}  // namespace

Result<TwoPhotoMatch> MatchTwoPhotos(const std::string& path_a, const std::string& path_b, const SiftOptions& sift,
                                     const MatchStageOptions& options) {
  FeatureStageOptions feature_options;
  feature_options.sift = sift;
  feature_options.num_threads = options.num_threads;
  feature_options.show_progress = false;
  std::vector<SiftFeatures> features;
  RECONAR_ASSIGN_OR_RETURN(const FeatureStageReport extracted,
                           RunFeatureStage({path_a, path_b}, nullptr, feature_options, &features));
  if (!extracted.skipped.empty()) return InvalidArgument(extracted.skipped.front());
  RECONAR_ASSIGN_OR_RETURN(std::unique_ptr<Matcher> matcher, Matcher::Create(options.match));
  FeatureFile files[2];
  for (int k = 0; k < 2; ++k) {
    files[k].image_width = extracted.extracted[k].image.width;
    files[k].image_height = extracted.extracted[k].image.height;
    files[k].features = std::move(features[k]);
    const SiftFeatures& f = files[k].features;
    RECONAR_RETURN_IF_ERROR(matcher->AddImage(k, f.descriptors.data(), static_cast<int>(f.keypoints.size())));
  }
  TwoPhotoMatch match;
  RECONAR_ASSIGN_OR_RETURN(match.pair, MatchAndVerify(matcher.get(), 0, 1, files[0], files[1], options.two_view));
  for (int k = 0; k < 2; ++k) {
    match.images[k] = extracted.extracted[k].image;
    match.features[k] = std::move(files[k].features);
  }
  return match;
}

std::string MatchedPositionsText(const TwoPhotoMatch& match) {
  std::string text;
  char line[128];
  for (const FeatureMatch& m : match.pair.inlier_matches) {
    const SiftKeypoint& ka = match.features[0].keypoints[m.index_a];
    const SiftKeypoint& kb = match.features[1].keypoints[m.index_b];
    std::snprintf(line, sizeof(line), "%.3f %.3f %.3f %.3f\n", ka.x, ka.y, kb.x, kb.y);
    text += line;
  }
  return text;
}

std::string MatchStageSettings(const MatchStageOptions& options) {
  return StageRecord::Settings({{"ratio", options.match.max_ratio},
                                {"checks", options.match.max_leaf_checks},
                                {"min_inliers", options.two_view.min_inliers},
                                {"f_threshold", options.two_view.f_threshold_fraction},
                                {"poorly_matched_partners", options.poorly_matched.min_partners},
                                {"poorly_matched_contrast", options.poorly_matched.contrast_threshold}}) +
         " pairs=" + options.pairs.Describe() + ExtractAgainDigest(options.extract_again);
}

Result<MatchStageReport> RunMatchStage(const Project& project, const MatchStageOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.match.Check());
  RECONAR_RETURN_IF_ERROR(options.two_view.Check());
  const auto start = Clock::now();
  RECONAR_ASSIGN_OR_RETURN(const std::vector<ProjectImage> images, project.ReadImageList());
  if (images.size() < 2) {
    return InvalidArgument(project.ImageListPath() + ": matching needs at least two images, the project has " +
                           std::to_string(images.size()));
  }
  RECONAR_RETURN_IF_ERROR(options.pairs.Check());
  const int n = static_cast<int>(images.size());
  const int threads = std::min<int>(ThreadPool::ResolveThreadCount(options.num_threads), n * (n - 1) / 2);
  ThreadPool pool(threads);
  const double per_feature = MatchBytesPerFeature(options.match, pool.num_threads());
  const double budget = options.memory_budget_bytes > 0 ? static_cast<double>(options.memory_budget_bytes)
                                                        : std::numeric_limits<double>::infinity();

  // Richer features of an earlier run are not this run's input.
  for (const ProjectImage& image : images) RECONAR_RETURN_IF_ERROR(RemoveFileIfPresent(project.RicherFeaturePath(image.name)));
  // Each image's features: the feature stage's, until it is extracted again.
  std::vector<char> reextracted(images.size(), 0);
  const auto feature_path = [&](size_t i) {
    return reextracted[i] ? project.RicherFeaturePath(images[i].name) : project.FeaturePath(images[i].name);
  };
  // Every image's size and feature count; the features stay loaded while all of them fit.
  std::vector<FeatureFile> files(images.size());
  std::vector<double> image_bytes(images.size());
  std::vector<int> feature_counts(images.size());
  double total_bytes = 0.0;
  bool all_loaded = true;
  for (size_t i = 0; i < images.size(); ++i) {
    // Once over the budget, only the headers are read (the counts); the blocks load the rest.
    FeatureFile file;
    size_t count = 0;
    if (all_loaded) {
      RECONAR_ASSIGN_OR_RETURN(file, ReadFeatureFile(project.FeaturePath(images[i].name)));
      count = file.features.keypoints.size();
    } else {
      RECONAR_ASSIGN_OR_RETURN(const FeatureFileHeader header,
                               ReadFeatureFileHeader(project.FeaturePath(images[i].name)));
      file.image_width = header.image_width;
      file.image_height = header.image_height;
      count = header.count;
    }
    image_bytes[i] = per_feature * static_cast<double>(count);
    feature_counts[i] = static_cast<int>(count);
    total_bytes += image_bytes[i];
    if (all_loaded && total_bytes > budget) {
      all_loaded = false;
      for (FeatureFile& loaded : files) loaded.features = SiftFeatures{};
    }
    if (!all_loaded) file.features = SiftFeatures{};
    files[i] = std::move(file);
  }

  // Consecutive blocks of at most half the budget each, so that two fit at once.
  std::vector<int> block_of(images.size(), 0);
  int num_blocks = 1;
  double block_bytes = 0.0, peak_bytes = total_bytes;
  if (!all_loaded) {
    std::vector<double> bytes_of_block = {0.0};
    for (size_t i = 0; i < images.size(); ++i) {
      if (block_bytes > 0.0 && block_bytes + image_bytes[i] > 0.5 * budget) {
        bytes_of_block.push_back(0.0);
        block_bytes = 0.0;
        ++num_blocks;
      }
      block_bytes += image_bytes[i];
      bytes_of_block.back() = block_bytes;
      block_of[i] = num_blocks - 1;
    }
    std::sort(bytes_of_block.rbegin(), bytes_of_block.rend());
    peak_bytes = bytes_of_block[0] + (bytes_of_block.size() > 1 ? bytes_of_block[1] : 0.0);
  }
  // The chosen pairs in the usual order (image_a < image_b), grouped by the pair of blocks they fall in.
  const auto selection_start = Clock::now();
  using ImagePairs = std::vector<std::pair<int, int>>;
  RECONAR_ASSIGN_OR_RETURN(const ImagePairs pairs,
                           ChoosePairs(project, images, files, all_loaded, options.pairs, pool.num_threads()));
  const double seconds_pair_selection = std::chrono::duration<double>(Clock::now() - selection_start).count();
  std::vector<std::vector<size_t>> pairs_of_blocks(static_cast<size_t>(num_blocks * num_blocks));
  for (size_t p = 0; p < pairs.size(); ++p) {
    pairs_of_blocks[static_cast<size_t>(block_of[pairs[p].first] * num_blocks + block_of[pairs[p].second])].push_back(
        p);
  }

  MatchOptions per_worker = options.match;
  per_worker.num_threads = 1;
  std::vector<std::unique_ptr<Matcher>> matchers(pool.num_threads());
  for (auto& matcher : matchers) {
    RECONAR_ASSIGN_OR_RETURN(matcher, Matcher::Create(per_worker));
  }
  // Holds exactly the images of blocks a and b in memory and in every worker's matcher.
  const auto hold_blocks = [&](int a, int b) -> Status {
    for (size_t i = 0; i < files.size(); ++i) {
      const bool wanted = block_of[i] == a || block_of[i] == b;
      if (!wanted && !all_loaded && !files[i].features.keypoints.empty()) {
        for (auto& matcher : matchers) matcher->RemoveImage(static_cast<int>(i));
        files[i].features = SiftFeatures{};
      }
      if (!wanted || matchers.front()->HasImage(static_cast<int>(i))) continue;
      if (!all_loaded) {
        RECONAR_ASSIGN_OR_RETURN(FeatureFile file, ReadFeatureFile(feature_path(i)));
        files[i].features = std::move(file.features);
      }
      const SiftFeatures& f = files[i].features;
      for (auto& matcher : matchers) {
        RECONAR_RETURN_IF_ERROR(matcher->AddImage(static_cast<int>(i), f.descriptors.data(),
                                                  static_cast<int>(f.keypoints.size())));
      }
    }
    return Status::Ok();
  };

  std::vector<std::optional<VerifiedPair>> results(pairs.size());
  std::vector<Status> errors(pairs.size());
  // Matches and verifies the pairs `chosen` (indices into `pairs`), a pair of blocks at a time.
  const auto match_pairs = [&](const std::vector<char>& chosen, const char* label) -> Status {
    size_t count = 0;
    for (char c : chosen) count += c ? 1 : 0;
    std::optional<Progress> progress;
    if (options.show_progress) progress.emplace(label, count);
    for (int a = 0; a < num_blocks; ++a) {
      for (int b = a; b < num_blocks; ++b) {
        std::vector<size_t> block_pairs;
        for (size_t p : pairs_of_blocks[static_cast<size_t>(a * num_blocks + b)])
          if (chosen[p]) block_pairs.push_back(p);
        if (block_pairs.empty()) continue;
        RECONAR_RETURN_IF_ERROR(hold_blocks(a, b));
        pool.ParallelFor(0, block_pairs.size(), [&](size_t k, int worker) {
          const size_t p = block_pairs[k];
          const auto [i, j] = pairs[p];
          auto verified = MatchAndVerify(matchers[worker].get(), i, j, files[i], files[j], options.two_view);
          if (verified.ok()) {
            results[p] = std::move(verified).value();
          } else {
            errors[p] = verified.status().WithContext(images[i].name + " / " + images[j].name);
          }
          if (progress) progress->Advance();
        });
        for (size_t p : block_pairs) RECONAR_RETURN_IF_ERROR(errors[p]);
      }
    }
    if (progress) progress->Finish();
    return Status::Ok();
  };
  RECONAR_RETURN_IF_ERROR(match_pairs(std::vector<char>(pairs.size(), 1), "matching"));

  // The poorly matched photos, extracted again, and their pairs matched again.
  MatchStageReport report;
  const auto reextraction_start = Clock::now();
  const std::vector<int> partners_before = VerifiedPartners(results, images.size());
  const int needed = std::min(options.poorly_matched.min_partners, n - 1);
  std::vector<ReextractionReason> reasons = PhotosToExtractAgain(partners_before, feature_counts, needed);
  for (size_t i = 0; i < images.size(); ++i) {
    if (reasons[i] == ReextractionReason::kNone && options.extract_again.count(images[i].name) != 0)
      reasons[i] = ReextractionReason::kAskedFor;
  }
  std::vector<char> rematch(pairs.size(), 0);
  {
    FeatureStageOptions richer;
    richer.sift = options.poorly_matched.sift;
    richer.sift.contrast_threshold = options.poorly_matched.contrast_threshold;
    PhotoFeatureExtractor extractor(richer);
    for (size_t i = 0; i < images.size(); ++i) {
      if (reasons[i] == ReextractionReason::kNone) continue;
      SiftFeatures features;
      const Result<ImageFeatureSummary> summary = extractor.Extract(images[i].path, &features);
      if (!summary.ok()) {
        LogWarning("matching: " + images[i].name + " not extracted again: " + summary.status().message());
        continue;
      }
      RECONAR_ASSIGN_OR_RETURN(const FeatureFileHeader before, ReadFeatureFileHeader(project.FeaturePath(images[i].name)));
      if (features.keypoints.size() <= before.count) continue;  // nothing more to find
      FeatureFile file;
      file.image_width = summary->image.width;
      file.image_height = summary->image.height;
      if (file.image_width != files[i].image_width || file.image_height != files[i].image_height) {
        return FileError(StatusCode::kCorruptData, images[i].path, "the photo's size differs from its features'");
      }
      const int features_after = static_cast<int>(features.keypoints.size());
      file.features = std::move(features);
      RECONAR_RETURN_IF_ERROR(WriteFeatureFile(project.RicherFeaturePath(images[i].name), file));
      reextracted[i] = 1;
      for (auto& matcher : matchers) matcher->RemoveImage(static_cast<int>(i));
      files[i].features = all_loaded ? std::move(file.features) : SiftFeatures{};
      MatchStageReport::ReextractedPhoto photo;
      photo.name = images[i].name;
      photo.partners_before = partners_before[i];
      photo.reason = reasons[i] == ReextractionReason::kAskedFor
                         ? options.extract_again.at(images[i].name)
                         : ReextractionReasonText(reasons[i], partners_before[i], needed);
      photo.features_before = static_cast<int>(before.count);
      photo.features_after = features_after;
      photo.contrast_threshold = richer.sift.contrast_threshold;
      report.reextracted.push_back(photo);
    }
    for (size_t p = 0; p < pairs.size(); ++p) rematch[p] = reextracted[pairs[p].first] || reextracted[pairs[p].second];
  }
  if (!report.reextracted.empty()) {
    RECONAR_RETURN_IF_ERROR(match_pairs(rematch, "matching again"));
    const std::vector<int> partners_after = VerifiedPartners(results, images.size());
    for (MatchStageReport::ReextractedPhoto& photo : report.reextracted) {
      for (size_t i = 0; i < images.size(); ++i) {
        if (images[i].name == photo.name) photo.partners_after = partners_after[i];
      }
    }
  }
  report.seconds_reextraction = std::chrono::duration<double>(Clock::now() - reextraction_start).count();
  report.extract_again = options.extract_again;

  report.num_images = static_cast<int>(images.size());
  report.num_pairs = static_cast<int>(pairs.size());
  report.num_blocks = num_blocks;
  report.seconds_pair_selection = seconds_pair_selection;
  report.estimated_peak_bytes = peak_bytes;
  for (auto& result : results) {
    switch (result->geometry.config) {
      case TwoViewGeometry::Config::kVerified: ++report.num_verified; break;
      case TwoViewGeometry::Config::kPlanarOrRotation: ++report.num_planar; break;
      case TwoViewGeometry::Config::kTooFewInliers: ++report.num_rejected; continue;
    }
    report.pairs.push_back(std::move(*result));
  }
  RECONAR_RETURN_IF_ERROR(WriteMatchesFile(project, images, report.pairs));
  report.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  RECONAR_RETURN_IF_ERROR(WriteFileAtomically(project.MatchesDir() + "/report.json", MatchStageReportJson(report)));
  return report;
}

std::string MatchStageReportJson(const MatchStageReport& report) {
  JsonWriter json(2);
  json.BeginObject();
  json.Key("images").Int(report.num_images).Key("pairs_matched").Int(report.num_pairs);
  json.Key("pairs_verified").Int(report.num_verified).Key("pairs_planar").Int(report.num_planar);
  json.Key("seconds").Double(report.seconds).Key("seconds_reextraction").Double(report.seconds_reextraction);
  json.Key("reextracted").BeginArray();
  for (const MatchStageReport::ReextractedPhoto& photo : report.reextracted) {
    json.BeginObject().Key("image").String(photo.name);
    json.Key("reason").String(photo.reason);
    json.Key("partners_before").Int(photo.partners_before).Key("partners_after").Int(photo.partners_after);
    json.Key("features_before").Int(photo.features_before).Key("features_after").Int(photo.features_after);
    json.Key("contrast_threshold").Double(photo.contrast_threshold).EndObject();
  }
  json.EndArray();
  json.Key("extract_again").BeginArray();
  for (const auto& [name, reason] : report.extract_again)
    json.BeginObject().Key("image").String(name).Key("reason").String(reason).EndObject();
  json.EndArray().EndObject();
  return json.str() + "\n";
}

}  // namespace reconar
