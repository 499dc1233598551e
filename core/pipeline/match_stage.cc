#include "core/pipeline/match_stage.h"

#include <chrono>
#include <memory>
#include <optional>
#include <sstream>

#include "core/base/atomic_file.h"
#include "core/base/progress.h"
#include "core/base/thread_pool.h"
#include "core/features/sift/sift_io.h"

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

}  // namespace

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

Result<MatchStageReport> RunMatchStage(const Project& project, const MatchStageOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.match.Check());
  RECONAR_RETURN_IF_ERROR(options.two_view.Check());
  const auto start = Clock::now();
  RECONAR_ASSIGN_OR_RETURN(const std::vector<ProjectImage> images, project.ReadImageList());
  if (images.size() < 2) {
    return InvalidArgument(project.ImageListPath() + ": matching needs at least two images, the project has " +
                           std::to_string(images.size()));
  }
  std::vector<FeatureFile> files;
  files.reserve(images.size());
  for (const ProjectImage& image : images) {
    RECONAR_ASSIGN_OR_RETURN(FeatureFile file, ReadFeatureFile(project.FeaturePath(image.name)));
    files.push_back(std::move(file));
  }
  std::vector<std::pair<int, int>> pairs;
  for (int i = 0; i < static_cast<int>(images.size()); ++i) {
    for (int j = i + 1; j < static_cast<int>(images.size()); ++j) pairs.emplace_back(i, j);
  }

  const int threads = std::min<int>(ThreadPool::ResolveThreadCount(options.num_threads), static_cast<int>(pairs.size()));
  ThreadPool pool(threads);
  MatchOptions per_worker = options.match;
  per_worker.num_threads = 1;
  std::vector<std::unique_ptr<Matcher>> matchers(pool.num_threads());
  for (auto& matcher : matchers) {
    RECONAR_ASSIGN_OR_RETURN(matcher, Matcher::Create(per_worker));
    for (size_t i = 0; i < files.size(); ++i) {
      const SiftFeatures& f = files[i].features;
      RECONAR_RETURN_IF_ERROR(matcher->AddImage(static_cast<int>(i), f.descriptors.data(),
                                                static_cast<int>(f.keypoints.size())));
    }
  }
  std::vector<std::optional<VerifiedPair>> results(pairs.size());
  std::vector<Status> errors(pairs.size());
  std::optional<Progress> progress;
  if (options.show_progress) progress.emplace("matching", pairs.size());
  pool.ParallelFor(0, pairs.size(), [&](size_t p, int worker) {
    const auto [i, j] = pairs[p];
    auto putative = matchers[worker]->Match(i, j);
    if (!putative.ok()) {
      errors[p] = putative.status();
    } else {
      auto verified = VerifyMatches(files[i].features, files[i].image_width, files[i].image_height,
                                    files[j].features, files[j].image_width, files[j].image_height, *putative,
                                    options.two_view);
      if (verified.ok()) {
        verified->image_a = i;
        verified->image_b = j;
        results[p] = std::move(verified).value();
      } else {
        errors[p] = verified.status().WithContext(images[i].name + " / " + images[j].name);
      }
    }
    if (progress) progress->Advance();
  });
  if (progress) progress->Finish();
  for (const Status& status : errors) RECONAR_RETURN_IF_ERROR(status);

  MatchStageReport report;
  report.num_images = static_cast<int>(images.size());
  report.num_pairs = static_cast<int>(pairs.size());
  std::ostringstream out;
  out << "# reconar matches v1\n";
  out.precision(12);
  for (auto& result : results) {
    switch (result->geometry.config) {
      case TwoViewGeometry::Config::kVerified: ++report.num_verified; break;
      case TwoViewGeometry::Config::kPlanarOrRotation: ++report.num_planar; break;
      case TwoViewGeometry::Config::kTooFewInliers: ++report.num_rejected; continue;
    }
    const TwoViewGeometry& g = result->geometry;
    out << "pair " << images[result->image_a].name << ' ' << images[result->image_b].name << ' '
        << (g.config == TwoViewGeometry::Config::kVerified ? "verified" : "planar") << ' '
        << result->inlier_matches.size();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) out << ' ' << g.F(r, c);
    }
    out << '\n';
    for (const FeatureMatch& m : result->inlier_matches) out << m.index_a << ' ' << m.index_b << '\n';
    report.pairs.push_back(std::move(*result));
  }
  RECONAR_RETURN_IF_ERROR(CreateDirectories(project.MatchesDir()));
  RECONAR_RETURN_IF_ERROR(WriteFileAtomically(project.MatchesPath(), out.str()));
  report.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return report;
}

Result<std::vector<MatchesFilePair>> ReadMatchesFile(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path));
  std::istringstream in(text);
  std::vector<MatchesFilePair> pairs;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string tag;
    MatchesFilePair pair;
    size_t count = 0;
    if (!(fields >> tag >> pair.name_a >> pair.name_b >> pair.config >> count) || tag != "pair") {
      return FileError(StatusCode::kCorruptData, path, "expected a 'pair' line, got: " + line.substr(0, 80));
    }
    if (pair.config != "verified" && pair.config != "planar") {
      return FileError(StatusCode::kCorruptData, path,
                       "pair config must be 'verified' or 'planar', got: " + line.substr(0, 80));
    }
    for (int k = 0; k < 9; ++k) fields >> pair.F(k / 3, k % 3);
    if (!fields) return FileError(StatusCode::kCorruptData, path, "bad F on pair line: " + line.substr(0, 80));
    pair.matches.resize(count);
    for (FeatureMatch& m : pair.matches) {
      if (!std::getline(in, line)) return FileError(StatusCode::kCorruptData, path, "truncated match list");
      std::istringstream match_fields(line);
      if (!(match_fields >> m.index_a >> m.index_b)) {
        return FileError(StatusCode::kCorruptData, path, "bad match line: " + line.substr(0, 80));
      }
    }
    pairs.push_back(std::move(pair));
  }
  return pairs;
}

}  // namespace reconar
