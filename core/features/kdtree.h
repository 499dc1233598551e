#pragma once
// KdForest: a randomized kd-forest over 128-byte uint8 descriptors (Silpa-Anan & Hartley 2008,
// as popularised by FLANN) searched best-bin-first with one priority queue shared by all trees
// (Lowe 2004 / Beis & Lowe 1997), so the search stops after a fixed number of distance checks.
//
// The forest borrows its points: it keeps a pointer to the caller's row-major descriptor array
// (128 bytes per row), which must outlive it and stay unchanged. Nodes and the per-tree point
// permutations live in flat arrays (no per-node allocation). Each split node also keeps the data
// extents on both sides of its split, which tighten the search bounds. Searches write results into
// caller buffers and take all their working memory from a KdSearchScratch (per thread,
// arena-backed), so a search makes no allocation. Build and search are deterministic for a seed.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/base/arena.h"
#include "core/base/prng.h"
#include "core/base/status.h"
#include "core/features/descriptor_distance.h"

namespace reconar {

struct KdForestOptions {
  int num_trees = 4;
  // A node with at most this many points becomes a leaf (searched whole, batched SIMD distances).
  // Recall per check is best with single-point leaves (as FLANN); larger leaves trade recall at a
  // fixed budget for speed (two fountain-P11 SIFT pairs, 200 checks, 4 seeds: recall@1 0.968 /
  // 0.959 / 0.948 / 0.930 for leaves of 1 / 2 / 4 / 8, time about 1 : 0.55 : 0.4 : 0.25).
  int leaf_size = 1;
  // Default search budget: distinct descriptors whose distance is computed (FLANN's "checks";
  // Lowe's paper checks ~200 candidates). Once k neighbours are known and this many have been
  // checked, the search stops (the leaf being scanned is cut short too).
  int max_leaf_checks = 200;
  // The split dimension of a node is drawn uniformly among its `num_top_dims` highest-variance
  // dimensions, estimated on up to `variance_samples` points of the node; the threshold lies
  // halfway between the mean and the middle of the node's range on that dimension.
  int num_top_dims = 5;
  int variance_samples = 100;
  static constexpr int kMaxVarianceSamples = 10000;
  uint64_t seed = 0x5eed'f00d'cafe'beefull;

  Status Check() const;
};

// Search counters, for tests and tuning.
struct KdSearchStats {
  int checks = 0;       // distance computations
  int leaves = 0;       // leaves entered
  int queued = 0;       // branches queued
};

class KdForest;

// Working memory of one search at a time (so one per thread): a visited stamp per point, which
// deduplicates points met in several trees, and the branch queue. Sized for a forest; it also
// serves any forest with no more points, inner nodes and leaf points.
class KdSearchScratch {
 public:
  KdSearchScratch() = default;
  // Owns its memory (one allocation).
  explicit KdSearchScratch(const KdForest& forest);
  KdSearchScratch(KdSearchScratch&&) = default;
  KdSearchScratch& operator=(KdSearchScratch&&) = default;

  // Bytes InitFromArena needs, alignment padding included.
  static size_t RequiredBytes(const KdForest& forest);
  // Takes the buffers from `arena`; they are valid until the arena is reset below this point.
  // ResourceExhausted if the arena is too small (the arena is then left as it was).
  Status InitFromArena(const KdForest& forest, Arena* arena);

  bool Fits(const KdForest& forest) const;

 private:
  friend class KdForest;
  struct Sizes {
    int points = 0;
    int queue = 0;  // every child of every inner node can be queued once per search
    int leaf_points = 0;
  };
  static Sizes SizesFor(const KdForest& forest);
  static size_t BytesFor(const Sizes& sizes);
  uint32_t NextStamp();

  Sizes sizes_;
  uint32_t* stamps_ = nullptr;     // sizes_.points
  uint32_t stamp_ = 0;
  // The branch queue (a radix heap): entry i has key queue_keys_[i] (the bound), value
  // queue_refs_[i] (a child reference) and the next entry of its bucket queue_links_[i].
  uint32_t* queue_keys_ = nullptr;  // sizes_.queue
  int32_t* queue_refs_ = nullptr;   // sizes_.queue
  int32_t* queue_links_ = nullptr;  // sizes_.queue
  int32_t* candidates_ = nullptr;  // sizes_.leaf_points
  int32_t* candidate_distances_ = nullptr;
  std::unique_ptr<Arena> owned_;
};

class KdForest {
 public:
  KdForest() = default;  // an empty forest: every search finds nothing
  KdForest(KdForest&&) = default;
  KdForest& operator=(KdForest&&) = default;
  KdForest(const KdForest&) = delete;
  KdForest& operator=(const KdForest&) = delete;

  // Builds over `count` descriptors at `descriptors` (count * 128 bytes, borrowed, not copied).
  // count == 0 gives an empty forest. InvalidArgument on bad options, count < 0, or a null
  // pointer with count > 0.
  static Result<KdForest> Build(const uint8_t* descriptors, int count, const KdForestOptions& options);

  // Approximate k nearest neighbours of `query` (128 bytes) in squared L2. Writes up to k results
  // sorted by increasing distance to indices[0..k) and squared_distances[0..k); slots beyond the
  // number found (returned; min(k, size())) get index -1 and distance INT32_MAX.
  // max_leaf_checks <= 0 uses options().max_leaf_checks. `scratch` must Fit this forest.
  int Search(const uint8_t* query, int k, int max_leaf_checks, int* indices, int* squared_distances,
             KdSearchScratch* scratch, KdSearchStats* stats = nullptr) const;

  int size() const { return count_; }
  bool empty() const { return count_ == 0; }
  const uint8_t* descriptors() const { return descriptors_; }
  const KdForestOptions& options() const { return options_; }
  int num_trees() const { return static_cast<int>(roots_.size()); }
  int num_nodes() const { return static_cast<int>(nodes_.size()); }  // single points are not nodes
  int num_inner_nodes() const { return num_inner_nodes_; }
  int max_depth() const { return max_depth_; }
  int max_leaf_points() const { return max_leaf_points_; }
  size_t memory_bytes() const;  // owned bytes (the borrowed descriptors excluded)

 private:
  // Inner nodes split on `dim`: the left child holds the points with value < threshold, and keeps
  // the extents of both sides on that dimension (left_max < threshold <= right_min), which give
  // tighter bounds than the threshold where the data leaves a gap around it.
  // A child reference is a node index (>= 0) or, for a single point, PointRef(id) (< 0).
  static constexpr int32_t PointRef(int32_t id) { return -id - 1; }
  static constexpr int32_t PointOfRef(int32_t ref) { return -ref - 1; }
  static constexpr int16_t kRangeLeaf = -1;   // leaf: point_ids_[first, second)
  static constexpr int16_t kInlineLeaf = -2;  // leaf of 1-2 points: ids first and second (or -1)
  struct Node {
    int32_t first;      // inner: left child reference; leaf: see kRangeLeaf / kInlineLeaf
    int32_t second;     // inner: right child reference
    int16_t dim;        // split dimension, or a leaf kind (< 0)
    uint8_t left_max;   // largest value on `dim` in the left child
    uint8_t right_min;  // smallest value on `dim` in the right child
  };
  struct BuildTask {
    int32_t node;
    int32_t begin;
    int32_t end;
    int32_t depth;
  };
  class SearchState;

  void BuildTree(int tree, SplitMix64* random, std::vector<BuildTask>* stack);
  bool ChooseSplit(int begin, int end, SplitMix64* random, int* dim, int* threshold) const;

  const uint8_t* descriptors_ = nullptr;
  int count_ = 0;
  KdForestOptions options_;
  std::vector<Node> nodes_;
  std::vector<int32_t> roots_;
  std::vector<int32_t> point_ids_;  // num_trees * count, each tree's permutation of 0..count-1
  int num_inner_nodes_ = 0;
  int max_depth_ = 0;
  int max_leaf_points_ = 0;
  const DescriptorDistanceKernel* kernel_ = nullptr;
};

// Exact k nearest neighbours by linear scan (reference for tests and recall measurements).
// Same output convention as KdForest::Search; ties keep the lower index first.
int BruteForceKnn(const uint8_t* query, const uint8_t* descriptors, int count, int k, int* indices,
                  int* squared_distances);

}  // namespace reconar
