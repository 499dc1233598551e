#include "core/features/matcher.h"

#include <algorithm>
#include <chrono>
#include <functional>
#include <string>
#include <utility>

#include "core/base/arena.h"
#include "core/base/elapsed.h"
#include "core/base/thread_pool.h"

namespace reconar {
namespace internal {

// Reused across pairs: the pool, one search arena + scratch per worker, and the per-pair buffers.
class MatchWorkspace {
 public:
  explicit MatchWorkspace(int num_threads)
      : pool_(num_threads), arenas_(static_cast<size_t>(pool_.num_threads())),
        scratches_(static_cast<size_t>(pool_.num_threads())) {}

  // k nearest neighbours of queries[id] for id = query_ids[i] (or i when query_ids is null),
  // written to out_indices / out_distances[i * k, (i + 1) * k). forest == nullptr: linear scan of
  // `base` (count rows) instead.
  Status SearchAll(const KdForest* forest, const uint8_t* base, int count, const uint8_t* queries,
                   const int* query_ids, int num_queries, int k, int max_checks, int* out_indices,
                   int* out_distances) {
    if (forest != nullptr) {
      const size_t bytes = KdSearchScratch::RequiredBytes(*forest);
      for (size_t w = 0; w < arenas_.size(); ++w) {
        if (arenas_[w] == nullptr || arenas_[w]->capacity() < bytes) arenas_[w] = std::make_unique<Arena>(bytes);
        arenas_[w]->Reset();
        RECONAR_RETURN_IF_ERROR(scratches_[w].InitFromArena(*forest, arenas_[w].get()));
      }
    }
    constexpr int kChunk = 32;  // queries per ParallelFor item
    const size_t num_chunks = static_cast<size_t>((num_queries + kChunk - 1) / kChunk);
    pool_.ParallelFor(0, num_chunks, [&](size_t chunk, int worker) {
      const int begin = static_cast<int>(chunk) * kChunk;
      const int end = std::min(num_queries, begin + kChunk);
      for (int i = begin; i < end; ++i) {
        const int id = query_ids != nullptr ? query_ids[i] : i;
        const uint8_t* query = queries + static_cast<int64_t>(id) * kDescriptorSize;
        int* indices = out_indices + static_cast<int64_t>(i) * k;
        int* distances = out_distances + static_cast<int64_t>(i) * k;
        if (forest != nullptr) {
          forest->Search(query, k, max_checks, indices, distances, &scratches_[static_cast<size_t>(worker)]);
        } else {
          BruteForceKnn(query, base, count, k, indices, distances);
        }
      }
    });
    return Status::Ok();
  }

  std::vector<int> knn_indices;
  std::vector<int> knn_distances;
  std::vector<int> ratio_passed;  // index_a of each ratio-test survivor
  std::vector<int> best_a_for_b;
  std::vector<int> reverse_queries;
  std::vector<int> reverse_indices;
  std::vector<int> reverse_distances;

 private:
  ThreadPool pool_;
  std::vector<std::unique_ptr<Arena>> arenas_;
  std::vector<KdSearchScratch> scratches_;
};

}  // namespace internal

namespace {

using Clock = std::chrono::steady_clock;
// Returns the forest to search (nullptr: brute force). Adds its build time to the report.
using ForestProvider = std::function<Result<const KdForest*>(MatchReport*)>;

Status CheckInput(const char* name, const uint8_t* descriptors, int count) {
  if (count < 0) return InvalidArgument(std::string("matching: negative descriptor count for ") + name);
  if (count > 0 && descriptors == nullptr) return InvalidArgument(std::string("matching: null descriptors for ") + name);
  return Status::Ok();
}

Result<std::vector<FeatureMatch>> MatchCore(const uint8_t* desc_a, int count_a, const uint8_t* desc_b, int count_b,
                                            const MatchOptions& options, const ForestProvider& forest_a,
                                            const ForestProvider& forest_b, internal::MatchWorkspace* ws,
                                            MatchReport* report) {
  const Clock::time_point start = Clock::now();
  MatchReport local;
  std::vector<FeatureMatch> matches;
  auto finish = [&]() {
    local.num_matches = static_cast<int>(matches.size());
    local.search_seconds = std::max(0.0, SecondsSince(start) - local.build_seconds);
    if (report != nullptr) *report = local;
  };
  if (count_a == 0 || count_b < 2) {
    finish();
    return matches;
  }

  // 1. Two nearest neighbours in B of every descriptor of A.
  RECONAR_ASSIGN_OR_RETURN(const KdForest* tree_b, forest_b(&local));
  local.num_queries = count_a;
  ws->knn_indices.resize(2 * static_cast<size_t>(count_a));
  ws->knn_distances.resize(2 * static_cast<size_t>(count_a));
  RECONAR_RETURN_IF_ERROR(ws->SearchAll(tree_b, desc_b, count_b, desc_a, nullptr, count_a, 2, options.max_leaf_checks,
                                        ws->knn_indices.data(), ws->knn_distances.data()));

  // 2. Ratio test, d1 < r * d2 on distances, i.e. d1^2 < r^2 * d2^2 on the squared ones.
  const double ratio_sq = options.max_ratio * options.max_ratio;
  ws->ratio_passed.clear();
  ws->best_a_for_b.assign(static_cast<size_t>(count_b), -1);
  for (int a = 0; a < count_a; ++a) {
    const int b1 = ws->knn_indices[2 * static_cast<size_t>(a)];
    const int b2 = ws->knn_indices[2 * static_cast<size_t>(a) + 1];
    if (b1 < 0 || b2 < 0) continue;
    const int d1 = ws->knn_distances[2 * static_cast<size_t>(a)];
    const int d2 = ws->knn_distances[2 * static_cast<size_t>(a) + 1];
    if (!(static_cast<double>(d1) < ratio_sq * static_cast<double>(d2))) continue;
    ws->ratio_passed.push_back(a);
    // 3. One A per B: the closest wins, the lowest index_a on ties (a increases).
    int& best = ws->best_a_for_b[static_cast<size_t>(b1)];
    if (best < 0 || d1 < ws->knn_distances[2 * static_cast<size_t>(best)]) best = a;
  }
  local.num_ratio_passed = static_cast<int>(ws->ratio_passed.size());
  matches.reserve(ws->ratio_passed.size());
  for (const int a : ws->ratio_passed) {
    const int b = ws->knn_indices[2 * static_cast<size_t>(a)];
    if (ws->best_a_for_b[static_cast<size_t>(b)] == a) {
      matches.push_back({a, b});
    } else {
      ++local.num_many_to_one_dropped;
    }
  }

  // 4. Mutual check: the nearest neighbour in A of each matched b must be its a.
  if (options.cross_check && !matches.empty()) {
    RECONAR_ASSIGN_OR_RETURN(const KdForest* tree_a, forest_a(&local));
    const int n = static_cast<int>(matches.size());
    ws->reverse_queries.resize(static_cast<size_t>(n));
    ws->reverse_indices.resize(static_cast<size_t>(n));
    ws->reverse_distances.resize(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) ws->reverse_queries[static_cast<size_t>(i)] = matches[static_cast<size_t>(i)].index_b;
    RECONAR_RETURN_IF_ERROR(ws->SearchAll(tree_a, desc_a, count_a, desc_b, ws->reverse_queries.data(), n, 1,
                                          options.max_leaf_checks, ws->reverse_indices.data(),
                                          ws->reverse_distances.data()));
    size_t kept = 0;
    for (int i = 0; i < n; ++i) {
      if (ws->reverse_indices[static_cast<size_t>(i)] == matches[static_cast<size_t>(i)].index_a) {
        matches[kept++] = matches[static_cast<size_t>(i)];
      }
    }
    local.num_cross_check_dropped = n - static_cast<int>(kept);
    matches.resize(kept);
  }
  finish();
  return matches;
}

// A provider that builds a forest into `storage` on first call.
ForestProvider BuildOnce(const uint8_t* descriptors, int count, const KdForestOptions& options,
                         std::unique_ptr<KdForest>* storage) {
  return [=](MatchReport* report) -> Result<const KdForest*> {
    if (*storage == nullptr) {
      const Clock::time_point start = Clock::now();
      RECONAR_ASSIGN_OR_RETURN(KdForest forest, KdForest::Build(descriptors, count, options));
      *storage = std::make_unique<KdForest>(std::move(forest));
      report->build_seconds += SecondsSince(start);
      ++report->forests_built;
    }
    return static_cast<const KdForest*>(storage->get());
  };
}

}  // namespace

Status MatchOptions::Check() const {
  if (!(max_ratio > 0.0 && max_ratio <= 1.0)) {
    return InvalidArgument("MatchOptions: max_ratio must be in (0, 1], got " + std::to_string(max_ratio));
  }
  return ForestOptions().Check();
}

KdForestOptions MatchOptions::ForestOptions() const {
  KdForestOptions forest;
  forest.num_trees = num_trees;
  forest.leaf_size = leaf_size;
  forest.max_leaf_checks = max_leaf_checks;
  return forest;
}

Status CheckMatchInputs(const uint8_t* desc_a, int count_a, const uint8_t* desc_b, int count_b,
                        const MatchOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  RECONAR_RETURN_IF_ERROR(CheckInput("A", desc_a, count_a));
  return CheckInput("B", desc_b, count_b);
}

Result<std::vector<FeatureMatch>> MatchDescriptors(const uint8_t* desc_a, int count_a, const uint8_t* desc_b,
                                                   int count_b, const MatchOptions& options, MatchReport* report) {
  RECONAR_RETURN_IF_ERROR(CheckMatchInputs(desc_a, count_a, desc_b, count_b, options));
  internal::MatchWorkspace workspace(options.num_threads);
  std::unique_ptr<KdForest> forest_a;
  std::unique_ptr<KdForest> forest_b;
  const KdForestOptions forest_options = options.ForestOptions();
  return MatchCore(desc_a, count_a, desc_b, count_b, options, BuildOnce(desc_a, count_a, forest_options, &forest_a),
                   BuildOnce(desc_b, count_b, forest_options, &forest_b), &workspace, report);
}

Result<std::vector<FeatureMatch>> BruteForceMatch(const uint8_t* desc_a, int count_a, const uint8_t* desc_b,
                                                  int count_b, const MatchOptions& options, MatchReport* report) {
  RECONAR_RETURN_IF_ERROR(CheckMatchInputs(desc_a, count_a, desc_b, count_b, options));
  internal::MatchWorkspace workspace(options.num_threads);
  const ForestProvider none = [](MatchReport*) -> Result<const KdForest*> {
    return static_cast<const KdForest*>(nullptr);
  };
  return MatchCore(desc_a, count_a, desc_b, count_b, options, none, none, &workspace, report);
}

// ---------------------------------------------------------------------------------------------
// Matcher

Matcher::Matcher(const MatchOptions& options)
    : options_(options), workspace_(std::make_unique<internal::MatchWorkspace>(options.num_threads)) {}

Matcher::~Matcher() = default;

Result<std::unique_ptr<Matcher>> Matcher::Create(const MatchOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  return std::unique_ptr<Matcher>(new Matcher(options));
}

Status Matcher::AddImage(int image_id, const uint8_t* descriptors, int count) {
  RECONAR_RETURN_IF_ERROR(CheckInput(("image " + std::to_string(image_id)).c_str(), descriptors, count));
  ImageEntry& entry = images_[image_id];
  entry.descriptors = descriptors;
  entry.count = count;
  entry.forest.reset();
  return Status::Ok();
}

void Matcher::RemoveImage(int image_id) { images_.erase(image_id); }

Result<std::vector<FeatureMatch>> Matcher::Match(int image_a, int image_b, MatchReport* report) {
  auto it_a = images_.find(image_a);
  auto it_b = images_.find(image_b);
  if (it_a == images_.end()) return NotFound("matcher: image " + std::to_string(image_a) + " was not added");
  if (it_b == images_.end()) return NotFound("matcher: image " + std::to_string(image_b) + " was not added");
  ImageEntry& a = it_a->second;
  ImageEntry& b = it_b->second;
  const KdForestOptions forest_options = options_.ForestOptions();
  return MatchCore(a.descriptors, a.count, b.descriptors, b.count, options_,
                   BuildOnce(a.descriptors, a.count, forest_options, &a.forest),
                   BuildOnce(b.descriptors, b.count, forest_options, &b.forest), workspace_.get(), report);
}

size_t Matcher::forest_memory_bytes() const {
  size_t bytes = 0;
  for (const auto& item : images_) {
    if (item.second.forest != nullptr) bytes += item.second.forest->memory_bytes();
  }
  return bytes;
}

}  // namespace reconar
