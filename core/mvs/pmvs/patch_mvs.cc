#include "core/mvs/pmvs/patch_mvs.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <numeric>
#include <string>

#include "core/base/elapsed.h"
#include "core/base/progress.h"
#include "core/base/thread_pool.h"
#include "core/mvs/pmvs/image_features.h"
#include "core/mvs/pmvs/initial_matching.h"
#include "core/mvs/pmvs/patch_cell_grid.h"
#include "core/mvs/pmvs/patch_expansion.h"
#include "core/mvs/pmvs/patch_filter.h"
#include "core/mvs/pmvs/patch_sampler.h"
#include "core/mvs/pmvs/pmvs_view.h"

namespace reconar {
namespace {

Status CheckViews(const std::vector<const DenseView*>& views, int min_views) {
  if (static_cast<int>(views.size()) < min_views) {
    return FailedPrecondition("patch MVS: " + std::to_string(views.size()) + " views, need at least " +
                              std::to_string(min_views));
  }
  for (size_t i = 0; i < views.size(); ++i) {
    const DenseView* v = views[i];
    const std::string name = "patch MVS: view " + std::to_string(i) + (v ? " (" + v->name + ")" : "");
    if (v == nullptr) return InvalidArgument(name + ": null");
    if (v->gray.empty() || v->gray.channels() != 1) return InvalidArgument(name + ": no single-channel grey image");
    if (v->rgb.width() != v->gray.width() || v->rgb.height() != v->gray.height() || v->rgb.channels() != 3) {
      return InvalidArgument(name + ": the rgb image does not match the grey one");
    }
    if (!(v->fx > 0.0 && v->fy > 0.0) || !std::isfinite(v->cx) || !std::isfinite(v->cy) ||
        !v->cam_from_world.rotation.allFinite() || !v->cam_from_world.translation.allFinite()) {
      return InvalidArgument(name + ": invalid intrinsics or pose");
    }
  }
  return Status::Ok();
}

}  // namespace

Status PatchMvsOptions::Check() const {
  if (patch_size < 3 || patch_size > PatchSampler::kMaxPatchSize || patch_size % 2 == 0) {
    return InvalidArgument("patch MVS: patch_size must be odd in [3, " +
                           std::to_string(PatchSampler::kMaxPatchSize) + "], got " + std::to_string(patch_size));
  }
  if (cell_size < 1) return InvalidArgument("patch MVS: cell_size must be positive");
  if (!(max_view_angle > 0.0 && max_view_angle < M_PI / 2)) {
    return InvalidArgument("patch MVS: max_view_angle must lie in (0, pi/2)");
  }
  if (!(min_ncc > -1.0 && min_ncc < 1.0)) return InvalidArgument("patch MVS: min_ncc must lie in (-1, 1)");
  if (!(image_noise_std >= 0.0 && image_noise_std < 64.0)) {
    return InvalidArgument("patch MVS: image_noise_std must lie in [0, 64) grey levels");
  }
  if (min_visible_views < 2) return InvalidArgument("patch MVS: min_visible_views must be at least 2");
  if (expansion_iterations < 0) return InvalidArgument("patch MVS: expansion_iterations must be >= 0");
  return Status::Ok();
}

Result<OrientedPoints> RunPatchMvs(const std::vector<const DenseView*>& dense_views, const PatchMvsOptions& options,
                                   PatchMvsReport* report) {
  if (Status s = options.Check(); !s.ok()) return s;
  if (Status s = CheckViews(dense_views, options.min_visible_views); !s.ok()) return s;
  PatchMvsReport local_report;
  PatchMvsReport& r = report ? *report : local_report;
  r = PatchMvsReport();

  std::vector<PmvsView> views;
  views.reserve(dense_views.size());
  for (const DenseView* v : dense_views) views.emplace_back(*v);
  ThreadPool pool(options.num_threads);
  const int num_views = static_cast<int>(views.size());

  auto start = std::chrono::steady_clock::now();
  std::vector<std::vector<SeedFeature>> features(num_views);
  pool.ParallelFor(0, num_views, [&](size_t i, int) {
    const Image<uint8_t>& gray = dense_views[i]->gray;
    features[i] = DetectSeedFeatures(gray.view(), SeedFeatureOptions());
  });
  for (const auto& f : features) r.features += f.size();
  r.seconds_features = SecondsSince(start);

  start = std::chrono::steady_clock::now();
  std::vector<Patch> patches;
  PatchCellGrids grids(views, options.cell_size);
  r.initial_patches = MatchSeedFeatures(views, features, options, &pool, &patches, &grids);
  r.seconds_matching = SecondsSince(start);
  features.clear();

  std::unique_ptr<Progress> progress;
  if (options.show_progress)
    progress = std::make_unique<Progress>(options.progress_label, options.expansion_iterations);
  for (int iteration = 0; iteration < options.expansion_iterations; ++iteration) {
    start = std::chrono::steady_clock::now();
    std::vector<int> seeds(patches.size());
    std::iota(seeds.begin(), seeds.end(), 0);
    r.expanded_patches += ExpandPatches(views, options, std::move(seeds), &pool, &patches, &grids);
    r.seconds_expansion += SecondsSince(start);
    start = std::chrono::steady_clock::now();
    FilterPatches(views, options, &pool, &patches, &grids);
    r.seconds_filtering += SecondsSince(start);
    if (progress) progress->Advance();
  }
  if (progress) progress->Finish();
  if (options.expansion_iterations == 0) {
    start = std::chrono::steady_clock::now();
    FilterPatches(views, options, &pool, &patches, &grids);
    r.seconds_filtering += SecondsSince(start);
  }
  r.final_patches = patches.size();
  if (patches.empty()) {
    return FailedPrecondition("patch MVS: no patch survived (" + std::to_string(r.features) + " features, " +
                              std::to_string(r.initial_patches) + " initial patches); textureless or unrelated views?");
  }

  OrientedPoints out;
  out.positions.resize(patches.size());
  out.normals.resize(patches.size());
  out.colors.resize(patches.size());
  out.scores.resize(patches.size());
  std::vector<std::unique_ptr<PatchSampler>> samplers;
  // Colours only: no texture floor (every output patch already passed it).
  for (int w = 0; w < pool.num_threads(); ++w) {
    samplers.push_back(std::make_unique<PatchSampler>(views, options.patch_size, 0.0));
  }
  pool.ParallelFor(0, patches.size(), [&](size_t i, int worker) {
    const Patch& p = patches[i];
    out.positions[i] = p.center;
    out.normals[i] = p.normal.normalized();
    out.scores[i] = p.score;
    PatchSampler& sampler = *samplers[worker];
    sampler.SetPatch(p.center.cast<double>(), p.normal.cast<double>(), p.reference);
    const Eigen::Vector3f color = sampler.MeanReferenceColor();
    for (int c = 0; c < 3; ++c) out.colors[i][c] = static_cast<uint8_t>(std::clamp(color[c] + 0.5f, 0.0f, 255.0f));
  });
  return out;
}

}  // namespace reconar
