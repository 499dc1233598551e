#pragma once
// Descriptor matching between two images: approximate nearest neighbours in a KdForest built on
// image B, Lowe's ratio test, one-to-one enforcement and an optional mutual (cross) check.
//
// Pipeline for every descriptor a of A (in this order):
//   1. its two nearest neighbours b1, b2 in B (kd-forest, `max_leaf_checks` checks);
//   2. ratio test on distances (not squared): keep (a, b1) iff d(a,b1) < max_ratio * d(a,b2);
//   3. many-to-one: of the survivors sharing one b, only the one closest to b is kept (equal
//      distances: the lowest index_a); the others are dropped;
//   4. cross_check: b's nearest neighbour in A (kd-forest on A, 1-NN, no ratio test) must be a.
// B with fewer than 2 descriptors (no second neighbour, so no ratio test) or an empty A gives an
// empty match list. Matches are sorted by index_a. Results do not depend on num_threads.
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include "core/base/status.h"
#include "core/features/kdtree.h"

namespace reconar {

struct MatchOptions {
  double max_ratio = 0.6;    // Lowe ratio on distances, in (0, 1]
  bool cross_check = false;  // also require the match to be mutual (forest on A too)
  int max_leaf_checks = 200;
  int num_trees = 4;
  int leaf_size = KdForestOptions{}.leaf_size;
  int num_threads = 1;  // <= 0: one per core

  Status Check() const;
  KdForestOptions ForestOptions() const;
};

struct FeatureMatch {
  int index_a = -1;
  int index_b = -1;
};

inline bool operator==(const FeatureMatch& x, const FeatureMatch& y) {
  return x.index_a == y.index_a && x.index_b == y.index_b;
}

struct MatchReport {
  int num_queries = 0;                // descriptors of A searched
  int num_ratio_passed = 0;           // survived the ratio test
  int num_many_to_one_dropped = 0;    // lost to a closer A on the same B
  int num_cross_check_dropped = 0;    // not mutual
  int num_matches = 0;
  int forests_built = 0;
  double build_seconds = 0.0;         // forest construction
  double search_seconds = 0.0;        // all searches and filtering
};

// Matches A against B with kd-forests (built here, B always, A too when cross-checking).
// `desc_a` holds count_a rows of 128 bytes, likewise B. InvalidArgument on bad options, negative
// counts or null pointers with a positive count.
Result<std::vector<FeatureMatch>> MatchDescriptors(const uint8_t* desc_a, int count_a, const uint8_t* desc_b,
                                                   int count_b, const MatchOptions& options,
                                                   MatchReport* report = nullptr);

// The same pipeline with exact nearest neighbours by linear scan (reference for tests and
// recall; max_leaf_checks, num_trees and leaf_size are ignored).
Result<std::vector<FeatureMatch>> BruteForceMatch(const uint8_t* desc_a, int count_a, const uint8_t* desc_b,
                                                  int count_b, const MatchOptions& options,
                                                  MatchReport* report = nullptr);

namespace internal {
class MatchWorkspace;
}

// Matches many image pairs (exhaustive or sequential matching) with each image's forest built
// once, on first use, and cached; the thread pool and per-worker search arenas are reused across
// pairs. Descriptors are borrowed and must outlive the Matcher (or RemoveImage). One Match call at
// a time (it is parallel inside).
class Matcher {
 public:
  static Result<std::unique_ptr<Matcher>> Create(const MatchOptions& options);
  ~Matcher();
  Matcher(const Matcher&) = delete;
  Matcher& operator=(const Matcher&) = delete;

  // Registers (or replaces) an image's descriptors. InvalidArgument on count < 0 or null data.
  Status AddImage(int image_id, const uint8_t* descriptors, int count);
  void RemoveImage(int image_id);  // drops its cached forest too
  bool HasImage(int image_id) const { return images_.count(image_id) != 0; }

  // Matches image_a (queries) against image_b; NotFound for an unregistered image.
  Result<std::vector<FeatureMatch>> Match(int image_a, int image_b, MatchReport* report = nullptr);

  const MatchOptions& options() const { return options_; }
  size_t forest_memory_bytes() const;

 private:
  struct ImageEntry {
    const uint8_t* descriptors = nullptr;
    int count = 0;
    std::unique_ptr<KdForest> forest;  // built on first use
  };
  explicit Matcher(const MatchOptions& options);

  MatchOptions options_;
  std::unordered_map<int, ImageEntry> images_;
  std::unique_ptr<internal::MatchWorkspace> workspace_;
};

}  // namespace reconar
